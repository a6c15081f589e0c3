use glam::{IVec2, Vec3};

use super::*;

fn unit_box() -> Bounds {
    Bounds { min: Vec3::new(-10.0, 0.0, -10.0), max: Vec3::new(10.0, 5.0, 10.0) }
}

/// Light straight down; 4 levels of 1024 texels in pages of 128 (8 x 8 pages), level 0 16 m.
fn clipmap(eye: Vec3) -> Clipmap {
    Clipmap::new(Vec3::new(0.0, -1.0, 0.0), &unit_box(), eye, 4, 1024, 128, 16.0)
}

#[test]
fn level_is_the_ceiling_of_log2_of_footprint_over_texel_plus_bias() {
    assert_eq!(level_for(0.5, 1.0, bias_scale(0.0), 8), 0);
    assert_eq!(level_for(1.0, 1.0, bias_scale(0.0), 8), 0);
    assert_eq!(level_for(1.5, 1.0, bias_scale(0.0), 8), 1);
    assert_eq!(level_for(2.0, 1.0, bias_scale(0.0), 8), 1);
    assert_eq!(level_for(2.001, 1.0, bias_scale(0.0), 8), 2);
    assert_eq!(level_for(100.0, 1.0, bias_scale(0.0), 8), 7, "clamped to the coarsest level");
    assert_eq!(level_for(5.0, 1.0, bias_scale(-1.0), 8), 2);
    assert_eq!(level_for(1.5, 1.0, bias_scale(-3.0), 8), 0, "clamped to level 0");
    assert_eq!(level_for(1.5, 1.0, bias_scale(2.0), 8), 3);
    let pa = pixel_angle(90.0, 1000);
    assert!((pa - 0.002).abs() < 1e-7);
}

#[test]
fn levels_double_the_texel_and_windows_centre_on_the_eye() {
    let c = clipmap(Vec3::ZERO);
    assert_eq!(c.pages_per_side(), 8);
    assert_eq!(c.table_len(), 4 * 64);
    assert_eq!(c.texel(0), 16.0 / 1024.0);
    assert_eq!(c.texel(3), 8.0 * 16.0 / 1024.0);
    for k in 0..4 {
        assert_eq!(c.origins[k as usize], IVec2::new(-4, -4), "level {k}");
    }
    // depth: 0 at the top of the box (nearest the light), 1 at the bottom, with the margin
    assert!(c.depth(Vec3::new(0.0, 5.0, 0.0)) > 0.0 && c.depth(Vec3::new(0.0, 5.0, 0.0)) < 0.01);
    assert!(c.depth(Vec3::ZERO) > 0.99 && c.depth(Vec3::ZERO) < 1.0);
}

#[test]
fn origins_snap_to_whole_pages() {
    let c = clipmap(Vec3::ZERO);
    let page0 = c.texel(0) * 128.0; // 2 m
    let g = |p: Vec3| c.texel_coords(0, p);
    // a world step along `right` of less than a page keeps every origin
    let near = clipmap(c.right * (0.9 * page0));
    assert_eq!(near.origins, c.origins);
    // one and a half pages moves level 0 by one page, level 1 (pages of 4 m) not at all
    let moved = clipmap(c.right * (1.5 * page0));
    assert_eq!(moved.origins[0], c.origins[0] + IVec2::new(1, 0));
    assert_eq!(moved.origins[1], c.origins[1]);
    assert!((g(c.right).x - 64.0).abs() < 1e-3, "1 m = 64 texels of level 0");
    // rows grow downwards: a point further `up` has a smaller row
    assert!(g(c.up).y < g(Vec3::ZERO).y);
}

#[test]
fn table_indices_are_unique_in_the_window_and_invert() {
    let c = clipmap(Vec3::new(37.0, 0.0, -11.0));
    let mut seen = vec![false; c.table_len()];
    for k in 0..4 {
        let o = c.origins[k as usize];
        for y in 0..8 {
            for x in 0..8 {
                let pg = o + IVec2::new(x, y);
                assert!(c.in_window(k, pg));
                let i = c.table_index(k, pg);
                assert!(!seen[i], "index {i} twice");
                seen[i] = true;
                assert_eq!(c.key_of_index(i), PageKey { level: k, x: pg.x, y: pg.y });
            }
        }
        assert!(!c.in_window(k, o - IVec2::new(1, 0)) && !c.in_window(k, o + IVec2::new(0, 8)));
    }
    assert!(seen.iter().all(|s| *s));
}

#[test]
fn a_page_projection_maps_its_square_to_the_viewport() {
    let c = clipmap(Vec3::ZERO);
    let key = PageKey { level: 1, x: 2, y: -3 };
    let m = c.page_view_proj(key);
    let t = c.texel(1);
    // the centre of texel (row 5, column 7) of the page, at the top of the box
    let gx = (2 * 128 + 7) as f32 + 0.5;
    let gy = (-3 * 128 + 5) as f32 + 0.5;
    let p = c.right * (gx * t) - c.up * (gy * t) + Vec3::new(0.0, 5.0, 0.0);
    let ndc = m * p.extend(1.0);
    // viewport pixel: x = (ndc.x + 1) / 2 * 128, y = (1 - ndc.y) / 2 * 128
    let px = (ndc.x + 1.0) * 64.0;
    let py = (1.0 - ndc.y) * 64.0;
    assert!((px - 7.5).abs() < 1e-3 && (py - 5.5).abs() < 1e-3, "{px} {py}");
    assert!((ndc.z - c.depth(p)).abs() < 1e-6);
}

#[test]
fn a_box_touches_the_pages_its_light_rectangle_covers() {
    let c = clipmap(Vec3::ZERO);
    // level 0 pages are 2 m; a box from x 0.5..2.5 and z -1..1 (light down: up = some axis)
    let b = Bounds { min: Vec3::new(0.5, 1.0, -1.0), max: Vec3::new(2.5, 2.0, 1.0) };
    let pages = c.pages_touching(0, &b);
    // expected from the box's texel rectangle
    let mut lo = glam::Vec2::splat(f32::INFINITY);
    let mut hi = glam::Vec2::splat(f32::NEG_INFINITY);
    for p in b.corners() {
        lo = lo.min(c.texel_coords(0, p));
        hi = hi.max(c.texel_coords(0, p));
    }
    let (a, z) = (c.page_of(lo), c.page_of(hi));
    assert_eq!(pages.len() as i32, (z.x - a.x + 1) * (z.y - a.y + 1));
    assert_eq!(pages.len(), 4, "2 m x 2 m straddling two page borders: 2 x 2 pages");
    // level 3's pages are 16 m: the box still straddles the page border at 0 across -1..1
    assert_eq!(c.pages_touching(3, &b).len(), 2);
    let inside = Bounds { min: Vec3::new(0.5, 1.0, 0.5), max: Vec3::new(2.5, 2.0, 1.0) };
    assert_eq!(c.pages_touching(3, &inside).len(), 1);
    // far outside every window: none
    let far = Bounds { min: Vec3::splat(1000.0), max: Vec3::splat(1001.0) };
    assert!(c.pages_touching(0, &far).is_empty());
}

fn key(level: u32, x: i32, y: i32) -> PageKey {
    PageKey { level, x, y }
}

#[test]
fn a_full_pool_keeps_the_coarse_pages_and_counts_the_rest() {
    let mut cache = PageCache::new(3);
    let req = [key(0, 1, 0), key(2, 0, 0), key(0, 0, 0), key(1, 5, 5), key(1, 0, 5), key(0, 0, 0)];
    let a = cache.allocate(&req);
    // priority: level 2, then level 1 by (y, x), then level 0
    assert_eq!(a.mapped, vec![(key(2, 0, 0), 0), (key(1, 0, 5), 1), (key(1, 5, 5), 2)]);
    assert_eq!(a.render, a.mapped);
    assert_eq!(a.fallen_back, vec![key(0, 0, 0), key(0, 1, 0)]);
    assert_eq!(a.cached, 0);
    // the same request again: nothing rendered, the same slots
    let b = cache.allocate(&req);
    assert_eq!(b.mapped, a.mapped);
    assert!(b.render.is_empty());
    assert_eq!(b.cached, 3);
    assert_eq!(b.fallen_back, a.fallen_back);
}

#[test]
fn cached_pages_keep_their_slots_and_stale_ones_are_rendered_again() {
    let mut cache = PageCache::new(4);
    let a = cache.allocate(&[key(0, 0, 0), key(0, 1, 0), key(0, 2, 0)]);
    assert_eq!(a.render.len(), 3);
    assert_eq!(cache.invalidate(&[key(0, 1, 0), key(0, 9, 9)]), 1);
    let b = cache.allocate(&[key(0, 0, 0), key(0, 1, 0), key(0, 2, 0)]);
    assert_eq!(b.cached, 2);
    // the invalidated page takes the lowest free slot: its old one (1)
    assert_eq!(b.render, vec![(key(0, 1, 0), 1)]);
    // new pages: the free slot 3, then the least recently requested unrequested page's slot
    let _ = cache.allocate(&[key(0, 0, 0), key(0, 1, 0)]); // (0,2,0) not requested: older
    let c = cache.allocate(&[key(0, 0, 0), key(0, 1, 0), key(0, 5, 0), key(0, 6, 0)]);
    assert_eq!(c.render, vec![(key(0, 5, 0), 3), (key(0, 6, 0), 2)]);
    assert!(!cache.is_resident(&key(0, 2, 0)));
    assert_eq!(cache.resident(), 4);
    assert_eq!(cache.invalidate_if(|k| k.x >= 5), 2);
    assert_eq!(cache.resident_pages().copied().collect::<Vec<_>>(), vec![key(0, 0, 0), key(0, 1, 0)]);
    cache.clear();
    assert_eq!(cache.allocate(&[key(0, 0, 0)]).render.len(), 1);
}

#[test]
fn a_sample_marks_its_kernel_pages_and_the_coarsest_level() {
    let c = clipmap(Vec3::ZERO);
    let t0 = c.texel(0);
    // footprint 3 t0: level 2; a point 1 texel of level 2 right of a page border (x = 0)
    let p = c.right * (c.texel(2) * 1.0) - c.up * (c.texel(2) * 64.0);
    let pages = c.sample_pages(p, 3.0 * t0, 1.0, 2.5);
    let want = vec![key(3, -1, 0), key(3, 0, 0), key(2, -1, 0), key(2, 0, 0)];
    assert_eq!(pages, want);
    // reach 0.5: one page of level 2, one of level 3
    assert_eq!(c.sample_pages(p, 3.0 * t0, 1.0, 0.5), vec![key(3, 0, 0), key(2, 0, 0)]);
    // far from the eye, out of level 0's window (8 pages of 2 m around 0): level 1 instead
    let q = c.right * 9.0 - c.up;
    assert_eq!(c.sample_pages(q, 0.1 * t0, 1.0, 0.5), vec![key(3, 0, 0), key(1, 2, 0)]);
    // outside every window: nothing
    assert!(c.sample_pages(c.right * 1000.0, t0, 1.0, 0.5).is_empty());
}

#[test]
fn left_out_pages_bring_their_coarser_candidates() {
    // 3 slots; five level-0 pages wanted; candidates at level 1 near their parents and far away
    let req = [key(0, 0, 0), key(0, 1, 0), key(0, 2, 0), key(0, 3, 0), key(0, 8, 8)];
    let cand = [key(1, 1, 0), key(1, 0, 0), key(1, 4, 4), key(1, 20, 20), key(2, 0, 0)];
    // room for everything: nothing added
    assert_eq!(with_fallbacks(&req, &cand, 5, 1, &Demand::default()), {
        let mut r = req.to_vec();
        r.sort();
        r
    });
    let out = with_fallbacks(&req, &cand, 3, 1, &Demand::default());
    // the two level-1 candidates near parents (0,0)/(1,0) come first; then (1,4,4) for (0,8,8)
    // once it is left out; (1,20,20) is near nothing, (2,0,0) is two levels up
    assert_eq!(&out[..3], &[key(1, 0, 0), key(1, 1, 0), key(1, 4, 4)]);
    assert!(!out.contains(&key(1, 20, 20)) && !out.contains(&key(2, 0, 0)));
    assert_eq!(out.len(), 8);
    // the allocation then maps the coarse ones and counts the finest as fallen back
    let a = PageCache::new(3).allocate(&out);
    assert_eq!(a.mapped.iter().map(|m| m.0).collect::<Vec<_>>(), vec![key(1, 0, 0), key(1, 1, 0), key(1, 4, 4)]);
    assert_eq!(a.fallen_back.len(), 5);
}

#[test]
fn demand_adds_samples_up_the_chain_and_orders_pages_inside_a_level() {
    // 5 samples chose level-0 page (0,0), 2 chose (1,0), 7 chose (-1,3); 4 chose level-1 page (3,3)
    let counts = [(key(0, 0, 0), 5), (key(0, 1, 0), 2), (key(0, -1, 3), 7), (key(1, 3, 3), 4)];
    let d = Demand::up_the_chain(&counts, 3, 1);
    assert_eq!((d.of(&key(0, 0, 0)), d.of(&key(0, 1, 0)), d.of(&key(0, 5, 5))), (5, 2, 0));
    // parents: (0,0) and (1,0) share (0,0) at level 1; (-1,3) -> (-1,1); (3,3) -> level 2 (1,1)
    assert_eq!((d.of(&key(1, 0, 0)), d.of(&key(1, -1, 1)), d.of(&key(1, 3, 3))), (7, 7, 4));
    assert_eq!((d.of(&key(2, 0, 0)), d.of(&key(2, -1, 0)), d.of(&key(2, 1, 1))), (7, 7, 4));
    // no level past the last
    assert_eq!(d.of(&key(3, 0, 0)), 0);
    let mut pages = vec![key(0, 0, 0), key(0, 1, 0), key(0, -1, 3), key(0, 5, 5), key(1, 3, 3)];
    d.sort(&mut pages);
    assert_eq!(pages, vec![key(1, 3, 3), key(0, -1, 3), key(0, 0, 0), key(0, 1, 0), key(0, 5, 5)]);
    // a full pool keeps the pages more samples read; equal counts keep page order
    let a = PageCache::new(3).allocate_by(&pages, &d);
    assert_eq!(a.mapped.iter().map(|m| m.0).collect::<Vec<_>>(), vec![key(1, 3, 3), key(0, -1, 3), key(0, 0, 0)]);
    assert_eq!(a.fallen_back, vec![key(0, 1, 0), key(0, 5, 5)]);
    let mut tie = vec![key(0, 2, 0), key(0, 1, 0)];
    Demand::default().sort(&mut tie);
    assert_eq!(tie, vec![key(0, 1, 0), key(0, 2, 0)]);
}

#[test]
fn left_out_pages_bring_candidates_of_the_pages_that_fall_back_in_turn() {
    // 2 slots, both taken by level-2 pages at first: the level-0 pages are left out; their
    // level-1 candidate is left out too; its own level-2 candidate comes in, ahead of the
    // level-2 page fewer samples read: the chain never stops short
    let req = [key(0, 0, 0), key(0, 1, 0), key(2, 5, 5), key(2, 6, 5)];
    let cand = [key(1, 0, 0), key(2, 0, 0)];
    let counts = [(key(0, 0, 0), 3), (key(0, 1, 0), 1), (key(2, 5, 5), 2), (key(2, 6, 5), 1)];
    let d = Demand::up_the_chain(&counts, 3, 1);
    let out = with_fallbacks(&req, &cand, 2, 1, &d);
    assert_eq!(out, vec![key(2, 0, 0), key(2, 5, 5), key(2, 6, 5), key(1, 0, 0), key(0, 0, 0), key(0, 1, 0)]);
    let a = PageCache::new(2).allocate_by(&out, &d);
    assert_eq!(a.mapped.iter().map(|m| m.0).collect::<Vec<_>>(), vec![key(2, 0, 0), key(2, 5, 5)]);
    assert_eq!(a.fallen_back, vec![key(2, 6, 5), key(1, 0, 0), key(0, 0, 0), key(0, 1, 0)]);
}
