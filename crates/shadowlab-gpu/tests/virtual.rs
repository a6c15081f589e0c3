//! GPU tests of `virtual` (virtual shadow maps): against `rt`, marking against the CPU, the
//! page cache, pool exhaustion, and PCF across page borders.

use std::collections::BTreeSet;

use glam::Vec3;
use shadowlab_core::builtin::builtin;
use shadowlab_core::params::{ParamSet, TechniqueSpec};
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{bias_scale, pixel_angle, Build, PageKey};
use shadowlab_gpu::lab::{Lab, View};
use shadowlab_gpu::registry;
use shadowlab_gpu::technique::submit_frame;
use shadowlab_gpu::techniques::virtual_sm::{VirtualSettings, VirtualShadows, DYNAMIC_CHUNK_TRIANGLES};

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

#[test]
fn virtual_matches_rt_on_planebox() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 256);
    let rt = lab.reference(&v, 1).unwrap();
    for s in ["virtual:resolution_bias=-1,pool_mib=64", "virtual:resolution_bias=-1,pool_mib=64,pcf=3"] {
        let run = lab.run(&v, &TechniqueSpec::parse(s).unwrap(), 1).unwrap();
        let a = agreement(&run.visibility, &rt.visibility, &v.mask);
        eprintln!("{s}: {a:.3}% agreement, counters {:?}", run.report.counters);
        assert!(run.report.degraded.is_empty(), "{s}: {:?}", run.report.degraded);
        if a < 99.0 {
            panic!("{s} agrees with rt on {a:.3}%; {}", save_images("virtual-planebox", &v, &run, &rt));
        }
        assert_eq!(run.stalls, vec!["virtual.readback".to_string()]);
    }
}

/// The GPU's marks equal `Clipmap::sample_pages` over the read-back G-buffer. A sample whose
/// answer changes under a 1e-4 relative nudge of its footprint or a 1e-3 texel nudge of its
/// position (float rounding between CPU and GPU at a level or page boundary) may go either way.
#[test]
fn marking_equals_the_cpu_computation() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 192);
    let mut t = make(&lab, &v, "virtual:pcf=3,resolution_bias=0");
    frame(&lab, &mut t, &v);
    let gpu_set: BTreeSet<PageKey> = t.requested().iter().copied().collect();
    let c = t.clipmap().unwrap().clone();
    let pa = pixel_angle(scene.camera.fov_y_deg, v.height);
    let scale = bias_scale(0.0);
    let reach = 1.0 + 0.5 + 1.0; // pcf 3: half 1, normal offset 0.5, one texel
    let (mut certain, mut possible) = (BTreeSet::new(), BTreeSet::new());
    let mut ambiguous = 0;
    for (p, m) in v.position.iter().zip(&v.mask) {
        if *m == 0 {
            continue;
        }
        let p = Vec3::new(p[0], p[1], p[2]);
        let f = (p - scene.camera.position).length() * pa;
        let base = c.sample_pages(p, f, scale, reach);
        let nudge = 1e-3 * c.texel(0);
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
        possible.extend(base);
        for x in variants {
            possible.extend(x);
        }
    }
    assert!(certain.len() > 10, "a real set of pages: {}", certain.len());
    assert!(ambiguous * 100 < v.mask.iter().filter(|m| **m != 0).count(), "few ambiguous samples: {ambiguous}");
    let missing: Vec<_> = certain.difference(&gpu_set).collect();
    let extra: Vec<_> = gpu_set.difference(&possible).collect();
    assert!(missing.is_empty() && extra.is_empty(), "missing {missing:?}, extra {extra:?}");
    // every level in use has its coarsest-level fallback marked
    assert!(gpu_set.iter().any(|p| p.level == c.levels - 1));
}

#[test]
fn a_still_camera_renders_no_page_on_its_second_frame() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let mut t = make(&lab, &v, "virtual");
    let first = frame(&lab, &mut t, &v);
    let a = t.allocation().clone();
    assert!(!a.render.is_empty() && a.render.len() == t.requested().len() && a.cached == 0);
    let second = frame(&lab, &mut t, &v);
    let b = t.allocation();
    assert!(b.render.is_empty(), "second frame rendered {} pages", b.render.len());
    assert_eq!(b.cached, t.requested().len());
    assert_eq!(b.mapped, a.mapped);
    assert!(first.iter().zip(&second).all(|(x, y)| x.to_bits() == y.to_bits()), "cached pages give the same bits");
    // a moved box invalidates exactly the resident pages it covers, which render again
    let c = t.clipmap().unwrap().clone();
    let hit = Bounds { min: Vec3::new(-0.5, 0.0, -0.5), max: Vec3::new(0.5, 1.0, 0.5) };
    let expect: BTreeSet<PageKey> =
        (0..c.levels).flat_map(|k| c.pages_touching(k, &hit)).filter(|k| b.mapped.iter().any(|(m, _)| m == k)).collect();
    assert!(!expect.is_empty(), "the box covers mapped pages");
    assert_eq!(t.invalidate_box(&hit), expect.len());
    let third = frame(&lab, &mut t, &v);
    let rendered: BTreeSet<PageKey> = t.allocation().render.iter().map(|(k, _)| *k).collect();
    assert_eq!(rendered, expect);
    assert!(first.iter().zip(&third).all(|(x, y)| x.to_bits() == y.to_bits()));
}

#[test]
fn a_tiny_pool_falls_back_counted_and_deterministic() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    // 0.25 MiB: 4 pages of 128^2
    let spec = TechniqueSpec::parse("virtual:pool_mib=0.25,resolution_bias=-1").unwrap();
    let runs: Vec<_> = (0..2).map(|_| lab.run(&v, &spec, 1).unwrap()).collect();
    let c = &runs[0].report.counters;
    assert_eq!(c["pool_pages"], 4.0);
    assert!(c["pages_marked"] > 4.0, "more pages wanted than the pool holds: {}", c["pages_marked"]);
    assert!(c["pages_fallback_added"] > 0.0, "coarser fallback pages were added");
    assert_eq!(c["pages_fallen_back"], c["pages_marked"] + c["pages_fallback_added"] - 4.0);
    assert!(!runs[0].report.degraded.is_empty());
    assert!(runs[0].visibility.iter().zip(&runs[1].visibility).all(|(x, y)| x.to_bits() == y.to_bits()));
    assert_eq!(runs[0].report.counters, runs[1].report.counters);
    // the fallen-back pages are the finest: every mapped page is at least as coarse
    let mut t = make(&lab, &v, "virtual:pool_mib=0.25,resolution_bias=-1");
    frame(&lab, &mut t, &v);
    let a = t.allocation();
    let coarsest_fallen = a.fallen_back.iter().map(|p| p.level).max().unwrap();
    assert!(a.mapped.iter().all(|(p, _)| p.level >= coarsest_fallen));
}

/// `resolution_bias=auto` (the default) takes the finest bias, from -1.5 in quarter steps,
/// whose pages fit the pool: a pool too small for -1.5 is not overfilled (nothing falls back,
/// nothing is flagged), the frame marked again for each step, and the result is bit for bit
/// that of the fixed bias it chose. The fixed -1.5 in the same pool falls back, flagged.
#[test]
fn auto_takes_the_finest_bias_whose_pages_fit() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let run = |s: &str| lab.run(&v, &TechniqueSpec::parse(s).unwrap(), 1).unwrap();
    let auto = run("virtual:pool_mib=1");
    let c = &auto.report.counters;
    let bias = c["resolution_bias"];
    assert!(bias > -1.5 && bias <= 2.0 && (bias * 4.0).fract() == 0.0, "a coarser quarter step: {bias}");
    assert!(c["pages_marked"] <= c["pool_pages"], "the pages fit: {c:?}");
    assert!(auto.report.degraded.is_empty() && c["pages_fallen_back"] == 0.0, "{:?}", auto.report.degraded);
    let fixed = run(&format!("virtual:pool_mib=1,resolution_bias={bias}"));
    assert!(auto.visibility.iter().zip(&fixed.visibility).all(|(x, y)| x.to_bits() == y.to_bits()), "auto = its chosen fixed bias");
    // one quarter finer does not fit (else auto would have taken it)
    let finer = run(&format!("virtual:pool_mib=1,resolution_bias={}", bias - 0.25));
    assert!(finer.report.counters["pages_marked"] > c["pool_pages"], "{:?}", finer.report.counters);
    assert!(!finer.report.degraded.is_empty(), "a fixed bias that overfills the pool is flagged");
    // a roomy pool: the finest bias, one marking pass
    let roomy = run("virtual:pool_mib=64");
    assert_eq!((roomy.report.counters["resolution_bias"], roomy.report.counters["resolution_bias_marks"]), (-1.5, 1.0));
}

/// A pool far too small for the view (16 pages of 128^2, a few times fewer than asked for) falls
/// back as many levels as it must, one level at a time: every sample finds a mapped level below
/// the coarsest (whose texels would be far too large for its bias), and the visibility still
/// agrees with `rt` on nearly every pixel. Before the candidates were marked at every level,
/// samples whose one-level-coarser page was left out too walked up to the coarsest level.
#[test]
fn a_deep_overcommit_falls_back_level_by_level() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 128);
    let rt = lab.reference(&v, 1).unwrap();
    let small = lab.run(&v, &TechniqueSpec::parse("virtual:pool_mib=1,resolution_bias=-3,levels=12").unwrap(), 1).unwrap();
    let c = &small.report.counters;
    assert!(c["pages_marked"] > 3.0 * c["pool_pages"], "overcommitted: {c:?}");
    assert!(!c.contains_key("pixels_in_level_11"), "samples at the coarsest level: {c:?}");
    let used: f64 = c.iter().filter(|(k, _)| k.starts_with("pixels_in_level_")).map(|(_, v)| v).sum();
    assert!((used - 1.0).abs() < 1e-9 && c["pixels_unresolved"] == 0.0, "every sample resolved: {c:?}");
    let a = agreement(&small.visibility, &rt.visibility, &v.mask);
    assert!(a > 97.0, "16 pages agree with rt on {a:.3}%");
}

/// PCF taps across page borders read the neighbouring pages: with one level, 64^2 pages give
/// the same visibility as the same level stored as one 2048^2 page (an unpaged map of the same
/// texel grid), on pixels whose 5x5 kernel straddles page borders too.
#[test]
fn pcf_across_page_borders_equals_an_unpaged_map() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let v = view(&lab, &scene, 0, 160);
    let extent = 4.0 * scene.bounds().diagonal();
    let common = format!("virtual:levels=1,virtual_res=2048,level0_extent={extent},pcf=5,pool_mib=16");
    let mut paged = make(&lab, &v, &format!("{common},page_res=64"));
    let mut whole = make(&lab, &v, &format!("{common},page_res=2048"));
    let a = frame(&lab, &mut paged, &v);
    let b = frame(&lab, &mut whole, &v);
    assert!(paged.allocation().fallen_back.is_empty() && whole.allocation().fallen_back.is_empty());
    assert_eq!(whole.allocation().mapped.len(), 1);
    assert!(paged.allocation().mapped.len() > 4);
    // pixels whose kernel (2 texels each way) crosses a 64-texel border
    let c = paged.clipmap().unwrap();
    let cw = whole.clipmap().unwrap();
    let (mut straddling, mut differ, mut differ_straddling, mut compared) = (0, 0, 0, 0);
    for ((p, m), (x, y)) in v.position.iter().zip(&v.mask).zip(a.iter().zip(&b)) {
        if *m == 0 {
            continue;
        }
        let g = c.texel_coords(0, Vec3::new(p[0], p[1], p[2]));
        // the one-page window holds the page containing the eye: compare where it holds the kernel
        let corners = [g - glam::Vec2::splat(3.5), g + glam::Vec2::splat(3.5)];
        if !corners.iter().all(|q| cw.in_window(0, cw.page_of(*q))) {
            continue;
        }
        compared += 1;
        let border = |u: f32| ((u - 2.5) / 64.0).floor() != ((u + 2.5) / 64.0).floor();
        let s = border(g.x) || border(g.y);
        straddling += s as usize;
        if x != y {
            differ += 1;
            differ_straddling += s as usize;
        }
    }
    assert!(compared > 2000, "pixels the one-page map holds: {compared}");
    assert!(straddling > 100, "the view has kernels across page borders: {straddling}");
    assert_eq!(differ, 0, "{differ} pixels differ between the paged and the unpaged map ({differ_straddling} of them straddling; {straddling} straddle borders)");
}

/// World boxes of the moving triangles at time `t` in `virtual`'s chunks (CPU, from the scene).
fn dynamic_chunk_boxes(scene: &shadowlab_core::scene::Scene, t: f32) -> Vec<Bounds> {
    let verts = scene.animated_vertices(t);
    verts
        .chunks(3 * DYNAMIC_CHUNK_TRIANGLES as usize)
        .map(|c| {
            let mut b = Bounds::EMPTY;
            for v in c {
                b.grow(Vec3::from(v.pos));
            }
            b
        })
        .collect()
}

/// Moving objects with a still camera: each frame drops exactly the resident pages that the
/// old or new box of a moved chunk covers (computed here from the scene), and renders exactly
/// the requested pages that are no longer resident; the rest stays cached.
#[test]
fn moving_objects_invalidate_exactly_their_pages() {
    let Some(gpu) = gpu() else { return };
    let scene = builtin("foliage").unwrap();
    assert!(!scene.animations.is_empty());
    let lab = Lab::new(&gpu, &scene).unwrap();
    let light = scene.lights[0];
    let v0 = lab.view(&scene.camera, &scene.camera, &light, 128, 128).unwrap();
    let mut t = make(&lab, &v0, "virtual:pool_mib=64");
    let mut cached_after_first = 0;
    let mut from_copy = 0;
    for f in 0..5 {
        let (time, prev) = (f as f32 * 2.0, (f as f32 - 1.0).max(0.0) * 2.0);
        lab.set_time(time, prev).unwrap();
        let v = lab.view(&scene.camera, &scene.camera, &light, 128, 128).unwrap();
        let resident: BTreeSet<PageKey> = t.cache().resident_pages().copied().collect();
        frame(&lab, &mut t, &v);
        let c = t.clipmap().unwrap().clone();
        let mut stale = BTreeSet::new();
        if f > 0 {
            let (before, now) = (dynamic_chunk_boxes(&scene, prev), dynamic_chunk_boxes(&scene, time));
            for (a, b) in before.iter().zip(&now) {
                if a != b {
                    let mut swept = *a;
                    swept.grow(b.min);
                    swept.grow(b.max);
                    stale.extend(resident.iter().filter(|k| c.page_overlaps(k, &swept)).copied());
                }
            }
            assert!(!stale.is_empty(), "frame {f}: the objects moved over resident pages");
            assert!(stale.len() < resident.len(), "frame {f}: not everything is stale");
        }
        assert_eq!(t.invalidated(), stale.len(), "frame {f}");
        let kept: BTreeSet<PageKey> = resident.difference(&stale).copied().collect();
        let want: BTreeSet<PageKey> = t.requested().iter().filter(|k| !kept.contains(k)).copied().collect();
        let rendered: BTreeSet<PageKey> = t.allocation().render.iter().map(|(k, _)| *k).collect();
        assert_eq!(rendered, want, "frame {f}");
        if f > 0 {
            cached_after_first += t.allocation().cached;
        }
        // pages under the moving objects keep a static copy and are rebuilt from it
        from_copy += t.builds().iter().filter(|b| matches!(b, Build::Copy(_))).count();
    }
    assert!(cached_after_first > 0, "pages stayed cached while objects moved");
    assert!(from_copy > 0, "invalidated pages were rebuilt from their static copies");
    // and the result is the fresh one: a new instance at the last time agrees bit for bit
    let v = lab.view(&scene.camera, &scene.camera, &light, 128, 128).unwrap();
    let live = frame(&lab, &mut t, &v);
    let mut fresh = make(&lab, &v, "virtual:pool_mib=64");
    let new = frame(&lab, &mut fresh, &v);
    assert!(live.iter().zip(&new).all(|(a, b)| a.to_bits() == b.to_bits()), "cached pages equal freshly rendered ones");
    // and a page rebuilt from its static copy equals one drawn whole
    let mut whole = make(&lab, &v, "virtual:pool_mib=64,static_share=0");
    let w = frame(&lab, &mut whole, &v);
    assert_eq!(whole.statics().slots(), 0);
    assert!(whole.builds().iter().all(|b| *b == Build::Full));
    assert!(live.iter().zip(&w).all(|(a, b)| a.to_bits() == b.to_bits()), "pages from static copies equal pages drawn whole");
}
