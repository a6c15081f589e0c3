//! The minimal shadow frustum (MSF; seed 000 section 3.2, seed 002 section 4.1.5): a light
//! projection whose x/y range is the minimum-area rectangle around the view samples projected
//! into the light (directional: the orthographic plane; spot: the light's image plane z = -1),
//! whose far plane is the farthest sample and whose near plane reaches the scene bounds towards the
//! light, so that every occluder between a visible sample and the light lands in the map.
//!
//! The GPU reduces the view samples first (`min-sm`'s reduce.wgsl): their bounding box in the
//! fixed [`LightFrame`], then per band of `grid` rows of that box the least and greatest x. The
//! four corners of each band's x range are a superset whose hull contains every sample and
//! exceeds the exact hull by at most one band height ([`Reduction::points`]). In one-pass mode
//! the bands divide a prior y range (the previous frame's) and samples outside it go to two
//! overflow slots: still a superset, tight again when the range holds.
//! Depth of the map is post-projective, 0 = near (orthographic: linear).

use glam::{DMat4, DVec2, DVec3, Mat4, Vec3};

use super::{convex_hull, min_area_rect, min_side_rect, Rect};
use crate::light::Light;
use crate::scene::Bounds;

/// Smallest half extent of the rectangle, as a fraction of the scene-fitted map's half extent: a
/// single sample or a line of samples gives a zero-width rectangle and a singular projection. Too
/// low: f32 rounding of world positions exceeds a texel; too high: tiny views lose resolution.
pub const MIN_EXTENT_FRACTION: f64 = 1e-3;
/// Depth margin (fraction of the scene diagonal) beyond the nearest bound and the farthest sample.
pub const DEPTH_MARGIN: f64 = 1e-3;

/// The light frame the samples are reduced in: world -> light view (right-handed, looking along
/// -z, the same frame as `lightspace::fit`), and the scene-fitted map's half extent in plane
/// units (to compare areas with `sm`).
#[derive(Clone, Copy, Debug)]
pub struct LightFrame {
    pub view: DMat4,
    pub perspective: bool,
    pub scene_half: f64,
}

fn up_for(d: DVec3) -> DVec3 {
    if d.cross(DVec3::Y).length_squared() < 1e-4 {
        DVec3::Z
    } else {
        DVec3::Y
    }
}

/// The fixed frame for `light`; `None` for point lights.
pub fn light_frame(light: &Light, bounds: &Bounds) -> Option<LightFrame> {
    let diag = (bounds.diagonal() as f64).max(1e-6);
    match *light {
        Light::Directional { direction } => {
            let d = direction.as_dvec3().normalize();
            let c = bounds.center().as_dvec3();
            let view = glam::dcamera::rh::view::look_at_mat4(c - d * diag, c, up_for(d));
            let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
            for p in bounds.corners() {
                let q = view.transform_point3(p.as_dvec3()).truncate();
                lo = lo.min(q);
                hi = hi.max(q);
            }
            Some(LightFrame { view, perspective: false, scene_half: (hi - lo).max_element() * 0.5 })
        }
        Light::Spot { position, direction, cone_deg } => {
            let (p, d) = (position.as_dvec3(), direction.as_dvec3().normalize());
            let view = glam::dcamera::rh::view::look_at_mat4(p, p + d, up_for(d));
            Some(LightFrame { view, perspective: true, scene_half: (cone_deg as f64).to_radians().tan() })
        }
        Light::Point { .. } => None,
    }
}

impl LightFrame {
    /// Plane coordinates and depth along the light (light-view -z) of a world point.
    pub fn project(&self, p: DVec3) -> (DVec2, f64) {
        let q = self.view.transform_point3(p);
        let depth = -q.z;
        let xy = if self.perspective { DVec2::new(q.x, q.y) / depth } else { DVec2::new(q.x, q.y) };
        (xy, depth)
    }
}

/// Order-preserving u32 code of an f32 (for atomicMax on the GPU); [`encode_min`] is its
/// complement so that atomicMax finds the least value. 0 never codes a finite value (= empty).
pub fn encode_max(x: f32) -> u32 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}
pub fn encode_min(x: f32) -> u32 {
    !encode_max(x)
}
pub fn decode_max(u: u32) -> f32 {
    if u & 0x8000_0000 != 0 {
        f32::from_bits(u & 0x7FFF_FFFF)
    } else {
        f32::from_bits(!u)
    }
}
pub fn decode_min(u: u32) -> f32 {
    decode_max(!u)
}

/// Words before the bands in the reduction buffer: min x, max x, min y, max y, max depth (codes),
/// sample count, 2 unused.
pub const HEADER_WORDS: usize = 8;

/// Words of the reduction buffer for `grid` bands: the header, (min x, max x) per band, then two
/// overflow slots for samples below and above the band range (one-pass mode).
pub fn buffer_words(grid: usize) -> usize {
    HEADER_WORDS + 2 * (grid + 2)
}

/// The reduced view samples.
#[derive(Clone, Debug, PartialEq)]
pub struct Reduction {
    /// Bounding box of the samples' plane coordinates.
    pub lo: DVec2,
    pub hi: DVec2,
    pub max_depth: f64,
    pub count: u64,
    /// The y range the bands divide: the samples' own (two passes) or a prior range, the
    /// previous frame's (one pass).
    pub band_lo: f64,
    pub band_hi: f64,
    /// Per band of rows over [band_lo, band_hi]: least and greatest x, `None` if empty.
    pub bands: Vec<Option<(f64, f64)>>,
    /// x ranges of the samples below `band_lo` and above `band_hi` (only with a prior range).
    pub under: Option<(f64, f64)>,
    pub over: Option<(f64, f64)>,
}

/// The slot of plane coordinate `y` among `grid` bands over [lo, hi], as the GPU computes it.
/// With `overflow`, y below lo goes to slot `grid` and above hi to `grid + 1`; else clamped.
pub fn band_of(y: f32, lo: f32, hi: f32, grid: u32, overflow: bool) -> u32 {
    if overflow && y < lo {
        return grid;
    }
    if overflow && y > hi {
        return grid + 1;
    }
    let t = (y - lo) / (hi - lo).max(1e-30);
    ((t.max(0.0) * grid as f32) as u32).min(grid - 1)
}

fn slot(w: &[u32], i: usize) -> Option<(f64, f64)> {
    let (a, c) = (w[HEADER_WORDS + 2 * i], w[HEADER_WORDS + 2 * i + 1]);
    (a != 0 && c != 0).then(|| (decode_min(a) as f64, decode_max(c) as f64))
}

impl Reduction {
    /// Decodes the GPU buffer ([`buffer_words`]); `prior` is the band range the pass used, if
    /// not the samples' own.
    pub fn from_words(w: &[u32], grid: usize, prior: Option<(f32, f32)>) -> Option<Reduction> {
        if w.len() < buffer_words(grid) || w[5] == 0 {
            return None;
        }
        let (lo, hi) =
            (DVec2::new(decode_min(w[0]) as f64, decode_min(w[2]) as f64), DVec2::new(decode_max(w[1]) as f64, decode_max(w[3]) as f64));
        let (band_lo, band_hi) = prior.map_or((lo.y, hi.y), |(a, b)| (a as f64, b as f64));
        Some(Reduction {
            lo,
            hi,
            max_depth: decode_max(w[4]) as f64,
            count: w[5] as u64,
            band_lo,
            band_hi,
            bands: (0..grid).map(|b| slot(w, b)).collect(),
            under: slot(w, grid),
            over: slot(w, grid + 1),
        })
    }

    /// What the GPU computes, on the CPU (tests): samples as (plane coordinates, depth).
    pub fn from_samples(samples: &[(DVec2, f64)], grid: usize, prior: Option<(f32, f32)>) -> Option<Reduction> {
        let mut w = vec![0u32; buffer_words(grid)];
        let f = |x: f64| x as f32;
        for (p, d) in samples {
            w[0] = w[0].max(encode_min(f(p.x)));
            w[1] = w[1].max(encode_max(f(p.x)));
            w[2] = w[2].max(encode_min(f(p.y)));
            w[3] = w[3].max(encode_max(f(p.y)));
            w[4] = w[4].max(encode_max(f(*d)));
            w[5] += 1;
        }
        if w[5] == 0 {
            return None;
        }
        let (lo, hi) = prior.unwrap_or((decode_min(w[2]), decode_max(w[3])));
        for (p, _) in samples {
            let b = HEADER_WORDS + 2 * band_of(f(p.y), lo, hi, grid as u32, prior.is_some()) as usize;
            w[b] = w[b].max(encode_min(f(p.x)));
            w[b + 1] = w[b + 1].max(encode_max(f(p.x)));
        }
        Reduction::from_words(&w, grid, prior)
    }

    /// The corners of every non-empty band's x range (and of the overflow slots, spanning from
    /// the band range to the samples' extreme y): their hull contains every sample.
    pub fn points(&self) -> Vec<DVec2> {
        let n = self.bands.len();
        let h = self.band_hi - self.band_lo;
        let corners =
            |(x0, x1): (f64, f64), y0: f64, y1: f64| [DVec2::new(x0, y0), DVec2::new(x1, y0), DVec2::new(x0, y1), DVec2::new(x1, y1)];
        let mut v = Vec::with_capacity(4 * n + 8);
        for (i, b) in self.bands.iter().enumerate() {
            if let Some(x) = *b {
                let y0 = self.band_lo + h * i as f64 / n as f64;
                let y1 = if i + 1 == n { self.band_hi } else { self.band_lo + h * (i + 1) as f64 / n as f64 };
                v.extend(corners(x, y0, y1));
            }
        }
        if let Some(x) = self.under {
            v.extend(corners(x, self.lo.y, self.band_lo));
        }
        if let Some(x) = self.over {
            v.extend(corners(x, self.band_hi, self.hi.y));
        }
        v
    }
}

crate::param_choice! {
    /// Which rectangle around the hull the map covers (`min-sm`'s `fit`).
    pub enum RectFit {
        /// Minimum area (the seeds' MSF): most texels on the samples, texels may be stretched.
        Area = "area",
        /// Shortest longer side: the smallest texel side (square texels in a square map).
        Side = "side",
    }
}

/// A fitted minimal shadow frustum.
#[derive(Clone, Debug)]
pub struct MinFrustum {
    /// World -> clip of the map (f64; [`MinFrustum::view_proj_f32`] for the GPU).
    pub view_proj: DMat4,
    /// World size of the larger side of a texel (orthographic), or the same per unit of depth
    /// along the light (perspective): the bias unit, as in `lightspace::LightProjection`.
    pub texel: f64,
    pub perspective: bool,
    /// Minimum-area rectangle of the hull, and the same grown by the padding the map gets.
    pub rect: Rect,
    pub padded: Rect,
    pub hull_points: usize,
    pub input_points: usize,
    /// Padded rectangle area / the scene-fitted map's area (`sm`).
    pub area_ratio: f64,
    pub near: f64,
    pub far: f64,
}

impl MinFrustum {
    pub fn view_proj_f32(&self) -> Mat4 {
        self.view_proj.as_mat4()
    }
}

/// Fits the MSF of `red` for a `res`-texel map, padding the rectangle by `pad_texels` texels on
/// every side (normal offset and PCF kernel reach beyond a sample). `None` for point lights.
pub fn fit(
    light: &Light,
    bounds: &Bounds,
    frame: &LightFrame,
    red: &Reduction,
    res: u32,
    pad_texels: f64,
    shape: RectFit,
) -> Option<MinFrustum> {
    if matches!(light, Light::Point { .. }) {
        return None;
    }
    let input = red.points();
    let hull = convex_hull(&input);
    let rect = match shape {
        RectFit::Area => min_area_rect(&hull)?,
        RectFit::Side => min_side_rect(&hull)?,
    };
    let floor = frame.scene_half * MIN_EXTENT_FRACTION;
    let half = rect.half.max(DVec2::splat(floor));
    // square map, side of the larger texel: M' = M + 2 pad M' / res
    let pad = pad_texels.clamp(0.0, res as f64 / 8.0);
    let m = half.max_element() / (1.0 - 2.0 * pad / res as f64);
    let pad_world = 2.0 * pad * m / res as f64;
    let padded = Rect { half: half + DVec2::splat(pad_world), ..rect };

    let diag = (bounds.diagonal() as f64).max(1e-6);
    let margin = diag * DEPTH_MARGIN;
    let depths: Vec<f64> = bounds.corners().iter().map(|c| frame.project(c.as_dvec3()).1).collect();
    let min_corner = depths.iter().copied().fold(f64::INFINITY, f64::min);
    let (near, far) = if frame.perspective {
        let far = red.max_depth + margin;
        // lightspace::fit's near: 1e-3 of the farthest bound (perspective depth precision)
        let farthest = bounds.corners().iter().map(|c| (*c - light_position(light)).length() as f64).fold(0.0, f64::max);
        let near = (min_corner - margin).max(farthest.max(margin) * 1e-3).min(far * 0.5);
        (near, far)
    } else {
        (min_corner - margin, red.max_depth.max(min_corner) + margin)
    };

    let (u, v, c) = (padded.axis, padded.axis.perp(), padded.center);
    let (a, b) = (padded.half.x, padded.half.y);
    let rows = if frame.perspective {
        [
            [u.x / a, u.y / a, u.dot(c) / a, 0.0],
            [v.x / b, v.y / b, v.dot(c) / b, 0.0],
            [0.0, 0.0, far / (near - far), near * far / (near - far)],
            [0.0, 0.0, -1.0, 0.0],
        ]
    } else {
        [
            [u.x / a, u.y / a, 0.0, -u.dot(c) / a],
            [v.x / b, v.y / b, 0.0, -v.dot(c) / b],
            [0.0, 0.0, -1.0 / (far - near), -near / (far - near)],
            [0.0, 0.0, 0.0, 1.0],
        ]
    };
    let proj = DMat4::from_cols_array_2d(&rows).transpose();
    Some(MinFrustum {
        view_proj: proj * frame.view,
        texel: 2.0 * padded.half.max_element() / res as f64,
        perspective: frame.perspective,
        rect,
        padded,
        hull_points: hull.len(),
        input_points: input.len(),
        area_ratio: padded.area() / (4.0 * frame.scene_half * frame.scene_half),
        near,
        far,
    })
}

fn light_position(light: &Light) -> Vec3 {
    match *light {
        Light::Spot { position, .. } | Light::Point { position } => position,
        Light::Directional { .. } => Vec3::ZERO,
    }
}

#[cfg(test)]
#[path = "frustum_tests.rs"]
mod tests;
