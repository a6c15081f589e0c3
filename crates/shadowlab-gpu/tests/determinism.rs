//! The same input gives the same bits, also where a technique runs out of capacity: the warped
//! maps' subdivision, given too few pieces, draws a level unsplit (coarser, flagged as
//! degraded) instead of dropping whichever pieces lose the race of the atomics.

mod common;

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::{Lab, Run};
use shadowlab_gpu::registry;

use common::*;

/// `spec` created twice, fresh, on `scene`'s light `light` at 96x96.
fn twice(gpu: &shadowlab_gpu::Gpu, scene: &str, light: usize, spec: &str) -> (Run, Run) {
    let scene = builtin(scene).unwrap();
    let lab = Lab::new(gpu, &scene).unwrap();
    let v = view(&lab, &scene, light, 96);
    let r = registry::resolve(&TechniqueSpec::parse(spec).unwrap(), Some(&v.light)).unwrap();
    let a = lab.step(&v, &mut lab.instantiate(&r, &v.light).unwrap(), true, 1).unwrap();
    let b = lab.step(&v, &mut lab.instantiate(&r, &v.light).unwrap(), true, 1).unwrap();
    (a, b)
}

fn bit_equal(a: &Run, b: &Run) -> bool {
    a.visibility.iter().zip(&b.visibility).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[test]
fn subdivision_out_of_capacity_is_deterministic_and_flagged() {
    let Some(gpu) = gpu() else { return };
    // a capacity far below what these views need (tens of thousands of pieces): the cut happens
    for (scene, light, name) in [
        ("courtyard", 0, "notw"),
        ("courtyard", 0, "rtw"),
        ("room", 0, "notw"),
        ("room", 1, "cube-notw"),
        ("room", 1, "dpsm"),
        ("room", 1, "dpsm-notw"),
    ] {
        let spec = format!("{name}:subdiv_capacity=64");
        let (a, b) = twice(&gpu, scene, light, &spec);
        assert!(bit_equal(&a, &b), "{spec} on {scene} light {light}: two runs differ");
        assert!(!a.report.degraded.is_empty(), "{spec} on {scene}: capacity reached but not flagged: {:?}", a.report.counters);
        let c = &a.report.counters;
        let dropped: f64 = c.iter().filter(|(k, _)| k.ends_with("subdiv_pieces_dropped")).map(|(_, v)| v).sum();
        assert_eq!(dropped, 0.0, "{spec} on {scene}: pieces dropped");
        // at the automatic capacity the same views fit: complete, unflagged, and as stable
        let (a, b) = twice(&gpu, scene, light, name);
        assert!(bit_equal(&a, &b), "{name} on {scene} light {light}: two runs differ");
        assert!(a.report.degraded.is_empty(), "{name} on {scene}: {:?}", a.report.degraded);
    }
}
