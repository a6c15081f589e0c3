//! `sv` (shadow volumes) against the exact reference `rt`: the seeds' ground truth must agree
//! with ours.

use shadowlab_core::builtin::builtin;
use shadowlab_core::metrics::compare;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;

mod common;
use common::*;

#[test]
fn sv_agrees_with_rt_on_every_opaque_builtin_scene_and_light() {
    let Some(gpu) = gpu() else { return };
    let spec = TechniqueSpec::parse("sv").unwrap();
    for name in ["courtyard", "room", "planebox"] {
        let scene = builtin(name).unwrap();
        assert!(!scene.has_cutouts(), "{name} has cut-outs");
        let lab = Lab::new(&gpu, &scene).unwrap();
        for li in 0..scene.lights.len() {
            let v = view(&lab, &scene, li, 256);
            let rt = lab.reference(&v, 1).unwrap();
            let sv = lab.run(&v, &spec, 1).unwrap();
            let m = compare(&sv.visibility, &rt.visibility, &v.mask);
            eprintln!(
                "{name} light {li}: agree {:.4}% (false lit {:.4}%, false shadow {:.4}%) {:?}",
                100.0 - m.wrong_pct,
                m.false_lit_pct,
                m.false_shadow_pct,
                sv.report.counters
            );
            let lit = rt.visibility.iter().zip(&v.mask).filter(|(x, m)| **m != 0 && **x > 0.5).count();
            assert!(lit > 0 && (lit as u64) < m.evaluated_pixels, "{name} light {li}: no shadow or no light at all");
            if 100.0 - m.wrong_pct < 99.9 {
                panic!(
                    "{name} light {li}: sv agrees with rt on {:.4}%; {}",
                    100.0 - m.wrong_pct,
                    save_images(&format!("sv-{name}-{li}"), &v, &sv, &rt)
                );
            }
        }
    }
}
