//! `iasm:fit=view`: the light square sized and placed from the view samples, the suggestion of
//! the IASM thesis (seed 001, 3.2 and chapter 5: the frustum sides "empirically chosen to
//! encompass all geometry in the scene" waste the tiles on geometry the camera does not see).
//! The GPU reduces the light-space x/y bounds of every evaluated sample (`sdsm`'s bounds
//! reduction with one cascade); [`fit_square`] turns them into the square: centred on the
//! bounds, the side their larger extent plus a margin, and with `snap` the side held in
//! `sdsm`'s fixed steps (with its hysteresis) and the origin on whole coarsest texels, so the
//! texel grids of all tiles stay put while the size holds. The tiles' depth ranges already come
//! from the samples (the analysis's per-tile receiver range, extended towards the light to the
//! casters over the tile: `plan.rs`).

use glam::Vec2;

use super::{light_basis, Placement, THESIS_RESOLUTIONS, TILES_PER_SIDE};
use crate::techniques::sdsm::held_extent;

/// How the square is placed: the thesis's fixed rule (`place`: ahead of the camera, side from
/// `size` or the scene's extent) or fitted to the view samples' bounds ([`fit_square`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    Fixed,
    View,
}

/// Steps of the snapped origin per square side: the coarsest texel of any tile (side / 4 / 16
/// for the thesis set), as `place`'s snapping.
pub fn snap_divisions() -> f32 {
    TILES_PER_SIDE as f32 * *THESIS_RESOLUTIONS.iter().min().unwrap_or(&16) as f32
}

/// The square fitted to the samples' light-space (x, y) bounds `[lo, hi]` for a light
/// travelling along `light_dir`. `margin`: fraction of the bounds' larger extent added on each
/// side (room for the normal offset of samples on the bounds and for motion when the fit is a
/// frame late). The side also holds two snap steps, so rounding the origin to a step never
/// leaves a sample outside. `min_side` keeps a degenerate fit (one sample) finite. With `snap`
/// the side is `sdsm`'s [`held_extent`] of the needed side against `prev` (the side this
/// returned last frame) and the origin sits on whole steps. Returns the placement and the
/// side to pass as `prev` next frame.
pub fn fit_square(
    light_dir: glam::Vec3,
    lo: Vec2,
    hi: Vec2,
    margin: f32,
    min_side: f32,
    snap: bool,
    prev: Option<f32>,
) -> (Placement, f32) {
    let (right, up, dir) = light_basis(light_dir);
    let div = snap_divisions();
    let extent = (hi - lo).max_element().max(0.0);
    // side = extent (1 + 2 margin) + 2 steps, step = side / div
    let need = (extent * (1.0 + 2.0 * margin.max(0.0)) / (1.0 - 2.0 / div)).max(min_side.max(1e-6));
    let side = if snap { held_extent(need, prev) } else { need };
    let centre = 0.5 * (lo + hi);
    let mut origin = centre - Vec2::splat(0.5 * side);
    if snap {
        let step = side / div;
        origin = (origin / step).round() * step;
    }
    (Placement { right, up, dir, origin, size: side }, side)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn contains(p: &Placement, lo: Vec2, hi: Vec2) -> bool {
        lo.cmpge(p.origin).all() && hi.cmple(p.origin + Vec2::splat(p.size)).all()
    }

    #[test]
    fn fitted_square_contains_the_bounds_with_margin() {
        let light = Vec3::new(0.3, -1.0, 0.2);
        for (lo, hi) in [
            (Vec2::new(-3.0, 1.0), Vec2::new(5.0, 2.0)),
            (Vec2::new(10.1, -7.3), Vec2::new(10.2, 30.0)),
            (Vec2::new(-0.004, 0.0071), Vec2::new(0.123, 0.0072)),
        ] {
            for margin in [0.0, 0.02, 0.1] {
                for snap in [false, true] {
                    let (p, side) = fit_square(light, lo, hi, margin, 1e-3, snap, None);
                    assert_eq!(side, p.size);
                    let e = (hi - lo).max_element();
                    assert!(p.size >= e * (1.0 + 2.0 * margin), "{lo} {hi} {margin}: side {}", p.size);
                    // the bounds grown by the margin (minus float slack) are inside
                    let m = Vec2::splat(margin * e * 0.999);
                    assert!(contains(&p, lo - m, hi + m), "{lo} {hi} {margin} {snap}: {p:?}");
                    // not much larger than needed: 2 steps, and with snap 1 size step up
                    let bound = e * (1.0 + 2.0 * margin) / (1.0 - 2.0 / 64.0) * if snap { 1.0444 } else { 1.0001 };
                    assert!(p.size <= bound.max(1e-3 * 1.0444), "{lo} {hi} {margin} {snap}: side {} > {bound}", p.size);
                    if snap {
                        let q = p.origin / (p.size / 64.0);
                        assert!((q - q.round()).abs().max_element() < 1e-2, "origin on whole steps: {q}");
                    }
                }
            }
        }
    }

    #[test]
    fn snapped_side_holds_until_the_samples_shrink_two_steps() {
        let light = Vec3::new(0.0, -1.0, 0.4);
        let (a, side) = fit_square(light, Vec2::ZERO, Vec2::new(10.0, 4.0), 0.0, 1e-3, true, None);
        // slightly smaller and shifted bounds: same side, the square follows in whole steps
        let (b, side_b) = fit_square(light, Vec2::new(0.3, 0.0), Vec2::new(10.0, 4.0), 0.0, 1e-3, true, Some(side));
        assert_eq!(side_b, side);
        assert_eq!(b.size, a.size);
        let d = (b.origin - a.origin) / (side / 64.0);
        assert!((d - d.round()).abs().max_element() < 1e-3, "{d}");
        // much smaller: the side follows down
        let (_, side_c) = fit_square(light, Vec2::ZERO, Vec2::new(5.0, 4.0), 0.0, 1e-3, true, Some(side));
        assert!(side_c < 0.6 * side);
        // larger: grows at once
        let (_, side_d) = fit_square(light, Vec2::ZERO, Vec2::new(11.0, 4.0), 0.0, 1e-3, true, Some(side));
        assert!(side_d >= 11.0);
        // a single sample: the minimum side, centred on it
        let (e, _) = fit_square(light, Vec2::splat(2.0), Vec2::splat(2.0), 0.02, 0.5, false, None);
        assert_eq!(e.size, 0.5);
        assert!((e.origin - Vec2::splat(1.75)).abs().max_element() < 1e-6);
    }
}
