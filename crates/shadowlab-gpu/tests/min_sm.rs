//! `min-sm` (shadow mapping over the minimal shadow frustum) against the exact reference.

use glam::Vec3;
use shadowlab_core::builtin::builtin;
use shadowlab_core::camera::Camera;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::{Lab, Run, View};

use crate::common::*;

fn spec(s: &str) -> TechniqueSpec {
    TechniqueSpec::parse(s).unwrap()
}

fn evaluated(v: &View) -> f64 {
    v.mask.iter().filter(|m| **m != 0).count() as f64
}

/// Every evaluated view sample was counted in some texel of the fitted map, and the reduction
/// saw exactly the evaluated samples.
fn assert_all_samples_inside(what: &str, v: &View, run: &Run) {
    let c = &run.report.counters;
    assert_eq!(c["view_samples"], evaluated(v), "{what}: reduction saw {} samples", c["view_samples"]);
    assert_eq!(c["samples_in_map"], evaluated(v), "{what}: {} samples outside the map", c["samples_outside_map"]);
    assert_eq!(c["samples_outside_map"], 0.0, "{what}");
    assert_eq!(c["fallback_scene_fit"], 0.0, "{what}");
    assert!(c["hull_points"] >= 3.0 && c["hull_points"] <= c["reduced_points"], "{what}: {c:?}");
}

#[test]
fn min_sm_at_high_resolution_matches_rt_on_planebox_and_the_room_spot() {
    let Some(gpu) = gpu() else { return };
    for (name, light) in [("planebox", 0), ("room", 0)] {
        let scene = builtin(name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        let v = view(&lab, &scene, light, 256);
        let rt = lab.reference(&v, 1).unwrap();
        let ms = lab.run(&v, &spec("min-sm:res=2048"), 1).unwrap();
        let a = agreement(&ms.visibility, &rt.visibility, &v.mask);
        if a < 99.0 {
            panic!("min-sm 2048 agrees with rt on {a:.3}% of {name}; {}", save_images(&format!("min-sm-{name}"), &v, &ms, &rt));
        }
        assert_all_samples_inside(name, &v, &ms);
        assert_eq!(ms.report.shadow_data_bytes, 2048 * 2048 * 4);
        // the map covers only what the view needs: less than the scene-fitted map
        let ratio = ms.report.counters["rect_area_vs_scene_map"];
        assert!(ratio > 0.0 && ratio < 1.0, "{name}: rectangle area ratio {ratio}");
    }
}

/// Near the ground under the courtyard's grazing sun, looking at a few metres of floor crossed by
/// the shadow streaks of the gallery: the scene-fitted map spends almost all its texels elsewhere.
#[test]
fn min_sm_beats_sm_clearly_on_a_close_up() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let cam = Camera::new(Vec3::new(11.0, 1.2, -1.0), Vec3::new(10.0, 0.0, -3.5), 60.0, 0.05, 120.0);
    let v = lab.view(&cam, &cam, &scene.lights[0], 256, 256).unwrap();
    let rt = lab.reference(&v, 1).unwrap();
    let sm = lab.run(&v, &spec("sm"), 1).unwrap();
    let ms = lab.run(&v, &spec("min-sm"), 1).unwrap();
    let w_sm = compare(&sm.visibility, &rt.visibility, &v.mask).wrong_pct;
    let w_ms = compare(&ms.visibility, &rt.visibility, &v.mask).wrong_pct;
    assert!(evaluated(&v) > 20000.0 && w_sm > 0.5, "the close-up must show shadow edges that sm gets wrong: sm {w_sm:.3}%");
    if w_ms > 0.5 * w_sm {
        panic!("close-up: min-sm {w_ms:.3}% wrong vs sm {w_sm:.3}%; {}", save_images("min-sm-closeup", &v, &ms, &rt));
    }
    assert_all_samples_inside("close-up", &v, &ms);
    let c = &ms.report.counters;
    assert!(c["rect_area_vs_scene_map"] < 0.1, "{c:?}");
    assert!(c["texel_vs_sm"] < 0.5, "{c:?}");
    // more of the map is used, by fewer samples per texel
    let (s_sm, s_ms) = (sm.report.sampling.unwrap(), ms.report.sampling.unwrap());
    assert!(s_ms.used_texel_fraction > 2.0 * s_sm.used_texel_fraction, "{s_ms:?} vs {s_sm:?}");
    assert!(s_ms.samples_per_used_texel_mean < s_sm.samples_per_used_texel_mean, "{s_ms:?} vs {s_sm:?}");
}

#[test]
fn every_view_sample_lands_inside_the_fitted_map() {
    let Some(gpu) = gpu() else { return };
    for (name, light, pcf) in [("courtyard", 0, 1), ("foliage", 0, 3), ("room", 0, 5)] {
        let scene = builtin(name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        let v = view(&lab, &scene, light, 128);
        let run = lab.run(&v, &spec(&format!("min-sm:pcf={pcf},grid=64")), 1).unwrap();
        assert_all_samples_inside(name, &v, &run);
        assert_eq!(run.report.counters["fetches_per_pixel"], (pcf * pcf) as f64);
        assert_eq!(run.report.images.len(), 2);
    }
}

/// No evaluated sample (the camera looks at the sky): the scene-fitted map, no error; a view
/// with a handful of samples still gets a valid map that holds them all.
#[test]
fn empty_and_tiny_views_are_handled() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let sky = Camera::new(Vec3::new(0.0, 1.7, 0.0), Vec3::new(0.0, 50.0, 0.01), 30.0, 0.1, 120.0);
    let v = lab.view(&sky, &sky, &scene.lights[0], 64, 64).unwrap();
    assert_eq!(evaluated(&v), 0.0);
    let run = lab.run(&v, &spec("min-sm"), 1).unwrap();
    assert_eq!(run.report.counters["fallback_scene_fit"], 1.0);
    assert_eq!(run.report.counters["view_samples"], 0.0);
    // a sliver of the building's top at the bottom edge of a sky view
    let edge = Camera::new(Vec3::new(0.0, 1.7, 0.0), Vec3::new(0.0, 6.0, -9.0), 20.0, 0.1, 120.0);
    let v = lab.view(&edge, &edge, &scene.lights[0], 64, 64).unwrap();
    let n = evaluated(&v);
    assert!(n > 0.0 && n < 0.25 * 64.0 * 64.0, "{n} samples: not a tiny view");
    let rt = lab.reference(&v, 1).unwrap();
    let run = lab.run(&v, &spec("min-sm"), 1).unwrap();
    assert_all_samples_inside("tiny view", &v, &run);
    let a = agreement(&run.visibility, &rt.visibility, &v.mask);
    assert!(a >= 95.0, "tiny view: {a:.2}% agreement over {n} samples");
}

#[test]
fn bad_requests_are_errors() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 1, 32); // point light
    let e = lab.run(&v, &spec("min-sm"), 1).err().expect("min-sm on a point light must fail");
    assert!(e.to_string().contains("point"), "{e}");
    let v = view(&lab, &scene, 0, 32);
    assert!(lab.run(&v, &spec("min-sm:grid=0"), 1).is_err());
    assert!(lab.run(&v, &spec("min-sm:res=8"), 1).is_err());
    assert!(lab.run(&v, &spec("min-sm:gird=8"), 1).is_err());
}

/// One-pass mode: on the same view again it reproduces the two-pass result exactly; along the
/// courtyard's camera path (the band range of the previous view is wrong for the next) every
/// sample still lands inside the map.
#[test]
fn one_pass_reduction_is_exact_on_a_repeat_and_conservative_along_a_path() {
    use shadowlab_core::camera::path_cameras;
    use shadowlab_gpu::registry::resolve;
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let light = scene.lights[0];
    let v = view(&lab, &scene, 0, 128);
    let one = lab.run(&v, &spec("min-sm"), 1).unwrap(); // warm-up: two passes, then one
    let two = lab.run(&v, &spec("min-sm:one_pass=false"), 1).unwrap();
    assert_eq!(one.report.counters["reduce_passes"], 1.0);
    assert_eq!(two.report.counters["reduce_passes"], 2.0);
    assert_eq!(one.visibility, two.visibility);
    assert_eq!(one.report.counters["hull_points"], two.report.counters["hull_points"]);

    let shadowlab_gpu::registry::Resolved { info, values: params, .. } = resolve(&spec("min-sm"), Some(&light)).unwrap();
    let mut inst = lab.instantiate(&shadowlab_gpu::registry::Resolved::new(info, params, "min-sm"), &light).unwrap();
    let cams = path_cameras(&scene.camera, &scene.camera_path, 5);
    for (i, cam) in cams.iter().enumerate() {
        let v = lab.view(cam, cam, &light, 128, 128).unwrap();
        let run = lab.step(&v, &mut inst, false, 1).unwrap();
        assert_eq!(run.report.counters["reduce_passes"], if i == 0 { 2.0 } else { 1.0 });
        assert_all_samples_inside(&format!("path view {i}"), &v, &run);
    }
}
