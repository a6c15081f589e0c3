//! The cost work on the warped maps (docs/bench/warp_cost.md): culling the subdivision pieces
//! that cover no texel centre must leave the depth map and the visibility unchanged, bit for bit.

use glam::Vec3;
use shadowlab_core::builtin::builtin;
use shadowlab_core::light::Light;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::{Lab, View};
use shadowlab_gpu::techniques::warp::{Cull, Variant, Warped};
use shadowlab_gpu::techniques::{self, Technique};
use shadowlab_gpu::timing::StageTimer;

mod common;
use common::*;

struct Out {
    visibility: Vec<f32>,
    map: Vec<f32>,
    drawn: f64,
    culled: f64,
    dropped: f64,
}

fn run(gpu: &shadowlab_gpu::Gpu, lab: &Lab, v: &View, spec: &str, variant: Variant, cull: Cull) -> Out {
    let (_, params) = techniques::resolve(&TechniqueSpec::parse(spec).unwrap(), Some(&v.light)).unwrap();
    let mut t = Warped::new(gpu, &lab.gscene, &params, &v.light, variant).unwrap();
    t.set_cull(gpu, cull);
    let f = v.inputs(&lab.gscene);
    techniques::run_frame(&mut t, gpu, &f, &mut StageTimer::default()).unwrap();
    gpu.take_error().unwrap();
    let visibility = gpu.read_buffer_as(&v.visibility, v.gbuffer.pixels());
    let map = t.read_map(gpu);
    let r = t.report(gpu);
    let c = |k: &str| *r.counters.get(k).unwrap_or_else(|| panic!("{spec}: no counter {k}"));
    Out { visibility, map, drawn: c("subdiv_triangles_drawn"), culled: c("subdiv_pieces_culled"), dropped: c("subdiv_pieces_dropped") }
}

/// Courtyard, sun (orthographic) and spot (perspective, near-plane clipping), notw (exact and
/// interpolated depth) and rtw: the same map and visibility without culling (the default),
/// culling the pieces outside the cropped map and also those covering no texel centre; the culled
/// pieces are exactly the pieces no longer drawn, and each culling removes some.
#[test]
fn culling_pieces_that_cover_no_texel_changes_nothing() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("courtyard").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    // the sun of the built-in scene and the spot light of setups/warp-courtyard.toml
    let spot = Light::Spot { position: Vec3::new(2.0, 12.0, 0.0), direction: Vec3::new(-0.3, -1.0, 0.0), cone_deg: 50.0 };
    for (light, l) in [scene.lights[0], spot].iter().enumerate() {
        let v = lab.view(&scene.camera, &scene.camera, l, 256, 256).unwrap();
        for (spec, variant) in
            [("notw:res=256", Variant::Notw), ("rtw:res=256", Variant::Rtw), ("notw:res=256,exact_depth=false", Variant::Notw)]
        {
            let off = run(&gpu, &lab, &v, spec, variant, Cull::Off);
            let what = format!("{spec}, light {light}");
            assert_eq!(off.culled, 0.0, "{what}: culling off culls nothing");
            let mut culled = 0.0;
            for cull in [Cull::Outside, Cull::Empty] {
                let on = run(&gpu, &lab, &v, spec, variant, cull);
                let what = format!("{what}, {cull:?}");
                assert_eq!((off.dropped, on.dropped), (0.0, 0.0), "{what}: no piece dropped");
                assert!(on.culled > culled, "{what}: culled {} (the weaker culling: {culled})", on.culled);
                culled = on.culled;
                assert_eq!(on.drawn + on.culled, off.drawn, "{what}: drawn {} + culled {} vs drawn without culling", on.drawn, on.culled);
                let maps = off.map.iter().zip(&on.map).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
                assert_eq!(maps, 0, "{what}: {maps} map texels differ with culling");
                let vis = off.visibility.iter().zip(&on.visibility).filter(|(a, b)| a.to_bits() != b.to_bits()).count();
                assert_eq!(vis, 0, "{what}: {vis} pixels' visibility differ with culling");
                eprintln!("{what}: {} pieces, {} culled ({:.1} %)", off.drawn, on.culled, 100.0 * on.culled / off.drawn);
            }
        }
    }
}
