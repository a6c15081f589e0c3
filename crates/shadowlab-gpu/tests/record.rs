//! The recorded frame: techniques record into the caller's encoder, a frame without declared
//! stalls is one submit, and the lab's analysis passes (outside the timed frame) leave the
//! visibility bit for bit as the timed frame wrote it.

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::ParamValues;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::registry::REGISTRY;

use crate::common::*;

/// Every technique on every light of planebox (directional) and room (spot, point) that it
/// supports, at 96x96: one timed frame with a warm-up.
fn each_technique(mut check: impl FnMut(&str, &str, &shadowlab_gpu::lab::Run, &[f32])) {
    let Some(gpu) = gpu() else { return };
    for scene_name in ["planebox", "room"] {
        let scene = builtin(scene_name).unwrap();
        let lab = Lab::new(&gpu, &scene).unwrap();
        for (l, light) in scene.lights.iter().enumerate() {
            let v = view(&lab, &scene, l, 96);
            for info in REGISTRY.iter().filter(|t| t.lights.contains(&light.kind())) {
                let params: ParamValues = shadowlab_core::params::TechniqueSpec::parse(info.name).unwrap().resolve(info.params()).unwrap();
                let mut inst = lab.instantiate(&shadowlab_gpu::registry::Resolved::new(info, params, info.name), light).unwrap();
                let run = lab.step(&v, &mut inst, true, 1).unwrap();
                // the visibility buffer after the analysis passes, report and shading
                let after: Vec<f32> = gpu.read_buffer_as(&v.visibility, v.gbuffer.pixels());
                check(&format!("{scene_name} light {l}"), info.name, &run, &after);
            }
        }
    }
}

/// One pass over the techniques for both checks (each technique once per light: the debug
/// build on lavapipe makes this the slowest test here).
#[test]
fn analysis_passes_leave_the_visibility_bit_equal_and_a_frame_is_one_submit_unless_declared() {
    let mut checked = 0;
    each_technique(|at, name, run, after| {
        let same = run.visibility.iter().zip(after).all(|(a, b)| a.to_bits() == b.to_bits());
        assert!(same, "{name} on {at}: the analysis passes changed the visibility");
        let info = REGISTRY.iter().find(|t| t.name == name).unwrap();
        if run.stalls.is_empty() {
            assert_eq!(run.submits_per_frame, 1, "{name} on {at}: {} submits without a declared stall", run.submits_per_frame);
        } else {
            assert!(!info.stalls.is_empty(), "{name} on {at} stalled ({:?}) but its registry entry declares no stall", run.stalls);
            assert_eq!(
                run.submits_per_frame,
                1 + run.stalls.len() as u64,
                "{name} on {at}: one submit per declared stall, plus the frame's"
            );
        }
        checked += 1;
    });
    if crate::common::gpu().is_some() {
        assert!(checked >= REGISTRY.len(), "only {checked} technique runs checked");
    }
}

#[test]
fn the_timed_frame_of_sm_has_no_sample_counting() {
    // the timed evaluation leaves the count map alone; the analysis pass fills it
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 64);
    let run = lab.run(&v, &shadowlab_core::params::TechniqueSpec::parse("sm").unwrap(), 1).unwrap();
    let s = run.report.sampling.expect("sm reports sampling");
    assert!(s.used_texel_fraction > 0.0, "the analysis pass counted the view samples");
    assert!(run.stages_ms.keys().all(|k| !k.ends_with(".analysis")), "analysis stages are not timed: {:?}", run.stages_ms.keys());
}

#[test]
fn delayed_modes_record_without_a_stall_and_match_on_a_still_view() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 96);
    for (now, delayed) in [("csm", "csm:delayed=true"), ("iasm", "iasm:delayed=true")] {
        let parse = |s: &str| shadowlab_core::params::TechniqueSpec::parse(s).unwrap();
        // a warm-up frame, then the timed one: the delayed mode reads the warm-up's reduction
        let a = lab.run(&v, &parse(now), 1).unwrap();
        let b = lab.run(&v, &parse(delayed), 1).unwrap();
        assert!(!a.stalls.is_empty(), "{now} reads back mid-frame");
        assert!(b.stalls.is_empty() && b.submits_per_frame == 1, "{delayed}: {:?}, {} submits", b.stalls, b.submits_per_frame);
        // a still view: the previous frame's reduction is this frame's
        let same = a.visibility.iter().zip(&b.visibility).all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "{delayed} differs from {now} on a still view");
    }
}
