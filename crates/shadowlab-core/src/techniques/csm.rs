//! Cascaded shadow maps, the CPU half (`csm`, and leak tracing's cascades later): split
//! distances along the view, one orthographic light box per slice of the view frustum, texel
//! snapping, and tightening to the depth range the G-buffer actually holds.
//!
//! Fitting ([`Fit`]): each slice gets its **bounding sphere** or its tight light-space bounding
//! square. With the sphere the box side (2 x radius) depends only on the slice's near/far
//! distances and the lens, not on the camera's rotation, so the texel size stays fixed while
//! the camera turns and snapping the box origin to whole texels removes shimmering entirely
//! (Valient 2008, "Stable cascaded shadow maps"). The tight square has smaller texels but
//! changes size as the camera turns.
//!
//! The light view is fixed in world space (origin at the world origin, looking along the
//! light), so a texel grid in light space is a grid fixed in the world. Depth is orthographic
//! (linear), 0 at the near plane towards the light; the near plane is pushed back to the scene
//! bounds so that every caster in the scene lands in the map.

use glam::{Mat4, Vec2, Vec3, Vec4Swizzles};

use crate::camera::{look_at, orthographic};
use crate::scene::Bounds;

/// The leak-tracing authors' blend: 0.85 logarithmic + 0.15 uniform (seed 004's code, GUIDE.md).
/// Too low (uniform): the first cascade covers a long stretch and the near shadows are coarse;
/// 1 (pure log): the first cascade is tiny and the far ones coarse.
pub const DEFAULT_LAMBDA: f32 = 0.85;
/// Upper bound on cascades (size of the GPU parameter array).
pub const MAX_CASCADES: usize = 8;

/// The practical split scheme (Zhang et al. 2006, PSSM): `n + 1` view depths from `near` to
/// `far`, split `i` = `lambda * log_i + (1 - lambda) * uniform_i` with
/// `log_i = near * (far / near)^(i / n)` and `uniform_i = near + (far - near) * i / n`.
pub fn practical_splits(near: f32, far: f32, n: usize, lambda: f32) -> Vec<f32> {
    (0..=n)
        .map(|i| {
            if i == 0 {
                return near;
            }
            if i == n {
                return far;
            }
            let t = i as f32 / n as f32;
            // lambda 0 (or a zero near plane) is uniform: no 0 x inf
            let log = if lambda > 0.0 && near > 0.0 { near * (far / near).powf(t) } else { 0.0 };
            let uni = near + (far - near) * t;
            lambda * log + (1.0 - lambda) * uni
        })
        .collect()
}

/// Manual splits: `near`, the given inner distances, `far`. They must increase strictly inside
/// (near, far).
pub fn manual_splits(near: f32, far: f32, inner: &[f32]) -> Result<Vec<f32>, String> {
    let mut v = vec![near];
    v.extend_from_slice(inner);
    v.push(far);
    if v.windows(2).all(|w| w[0] < w[1]) && v.iter().all(|x| x.is_finite()) {
        Ok(v)
    } else {
        Err(format!("manual split distances {inner:?} must increase strictly inside ({near}, {far})"))
    }
}

/// Steps per doubling of the tightened depth range's ends: the G-buffer's min is rounded down
/// and its max up to powers of 2^(1/8) (9 % steps), so the splits, and with them the box sizes
/// and texel grids, stay the same from frame to frame until an end crosses a step. Without it
/// every frame's range differs a little and snapping cannot hold the grid (measured on the
/// courtyard path: flicker spikes of 0.17 % vs 0.04 %). More steps: tighter, less stable.
pub const DEPTH_STEPS_PER_OCTAVE: f32 = 8.0;

/// The range of view depths to split: the camera's [near, far], or, when the G-buffer's
/// [min, max] linear depth is known (`tighten`), their intersection (sample distribution shadow
/// maps, Lauritzen et al. 2011) with the ends rounded outwards to [`DEPTH_STEPS_PER_OCTAVE`]
/// steps. An empty or invalid G-buffer range leaves the camera's.
pub fn depth_range(near: f32, far: f32, gbuffer: Option<(f32, f32)>) -> (f32, f32) {
    match gbuffer {
        Some((lo, hi)) if lo.is_finite() && hi.is_finite() && lo <= hi && hi > 0.0 => {
            let k = DEPTH_STEPS_PER_OCTAVE;
            let down = |x: f32| (2.0f32).powf((x.log2() * k).floor() / k);
            let up = |x: f32| (2.0f32).powf((x.log2() * k).ceil() / k);
            let lo = if lo > 0.0 { down(lo).min(lo) } else { near }.max(near);
            let hi = up(hi).max(hi).min(far).max(lo * 1.0001);
            (lo, hi)
        }
        _ => (near, far),
    }
}

/// The camera as the fit needs it, rebuilt from its view-projection matrix and position (what
/// the GPU frame uniform holds).
#[derive(Clone, Copy, Debug)]
pub struct ViewFrustum {
    pub position: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    pub near: f32,
    pub far: f32,
    /// The four near-plane corners (world).
    near_corners: [Vec3; 4],
}

impl ViewFrustum {
    /// From a perspective view-projection (NDC z in [0, 1]) and the eye position.
    pub fn from_view_proj(view_proj: Mat4, position: Vec3) -> Option<ViewFrustum> {
        let inv = view_proj.inverse();
        let un = |x: f32, y: f32, z: f32| {
            let p = inv * glam::Vec4::new(x, y, z, 1.0);
            p.xyz() / p.w
        };
        let nc = un(0.0, 0.0, 0.0);
        let fc = un(0.0, 0.0, 1.0);
        let forward = (fc - nc).normalize_or_zero();
        let near = (nc - position).dot(forward);
        let far = (fc - position).dot(forward);
        let near_corners = [un(-1.0, -1.0, 0.0), un(1.0, -1.0, 0.0), un(-1.0, 1.0, 0.0), un(1.0, 1.0, 0.0)];
        let ok = forward != Vec3::ZERO && near > 0.0 && far > near && near_corners.iter().all(|c| c.is_finite());
        ok.then_some(ViewFrustum { position, forward, near, far, near_corners })
    }

    /// The eight corners of the slice between view depths `d0 < d1` (near four first).
    pub fn slice_corners(&self, d0: f32, d1: f32) -> [Vec3; 8] {
        let mut c = [Vec3::ZERO; 8];
        for (k, nc) in self.near_corners.iter().enumerate() {
            let ray = *nc - self.position;
            c[k] = self.position + ray * (d0 / self.near);
            c[k + 4] = self.position + ray * (d1 / self.near);
        }
        c
    }
}

/// Smallest sphere around a symmetric frustum slice (near corners 0-3, far corners 4-7): its
/// centre lies on the axis where it is equally far from a near and a far corner, or at the far
/// plane's centre when that point lies beyond it (wide, short slices).
pub fn slice_sphere(c: &[Vec3; 8]) -> (Vec3, f32) {
    let nc = (c[0] + c[1] + c[2] + c[3]) * 0.25;
    let fc = (c[4] + c[5] + c[6] + c[7]) * 0.25;
    let axis = fc - nc;
    // |nc + s axis - c0|^2 = |nc + s axis - c4|^2, linear in s
    let (a, b) = (nc - c[0], nc - c[4]);
    let denom = 2.0 * axis.dot(a - b);
    let s = if denom.abs() > 1e-20 { ((b.length_squared() - a.length_squared()) / denom).clamp(0.0, 1.0) } else { 0.5 };
    let center = nc + axis * s;
    let r = c.iter().map(|p| (*p - center).length()).fold(0.0f32, f32::max);
    (center, r)
}

/// Rounds a radius up to a step of 2^-10 of its power of two, so float noise in the corners
/// does not change the texel size from one frame to the next.
pub fn quantize_radius(r: f32) -> f32 {
    let step = (2.0f32).powi(r.max(1e-12).log2().ceil() as i32 - 10);
    (r / step).ceil() * step
}

/// Snaps a light-space coordinate to a whole number of texels (idempotent).
pub fn snap_to_texel(x: f32, texel: f32) -> f32 {
    (x / texel).round() * texel
}

/// The fixed light view for direction `dir` (where the light travels): eye at `-dir`, looking at
/// the world origin, so light-space x/y are a world-fixed frame.
pub fn light_view(dir: Vec3) -> Mat4 {
    let d = dir.normalize();
    let up = if d.cross(Vec3::Y).length_squared() < 1e-4 { Vec3::Z } else { Vec3::Y };
    look_at(-d, Vec3::ZERO, up)
}

/// One cascade's orthographic light box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeBox {
    /// World -> light clip space (NDC x, y in [-1, 1], z in [0, 1], 0 towards the light).
    pub view_proj: Mat4,
    /// World size of one texel.
    pub texel: f32,
    /// Centre of the box in light-view x/y (snapped to whole texels when asked).
    pub origin: Vec2,
    /// Half side of the box (world units).
    pub half: f32,
    /// The slice of view depths it serves.
    pub d0: f32,
    pub d1: f32,
    /// The light view ([`light_view`]) and the light-view z of the box's near (towards the
    /// light) and far planes.
    pub light_view: Mat4,
    pub near_z: f32,
    pub far_z: f32,
}

impl CascadeBox {
    /// Whether `p` (world) lies inside the box.
    pub fn contains(&self, p: Vec3) -> bool {
        let q = (self.light_view * p.extend(1.0)).xyz();
        let d = (Vec2::new(q.x, q.y) - self.origin).abs();
        d.x <= self.half && d.y <= self.half && q.z <= self.near_z && q.z >= self.far_z
    }

    /// The same box with its side scaled by `factor` about its centre (leak tracing's cascade
    /// reuse enlarges each box by 15 % and re-renders it only when the slice leaves it).
    pub fn enlarged(&self, factor: f32, res: u32) -> CascadeBox {
        let half = self.half * factor;
        let (o, v) = (self.origin, self.light_view);
        let proj = orthographic(o.x - half, o.x + half, o.y - half, o.y + half, -self.near_z, -self.far_z);
        CascadeBox { view_proj: proj * v, texel: 2.0 * half / res as f32, half, ..*self }
    }
}

/// How a slice is enclosed in light space.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fit {
    /// Bounding sphere: the box side depends only on the slice and the lens, so it is the same
    /// in every frame and snapping removes all shimmer. Wastes area (up to ~2x the box's).
    Sphere,
    /// Light-space bounding square of the slice's corners: smaller texels, but the side changes
    /// as the camera turns (quantized to steps of 2^-10, so it changes in jumps: some shimmer).
    Box,
}

/// Fits the light box of the slice `[d0, d1]`: the slice's bounding sphere or light-space
/// square (`fit`), or the scene's light-space square when that is smaller, plus one texel of margin (so that snapping, which moves the box by at most
/// half a texel, keeps the slice inside); x/y centre snapped to whole texels when `snap`;
/// depth from the scene's nearest point to the light (every caster) to the far side of the
/// slice (clamped to the scene).
#[allow(clippy::too_many_arguments)]
pub fn fit_cascade(frustum: &ViewFrustum, dir: Vec3, scene: &Bounds, d0: f32, d1: f32, res: u32, snap: bool, fit: Fit) -> CascadeBox {
    let view = light_view(dir);
    let corners = frustum.slice_corners(d0, d1);
    let (center, r, recv_far) = match fit {
        Fit::Sphere => {
            let (center, r) = slice_sphere(&corners);
            let c = (view * center.extend(1.0)).xyz();
            (Vec2::new(c.x, c.y), r, c.z - r)
        }
        Fit::Box => {
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for p in corners {
                let q = (view * p.extend(1.0)).xyz();
                lo = lo.min(q);
                hi = hi.max(q);
            }
            (Vec2::new(lo.x + hi.x, lo.y + hi.y) * 0.5, 0.5 * (hi.x - lo.x).max(hi.y - lo.y), lo.z)
        }
    };
    // the scene's footprint in light space: no receiver lies outside it
    let (mut slo, mut shi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for p in scene.corners() {
        let q = (view * p.extend(1.0)).xyz();
        slo = slo.min(q);
        shi = shi.max(q);
    }
    let scene_r = 0.5 * (shi.x - slo.x).max(shi.y - slo.y);
    // a slice wider than the whole scene gets the scene's square (fixed: as stable as a sphere)
    let (center, r) = if r >= scene_r { (Vec2::new(slo.x + shi.x, slo.y + shi.y) * 0.5, scene_r) } else { (center, r) };
    let r = quantize_radius(r);
    let res_f = res as f32;
    // one texel of margin: half = r + texel, texel = 2 half / res
    let half = r * res_f / (res_f - 2.0);
    let texel = 2.0 * half / res_f;
    let mut origin = center;
    if snap {
        origin = Vec2::new(snap_to_texel(origin.x, texel), snap_to_texel(origin.y, texel));
    }
    let (zlo, zhi) = (slo.z, shi.z);
    let margin = scene.diagonal().max(1e-6) * 1e-3;
    let near_z = zhi + margin; // towards the light: every caster in the scene
    let far_z = recv_far.max(zlo) - margin; // away from it: the receivers of the slice
    let far_z = far_z.min(near_z - margin);
    let proj = orthographic(origin.x - half, origin.x + half, origin.y - half, origin.y + half, -near_z, -far_z);
    CascadeBox { view_proj: proj * view, texel, origin, half, d0, d1, light_view: view, near_z, far_z }
}

/// Every cascade of `splits` (n + 1 distances -> n boxes).
pub fn fit_cascades(frustum: &ViewFrustum, dir: Vec3, scene: &Bounds, splits: &[f32], res: u32, snap: bool, fit: Fit) -> Vec<CascadeBox> {
    splits.windows(2).map(|w| fit_cascade(frustum, dir, scene, w[0], w[1], res, snap, fit)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;

    fn frustum(cam: &Camera) -> ViewFrustum {
        ViewFrustum::from_view_proj(cam.view_proj(16, 9), cam.position).unwrap()
    }

    #[test]
    fn practical_splits_follow_the_formula() {
        let s = practical_splits(0.5, 200.0, 4, 0.85);
        assert_eq!(s.len(), 5);
        assert_eq!((s[0], s[4]), (0.5, 200.0));
        for (i, x) in s.iter().enumerate() {
            let t = i as f64 / 4.0;
            let want = 0.85 * 0.5 * (400.0f64).powf(t) + 0.15 * (0.5 + 199.5 * t);
            assert!((*x as f64 - want).abs() < 1e-4 * want, "split {i}: {x} vs {want}");
        }
        // hand values: lambda 1 is logarithmic, lambda 0 uniform
        let log = practical_splits(1.0, 1000.0, 3, 1.0);
        assert!((log[1] - 10.0).abs() < 1e-3 && (log[2] - 100.0).abs() < 1e-2, "{log:?}");
        assert_eq!(practical_splits(0.0, 9.0, 3, 0.0), vec![0.0, 3.0, 6.0, 9.0]);
        assert!(s.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn manual_splits_are_checked() {
        assert_eq!(manual_splits(1.0, 50.0, &[5.0, 20.0]).unwrap(), vec![1.0, 5.0, 20.0, 50.0]);
        assert!(manual_splits(1.0, 50.0, &[20.0, 5.0]).is_err());
        assert!(manual_splits(1.0, 50.0, &[60.0]).is_err());
    }

    #[test]
    fn tightening_intersects_with_the_gbuffer_range() {
        assert_eq!(depth_range(0.1, 100.0, Some((2.0, 32.0))), (2.0, 32.0));
        // rounded outwards to 2^(1/8) steps: 3 -> 2^(12/8) = 2.83, 40 -> 2^(43/8) = 41.5
        let (lo, hi) = depth_range(0.1, 100.0, Some((3.0, 40.0)));
        assert!((lo - 2.0f32.powf(1.5)).abs() < 1e-4 && (hi - 2.0f32.powf(43.0 / 8.0)).abs() < 1e-3, "{lo} {hi}");
        // and stable: nearby ranges give the same result
        assert_eq!(depth_range(0.1, 100.0, Some((2.95, 40.5))), (lo, hi));
        assert_eq!(depth_range(0.1, 100.0, Some((0.01, 400.0))), (0.1, 100.0));
        assert_eq!(depth_range(0.1, 100.0, None), (0.1, 100.0));
        assert_eq!(depth_range(0.1, 100.0, Some((f32::INFINITY, f32::NEG_INFINITY))), (0.1, 100.0));
    }

    #[test]
    fn frustum_is_rebuilt_from_the_view_projection() {
        let cam = Camera::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 1.0, -2.0), 60.0, 0.25, 80.0);
        let f = frustum(&cam);
        assert!((f.near - 0.25).abs() < 1e-4 && (f.far - 80.0).abs() < 0.05, "{} {}", f.near, f.far);
        assert!((f.forward - (cam.target - cam.position).normalize()).length() < 1e-4);
        // slice corners lie at their view depth and project to the screen corners
        let c = f.slice_corners(3.0, 10.0);
        for (k, p) in c.iter().enumerate() {
            let d = (*p - cam.position).dot(f.forward);
            assert!((d - if k < 4 { 3.0 } else { 10.0 }).abs() < 1e-3, "corner {k} at depth {d}");
            let px = cam.project_to_pixel(*p, 16, 9).unwrap();
            assert!((px.x.abs() < 1e-2 || (px.x - 16.0).abs() < 1e-2) && (px.y.abs() < 1e-2 || (px.y - 9.0).abs() < 1e-2), "{px}");
        }
    }

    #[test]
    fn boxes_contain_their_frustum_slices_and_the_casters() {
        let scene = Bounds { min: Vec3::new(-60.0, 0.0, -60.0), max: Vec3::new(60.0, 25.0, 60.0) };
        let cam = Camera::new(Vec3::new(3.0, 1.7, 5.0), Vec3::new(-8.0, 1.0, -20.0), 70.0, 0.1, 120.0);
        let f = frustum(&cam);
        let dir = Vec3::new(0.4, -1.0, 0.3);
        for (snap, fit) in [(false, Fit::Sphere), (true, Fit::Sphere), (false, Fit::Box), (true, Fit::Box)] {
            let splits = practical_splits(f.near, f.far, 4, DEFAULT_LAMBDA);
            let boxes = fit_cascades(&f, dir, &scene, &splits, 512, snap, fit);
            for (i, b) in boxes.iter().enumerate() {
                // points of the slice (corners and along its edges and across its far plane)
                // that lie in the scene, where receivers can be
                let c = f.slice_corners(splits[i], splits[i + 1]);
                let mut pts = Vec::new();
                for k in 0..4 {
                    for t in 0..=8 {
                        let u = t as f32 / 8.0;
                        pts.push(c[k].lerp(c[k + 4], u));
                        pts.push(c[4].lerp(c[4 + k], u));
                    }
                }
                let inside: Vec<Vec3> = pts.into_iter().filter(|p| p.cmpge(scene.min).all() && p.cmple(scene.max).all()).collect();
                assert!(!inside.is_empty());
                for p in inside {
                    let n = b.view_proj.project_point3(p);
                    // inside, with the margin of at least half a texel left after snapping
                    let lim = 1.0 - 1.0 / 512.0;
                    assert!(n.x.abs() <= lim && n.y.abs() <= lim, "cascade {i} snap {snap} {fit:?}: {p} at {n}");
                    assert!((0.0..=1.0).contains(&n.z), "cascade {i} snap {snap}: {p} at depth {n}");
                }
                // a caster at the top of the scene above a slice point is still in front of the near plane
                let mid = f.position + f.forward * (0.5 * (splits[i] + splits[i + 1]));
                let caster = mid - dir.normalize() * ((25.0 - mid.y) / -dir.normalize().y);
                let n = b.view_proj.project_point3(caster);
                assert!(n.z >= 0.0 && n.z < b.view_proj.project_point3(mid).z, "cascade {i}: caster at depth {n}");
                assert!((b.texel - 2.0 * b.half / 512.0).abs() < 1e-6);
            }
            assert!(boxes.windows(2).all(|w| w[0].texel <= w[1].texel), "texels grow with distance");
        }
    }

    #[test]
    fn snapping_moves_the_origin_by_whole_texels_and_is_idempotent() {
        let scene = Bounds { min: Vec3::splat(-50.0), max: Vec3::splat(50.0) };
        let dir = Vec3::new(0.3, -1.0, 0.5);
        let base = Camera::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(10.0, 1.0, -10.0), 60.0, 0.1, 60.0);
        let b0 = fit_cascade(&frustum(&base), dir, &scene, 2.0, 12.0, 1024, true, Fit::Sphere);
        for k in 1..20 {
            // translate and turn the camera a little
            let off = Vec3::new(0.0137 * k as f32, 0.003 * k as f32, -0.021 * k as f32);
            let cam = Camera { position: base.position + off, target: base.target + off * 1.5, ..base };
            let b = fit_cascade(&frustum(&cam), dir, &scene, 2.0, 12.0, 1024, true, Fit::Sphere);
            assert_eq!(b.texel, b0.texel, "the sphere keeps the texel size under motion");
            let steps = (b.origin - b0.origin) / b.texel;
            assert!((steps - steps.round()).abs().max_element() < 1e-2, "frame {k}: moved {steps} texels");
            // the grid itself: the origin is a whole number of texels from the light-space origin
            let g = b.origin / b.texel;
            assert!((g - g.round()).abs().max_element() < 1e-3, "{g}");
            // idempotent
            assert_eq!(snap_to_texel(b.origin.x, b.texel), b.origin.x);
            assert_eq!(snap_to_texel(b.origin.y, b.texel), b.origin.y);
        }
        let u = fit_cascade(&frustum(&base), dir, &scene, 2.0, 12.0, 1024, false, Fit::Sphere);
        // the box fit is snapped to its own (quantized) texel grid, and smaller than the sphere
        let bx = fit_cascade(&frustum(&base), dir, &scene, 2.0, 12.0, 1024, true, Fit::Box);
        let g = bx.origin / bx.texel;
        assert!((g - g.round()).abs().max_element() < 1e-3 && bx.texel < b0.texel, "{g} {} {}", bx.texel, b0.texel);
        assert!((u.origin - b0.origin).abs().max_element() <= 0.5 * b0.texel + 1e-5);
        assert_eq!(quantize_radius(quantize_radius(3.3)), quantize_radius(3.3));
        assert!(quantize_radius(3.3) >= 3.3 && quantize_radius(3.3) < 3.3 * 1.002);
    }

    #[test]
    fn an_enlarged_box_holds_a_slice_that_moved_a_little() {
        let scene = Bounds { min: Vec3::splat(-50.0), max: Vec3::splat(50.0) };
        let dir = Vec3::new(0.3, -1.0, 0.5);
        let cam = Camera::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(10.0, 1.0, -10.0), 60.0, 0.1, 60.0);
        let b = fit_cascade(&frustum(&cam), dir, &scene, 2.0, 12.0, 1024, true, Fit::Box);
        let big = b.enlarged(1.15, 1024);
        assert!((big.texel / b.texel - 1.15).abs() < 1e-5);
        let moved = Camera { position: cam.position + Vec3::new(0.4, 0.0, -0.3), target: cam.target + Vec3::new(0.4, 0.0, -0.3), ..cam };
        let corners = frustum(&moved).slice_corners(2.0, 12.0);
        assert!(corners.iter().all(|p| big.contains(*p)), "the 15 % box still holds the moved slice");
        assert!(!corners.iter().all(|p| b.contains(*p)), "the tight box does not");
        for p in corners {
            let n = big.view_proj.project_point3(p);
            assert!(n.x.abs() <= 1.0 && n.y.abs() <= 1.0 && (0.0..=1.0).contains(&n.z), "{n}");
        }
    }

    #[test]
    fn a_slice_wider_than_the_scene_gets_the_scene_square() {
        let scene = Bounds { min: Vec3::new(-5.0, 0.0, -5.0), max: Vec3::new(5.0, 1.0, 5.0) };
        let dir = -Vec3::Y; // straight down: light-space x/y footprint is the 10 x 10 square
        let a = Camera::new(Vec3::new(0.0, 2.0, 0.0), Vec3::new(0.0, 0.0, -10.0), 60.0, 0.1, 200.0);
        let b = Camera { position: Vec3::new(1.3, 2.0, 0.7), ..a };
        let (fa, fb) = (
            fit_cascade(&frustum(&a), dir, &scene, 20.0, 150.0, 512, true, Fit::Sphere),
            fit_cascade(&frustum(&b), dir, &scene, 20.0, 150.0, 512, true, Fit::Sphere),
        );
        assert_eq!(fa, CascadeBox { d0: fa.d0, ..fb }, "the same box from anywhere");
        assert!(fa.half >= 5.0 && fa.half < 5.0 * 1.01, "{}", fa.half);
        for p in scene.corners() {
            let n = fa.view_proj.project_point3(p);
            assert!(n.x.abs() <= 1.0 && n.y.abs() <= 1.0 && (0.0..=1.0).contains(&n.z), "{n}");
        }
    }

    #[test]
    fn sphere_is_equidistant_or_at_the_far_plane() {
        // a narrow lens (30 deg, 16:9): the centre lies between the planes for 5..20
        let cam = Camera::new(Vec3::ZERO, -Vec3::Z, 30.0, 0.1, 100.0);
        let f = frustum(&cam);
        let c = f.slice_corners(5.0, 20.0);
        let (ctr, r) = slice_sphere(&c);
        for p in c {
            assert!((p - ctr).length() <= r * (1.0 + 1e-5));
        }
        assert!(((c[0] - ctr).length() - (c[4] - ctr).length()).abs() < 1e-3 * r);
        // a thin wide slice: the centre sits on its far plane
        let f = frustum(&Camera { fov_y_deg: 60.0, ..cam });
        let c = f.slice_corners(50.0, 51.0);
        let (ctr, _) = slice_sphere(&c);
        assert!((ctr.z + 51.0).abs() < 1e-3, "{ctr}");
    }
}
