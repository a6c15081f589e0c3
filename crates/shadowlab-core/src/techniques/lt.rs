//! Leak tracing (seed 004, Kern, Brüll, Grosch): the CPU half. The leak-tracing shadow test
//! (LTT, eq. 3), the 3-bit temporal mask (section 3.1: shadow test ST, LTT, ray result RS), its
//! Table 1 classes, expand rays (ER, eq. 6), remove rays (RR, eq. 8), the per-pixel decision of
//! section 3.1.3, the 2x2 jittered neighbourhood that covers 3x3 over 4 frames, and the mask
//! format chosen by the light count, the cascade reuse of section 3.3, and the six cube faces
//! of a point light (one map of six layers, each a perspective face read with the 2x2 gather).
//! `techniques/lt/classify.wgsl` mirrors the per-pixel functions.

use glam::Vec4Swizzles;

use crate::camera::{look_at, perspective};
use crate::lightspace::LightProjection;
use crate::scene::Bounds;
use crate::techniques::csm::CascadeBox;

/// LTT epsilon: a ray where `eps < s < 1 - eps` (seed 004 eq. 3 and section 4: 0.01). Too low:
/// numerical noise of the bounds flags whole lit/shadowed regions; too high: misses leaks whose
/// bound is close to 0 or 1.
pub const DEFAULT_EPS: f64 = 0.01;
/// Shadow test cut-off: ST := s < 0.5 (seed 004 eq. 4).
pub const ST_CUTOFF: f32 = 0.5;
/// Lights one mask texel can hold (3 bits each in at most 32 bits).
pub const MAX_LIGHTS: usize = 10;

/// Mask bits of one light, in the order of section 3.1.
pub const BIT_ST: u32 = 1;
pub const BIT_LTT: u32 = 2;
pub const BIT_RS: u32 = 4;

/// Leak-tracing shadow test (eq. 3): the filtered bound is neither confidently 0 nor 1.
pub fn ltt(s: f32, eps: f32) -> bool {
    eps < s && s < 1.0 - eps
}

/// Shadow test (eq. 4): the map says shadowed.
pub fn shadow_test(s: f32) -> bool {
    s < ST_CUTOFF
}

/// One light's entry of the temporal mask: ST, LTT (a ray was traced) and RS (the ray hit).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Mask {
    pub st: bool,
    pub ltt: bool,
    pub rs: bool,
}

impl Mask {
    pub fn bits(self) -> u32 {
        ((self.st as u32) * BIT_ST) | ((self.ltt as u32) * BIT_LTT) | ((self.rs as u32) * BIT_RS)
    }
    pub fn from_bits(b: u32) -> Mask {
        Mask { st: b & BIT_ST != 0, ltt: b & BIT_LTT != 0, rs: b & BIT_RS != 0 }
    }
}

/// The classes of Table 1 (seed 004).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// LTT 0, ST 0: confidently lit (or facing away from the light).
    Black,
    /// LTT 0, ST 1: confidently shadowed.
    Green,
    /// LTT 1, ST 1, RS 1: shadowed test confirmed by the ray.
    White,
    /// LTT 1, ST 0, RS 1: lit test corrected by the ray (a leak or an edge).
    Purple,
    /// LTT 1, ST 0, RS 0: lit test confirmed by the ray.
    Red,
    /// LTT 1, ST 1, RS 0: shadowed test corrected by the ray.
    Yellow,
}

impl Class {
    pub fn of(m: Mask) -> Class {
        match (m.ltt, m.st, m.rs) {
            (false, false, _) => Class::Black,
            (false, true, _) => Class::Green,
            (true, true, true) => Class::White,
            (true, false, true) => Class::Purple,
            (true, false, false) => Class::Red,
            (true, true, false) => Class::Yellow,
        }
    }
    /// The colour of Table 1 / Figure 5.
    pub fn rgb(self) -> [u8; 3] {
        match self {
            Class::Black => [0, 0, 0],
            Class::Green => [0, 200, 0],
            Class::White => [255, 255, 255],
            Class::Purple => [160, 32, 240],
            Class::Red => [230, 0, 0],
            Class::Yellow => [255, 220, 0],
        }
    }
}

/// Expand rays (eq. 6) for one neighbour `m` of last frame and the current shadow test `st`:
/// the neighbour's ray disagreed with the current test, or its test changed.
pub fn expand(m: Mask, st: bool) -> bool {
    (m.ltt && (m.rs ^ st)) || (m.st ^ st)
}

/// Remove rays (eq. 8) for one neighbour: it stays in the same shadow case and, if it traced a
/// ray, the ray confirmed the current test. A ray is removed when this holds for all neighbours.
pub fn remove(m: Mask, st: bool) -> bool {
    (st == m.st) && (!m.ltt || st == m.rs)
}

/// What the current pixel knows when it decides (section 3.1.3).
#[derive(Clone, Copy, Debug)]
pub struct Pixel {
    /// LTT of this frame's map (eq. 3).
    pub ltt: bool,
    /// ST of this frame's map (eq. 4).
    pub st: bool,
    /// The pixel's position was found in last frame's mask (on screen, same surface).
    pub reprojected: bool,
    /// RR allowed here (off for dynamic-geometry samples, section 3.4).
    pub may_remove: bool,
}

/// Whether the pixel traces a ray: steps 2-5 of section 3.1.3 over the reprojected neighbours
/// (2x2 jittered or full 3x3) of last frame's mask. `remove_rays` switches RR (step 5) on.
pub fn decide(p: Pixel, neighbours: &[Mask], remove_rays: bool) -> bool {
    if !p.reprojected {
        return true;
    }
    if !p.ltt {
        return neighbours.iter().any(|m| expand(*m, p.st));
    }
    !(remove_rays && p.may_remove && neighbours.iter().all(|m| remove(*m, p.st)))
}

/// The 2x2 block of the 3x3 neighbourhood read in frame `frame` (section 3.1.1: a gather with
/// a sub-pixel jitter so that 4 frames cover 3x3). Every block holds the centre (0, 0).
pub fn jitter_block(frame: u32) -> [(i32, i32); 4] {
    let k = (frame % 4) as i32;
    let (ox, oy) = (-1 + (k & 1), -1 + (k >> 1));
    [(ox, oy), (ox + 1, oy), (ox, oy + 1), (ox + 1, oy + 1)]
}

/// Bits per mask texel for `lights` lights of 3 bits each: 8, 16 or 32 (R8Uint, R16Uint,
/// R32Uint); at most [`MAX_LIGHTS`].
pub fn mask_texel_bits(lights: usize) -> Result<u32, String> {
    match lights {
        0 => Err("the temporal mask needs at least one light".into()),
        1..=2 => Ok(8),
        3..=5 => Ok(16),
        6..=MAX_LIGHTS => Ok(32),
        _ => Err(format!("{lights} lights: the temporal mask holds at most {MAX_LIGHTS} (3 bits each in 32 bits)")),
    }
}

/// Bytes of temporal mask per light for `pixels` pixels: two ping-pong textures of
/// [`mask_texel_bits`] shared by `lights` lights.
pub fn mask_bytes_per_light(lights: usize, pixels: u64) -> Result<f64, String> {
    let bits = mask_texel_bits(lights)? as u64;
    Ok((2 * pixels * bits / 8) as f64 / lights as f64)
}

/// Cascade reuse: each box is enlarged by 15 % when it is rendered (seed 004 section 3.3).
/// Too low: every small camera move re-renders the cascade; too high: coarser texels (wider
/// uncertain bands, more rays).
pub const DEFAULT_ENLARGE: f64 = 0.15;

/// The box a cascade is rendered with for reuse (section 3.3): this frame's fitted box `fit`
/// with its side enlarged by `1 + enlarge` and its depth range extended to the whole scene
/// (so any later slice it still covers sideways also fits in depth).
pub fn reuse_box(fit: &CascadeBox, scene: &Bounds, enlarge: f32, res: u32) -> CascadeBox {
    let zlo = scene.corners().iter().map(|p| (fit.light_view * p.extend(1.0)).z).fold(f32::INFINITY, f32::min);
    let margin = scene.diagonal().max(1e-6) * 1e-3;
    let far_z = fit.far_z.min(zlo - margin);
    CascadeBox { far_z, ..*fit }.enlarged(1.0 + enlarge, res)
}

/// Whether the kept (enlarged) box still serves this frame's fitted box: the same light view,
/// and the fitted square inside the kept one in light x/y (section 3.3: "all edges of the
/// current cascade frustum within the enlarged one of the last frame").
pub fn reusable(kept: &CascadeBox, fit: &CascadeBox) -> bool {
    let d = (fit.origin - kept.origin).abs();
    kept.light_view == fit.light_view && d.x + fit.half <= kept.half && d.y + fit.half <= kept.half
}

/// Whether world point `p` lies in `b`'s x/y square (any depth).
pub fn covers(b: &CascadeBox, p: glam::Vec3) -> bool {
    let q = (b.light_view * p.extend(1.0)).xy();
    let d = (q - b.origin).abs();
    d.x <= b.half && d.y <= b.half
}

/// Cube face of a direction from a point light: 2 * axis + (1 if negative), the axis of the
/// largest component (x before y before z on ties); `classify.wgsl`'s `cube_face` mirrors it.
pub fn cube_face(d: glam::Vec3) -> usize {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + (d[axis] < 0.0) as usize
}

/// The six faces of a point light's cube map (+x, -x, +y, -y, +z, -z, the order of
/// [`cube_face`]): perspective frusta of 90 degrees widened by one texel on each side (as a
/// spot's cone), so the 2x2 gather of a point on a face's border stays inside that face; far =
/// the farthest bounds corner, near = far / 1000. Depth is linear, along the face's axis.
pub fn cube_faces(position: glam::Vec3, bounds: &Bounds, res: u32) -> [LightProjection; 6] {
    use glam::Vec3;
    let far = bounds.corners().iter().map(|p| (*p - position).length()).fold(0.0f32, f32::max).max(bounds.diagonal() * 1e-3).max(1e-4);
    let near = (far * 1e-3).max(1e-5);
    let tan_half = 1.0 + 2.0 / res as f32;
    let proj = perspective(2.0 * tan_half.atan(), 1.0, near, far);
    let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
    axes.map(|d| {
        let up = if d.y != 0.0 { Vec3::Z } else { Vec3::Y };
        LightProjection { view_proj: proj * look_at(position, position + d, up), texel: 2.0 * tan_half / res as f32, perspective: true }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_masks() -> impl Iterator<Item = Mask> {
        (0..8).map(Mask::from_bits)
    }

    #[test]
    fn ltt_is_strict_on_both_sides() {
        let eps = DEFAULT_EPS as f32;
        assert!(!ltt(0.0, eps) && !ltt(0.01, eps) && !ltt(0.99, eps) && !ltt(1.0, eps));
        assert!(ltt(0.0101, eps) && ltt(0.5, eps) && ltt(0.9899, eps));
        assert!(!ltt(0.3, 0.5), "eps = 0.5 flags nothing");
        assert!(shadow_test(0.49) && !shadow_test(0.5));
    }

    #[test]
    fn table_1_classes() {
        let m = |ltt, st, rs| Mask { st, ltt, rs };
        assert_eq!(Class::of(m(false, false, false)), Class::Black);
        assert_eq!(Class::of(m(false, false, true)), Class::Black);
        assert_eq!(Class::of(m(false, true, false)), Class::Green);
        assert_eq!(Class::of(m(true, true, true)), Class::White);
        assert_eq!(Class::of(m(true, false, true)), Class::Purple);
        assert_eq!(Class::of(m(true, false, false)), Class::Red);
        assert_eq!(Class::of(m(true, true, false)), Class::Yellow);
        for b in 0..8 {
            assert_eq!(Mask::from_bits(b).bits(), b);
        }
    }

    #[test]
    fn expand_is_eq_5_plus_a_changed_test() {
        for m in all_masks() {
            for st in [false, true] {
                // eq. 5 and the changed shadow test of section 3.1.1
                let purple = m.ltt && m.rs && !st;
                let yellow = m.ltt && !m.rs && st;
                assert_eq!(expand(m, st), purple || yellow || (m.st != st), "{m:?} st {st}");
            }
        }
        // by class, for an unchanged test: expand only next to corrections
        let lit = false;
        assert!(expand(Mask { st: false, ltt: true, rs: true }, lit), "purple expands into a lit-test pixel");
        assert!(!expand(Mask { st: false, ltt: true, rs: false }, lit), "red does not");
        assert!(!expand(Mask { st: false, ltt: false, rs: false }, lit), "black does not");
        assert!(expand(Mask { st: true, ltt: true, rs: false }, true), "yellow expands into a shadowed-test pixel");
        assert!(!expand(Mask { st: true, ltt: true, rs: true }, true), "white does not");
        assert!(!expand(Mask { st: true, ltt: false, rs: false }, true), "green does not");
    }

    #[test]
    fn remove_is_eq_7_combined() {
        for m in all_masks() {
            for st in [false, true] {
                let white_red = m.ltt && st == m.st && st == m.rs;
                let black_green = !m.ltt && st == m.st;
                assert_eq!(remove(m, st), white_red || black_green, "{m:?} st {st}");
            }
        }
        // by class: confirmations and confident pixels allow removal, corrections do not
        for (c, ok) in [(Class::Black, true), (Class::Green, true), (Class::White, true), (Class::Red, true)] {
            let m = all_masks().find(|m| Class::of(*m) == c).unwrap();
            assert_eq!(remove(m, m.st), ok, "{c:?}");
        }
        assert!(!remove(Mask { st: false, ltt: true, rs: true }, false), "purple");
        assert!(!remove(Mask { st: true, ltt: true, rs: false }, true), "yellow");
    }

    #[test]
    fn decide_follows_section_3_1_3() {
        let red = Mask { st: false, ltt: true, rs: false };
        let purple = Mask { st: false, ltt: true, rs: true };
        let black = Mask::default();
        let px = |ltt, reprojected| Pixel { ltt, st: false, reprojected, may_remove: true };
        assert!(decide(px(false, false), &[black; 4], true), "a failed reprojection forces a ray");
        assert!(!decide(px(false, true), &[black, red, black, black], true), "no ER next to confirmations");
        assert!(decide(px(false, true), &[black, purple, black, black], true), "ER next to purple");
        assert!(!decide(px(true, true), &[black, red, red, black], true), "RR among confirmations");
        assert!(decide(px(true, true), &[black, red, red, black], false), "RR off keeps the ray");
        assert!(decide(px(true, true), &[black, purple, red, black], true), "no RR next to a correction");
        let dynamic = Pixel { may_remove: false, ..px(true, true) };
        assert!(decide(dynamic, &[black; 4], true), "no RR on dynamic geometry");
    }

    #[test]
    fn four_jittered_2x2_blocks_cover_3x3() {
        let mut seen = std::collections::BTreeSet::new();
        for f in 0..4 {
            let b = jitter_block(f);
            assert!(b.contains(&(0, 0)));
            assert_eq!(jitter_block(f + 4), b);
            seen.extend(b);
        }
        let full: std::collections::BTreeSet<_> = (-1..=1).flat_map(|y| (-1..=1).map(move |x| (x, y))).collect();
        assert_eq!(seen, full);
    }

    #[test]
    fn mask_format_by_light_count() {
        assert!(mask_texel_bits(0).is_err());
        assert_eq!(mask_texel_bits(1), Ok(8));
        assert_eq!(mask_texel_bits(2), Ok(8));
        assert_eq!(mask_texel_bits(3), Ok(16));
        assert_eq!(mask_texel_bits(5), Ok(16));
        assert_eq!(mask_texel_bits(6), Ok(32));
        assert_eq!(mask_texel_bits(10), Ok(32));
        assert!(mask_texel_bits(11).is_err());
        for n in 1..=MAX_LIGHTS {
            assert!(3 * n as u32 <= mask_texel_bits(n).unwrap());
        }
        // one light: two R8Uint textures, 2 bytes per pixel
        assert_eq!(mask_bytes_per_light(1, 100), Ok(200.0));
        assert_eq!(mask_bytes_per_light(10, 100), Ok(80.0));
    }
}

#[cfg(test)]
mod cascade_tests {
    use super::*;
    use crate::camera::Camera;
    use crate::techniques::csm::{fit_cascade, Fit, ViewFrustum};
    use glam::Vec3;

    fn fit_at(x: f32, yaw: f32) -> (CascadeBox, [Vec3; 8]) {
        let cam = Camera::new(Vec3::new(x, 2.0, 0.0), Vec3::new(x + 10.0 * yaw.cos(), 2.0, 10.0 * yaw.sin()), 60.0, 0.1, 100.0);
        let f = ViewFrustum::from_view_proj(cam.view_proj(16, 9), cam.position).unwrap();
        let scene = Bounds { min: Vec3::new(-50.0, 0.0, -50.0), max: Vec3::new(50.0, 10.0, 50.0) };
        let dir = Vec3::new(0.3, -1.0, 0.2);
        (fit_cascade(&f, dir, &scene, 1.0, 8.0, 512, true, Fit::Sphere), f.slice_corners(1.0, 8.0))
    }

    #[test]
    fn enlarged_boxes_are_reused_for_small_moves_only() {
        let scene = Bounds { min: Vec3::new(-50.0, 0.0, -50.0), max: Vec3::new(50.0, 10.0, 50.0) };
        let (fit0, corners0) = fit_at(0.0, 0.0);
        let kept = reuse_box(&fit0, &scene, DEFAULT_ENLARGE as f32, 512);
        assert!((kept.half - fit0.half * 1.15).abs() < 1e-5 * kept.half);
        assert!((kept.texel - 2.0 * kept.half / 512.0).abs() < 1e-9);
        assert!(reusable(&kept, &fit0));
        assert!(corners0.iter().all(|c| covers(&kept, *c)));
        // every point of the scene is inside the kept box's depth range
        for c in scene.corners() {
            let z = (kept.view_proj * c.extend(1.0)).z;
            assert!((0.0..=1.0).contains(&z) || !covers(&kept, c), "scene corner depth {z}");
        }
        // a small step keeps it, and the slice stays covered; a large one does not
        let (fit1, corners1) = fit_at(0.3, 0.0);
        assert!(reusable(&kept, &fit1));
        assert!(corners1.iter().all(|c| covers(&kept, *c)));
        let (fit2, _) = fit_at(3.0, 0.0);
        assert!(!reusable(&kept, &fit2));
        let (fit3, _) = fit_at(0.0, 1.0);
        assert!(!reusable(&kept, &fit3), "a large turn moves the slice out");
    }

    #[test]
    fn cube_faces_hold_every_direction_with_a_texel_of_margin() {
        use glam::Vec3;
        let b = Bounds { min: Vec3::new(-5.0, 0.0, -3.0), max: Vec3::new(5.0, 4.0, 3.0) };
        let pos = Vec3::new(1.0, 2.0, 0.5);
        let res = 256;
        let faces = cube_faces(pos, &b, res);
        let far = b.corners().iter().map(|p| (*p - pos).length()).fold(0.0f32, f32::max);
        let mut seen = [0; 6];
        for i in 0..2000 {
            // directions spread over the sphere, plus the axes and the cube's corners
            let (u, v) = ((i as f32 * 0.618034).fract(), (i as f32 + 0.5) / 2000.0);
            let (phi, z) = (u * std::f32::consts::TAU, 1.0 - 2.0 * v);
            let r = (1.0 - z * z).sqrt();
            let d = Vec3::new(r * phi.cos(), z, r * phi.sin());
            let p = pos + d * (0.5 + 3.0 * v);
            let f = cube_face(p - pos);
            seen[f] += 1;
            let c = faces[f].view_proj * p.extend(1.0);
            let ndc = c.xyz() / c.w;
            // inside the 90 degree part: at least one texel (2 / res in ndc, scaled) from the border
            let inner = 1.0 / (1.0 + 2.0 / res as f32);
            assert!(ndc.x.abs() <= inner + 1e-5 && ndc.y.abs() <= inner + 1e-5, "face {f} of {d}: {ndc}");
            assert!(c.w > 0.0 && c.w <= far, "linear depth {} along the axis, far {far}", c.w);
            let axis_depth = (p - pos)[f / 2].abs();
            assert!((c.w - axis_depth).abs() < 1e-4 * far, "w {} = depth along the face axis {axis_depth}", c.w);
        }
        assert!(seen.iter().all(|&n| n > 100), "every face is used: {seen:?}");
        assert_eq!(cube_face(Vec3::new(1.0, 1.0, 1.0)), 0, "ties: x first");
        assert_eq!(cube_face(Vec3::new(0.0, -1.0, -1.0)), 3, "ties: y before z");
        assert_eq!(cube_face(-Vec3::Z), 5);
    }
}
