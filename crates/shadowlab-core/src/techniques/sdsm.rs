//! Sample distribution shadow maps (`sdsm`, Lauritzen, Salvi and Lefohn, I3D 2011), the CPU
//! half: split distances from the view samples' [min, max] depth, logarithmic between them,
//! and each cascade's light-space box fitted to the samples that fall into it. The GPU half
//! (shadowlab-gpu `techniques/sdsm/`, sharing `csm`'s maps, passes and evaluation)
//! reduces the samples to per-cascade light-space bounds and mirrors [`sample_splits`] in WGSL.
//!
//! The light view is `csm`'s ([`light_view`]): fixed in the world, so a texel grid in light
//! space is fixed in the world and snapping works as for `csm`.

use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};

use super::csm::{depth_range, practical_splits, snap_to_texel, CascadeBox};
use crate::camera::{orthographic, Camera};
use crate::scene::Bounds;

/// Pure logarithmic partition between the samples' min and max depth: Lauritzen et al. 2011
/// (section 3.1) use log splits once the range is tight, since the near plane no longer sits
/// far in front of the first sample. Lower values blend in uniform splits (coarser near).
pub const DEFAULT_LAMBDA: f32 = 1.0;

/// Steps per doubling of a fitted box's half sides when snapping: each half side is rounded up
/// to a power of 2^(1/16) (4.4 % steps, at most 9 % more area), so the texel size takes a
/// fixed set of values and stays put from frame to frame until the samples' extent crosses a
/// step; the origin then snaps to whole texels of that size. More steps: tighter boxes, size
/// changes (shimmer) more often; fewer: more wasted area.
pub const SIZE_STEPS_PER_OCTAVE: f32 = 16.0;

/// Steps of [`SIZE_STEPS_PER_OCTAVE`] a snapped size may shrink by before it follows the
/// samples down: hysteresis, so an extent that hovers around a step does not switch the texel
/// size (and re-rasterise every shadow edge) back and forth. 2 = a box keeps its size until
/// the samples' extent is 8.7 % smaller; it grows at once. Higher: fewer size changes, more
/// wasted area while the view narrows.
pub const SHRINK_STEPS: f32 = 2.0;

/// Split distances (`n + 1` view depths) from the samples' [min, max] view depth `range`
/// (None: the camera's [near, far]): `csm`'s [`depth_range`] (the range, its ends rounded
/// outwards to 2^(1/8) steps for stability) partitioned by [`practical_splits`] with `lambda`
/// (1 = logarithmic, SDSM's choice).
pub fn sample_splits(near: f32, far: f32, range: Option<(f32, f32)>, n: usize, lambda: f32) -> Vec<f32> {
    let (lo, hi) = depth_range(near, far, range);
    practical_splits(lo, hi, n, lambda)
}

/// `x > 0` rounded up to a power of 2^(1/steps): the smallest [`size_step`] not below `x`
/// (idempotent, never below `x`). `steps` a whole number.
pub fn quantize_up(x: f32, steps: f32) -> f32 {
    if !(x > 0.0 && x.is_finite()) {
        return x;
    }
    let n = steps as i32;
    let mut k = (x.log2() * steps).ceil() as i32;
    // log2's rounding can put k one step off either way
    while size_step(k - 1, n) >= x {
        k -= 1;
    }
    while size_step(k, n) < x {
        k += 1;
    }
    size_step(k, n)
}

/// 2^(k/steps) for a whole `k`: 2^(r/steps) (0 <= r < steps, [`step_fractions`]) times the
/// octave's power of two, exact, so that a GPU holding the same fractions gets the same bits
/// (iasm's fit.wgsl). Equal to powf(2, k/steps) for every k of a normal f32 (tested).
pub fn size_step(k: i32, steps: i32) -> f32 {
    let (octave, r) = (k.div_euclid(steps), k.rem_euclid(steps));
    (2.0f32).powf(r as f32 / steps as f32) * (2.0f32).powi(octave)
}

/// 2^(r/16) for r in 0..16: the fractions of [`size_step`] at [`SIZE_STEPS_PER_OCTAVE`].
pub fn step_fractions() -> [f32; 16] {
    std::array::from_fn(|r| size_step(r as i32, SIZE_STEPS_PER_OCTAVE as i32))
}

/// The light-space (light view, [`light_view`]) bounds of the view samples of one cascade, as
/// the GPU reduction returns them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleBounds {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Samples reduced into the cascade.
    pub samples: u32,
}

impl SampleBounds {
    /// The bounds swept along `step` (light x, y, z: the union with themselves moved by it)
    /// and then grown by `grow` world units on every side.
    pub fn swept(&self, step: Vec3, grow: f32) -> SampleBounds {
        let g = Vec3::splat(grow);
        SampleBounds { lo: self.lo.min(self.lo + step) - g, hi: self.hi.max(self.hi + step) + g, samples: self.samples }
    }
}

/// The camera's motion between two frames, as the delayed `sdsm` needs it to move last frame's
/// sample bounds to this frame's view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMotion {
    /// The camera's step (world).
    pub step: Vec3,
    /// The change of the unit forward direction (world): times a view depth, how far the turn
    /// moves the view's centre at that depth.
    pub turn: Vec3,
    /// Distance / view depth at the far corners of the frustum (`to`'s lens at the aspect).
    pub corner: f32,
}

impl CameraMotion {
    pub fn between(from: &Camera, to: &Camera, aspect: f32) -> CameraMotion {
        let fa = (from.target - from.position).normalize_or_zero();
        let fb = (to.target - to.position).normalize_or_zero();
        let t = (0.5 * to.fov_y_deg.to_radians()).tan();
        CameraMotion { step: to.position - from.position, turn: fb - fa, corner: (1.0 + t * t * (1.0 + aspect * aspect)).sqrt() }
    }

    /// How far (world) the view moves at view depth `depth`: the step plus the turn's
    /// displacement there, out to the frustum's corner.
    pub fn displacement(&self, depth: f32) -> Vec3 {
        self.step + self.turn * (depth * self.corner)
    }
}

/// One cascade's box fitted to its samples: a rectangle in light x/y (its own texel size per
/// axis), depth from the scene's side nearest the light (every caster) to the farthest sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FittedBox {
    /// World -> light clip space (NDC x, y in [-1, 1], z in [0, 1], 0 towards the light).
    pub view_proj: Mat4,
    /// Centre in light-view x/y (snapped to whole texels when asked).
    pub origin: Vec2,
    /// Half sides (world units).
    pub half: Vec2,
    /// World size of one texel along light x and y.
    pub texel: Vec2,
    /// Light-view z of the near (towards the light) and far planes.
    pub near_z: f32,
    pub far_z: f32,
    pub light_view: Mat4,
    /// The half extents the box was sized for before the margin (snapped: the quantised
    /// ones), for the next frame's hysteresis ([`fit_to_samples`]'s `prev`).
    pub extent: Vec2,
}

impl FittedBox {
    /// Whether `p` (world) lies inside the box.
    pub fn contains(&self, p: Vec3) -> bool {
        let q = (self.light_view * p.extend(1.0)).xyz();
        let d = (Vec2::new(q.x, q.y) - self.origin).abs();
        d.x <= self.half.x && d.y <= self.half.y && q.z <= self.near_z && q.z >= self.far_z
    }

    /// Light-space x/y area (world units squared).
    pub fn area(&self) -> f32 {
        4.0 * self.half.x * self.half.y
    }

    /// The larger texel side (what the evaluation's texel-relative biases use).
    pub fn max_texel(&self) -> f32 {
        self.texel.max_element()
    }
}

/// The snapped half extent for a needed one `e`: `e` rounded up to [`SIZE_STEPS_PER_OCTAVE`]
/// steps, or the previous frame's `prev` while `e` fits in it and has not shrunk by
/// [`SHRINK_STEPS`] steps.
pub fn held_extent(e: f32, prev: Option<f32>) -> f32 {
    match prev {
        Some(p) if e <= p && e > p * (2.0f32).powf(-SHRINK_STEPS / SIZE_STEPS_PER_OCTAVE) => p,
        _ => quantize_up(e, SIZE_STEPS_PER_OCTAVE),
    }
}

/// Fits cascade `slice`'s box (the frustum-slice fit of `csm`, whose light view and near plane
/// it keeps) to the samples' bounds `b`: centre of the bounds, half sides the bounds' half
/// extents plus `margin_texels` texels (room for snapping and the evaluation's normal offset
/// and kernel). With `snap` the extents are [`held_extent`]s (quantised, with hysteresis
/// against the previous frame's `prev`) and the origin snaps to whole texels: the size only
/// changes in steps and the texel grid is fixed in the world. Without `snap` an axis that
/// would come out wider than the slice's box takes the slice's (with `snap` it keeps its
/// quantised size: the slice's own size changes every frame, a few per cent wider is steadier).
/// Depth: the slice's near plane (the scene's side nearest the light, so casters between the
/// light and the samples stay in the map) to the farthest sample, less the margin.
#[allow(clippy::too_many_arguments)]
pub fn fit_to_samples(
    slice: &CascadeBox,
    b: &SampleBounds,
    scene: &Bounds,
    res: u32,
    snap: bool,
    margin_texels: f32,
    prev: Option<Vec2>,
) -> FittedBox {
    let res_f = res as f32;
    let lo = Vec2::new(b.lo.x, b.lo.y);
    let hi = Vec2::new(b.hi.x, b.hi.y);
    let centre = (lo + hi) * 0.5;
    // a degenerate extent (one sample, a line) still gets a box of finite texels
    let extent = ((hi - lo) * 0.5).max(Vec2::splat(slice.half * 1e-4));
    // half = extent + margin * texel, texel = 2 half / res
    let grow = 1.0 / (1.0 - 2.0 * margin_texels / res_f).max(0.5);
    let mut origin = centre;
    let mut half = Vec2::ZERO;
    let mut sized = Vec2::ZERO;
    for k in 0..2 {
        sized[k] = if snap { held_extent(extent[k], prev.map(|p| p[k])) } else { extent[k] };
        let h = sized[k] * grow;
        if snap {
            half[k] = h;
            origin[k] = snap_to_texel(centre[k], 2.0 * h / res_f);
        } else if h >= slice.half {
            half[k] = slice.half;
            origin[k] = slice.origin[k];
        } else {
            half[k] = h;
        }
    }
    let texel = half * 2.0 / res_f;
    let margin = scene.diagonal().max(1e-6) * 1e-3 + margin_texels * texel.max_element();
    let near_z = slice.near_z;
    let far_z = (b.lo.z - margin).min(near_z - margin);
    let v = slice.light_view;
    let proj = orthographic(origin.x - half.x, origin.x + half.x, origin.y - half.y, origin.y + half.y, -near_z, -far_z);
    FittedBox { view_proj: proj * v, origin, half, texel, near_z, far_z, light_view: v, extent: sized }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::techniques::csm::{fit_cascade, Fit, ViewFrustum};

    #[test]
    fn splits_are_logarithmic_between_the_samples_min_and_max() {
        // 2 and 32 are powers of 2^(1/8): the range stays as it is
        let s = sample_splits(0.1, 100.0, Some((2.0, 32.0)), 4, 1.0);
        assert_eq!(s.len(), 5);
        assert_eq!((s[0], s[4]), (2.0, 32.0));
        for w in s.windows(2) {
            // equal ratios: 16^(1/4) = 2
            assert!((w[1] / w[0] - 2.0).abs() < 1e-4, "{s:?}");
        }
        // no samples: the camera's range, still logarithmic
        let c = sample_splits(0.5, 50.0, None, 2, 1.0);
        assert!((c[1] - 5.0).abs() < 1e-3 && c[0] == 0.5 && c[2] == 50.0, "{c:?}");
        // a range wider than the camera's is clipped to it; lambda 0 is uniform
        assert_eq!(sample_splits(1.0, 10.0, Some((0.01, 400.0)), 3, 0.0), vec![1.0, 4.0, 7.0, 10.0]);
        // ends rounded outwards: the range holds the samples
        let r = sample_splits(0.1, 100.0, Some((3.0, 40.0)), 3, 1.0);
        assert!(r[0] <= 3.0 && r[0] > 2.7 && r[3] >= 40.0 && r[3] < 44.0, "{r:?}");
    }

    #[test]
    fn size_steps_are_powf_and_quantize_up_is_the_old_rule() {
        for k in -16 * 126..16 * 127 {
            assert_eq!(size_step(k, 16).to_bits(), (2.0f32).powf(k as f32 / 16.0).to_bits(), "k {k}");
        }
        // the previous rule (powf of the ceiled log2, one step more if short) on ordinary sizes
        let old = |x: f32| {
            let q = (2.0f32).powf((x.log2() * 16.0).ceil() / 16.0);
            if q >= x {
                q
            } else {
                (2.0f32).powf(((x.log2() * 16.0).ceil() + 1.0) / 16.0)
            }
        };
        let mut x = 1e-5f32;
        while x < 1e7 {
            assert_eq!(quantize_up(x, 16.0), old(x), "{x}");
            x *= 1.000_37;
        }
        assert_eq!(quantize_up(0.0, 16.0), 0.0);
        assert!(quantize_up(f32::INFINITY, 16.0).is_infinite());
    }

    #[test]
    fn quantized_sizes_are_a_fixed_set() {
        for x in [0.013f32, 0.5, 1.0, 3.3, 77.7, 1e4] {
            let q = quantize_up(x, 16.0);
            assert!(q >= x && q < x * 2.0f32.powf(1.0 / 16.0) * 1.0001, "{x} -> {q}");
            assert_eq!(quantize_up(q, 16.0), q, "idempotent at {x}");
        }
        // nearby sizes give the same step
        assert_eq!(quantize_up(3.30, 16.0), quantize_up(3.31, 16.0));
    }

    fn setup() -> (Bounds, ViewFrustum, Vec3, CascadeBox) {
        let scene = Bounds { min: Vec3::new(-60.0, 0.0, -60.0), max: Vec3::new(60.0, 25.0, 60.0) };
        let cam = Camera::new(Vec3::new(3.0, 1.7, 5.0), Vec3::new(-8.0, 1.0, -20.0), 70.0, 0.1, 120.0);
        let f = ViewFrustum::from_view_proj(cam.view_proj(16, 9), cam.position).unwrap();
        let dir = Vec3::new(0.4, -1.0, 0.3);
        let slice = fit_cascade(&f, dir, &scene, 4.0, 16.0, 1024, true, Fit::Box);
        (scene, f, dir, slice)
    }

    /// Points of the slice [4, 16] seen through the lower left part of the screen.
    fn samples(f: &ViewFrustum) -> Vec<Vec3> {
        let mut pts = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                let d = 4.0 + 12.0 * i as f32 / 39.0;
                let c = f.slice_corners(d, d + 1e-3);
                // the lower 30 % of the screen, 30 % across
                let u = 0.2 + 0.3 * j as f32 / 39.0;
                pts.push(c[0].lerp(c[1], u).lerp(c[2].lerp(c[3], u), 0.3 * (i % 7) as f32 / 6.0));
            }
        }
        pts
    }

    fn bounds_of(pts: &[Vec3], view: Mat4) -> SampleBounds {
        let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
        for p in pts {
            let q = (view * p.extend(1.0)).xyz();
            lo = lo.min(q);
            hi = hi.max(q);
        }
        SampleBounds { lo, hi, samples: pts.len() as u32 }
    }

    #[test]
    fn fitted_boxes_hold_their_samples_and_casters_and_are_smaller_than_the_slice() {
        let (scene, f, dir, slice) = setup();
        let pts = samples(&f);
        let b = bounds_of(&pts, slice.light_view);
        for snap in [false, true] {
            let fit = fit_to_samples(&slice, &b, &scene, 1024, snap, 3.0, None);
            for p in &pts {
                let n = fit.view_proj.project_point3(*p);
                // inside with the margin left (3 texels, less half a texel of snapping)
                let lim = Vec2::ONE - 2.0 * Vec2::splat(2.5) / 1024.0;
                assert!(n.x.abs() <= lim.x && n.y.abs() <= lim.y && (0.0..1.0).contains(&n.z), "snap {snap}: {p} at {n}");
                assert!(fit.contains(*p));
                // a caster at the top of the scene above the sample is in the map, in front of it
                let caster = *p - dir.normalize() * (25.0 / -dir.normalize().y);
                let c = fit.view_proj.project_point3(caster);
                assert!(c.z >= 0.0 && c.z < n.z, "caster at {c}");
            }
            assert!(fit.area() < 0.7 * (2.0 * slice.half).powi(2), "snap {snap}: {} vs {}", fit.area(), (2.0 * slice.half).powi(2));
            assert!(fit.max_texel() < slice.texel);
            if snap {
                let g = fit.origin / fit.texel;
                assert!((g - g.round()).abs().max_element() < 1e-3, "whole texels: {g}");
            }
        }
    }

    #[test]
    fn snapped_fits_keep_their_size_and_grid_while_the_samples_move_a_little() {
        let (scene, f, _, slice) = setup();
        let b0 = bounds_of(&samples(&f), slice.light_view);
        let a = fit_to_samples(&slice, &b0, &scene, 1024, true, 3.0, None);
        let mut prev = a.extent;
        for k in 1..20 {
            // the samples move and their extent wobbles by up to 3 % (under the 8.7 % of
            // hysteresis, across a 4.4 % step)
            let d = Vec3::new(0.01 * k as f32, -0.007 * k as f32, 0.0);
            let wobble = 1.0 - 0.03 * (k % 2) as f32;
            let b = SampleBounds { lo: b0.lo + d, hi: b0.lo + d + (b0.hi - b0.lo) * wobble, ..b0 };
            let m = fit_to_samples(&slice, &b, &scene, 1024, true, 3.0, Some(prev));
            assert_eq!(m.texel, a.texel, "frame {k}: the size holds");
            let steps = (m.origin - a.origin) / a.texel;
            assert!((steps - steps.round()).abs().max_element() < 1e-2, "moved {steps} texels");
            prev = m.extent;
        }
        // a clearly narrower view shrinks the box, a wider one grows it at once
        let narrow = SampleBounds { hi: b0.lo + (b0.hi - b0.lo) * 0.8, ..b0 };
        assert!(fit_to_samples(&slice, &narrow, &scene, 1024, true, 3.0, Some(prev)).area() < a.area());
        let wide = SampleBounds { hi: b0.lo + (b0.hi - b0.lo) * 1.06, ..b0 };
        assert!(fit_to_samples(&slice, &wide, &scene, 1024, true, 3.0, Some(prev)).area() > a.area());
        assert_eq!(held_extent(1.0, Some(1.02)), 1.02);
        assert_eq!(held_extent(1.05, Some(1.02)), quantize_up(1.05, SIZE_STEPS_PER_OCTAVE));
        assert_eq!(held_extent(0.9, Some(1.02)), quantize_up(0.9, SIZE_STEPS_PER_OCTAVE));
    }

    #[test]
    fn an_axis_wider_than_the_slice_takes_the_slice_unless_snapped() {
        let (scene, _, _, slice) = setup();
        let c = Vec3::new(slice.origin.x, slice.origin.y, slice.near_z - 10.0);
        let b = SampleBounds { lo: c - Vec3::new(slice.half, 1.0, 5.0), hi: c + Vec3::new(slice.half, 1.0, 0.0), samples: 2 };
        let fit = fit_to_samples(&slice, &b, &scene, 1024, false, 3.0, None);
        assert_eq!((fit.half.x, fit.origin.x), (slice.half, slice.origin.x));
        assert!(fit.half.y < 0.1 * slice.half);
        assert!(fit.far_z < c.z - 5.0 && fit.near_z == slice.near_z);
        // snapped: the quantised size, a little wider than the slice, still holding the samples
        let s = fit_to_samples(&slice, &b, &scene, 1024, true, 3.0, None);
        assert!(s.half.x >= slice.half && s.half.x < slice.half * 1.06, "{} vs {}", s.half.x, slice.half);
        assert!(s.origin.x - s.half.x <= b.lo.x && s.origin.x + s.half.x >= b.hi.x, "holds the samples along x");
    }

    #[test]
    fn camera_motion_is_the_step_plus_the_turn() {
        let a = Camera::new(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 90.0, 0.1, 100.0);
        assert_eq!(CameraMotion::between(&a, &a, 1.0).displacement(50.0), Vec3::ZERO);
        let b = Camera { position: Vec3::new(3.0, 0.0, 4.0), target: Vec3::new(3.0, 0.0, 3.0), ..a };
        assert_eq!(CameraMotion::between(&a, &b, 1.0).displacement(10.0), Vec3::new(3.0, 0.0, 4.0));
        // a turn of 0.1 rad: the centre's move at the frustum corner (90 degrees, square: sqrt(3) x depth)
        let c = Camera { target: Vec3::new(0.1f32.sin(), 0.0, -0.1f32.cos()), ..a };
        let d = CameraMotion::between(&a, &c, 1.0).displacement(10.0);
        let chord = 2.0 * 0.05f32.sin() * 10.0 * 3.0f32.sqrt();
        assert!((d.length() - chord).abs() < 1e-4 && d.x > 0.0, "{d}");
        // swept bounds: extended towards the step only, then grown on every side
        let s = SampleBounds { lo: Vec3::ZERO, hi: Vec3::ONE, samples: 7 }.swept(Vec3::new(2.0, -1.0, 0.0), 0.5);
        assert_eq!((s.lo, s.hi, s.samples), (Vec3::new(-0.5, -1.5, -0.5), Vec3::new(3.5, 1.5, 1.5), 7));
    }
}
