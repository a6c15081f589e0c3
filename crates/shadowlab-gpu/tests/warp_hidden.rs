//! GPU tests of hidden-edge culling in the warped maps' subdivision (`cull_hidden`,
//! warp/occluders.rs): the occluder pyramid is the maximum it claims to be, and leaving hidden
//! edges unsplit draws fewer pieces without losing agreement with `rt`.

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::{ParamSet, TechniqueSpec};
use shadowlab_gpu::lab::{Lab, View};
use shadowlab_gpu::registry;
use shadowlab_gpu::technique;
use shadowlab_gpu::techniques::warp::{Knobs, NotwSettings, Warped};

use crate::common::*;

fn run_direct(gpu: &shadowlab_gpu::Gpu, lab: &Lab, v: &View, spec: &str) -> Warped {
    let resolved = registry::resolve(&TechniqueSpec::parse(spec).unwrap(), Some(&v.light)).unwrap();
    let knobs = Knobs::notw(&NotwSettings::from_values(&resolved.values));
    let mut t = Warped::new(gpu, &lab.gscene, &knobs, &v.light).unwrap();
    technique::submit_frame(&mut t, gpu, &v.inputs(&lab.gscene)).unwrap();
    gpu.take_error().unwrap();
    t
}

/// The pyramid, level by level, against the CPU: level 0 is the occluder map, each level above
/// the maximum of the 2x2 texels below it (ceil(side / 2) a side; an odd side's last texel
/// stands alone). Res 100 makes every level odd-sided somewhere.
#[test]
fn the_occluder_pyramid_holds_the_maxima_of_the_occluder_map() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("city").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let t = run_direct(&gpu, &lab, &v, "notw:res=100,window=16,cull_hidden=true");
    let (depth, hzb) = t.read_occluders(&gpu).expect("cull_hidden=true builds the occluder pyramid");
    let res = 100usize;
    let drawn = depth.iter().filter(|d| **d < 1.0).count();
    let mut distinct: Vec<u32> = depth.iter().map(|d| d.to_bits()).collect();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(
        drawn > res * res / 2 && distinct.len() > res,
        "{drawn} texels drawn, {} depths: the city's ground and blocks expected",
        distinct.len()
    );
    assert_eq!(&hzb[..res * res], &depth[..], "level 0 is the occluder map");
    let (mut side, mut at) = (res, 0usize);
    let mut levels = 0;
    while side > 1 {
        let up = side.div_ceil(2);
        for y in 0..up {
            for x in 0..up {
                let mut m = f32::MIN;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = ((2 * x + dx).min(side - 1), (2 * y + dy).min(side - 1));
                    m = m.max(hzb[at + sy * side + sx]);
                }
                assert_eq!(hzb[at + side * side + y * up + x], m, "level {} texel ({x}, {y})", levels + 1);
            }
        }
        at += side * side;
        side = up;
        levels += 1;
    }
    assert_eq!(levels, 7, "100 -> 50 -> 25 -> 13 -> 7 -> 4 -> 2 -> 1");
    assert_eq!(hzb.len(), at + 1);
}

/// `cube-notw` on the room's point light (furniture, walls and the ceiling seen from inside:
/// several layers on every face): culling hidden edges leaves some bent edges unsplit, draws
/// fewer pieces, and agrees with `rt` as well as splitting everything does.
#[test]
fn culling_hidden_edges_draws_fewer_pieces_at_the_same_quality() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("room").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 1, 192);
    let rt = lab.reference(&v, 1).unwrap();
    let run = |s: &str| lab.run(&v, &TechniqueSpec::parse(s).unwrap(), 1).unwrap();
    let on = run("cube-notw:res=128,window=64,cull_hidden=true");
    let off = run("cube-notw:res=128,window=64");
    let pieces = |r: &shadowlab_gpu::lab::Run| r.report.counters["subdiv_triangles_drawn"];
    let wrong = |r: &shadowlab_gpu::lab::Run| 100.0 - agreement(&r.visibility, &rt.visibility, &v.mask);
    eprintln!(
        "room point 192, cube-notw res 128: culled {} pieces, {:.3} % wrong ({} hidden edge tests); all split {} pieces, {:.3} %",
        pieces(&on),
        wrong(&on),
        on.report.counters["subdiv_hidden_edge_tests"],
        pieces(&off),
        wrong(&off)
    );
    assert!(on.report.counters["subdiv_hidden_edge_tests"] > 0.0);
    assert!(!off.report.counters.contains_key("subdiv_hidden_edge_tests"));
    assert!(pieces(&on) < pieces(&off), "{} pieces culled vs {} all split", pieces(&on), pieces(&off));
    assert!(wrong(&on) <= wrong(&off) + 0.05, "{:.3} % wrong culled vs {:.3} % all split", wrong(&on), wrong(&off));
    assert!(on.report.degraded.is_empty() && off.report.degraded.is_empty());
}

/// `edge_importance` on the city under its sun: a view sample on a shadow edge of the occluder
/// map counts 1 + k, any other 1. So the count map with k = 4 minus the one without is 4 x the
/// edge samples per texel: divisible by 4, present, a minority of the sampled texels, and only
/// where the occluder map's 3x3 texels around the texel hold different depths.
#[test]
fn edge_importance_counts_shadow_edge_samples_more() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("city").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let spec = "notw:res=100,window=16";
    let plain = run_direct(&gpu, &lab, &v, spec);
    let edged = run_direct(&gpu, &lab, &v, &format!("{spec},edge_importance=4"));
    assert!(plain.read_occluders(&gpu).is_none(), "no occluder pass without cull_hidden or edge_importance");
    let (depth, _) = edged.read_occluders(&gpu).expect("edge_importance draws the occluder map");
    let (a, b) = (plain.read_counts_before(&gpu), edged.read_counts_before(&gpu));
    let res = 100usize;
    let (mut edge_texels, mut sampled) = (0, 0);
    for (i, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(y >= x && (y - x) % 4 == 0, "texel {i}: {x} -> {y}");
        sampled += (*x > 0) as usize;
        if y > x {
            edge_texels += 1;
            let (tx, ty) = ((i % res) as i64, (i / res) as i64);
            let around: Vec<f32> = (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| ((tx + dx).clamp(0, 99), (ty + dy).clamp(0, 99))))
                .map(|(x, y)| depth[y as usize * res + x as usize])
                .collect();
            let (lo, hi) = around.iter().fold((f32::MAX, f32::MIN), |(l, h), d| (l.min(*d), h.max(*d)));
            assert!(hi > lo, "texel ({tx}, {ty}) counted as a shadow edge over a flat occluder map");
        }
    }
    eprintln!("{edge_texels} of {sampled} sampled texels hold shadow-edge samples");
    assert!(edge_texels > 20 && edge_texels * 2 < sampled, "{edge_texels} of {sampled}");
}
