//! Moving objects on the GPU: the reference sees the moved geometry (against the CPU tracer
//! of `Scene::at_time`), motion vectors of a translating box equal its hand-computed pixel
//! motion, views keep their own time, and still scenes are untouched.

use glam::{Vec2, Vec3};
use shadowlab_core::anim::{apply, AnimationSpec, Motion};
use shadowlab_core::builtin::{builtin, MeshBuilder};
use shadowlab_core::bvh::{cpu_visibility, Bvh};
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::compare;
use shadowlab_core::scene::{Material, Scene};
use shadowlab_gpu::lab::{Lab, View};

use crate::common::*;

/// GPU `rt` at time `t` against the CPU tracer over `scene.at_time(t)` on the same samples.
fn rt_matches_cpu_at(lab: &Lab, scene: &Scene, light: usize, t: f32) -> (View, Vec<f32>) {
    lab.set_time(t, t - 1.0).unwrap();
    let v = view(lab, scene, light, 256);
    assert_eq!((v.time, v.prev_time), (t, t - 1.0));
    let rt = lab.reference(&v, 1).unwrap();
    let moved = scene.at_time(t);
    let bvh = Bvh::build(&moved).unwrap();
    let cpu = cpu_visibility(&bvh, &moved, &scene.lights[light], &v.position, &v.normal, &v.mask, lab.gscene.eps);
    let m = compare(&rt.visibility, &cpu, &v.mask);
    assert!(m.evaluated_pixels > 1000, "{} t = {t}: {} evaluated", scene.name, m.evaluated_pixels);
    assert!(100.0 - m.wrong_pct >= 99.99, "{} t = {t}: GPU/CPU agree on {:.4}%", scene.name, 100.0 - m.wrong_pct);
    (v, rt.visibility)
}

#[test]
fn rt_sees_the_moved_geometry_of_animated_builtins() {
    let Some(gpu) = gpu() else { return };
    for (name, light, t) in [("foliage", 0, 16.0), ("room", 0, 24.0), ("courtyard", 0, 11.0)] {
        let scene = builtin(name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        assert!(lab.gscene.dynamic_first < lab.gscene.triangle_count);
        assert_eq!(lab.gscene.dynamic_first as usize, scene.dynamic_first());
        let (v0, still) = rt_matches_cpu_at(&lab, &scene, light, 0.0);
        let (v1, moved) = rt_matches_cpu_at(&lab, &scene, light, t);
        // the motion is visible: shadows (or surfaces) change between t = 0 and t
        let changed = (0..still.len()).filter(|&i| v0.mask[i] != 0 && v1.mask[i] != 0 && (still[i] > 0.5) != (moved[i] > 0.5)).count();
        assert!(changed > 20, "{name}: only {changed} pixels change between t = 0 and t = {t}");
    }
}

#[test]
fn the_gbuffer_draws_the_moved_cart() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let (c0, c1) = shadowlab_core::builtin::FOLIAGE_CART;
    let side = Vec3::new((c0.x + c1.x) / 2.0, 0.8, c1.z); // middle of the cart's front side
    let mut cart_x = Vec::new();
    for t in [0.0, 16.0] {
        lab.set_time(t, t).unwrap();
        let v = view(&lab, &scene, 0, 256);
        let at =
            side + Motion::Translate { offset: shadowlab_core::builtin::FOLIAGE_CART_TRAVEL, period: 64.0 }.transform(t).w_axis.truncate();
        let px = scene.camera.project_to_pixel(at, 256, 256).unwrap();
        let p = v.position[px.y as usize * 256 + px.x as usize];
        assert!((Vec3::new(p[0], p[1], p[2]) - at).length() < 0.15, "t = {t}: G-buffer at {px} holds {p:?}, cart side at {at}");
        cart_x.push(p[0]);
    }
    assert!((cart_x[0] - cart_x[1] - 4.5).abs() < 0.2, "a quarter period: half of the 9 m crossing: {cart_x:?}");
}

/// A 20 m ground and a 1 m box whose centre starts at the origin; the box moves along +x.
fn moving_box(offset: Vec3, period: f32) -> Scene {
    let mut b = MeshBuilder::default();
    let g = b.material(Material::solid("ground", [0.5; 3]));
    let c = b.material(Material::solid("crate", [0.8; 3]));
    b.cuboid(Vec3::new(-10.0, -0.1, -10.0), Vec3::new(10.0, 0.0, 10.0), g);
    b.cuboid(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5), c);
    // straight down from 10 m: the box top (y = 1) is 9 m away
    let cam = Camera::new(Vec3::new(0.0, 10.0, 0.0), Vec3::ZERO, 60.0, 0.5, 30.0);
    let light = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) };
    let mut s = b.finish("moving box", cam, vec![light], vec![]);
    apply(
        &mut s,
        &[AnimationSpec {
            name: "crate".into(),
            materials: vec!["crate".into()],
            inside: None,
            motion: Motion::Translate { offset, period },
        }],
    )
    .unwrap();
    s
}

#[test]
fn motion_vectors_of_a_translating_box_are_its_pixel_motion() {
    let Some(gpu) = gpu() else { return };
    let scene = moving_box(Vec3::X, 8.0);
    let lab = Lab::new(&gpu, &scene).unwrap();
    // t = 2: offset (1 - cos(pi/2))/2 = 0.5 m; t = 1: (1 - cos(pi/4))/2 = 0.146447 m
    let dx = 0.5 - (1.0 - std::f32::consts::FRAC_PI_4.cos()) / 2.0;
    lab.set_time(2.0, 1.0).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let motion: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&v.gbuffer.motion, 8));
    // pixels per metre at 9 m depth: (256 / 2) / (9 tan 30 deg); the camera looks down -y with
    // +z up on screen, so its right is -x: the box moving +x moves left on screen
    let px_per_m = 128.0 / (9.0 * 30f32.to_radians().tan());
    let expected = Vec2::new(-dx * px_per_m, 0.0);
    let (mut top, mut ground) = (0, 0);
    for (i, p) in v.position.iter().enumerate() {
        let m = Vec2::from(motion[i]);
        if p[3] == 0.0 {
            continue;
        }
        if (p[1] - 1.0).abs() < 1e-4 {
            top += 1;
            assert!((m - expected).length() < 0.02, "box top pixel {i}: motion {m}, expected {expected}");
            // and the same from the camera's own projection of the point and its previous place
            let now = Vec3::new(p[0], p[1], p[2]);
            let c = scene.camera;
            let proj = c.project_to_pixel(now, 256, 256).unwrap() - c.project_to_pixel(now - Vec3::X * dx, 256, 256).unwrap();
            assert!((m - proj).length() < 0.02, "pixel {i}: {m} vs projected {proj}");
        } else if p[1].abs() < 1e-4 {
            ground += 1;
            assert_eq!(m, Vec2::ZERO, "still ground pixel {i} (camera still)");
        }
    }
    assert!(top > 500 && ground > 10_000, "{top} box-top pixels, {ground} ground pixels");
    assert!(expected.x < -8.0, "about 8.7 px to the left: {expected}");
}

#[test]
fn a_view_keeps_its_time_when_the_scene_moves_on() {
    let Some(gpu) = gpu() else { return };
    let scene = moving_box(Vec3::new(3.0, 0.0, 0.0), 10.0);
    let lab = Lab::new(&gpu, &scene).unwrap();
    lab.set_time(0.0, 0.0).unwrap();
    let v0 = view(&lab, &scene, 0, 128);
    let first = lab.reference(&v0, 1).unwrap().visibility;
    lab.set_time(5.0, 4.0).unwrap();
    let v5 = view(&lab, &scene, 0, 128);
    let later = lab.reference(&v5, 1).unwrap().visibility;
    assert_ne!(first, later, "the box moved 3 m");
    // running on the old view moves the scene back to that view's time
    assert_eq!(lab.reference(&v0, 1).unwrap().visibility, first);
    assert_eq!(lab.time(), (0.0, 0.0));
    assert!(lab.set_time(f32::NAN, 0.0).is_err(), "a NaN time is an error");
}

#[test]
fn still_scenes_have_no_dynamic_part_and_ignore_time() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    assert_eq!(lab.gscene.dynamic_first, lab.gscene.triangle_count);
    assert_eq!(lab.gscene.bvh_bytes, lab.bvh.bytes(), "no dynamic tree capacity");
    let v0 = view(&lab, &scene, 0, 128);
    let a = lab.reference(&v0, 1).unwrap().visibility;
    lab.set_time(7.0, 6.0).unwrap();
    let v7 = view(&lab, &scene, 0, 128);
    assert_eq!(lab.reference(&v7, 1).unwrap().visibility, a);
    let motion: Vec<[f32; 2]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&v7.gbuffer.motion, 8));
    assert!(motion.iter().all(|m| *m == [0.0, 0.0]), "nothing moves");
    assert!(!v7.stages_ms.contains_key("scene.animate"));
}

/// Per sample: bit 0 = `occluded_static`, bit 1 = `occluded_dynamic` (the ray of `sample_shadowed`).
const SPLIT_WGSL: &str = r#"
@group(0) @binding(6) var<storage, read_write> hits: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    var s: Sample;
    if !load_sample(id, &s) {
        return;
    }
    let r = shadow_ray(s.p, s.n);
    hits[s.i] = select(0u, 1u, occluded_static(r.o, r.d, r.tmax)) | select(0u, 2u, occluded_dynamic(r.o, r.d, r.tmax));
}
"#;

#[test]
fn occluded_static_and_occluded_dynamic_each_see_their_part() {
    use shadowlab_core::bvh::{occluded_from, shadow_ray};
    use shadowlab_gpu::reference::TRACE_WGSL;
    use shadowlab_gpu::technique::{compose_view, view_layout};
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let t = 16.0;
    lab.set_time(t, t).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let layout = view_layout(&gpu, "split", &[shadowlab_gpu::binding::storage(false)]);
    let pipeline =
        gpu.compute_pipeline("split", &compose_view(&format!("{TRACE_WGSL}{SPLIT_WGSL}"), true), "main", &[&layout, &lab.gscene.layout]);
    let hits = gpu.storage("split.hits", 256 * 256 * 4);
    let inputs = v.inputs(&lab.gscene);
    let group = inputs.view_group(&gpu, &Default::default(), "split", &layout, &[hits.as_entire_binding()]);
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    gpu.dispatch_2d(&mut enc, "split", &pipeline, &[&group, &lab.gscene.group], 256, 256);
    gpu.queue.submit([enc.finish()]);
    gpu.take_error().unwrap();
    let got: Vec<u32> = gpu.read_buffer_as(&hits, 256 * 256);
    // CPU: the moved scene, one tree per part
    let moved = scene.at_time(t);
    let d = moved.dynamic_first();
    let st = Bvh::build_range(&moved, 0..d).unwrap();
    let dy = Bvh::build_range(&moved, d..moved.triangle_count()).unwrap();
    let light = scene.lights[0];
    let (mut n, mut wrong, mut by_dynamic) = (0, 0, 0);
    for (i, &g) in got.iter().enumerate() {
        if v.mask[i] == 0 {
            continue;
        }
        let p = Vec3::from_slice(&v.position[i][..3]);
        let nn = Vec3::from_slice(&v.normal[i][..3]);
        let r = shadow_ray(&light, p, nn, lab.gscene.eps);
        let s = occluded_from(&st.nodes, &st.prim_indices, 0, &moved, &r) as u32;
        let dd = occluded_from(&dy.nodes, &dy.prim_indices, 0, &moved, &r) as u32;
        n += 1;
        wrong += (g != s | (dd << 1)) as u32;
        by_dynamic += dd;
    }
    assert!(n > 10_000 && by_dynamic > 50, "{n} samples, {by_dynamic} shadowed by moving objects");
    assert!(wrong * 10_000 <= n, "{wrong} of {n} samples disagree with the CPU per tree");
}
