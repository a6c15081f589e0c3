//! GPU tests of `sdsm` (sample distribution shadow maps; lavapipe in CI): its reduction
//! against the G-buffer read back on the CPU, its boxes against the samples, `rt` on
//! planebox, the delayed variant's frames and syncs, and determinism.

use std::collections::BTreeMap;

use glam::{Vec3, Vec4Swizzles};
use shadowlab_core::builtin::builtin;
use shadowlab_core::light::Light;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::techniques::csm::light_view;
use shadowlab_core::techniques::sdsm::sample_splits;
use shadowlab_gpu::lab::{Instance, Lab, Run, View};
use shadowlab_gpu::registry;

use crate::common::*;

fn spec(s: &str) -> TechniqueSpec {
    TechniqueSpec::parse(s).unwrap()
}

fn instance(lab: &Lab, v: &View, s: &str) -> Instance {
    lab.instantiate(&registry::resolve(&spec(s), Some(&v.light)).unwrap(), &v.light).unwrap()
}

/// The `sdsm` counters of one cascade's fitted box and sample bounds.
fn boxes(c: &BTreeMap<String, f64>, n: usize) -> Vec<Vec<f64>> {
    let keys = ["x0", "x1", "y0", "y1", "znear", "zfar"];
    (0..n).map(|i| keys.iter().map(|k| c[&format!("box_{i}_{k}")]).collect()).collect()
}

#[test]
fn bounds_hold_every_sample_of_their_cascade_and_are_tight() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    // odd size: partial workgroups and partial per-thread blocks
    let v = lab.view(&scene.camera, &scene.camera, &scene.lights[0], 203, 131).unwrap();
    let run = lab.run(&v, &spec("sdsm"), 1).unwrap();
    let c = &run.report.counters;
    assert_eq!(c["bounds_source"], 1.0, "this frame's samples");
    assert_eq!(c["fitted_cascades"], 3.0);
    let Light::Directional { direction } = v.light else { panic!("courtyard's light 0 is directional") };
    let lv = light_view(direction);

    // the GPU's splits are the core's log splits of the read-back [min, max]
    let splits: Vec<f32> = (0..=3).map(|i| c[&format!("split_{i}")] as f32).collect();
    let (lo, hi) = (c["gbuffer_depth_min"] as f32, c["gbuffer_depth_max"] as f32);
    let want = sample_splits(scene.camera.near, scene.camera.far, Some((lo, hi)), 3, 1.0);
    for (s, w) in splits.iter().zip(&want) {
        assert!((s - w).abs() <= 1e-4 * w, "splits {splits:?} vs {want:?}");
    }

    // the samples of each cascade (the evaluation's rule), reduced on the CPU
    let (mut blo, mut bhi, mut count) = ([Vec3::INFINITY; 3], [Vec3::NEG_INFINITY; 3], [0u32; 3]);
    let mut by_cascade: Vec<Vec<Vec3>> = vec![Vec::new(); 3];
    for (p, m) in v.position.iter().zip(&v.mask) {
        if *m == 0 {
            continue;
        }
        let mut k = 0;
        while k + 1 < 3 && p[3] > splits[k + 1] {
            k += 1;
        }
        let q = (lv * Vec3::new(p[0], p[1], p[2]).extend(1.0)).xyz();
        (blo[k], bhi[k], count[k]) = (blo[k].min(q), bhi[k].max(q), count[k] + 1);
        by_cascade[k].push(q);
    }
    let scale = scene.bounds().diagonal();
    let b = boxes(c, 3);
    for k in 0..3 {
        assert_eq!(c[&format!("samples_{k}")], count[k] as f64, "cascade {k}: samples");
        assert!(count[k] > 0, "cascade {k} is empty on this view");
        // the read-back bounds are the samples' (up to the GPU's rounding of the light transform)
        for (name, cpu) in [("lo", blo[k]), ("hi", bhi[k])] {
            for (axis, x) in ["x", "y", "z"].iter().zip(cpu.to_array()) {
                let g = c[&format!("bounds_{k}_{name}_{axis}")] as f32;
                assert!((g - x).abs() <= 1e-5 * scale, "cascade {k} {name}.{axis}: GPU {g} vs CPU {x}");
            }
        }
        // every sample of the cascade inside its fitted box (light-view x, y; z between the
        // far plane and the near one, which lies towards the light beyond the whole scene)
        let [x0, x1, y0, y1, zn, zf] = b[k][..] else { unreachable!() };
        for q in &by_cascade[k] {
            let (x, y, z) = (q.x as f64, q.y as f64, q.z as f64);
            assert!(x > x0 && x < x1 && y > y0 && y < y1 && z < zn && z > zf, "cascade {k}: sample {q} outside {:?}", b[k]);
        }
        let scene_top = scene.bounds().corners().iter().map(|p| (lv * p.extend(1.0)).z).fold(f32::MIN, f32::max);
        assert!(zn >= scene_top as f64, "cascade {k}: near plane {zn} below the scene's top {scene_top} (casters lost)");
        let ratio = c[&format!("area_ratio_{k}")];
        assert!(ratio > 0.0 && ratio <= 1.0, "cascade {k}: fitted/slice area {ratio}");
    }
    assert_eq!(run.report.shadow_data_bytes, 3 * 1024 * 1024 * 4 + shadowlab_gpu::techniques::csm::SDSM_BOUNDS_BYTES);
}

#[test]
fn sdsm_at_high_resolution_matches_rt_on_planebox() {
    let Some(gpu) = gpu() else { return };
    let mut scene = builtin("planebox").unwrap();
    scene.camera.far = 20.0;
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for s in ["sdsm:res=2048", "sdsm:res=2048,cascades=4,blend=0.2,pcf=3", "sdsm:res=2048,delayed=true", "sdsm:res=2048,snap=false"] {
        let run = lab.run(&v, &spec(s), 1).unwrap();
        let a = agreement(&run.visibility, &rt.visibility, &v.mask);
        if a < 99.0 {
            panic!("{s} agrees with rt on {a:.3}%; {}", save_images("sdsm-planebox", &v, &run, &rt));
        }
    }
}

#[test]
fn delayed_uses_the_slice_fit_then_the_previous_frames_bounds_and_never_syncs() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let mut now = instance(&lab, &v, "sdsm");
    let mut late = instance(&lab, &v, "sdsm:delayed=true");
    let frames: Vec<(Run, Run)> =
        (0..3).map(|_| (lab.step(&v, &mut now, false, 1).unwrap(), lab.step(&v, &mut late, false, 1).unwrap())).collect();
    for (i, (a, b)) in frames.iter().enumerate() {
        assert_eq!(a.stalls, vec!["sdsm.readback".to_string()], "frame {i}: the synchronous variant's one stall");
        assert_eq!(a.submits_per_frame, 2, "frame {i}");
        assert!(b.stalls.is_empty() && b.submits_per_frame == 1, "frame {i} delayed: {:?}, {} submits", b.stalls, b.submits_per_frame);
        assert_eq!(a.report.counters["bounds_source"], 1.0);
    }
    // frame 0: nothing to read yet, the frustum-slice fit
    let c0 = &frames[0].1.report.counters;
    assert_eq!((c0["bounds_source"], c0["fitted_cascades"]), (0.0, 0.0));
    assert!((0..3).all(|k| c0[&format!("area_ratio_{k}")] == 1.0 && c0[&format!("texel_{k}")] == c0[&format!("slice_texel_{k}")]));
    // frame 1 on: the previous frame's bounds; on a still view they are this frame's, so the
    // boxes and the visibility equal the synchronous variant's
    for (i, (a, b)) in frames.iter().enumerate().skip(1) {
        let (ca, cb) = (&a.report.counters, &b.report.counters);
        assert_eq!(cb["bounds_source"], 2.0, "frame {i}");
        assert_eq!(boxes(ca, 3), boxes(cb, 3), "frame {i}: fitted boxes");
        assert!(a.visibility.iter().zip(&b.visibility).all(|(x, y)| x.to_bits() == y.to_bits()), "frame {i}: visibility");
    }
    assert!(frames[0].1.visibility != frames[1].1.visibility, "the slice fit and the fitted boxes give different maps");
}

#[test]
fn two_fresh_runs_give_the_same_bits() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 96);
    for s in ["sdsm", "sdsm:delayed=true,pcf=3"] {
        let a = lab.step(&v, &mut instance(&lab, &v, s), true, 1).unwrap();
        let b = lab.step(&v, &mut instance(&lab, &v, s), true, 1).unwrap();
        assert!(a.visibility.iter().zip(&b.visibility).all(|(x, y)| x.to_bits() == y.to_bits()), "{s}: two runs differ");
        assert_eq!(a.report.counters, b.report.counters, "{s}");
        assert!(a.report.degraded.is_empty());
    }
}

#[test]
fn delayed_boxes_follow_the_cameras_motion() {
    let Some(gpu) = gpu() else { return };
    // four frames apart on the city's path, on its second leg: a step of metres and a turn
    // towards the next key, where last frame's bounds alone leave samples outside every box
    // (they count as lit)
    let scene = builtin("city").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let cams = shadowlab_core::camera::path_cameras(&scene.camera, &scene.camera_path, 24);
    let (a, b) = (cams[8], cams[12]);
    let light = scene.lights[0];
    let Light::Directional { direction } = light else { panic!("city's light 0 is directional") };
    let lv = light_view(direction);
    let (va, vb) = (lab.view(&a, &a, &light, 160, 120).unwrap(), lab.view(&b, &a, &light, 160, 120).unwrap());
    // samples of the second view outside every fitted box, and the run's counters
    let outside = |s: &str| {
        let mut t = instance(&lab, &va, s);
        lab.step(&va, &mut t, false, 1).unwrap();
        let run = lab.step(&vb, &mut t, false, 1).unwrap();
        let c = run.report.counters.clone();
        assert_eq!(c["bounds_source"], 2.0, "{s}: the previous frame's bounds");
        let bx = boxes(&c, 3);
        let n = vb
            .position
            .iter()
            .zip(&vb.mask)
            .filter(|(p, m)| {
                let q = (lv * Vec3::new(p[0], p[1], p[2]).extend(1.0)).xyz().as_dvec3();
                **m != 0 && !bx.iter().any(|b| q.x > b[0] && q.x < b[1] && q.y > b[2] && q.y < b[3] && q.z < b[4] && q.z > b[5])
            })
            .count();
        (n, c)
    };
    let (n0, c0) = outside("sdsm:delayed=true,reach=0");
    let (n1, c1) = outside("sdsm:delayed=true");
    let evaluated = vb.mask.iter().filter(|m| **m != 0).count();
    // the sweep is the CPU's motion at each cascade's far split, in light view
    let m = shadowlab_core::techniques::sdsm::CameraMotion::between(&a, &b, 160.0 / 120.0);
    for k in 0..3 {
        let want = lv.transform_vector3(m.displacement(c1[&format!("split_{}", k + 1)] as f32));
        for (axis, w) in ["x", "y", "z"].iter().zip(want.to_array()) {
            let got = c1[&format!("reach_{k}_{axis}")] as f32;
            assert!((got - w).abs() <= 1e-4 * w.abs().max(1.0), "cascade {k} {axis}: {got} vs {w}");
        }
        assert!(c0[&format!("reach_{k}_x")] == 0.0, "reach=0 does not move the bounds");
    }
    eprintln!("outside every box: {n0} unswept, {n1} swept, of {evaluated}");
    assert!(n0 > evaluated / 200, "the step leaves samples out of last frame's boxes ({n0} of {evaluated}): not a test of the sweep");
    assert!(n1 * 5 < n0, "swept boxes leave {n1} samples outside every box, against {n0} unswept (of {evaluated})");
}
