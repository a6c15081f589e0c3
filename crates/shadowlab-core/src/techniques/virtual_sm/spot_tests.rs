//! Spot maps of `virtual`: the perspective page projection, the mip levels, footprint matching
//! and clamping at the map's edge.

use glam::{IVec2, Vec2, Vec3};

use super::*;

fn room() -> Bounds {
    Bounds { min: Vec3::new(-10.0, 0.0, -10.0), max: Vec3::new(10.0, 5.0, 10.0) }
}

/// A 40-degree spot 4 m up, pointing down and a little sideways; 2048 texels in 128^2 pages
/// (16 x 16 pages at level 0, 5 mip levels down to one page).
fn spot() -> Clipmap {
    Clipmap::spot(Vec3::new(0.0, 4.0, 0.0), Vec3::new(0.2, -1.0, 0.1), 40.0, &room(), 16, 2048, 128)
}

#[test]
fn the_mip_chain_ends_at_one_page() {
    assert_eq!(spot_levels(16, 16384, 128), 8);
    assert_eq!(spot_levels(3, 16384, 128), 3);
    assert_eq!(spot_levels(16, 128, 128), 1);
    let c = spot();
    assert_eq!(c.levels, 5);
    assert_eq!((0..5).map(|k| c.side(k)).collect::<Vec<_>>(), vec![16, 8, 4, 2, 1]);
    assert!(c.origins.iter().all(|o| *o == IVec2::ZERO));
}

#[test]
fn the_cone_fills_the_map_and_its_axis_is_the_centre() {
    let c = spot();
    let Projection::Persp { position, .. } = c.projection else { panic!("a spot map") };
    let g = c.light_coords(position + c.dir * 3.0);
    assert!((g - Vec2::ONE).abs().max_element() < 1e-6, "{g}");
    // a point on the cone's edge (40 degrees off the axis, along `right`) is on the map's edge
    let edge = position + (c.dir + c.right * 40f32.to_radians().tan()) * 2.0;
    let g = c.light_coords(edge);
    assert!((g.x - 2.0).abs() < 1e-5 && (g.y - 1.0).abs() < 1e-5, "{g}");
    // up in light space is the top row (smaller w)
    assert!(c.light_coords(position + (c.dir + c.up * 0.3) * 2.0).y < 1.0);
    assert!(c.light_coords_in_front(0, position - c.dir).is_none());
}

#[test]
fn a_spot_page_projection_maps_its_square_to_the_viewport_and_depth() {
    let c = spot();
    for (key, (tx, ty), z) in [
        (PageKey { level: 0, x: 9, y: 4 }, (7.5, 5.5), 3.0),
        (PageKey { level: 2, x: 0, y: 3 }, (120.5, 0.5), 6.5),
        (PageKey { level: 4, x: 0, y: 0 }, (64.5, 64.5), 1.0),
    ] {
        let m = c.page_view_proj(key);
        // the point at texel (tx, ty) of the page, at light-view depth z
        let s = c.texel(key.level);
        let u = (key.x as f32 * 128.0 + tx) * s;
        let w = (key.y as f32 * 128.0 + ty) * s;
        let Projection::Persp { position, tan_half } = c.projection else { unreachable!() };
        let p = position + (c.dir + c.right * ((u - 1.0) * tan_half) + c.up * ((1.0 - w) * tan_half)) * z;
        let g = c.texel_coords(key.level, p);
        assert!((g - Vec2::new(key.x as f32 * 128.0 + tx, key.y as f32 * 128.0 + ty)).abs().max_element() < 2e-3, "{g}");
        let clip = m * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (px, py) = ((ndc.x + 1.0) * 64.0, (1.0 - ndc.y) * 64.0);
        assert!((px - tx).abs() < 2e-3 && (py - ty).abs() < 2e-3, "{key:?}: {px} {py}");
        assert!((ndc.z - c.depth(p)).abs() < 1e-6, "{} vs {}", ndc.z, c.depth(p));
        assert!(ndc.z > 0.0 && ndc.z < 1.0);
    }
    // depth grows away from the light
    let Projection::Persp { position, .. } = c.projection else { unreachable!() };
    assert!(c.depth(position + c.dir * 2.0) < c.depth(position + c.dir * 2.01));
}

#[test]
fn a_spot_sample_picks_the_level_whose_texel_matches_its_footprint() {
    let c = spot();
    let Projection::Persp { position, .. } = c.projection else { unreachable!() };
    let p = position + (c.dir + c.right * 0.2) * 3.0;
    let t0 = c.texel0_at(p);
    // a level-0 texel at light depth 3: 3 x 2 tan(40) / 2048
    assert!((t0 - 3.0 * 2.0 * 40f32.to_radians().tan() / 2048.0).abs() < 1e-7);
    for (footprint, level) in [(0.5 * t0, 0), (1.5 * t0, 1), (3.0 * t0, 2), (1e3 * t0, 4)] {
        let pages = c.sample_pages(p, footprint, 1.0, 1.5);
        let finest = pages.iter().map(|k| k.level).min().unwrap();
        assert_eq!(finest, level, "footprint {footprint}");
        // and the single page of the coarsest level, the fallback of last resort
        assert!(pages.contains(&PageKey { level: 4, x: 0, y: 0 }));
    }
}

#[test]
fn marks_at_the_map_edge_clamp_to_it() {
    let c = spot();
    let Projection::Persp { position, tan_half } = c.projection else { unreachable!() };
    // just inside the cone's edge on the -right side: the kernel reaches past column 0
    let p = position + (c.dir - c.right * (tan_half * 0.9999)) * 2.0;
    let pages = c.sample_pages(p, 0.1 * c.texel0_at(p), 1.0, 2.5);
    assert!(!pages.is_empty());
    assert!(pages.iter().all(|k| k.x >= 0 && k.y >= 0 && k.x < c.side(k.level) && k.y < c.side(k.level)), "{pages:?}");
    assert!(pages.iter().any(|k| k.level == 0 && k.x == 0));
    // boxes: one behind the light spans the map; one in front its rectangle
    let behind = Bounds { min: position - Vec3::splat(0.5), max: position + Vec3::splat(0.5) };
    assert_eq!(c.pages_touching(1, &behind).len(), 64);
    assert!(c.page_overlaps(&PageKey { level: 0, x: 15, y: 15 }, &behind));
    let q = position + c.dir * 3.0;
    let small = Bounds { min: q - Vec3::splat(0.01), max: q + Vec3::splat(0.01) };
    let touched = c.pages_touching(0, &small);
    assert!(!touched.is_empty() && touched.len() <= 4, "{touched:?}");
    assert!(touched.iter().all(|k| (7..=8).contains(&k.x) && (7..=8).contains(&k.y)));
}
