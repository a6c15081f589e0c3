//! GPU tests of `virtual` on local lights: spot lights (one perspective virtual map with a mip
//! chain) and point lights (six, one per cube face), on the built-in room's spot (light 0) and
//! point light (light 1): against `rt`, marking against the CPU, the page cache on a still
//! camera, and determinism.

use std::collections::BTreeSet;

use glam::Vec3;
use shadowlab_core::builtin::builtin;
use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamSet, TechniqueSpec};
use shadowlab_core::techniques::virtual_sm::{bias_scale, pixel_angle, PageKey, Projection};
use shadowlab_gpu::lab::{Lab, View};
use shadowlab_gpu::registry;
use shadowlab_gpu::technique::submit_frame;
use shadowlab_gpu::techniques::virtual_sm::{VirtualSettings, VirtualShadows};

use crate::common::*;

fn make(lab: &Lab, v: &View, spec: &str) -> VirtualShadows {
    let spec = TechniqueSpec::parse(spec).unwrap();
    let r = registry::resolve(&spec, Some(&v.light)).unwrap();
    VirtualShadows::new(lab.gpu, &lab.gscene, &VirtualSettings::from_values(&r.values), &v.light).unwrap()
}

fn frame(lab: &Lab, t: &mut VirtualShadows, v: &View) -> Vec<f32> {
    submit_frame(t, lab.gpu, &v.inputs(&lab.gscene)).unwrap();
    lab.gpu.take_error().unwrap();
    lab.gpu.read_buffer_as(&v.visibility, v.gbuffer.pixels())
}

/// The room with its spot light (light 0) and its point light (light 1).
const LIGHTS: [usize; 2] = [0, 1];

fn room() -> shadowlab_core::scene::Scene {
    let scene = builtin("room").unwrap();
    assert!(matches!(scene.lights[0], Light::Spot { .. }));
    assert!(matches!(scene.lights[1], Light::Point { .. }));
    scene
}

#[test]
fn virtual_local_lights_match_rt_on_room() {
    let Some(gpu) = gpu() else { return };
    let scene = room();
    let lab = Lab::new(&gpu, &scene).unwrap();
    for light in LIGHTS {
        let v = view(&lab, &scene, light, 256);
        let rt = lab.reference(&v, 1).unwrap();
        for s in ["virtual:resolution_bias=-1,pool_mib=64", "virtual:resolution_bias=-1,pool_mib=64,pcf=3"] {
            let run = lab.run(&v, &TechniqueSpec::parse(s).unwrap(), 1).unwrap();
            let a = agreement(&run.visibility, &rt.visibility, &v.mask);
            eprintln!("light {light}, {s}: {a:.3}% agreement, counters {:?}", run.report.counters);
            assert!(run.report.degraded.is_empty(), "{s}: {:?}", run.report.degraded);
            assert!(run.report.counters["pages_marked"] > 8.0, "a real page set: {:?}", run.report.counters);
            if light == 1 {
                let faces = (0..6).filter(|f| run.report.counters[&format!("pages_marked_face_{f}")] > 0.0).count();
                assert!(faces >= 4, "the room's walls around the point light use most faces: {faces}");
            }
            if a < 99.0 {
                panic!("light {light}, {s} agrees with rt on {a:.3}%; {}", save_images("virtual-local-room", &v, &run, &rt));
            }
            assert_eq!(run.stalls, vec!["virtual.readback".to_string()]);
        }
    }
}

/// The GPU's marks equal `Clipmap::sample_pages` over the read-back G-buffer, as the directional
/// test (virtual.rs) does: samples whose answer changes under a small nudge may go either way.
#[test]
fn local_light_marking_equals_the_cpu_computation() {
    let Some(gpu) = gpu() else { return };
    let scene = room();
    let lab = Lab::new(&gpu, &scene).unwrap();
    for light in LIGHTS {
        local_marking(&lab, &scene, light);
    }
}

fn local_marking(lab: &Lab, scene: &shadowlab_core::scene::Scene, light: usize) {
    let v = view(lab, scene, light, 192);
    // two levels finer than the footprint: a page set large enough to compare
    let mut t = make(lab, &v, "virtual:pcf=3,resolution_bias=-2");
    frame(lab, &mut t, &v);
    let gpu_set: BTreeSet<PageKey> = t.requested().iter().copied().collect();
    let c = t.clipmap().unwrap().clone();
    match light {
        0 => assert!(matches!(c.projection, Projection::Persp { .. })),
        _ => assert!(matches!(c.projection, Projection::Cube { .. }) && c.faces() == 6),
    }
    let pa = pixel_angle(scene.camera.fov_y_deg, v.height);
    let scale = bias_scale(-2.0);
    let reach = 1.0 + 0.5 + 1.0; // pcf 3: half 1, normal offset 0.5, one texel
    let (mut certain, mut possible) = (BTreeSet::new(), BTreeSet::new());
    let (mut ambiguous, mut levels) = (0, BTreeSet::new());
    for (p, m) in v.position.iter().zip(&v.mask) {
        if *m == 0 {
            continue;
        }
        let p = Vec3::new(p[0], p[1], p[2]);
        let f = (p - scene.camera.position).length() * pa;
        let base = c.sample_pages(p, f, scale, reach);
        let nudge = 1e-3 * c.texel0_at(p);
        let variants = [
            c.sample_pages(p, f * (1.0 + 1e-4), scale, reach),
            c.sample_pages(p, f * (1.0 - 1e-4), scale, reach),
            c.sample_pages(p, f, scale, reach + 1e-3),
            c.sample_pages(p, f, scale, reach - 1e-3),
            c.sample_pages(p + c.right * nudge + c.up * nudge, f, scale, reach),
            c.sample_pages(p - c.right * nudge - c.up * nudge, f, scale, reach),
        ];
        if variants.iter().all(|x| *x == base) {
            certain.extend(base.iter().copied());
        } else {
            ambiguous += 1;
        }
        levels.extend(base.iter().map(|k| c.mip(k.level)));
        possible.extend(base);
        for x in variants {
            possible.extend(x);
        }
    }
    eprintln!(
        "light {light}: {} pages certain, {} possible, {} on the GPU, levels {levels:?}, {ambiguous} ambiguous samples",
        certain.len(),
        possible.len(),
        gpu_set.len()
    );
    assert!(certain.len() > 10, "a real set of pages: {}", certain.len());
    assert!(levels.len() >= 3, "the view spans mip levels: {levels:?}");
    assert!(ambiguous * 100 < v.mask.iter().filter(|m| **m != 0).count(), "few ambiguous samples: {ambiguous}");
    let missing: Vec<_> = certain.difference(&gpu_set).collect();
    let extra: Vec<_> = gpu_set.difference(&possible).collect();
    assert!(missing.is_empty() && extra.is_empty(), "missing {missing:?}, extra {extra:?}");
    // the coarsest level of each face used is one page, the fallback of its samples
    for k in &gpu_set {
        let top = c.level_index(c.face(k.level), c.mips - 1);
        assert!(gpu_set.contains(&PageKey { level: top, x: 0, y: 0 }), "{k:?}: no top page {top}");
    }
    assert!(gpu_set.iter().all(|k| k.x >= 0 && k.y >= 0 && k.x < c.side(k.level) && k.y < c.side(k.level)));
}

#[test]
fn a_still_camera_renders_no_local_light_page_on_its_second_frame() {
    let Some(gpu) = gpu() else { return };
    let scene = room();
    let lab = Lab::new(&gpu, &scene).unwrap();
    for light in LIGHTS {
        still_camera(&lab, &scene, light);
    }
}

fn still_camera(lab: &Lab, scene: &shadowlab_core::scene::Scene, light: usize) {
    let v = view(lab, scene, light, 128);
    let mut t = make(lab, &v, "virtual");
    let first = frame(lab, &mut t, &v);
    let a = t.allocation().clone();
    assert!(!a.render.is_empty() && a.render.len() == t.requested().len() && a.cached == 0);
    let second = frame(lab, &mut t, &v);
    let b = t.allocation();
    assert!(b.render.is_empty(), "second frame rendered {} pages", b.render.len());
    assert_eq!(b.cached, t.requested().len());
    assert_eq!(b.mapped, a.mapped);
    assert!(first.iter().zip(&second).all(|(x, y)| x.to_bits() == y.to_bits()), "cached pages give the same bits");
}

#[test]
fn virtual_local_lights_are_deterministic() {
    let Some(gpu) = gpu() else { return };
    let scene = room();
    let lab = Lab::new(&gpu, &scene).unwrap();
    for light in LIGHTS {
        let v = view(&lab, &scene, light, 128);
        // also with a pool too small for the view: the fallback is deterministic too
        for s in ["virtual:pcf=3", "virtual:pool_mib=0.25,resolution_bias=-2"] {
            let spec = TechniqueSpec::parse(s).unwrap();
            let runs: Vec<_> = (0..2).map(|_| lab.run(&v, &spec, 1).unwrap()).collect();
            let same = runs[0].visibility.iter().zip(&runs[1].visibility).all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "light {light}, {s}");
            assert_eq!(runs[0].report.counters, runs[1].report.counters, "light {light}, {s}");
            if s.contains("pool_mib=0.25") {
                let c = &runs[0].report.counters;
                assert_eq!(c["pool_pages"], 4.0);
                assert!(c["pages_fallen_back"] > 0.0, "{c:?}");
                assert!(!runs[0].report.degraded.is_empty());
            }
        }
    }
}
