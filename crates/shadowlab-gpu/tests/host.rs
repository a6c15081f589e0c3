//! The library seam: `examples/host_app.rs` (its own device, its own depth/normal pass, `sm`
//! and `lt` recorded into its encoder, one submit per frame) agrees with the lab on the same view.

#[allow(dead_code)]
#[path = "../examples/host_app.rs"]
mod host_app;

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;

#[test]
fn host_app_matches_the_lab_with_one_submit_per_frame() {
    let Some(lab_gpu) = crate::common::gpu() else { return };
    let gpu = host_app::open_device().expect("host device");
    let scene = builtin("courtyard").unwrap();
    let frames = 3;
    let r = host_app::run(&gpu, &scene, 128, frames).expect("host frames");
    assert_eq!(r.frame_submits, vec![1; frames], "the host's frames are one submit each (sm and lt declare no stall)");

    let lab = Lab::new(&lab_gpu, &scene).unwrap();
    let v = lab.view(&r.camera, &r.camera, &r.light, r.width, r.height).unwrap();
    for (name, host_vis) in &r.visibility {
        let shadowlab_gpu::registry::Resolved { info, values: params, .. } =
            shadowlab_gpu::registry::resolve(&TechniqueSpec::parse(name).unwrap(), Some(&r.light)).unwrap();
        let mut inst = lab.instantiate(&shadowlab_gpu::registry::Resolved::new(info, params, name.clone()), &r.light).unwrap();
        // the same number of frames as the host ran (lt keeps a temporal mask)
        let mut run = lab.step(&v, &mut inst, false, 1).unwrap();
        for _ in 1..frames {
            run = lab.step(&v, &mut inst, false, 1).unwrap();
        }
        let m = compare(host_vis, &run.visibility, &v.mask);
        let bit_equal = host_vis.iter().zip(&run.visibility).filter(|(a, b)| a.to_bits() == b.to_bits()).count();
        eprintln!(
            "{name}: host vs lab {:.4} % wrong over {} pixels, {bit_equal} of {} values bit-equal",
            m.wrong_pct,
            m.evaluated_pixels,
            host_vis.len()
        );
        // The host's own G-buffer shader computes what the lab's does (world position, linear
        // depth, the stored face normal towards the camera), and courtyard has no cut-outs or
        // single-sided materials for the lab to discard: the inputs, and so the visibility,
        // are the same bit for bit.
        assert_eq!(bit_equal, host_vis.len(), "{name}: host and lab differ on {:.3} % of the pixels", m.wrong_pct);
    }
}
