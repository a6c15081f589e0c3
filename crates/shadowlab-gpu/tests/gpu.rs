//! GPU integration tests (lavapipe in CI). A missing adapter fails them unless
//! SHADOWLAB_SKIP_GPU_TESTS=1 is set; CI never sets it.

use shadowlab_core::builtin::builtin;
use shadowlab_core::bvh::cpu_visibility;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;

use crate::common::*;

#[test]
fn rt_gpu_matches_cpu_on_every_builtin_scene_and_light() {
    let Some(gpu) = gpu() else { return };
    for s in shadowlab_core::builtin::BUILTIN_SCENES {
        let scene = (s.build)();
        let lab = Lab::new(&gpu, &scene).unwrap();
        for li in 0..scene.lights.len() {
            let v = view(&lab, &scene, li, 256);
            let rt = lab.reference(&v, 1).unwrap();
            let cpu = cpu_visibility(&lab.bvh, &scene, &scene.lights[li], &v.position, &v.normal, &v.mask, lab.gscene.eps);
            let m = compare(&rt.visibility, &cpu, &v.mask);
            assert!(m.evaluated_pixels > 1000, "{} light {li}: only {} evaluated pixels", s.name, m.evaluated_pixels);
            assert!(100.0 - m.wrong_pct >= 99.99, "{} light {li}: GPU/CPU agree on {:.4}%", s.name, 100.0 - m.wrong_pct);
            let lit = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.5).count();
            assert!(lit > 0 && (lit as u64) < m.evaluated_pixels, "{} light {li}: no shadow or no light at all", s.name);
            assert_eq!(rt.report.counters["rays_traced"] as u64, m.evaluated_pixels);
        }
    }
}

#[test]
fn sm_at_high_resolution_matches_rt_on_planebox() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    let sm = lab.run(&v, &TechniqueSpec::parse("sm:res=4096,pcf=1").unwrap(), 1).unwrap();
    let a = agreement(&sm.visibility, &rt.visibility, &v.mask);
    if a < 99.0 {
        panic!("sm 4096 agrees with rt on {a:.3}%; {}", save_images("sm4096-planebox", &v, &sm, &rt));
    }
    let s = sm.report.sampling.unwrap();
    assert!(s.used_texel_fraction > 0.0 && s.samples_per_used_texel_mean >= 1.0);
    assert_eq!(sm.report.shadow_data_bytes, 4096 * 4096 * 4);
}

#[test]
fn sm_error_falls_with_resolution_on_courtyard() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 512);
    let rt = lab.reference(&v, 1).unwrap();
    let wrong: Vec<f64> = [256, 512, 1024]
        .iter()
        .map(|r| {
            let run = lab.run(&v, &TechniqueSpec::parse(&format!("sm:res={r}")).unwrap(), 1).unwrap();
            compare(&run.visibility, &rt.visibility, &v.mask).wrong_pct
        })
        .collect();
    assert!(wrong[0] > wrong[1] && wrong[1] > wrong[2], "wrong % at 256/512/1024: {wrong:?}");
}

#[test]
fn same_run_twice_gives_identical_visibility() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let spec = TechniqueSpec::parse("sm:pcf=3").unwrap();
    let v1 = view(&lab, &scene, 0, 128);
    let a = lab.run(&v1, &spec, 1).unwrap();
    let v2 = view(&lab, &scene, 0, 128);
    let b = lab.run(&v2, &spec, 1).unwrap();
    assert_eq!(v1.mask, v2.mask);
    assert_eq!(a.visibility, b.visibility);
    assert_eq!(a.shaded, b.shaded);
}

#[test]
fn bad_requests_are_errors_not_panics() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    assert!(lab.view(&scene.camera, &scene.camera, &scene.lights[0], 0, 16).is_err());
    assert!(lab.view(&scene.camera, &scene.camera, &scene.lights[0], 1 << 20, 16).is_err());
    let v = view(&lab, &scene, 1, 32); // point light
    let e = lab.run(&v, &TechniqueSpec::parse("sm").unwrap(), 1).err().expect("sm on a point light must fail");
    assert!(e.to_string().contains("point"), "{e}");
    assert!(lab.run(&v, &TechniqueSpec::parse("nope").unwrap(), 1).is_err());
    assert!(lab.run(&v, &TechniqueSpec::parse("sm:res=3").unwrap(), 1).is_err());
}

#[test]
fn pcf_and_spot_maps_at_high_resolution_match_rt() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    let pcf = lab.run(&v, &TechniqueSpec::parse("sm:res=4096,pcf=3").unwrap(), 1).unwrap();
    let a = agreement(&pcf.visibility, &rt.visibility, &v.mask);
    if a < 99.0 {
        panic!("sm 4096 pcf 3 agrees with rt on {a:.3}%; {}", save_images("pcf-planebox", &v, &pcf, &rt));
    }
    assert_eq!(pcf.report.counters["fetches_per_pixel"], 9.0);
    // PCF gives fractional values at the shadow edge, and only there
    let fractional = pcf.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.01 && **x < 0.99).count();
    assert!(
        fractional > 0 && (fractional as f64) < 0.05 * v.mask.iter().filter(|m| **m != 0).count() as f64,
        "{fractional} fractional pixels"
    );

    let room = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &room).unwrap();
    let v = view(&lab, &room, 0, 256); // spot light
    let rt = lab.reference(&v, 1).unwrap();
    let sm = lab.run(&v, &TechniqueSpec::parse("sm:res=4096").unwrap(), 1).unwrap();
    let a = agreement(&sm.visibility, &rt.visibility, &v.mask);
    if a < 99.0 {
        panic!("spot sm 4096 agrees with rt on {a:.3}%; {}", save_images("spot-room", &v, &sm, &rt));
    }
}

/// A card whose texture is transparent on its left half floats over a floor under a vertical
/// light: the shadow must cover exactly the right half, for `rt` and for `sm`.
#[test]
fn alpha_cutouts_cast_exact_shadows() {
    use glam::{Vec2, Vec3};
    use shadowlab_core::builtin::MeshBuilder;
    use shadowlab_core::camera::Camera;
    use shadowlab_core::light::Light;
    use shadowlab_core::scene::{Material, Texture};
    let Some(gpu) = gpu() else { return };
    let mut b = MeshBuilder::default();
    let floor = b.material(Material::solid("floor", [0.8; 3]));
    let rgba: Vec<u8> = (0..8 * 8).flat_map(|i| if i % 8 < 4 { [255, 0, 0, 0] } else { [255, 0, 0, 255] }).collect();
    let tex = b.texture(Texture { name: "half".into(), width: 8, height: 8, rgba });
    let card = b.material(Material { texture: Some(tex), alpha_cutoff: Some(0.5), ..Material::solid("card", [1.0; 3]) });
    b.quad(Vec3::new(-4.0, 0.0, 4.0), Vec3::new(8.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -8.0), Vec2::ONE, floor);
    // card spans x in [-1, 1]; uv.x = 0 at x = -1
    b.quad(Vec3::new(-1.0, 1.0, 1.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -2.0), Vec2::ONE, card);
    let cam = Camera::new(Vec3::new(0.0, 6.0, 0.01), Vec3::ZERO, 60.0, 0.1, 20.0);
    let scene = b.finish("cutout", cam, vec![Light::Directional { direction: -Vec3::Y }], vec![]);
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = lab.view(&cam, &cam, &scene.lights[0], 128, 128).unwrap();
    let rt = lab.reference(&v, 1).unwrap();
    let sm = lab.run(&v, &TechniqueSpec::parse("sm:res=2048").unwrap(), 1).unwrap();
    let (mut checked, mut wrong_rt, mut wrong_sm) = (0, 0, 0);
    for i in 0..v.mask.len() {
        let p = v.position[i];
        // floor pixels away from the card's outline and from the alpha edge at x = 0
        if v.mask[i] == 0 || p[1] > 0.5 || p[2].abs() > 0.9 || p[0].abs() > 0.9 || p[0].abs() < 0.1 {
            continue;
        }
        let expect_lit = p[0] < 0.0;
        checked += 1;
        wrong_rt += ((rt.visibility[i] >= 0.5) != expect_lit) as u32;
        wrong_sm += ((sm.visibility[i] >= 0.5) != expect_lit) as u32;
    }
    assert!(checked > 500, "only {checked} floor pixels under the card");
    assert_eq!(wrong_rt, 0, "rt ignores or misplaces the cut-out");
    assert_eq!(wrong_sm, 0, "sm ignores or misplaces the cut-out");
}

#[test]
fn motion_vectors_match_the_camera_motion() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let cam = scene.camera;
    let mut prev = cam;
    prev.position += glam::Vec3::new(0.3, 0.05, -0.2);
    prev.target += glam::Vec3::new(0.3, 0.0, 0.0);
    let (w, h) = (64, 48);
    let v = lab.view(&cam, &prev, &scene.lights[0], w, h).unwrap();
    let motion: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&v.gbuffer.motion, 8));
    let mut checked = 0;
    for y in (0..h).step_by(7) {
        for x in (0..w).step_by(7) {
            let i = (y * w + x) as usize;
            let p = v.position[i];
            if p[3] <= 0.0 {
                continue;
            }
            let world = glam::Vec3::new(p[0], p[1], p[2]);
            let now = cam.project_to_pixel(world, w, h).unwrap();
            let before = prev.project_to_pixel(world, w, h).unwrap();
            let expect = now - before;
            let got = glam::Vec2::from(motion[i]);
            assert!((got - expect).length() < 0.05 + 1e-3 * expect.length(), "pixel ({x},{y}): motion {got} expected {expect}");
            // the sample is where the pixel centre is
            assert!((now - glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5)).length() < 0.01, "{now}");
            checked += 1;
        }
    }
    assert!(checked > 20);
}

/// Manual (needs ../shared/scenes): `cargo test --release -p shadowlab-gpu --test gpu -- --ignored`.
#[test]
#[ignore = "needs the real scenes of ../shared/scenes"]
fn rt_gpu_matches_cpu_on_real_scenes() {
    let Some(gpu) = gpu() else { return };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../setups");
    for name in ["sponza", "conference", "sibenik"] {
        let setup = shadowlab_core::setup::Setup::load(&root.join(format!("{name}.toml"))).unwrap();
        let Some(path) = setup.scene.path.clone().filter(|p| p.exists()) else {
            panic!("{name}: scene file missing");
        };
        let scene = shadowlab_core::loaders::load(&path, &setup.transform()).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        let cam = setup.camera.as_ref().unwrap().camera();
        for light in &setup.lights {
            let v = lab.view(&cam, &cam, light, 512, 512).unwrap();
            let rt = lab.reference(&v, 1).unwrap();
            let cpu = cpu_visibility(&lab.bvh, &scene, light, &v.position, &v.normal, &v.mask, lab.gscene.eps);
            let m = compare(&rt.visibility, &cpu, &v.mask);
            eprintln!("{name} {}: GPU/CPU agree on {:.4} % of {} pixels", light.kind(), 100.0 - m.wrong_pct, m.evaluated_pixels);
            assert!(100.0 - m.wrong_pct >= 99.99);
        }
    }
}

#[test]
fn both_stage_timers_give_plausible_times() {
    use shadowlab_gpu::record::Recorder;
    let Some(mut gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    for timestamps in [false, true] {
        let ts = wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
        if timestamps && !gpu.device.features().contains(ts) {
            eprintln!("adapter lacks encoder timestamps: GPU timer not exercised");
            continue;
        }
        gpu.gpu_timestamps = timestamps;
        let lab = Lab::new(&gpu, &scene).unwrap();
        let v = view(&lab, &scene, 0, 64);
        let run = lab.run(&v, &TechniqueSpec::parse("sm:res=1024").unwrap(), 2).unwrap();
        for (stage, ms) in &run.stages_ms {
            assert!(ms.is_finite() && *ms >= 0.0 && *ms < 10_000.0, "{stage}: {ms} ms with timestamps={timestamps}");
        }
        assert!(run.stages_ms.contains_key("sm.render") && run.stages_ms.contains_key("sm.evaluate"));
        assert!(run.total_ms.is_finite() && run.total_ms > 0.0, "frame time {} with timestamps={timestamps}", run.total_ms);
        assert_eq!(run.submits_per_frame, 1, "sm records its frame in one submit");
        // an empty recorded frame resolves nothing and times nothing
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        let mut rec = Recorder::new(&gpu, &mut enc);
        rec.stage("empty", |_| ());
        assert!(rec.finish().stamped.is_empty());
    }
}
