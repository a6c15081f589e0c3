//! CPU half of Irregular Adaptive Shadow Maps (seed 001, chapter 3) for directional lights:
//! the light frustum placement (thesis 3.2, Figure 3.1), the importance of a view sample
//! (equation 3.1), the ranking of the 4x4 tiles and the assignment of a fixed resolution set by
//! rank (3.4), the linear buffer layout (accumulated offsets sum r_i^2, 3.6) and the texel index
//! equations 3.2-3.5, and per-tile orthographic frusta (3.5).
//!
//! Light space: `x` = `right`, `y` = `up` (both perpendicular to the light), depth = distance
//! along the direction the light travels (larger = farther from the light). Buffer coordinates
//! `uv` in [0, 1]^2 cover the whole frustum square; `u` grows with light-space x, `v` grows
//! *downwards* (v = 0 at the largest y), like texture rows. Tile (tx, ty) has index
//! `ty * 4 + tx` (equation 3.3 with n = 4); tile row 0 is the top row.

use glam::{Mat4, Vec2, Vec3, Vec4};

pub mod fit;

/// Tiles per side (thesis 3.2: 4x4 tiles).
pub const TILES_PER_SIDE: u32 = 4;
pub const TILE_COUNT: usize = 16;

/// The thesis's resolution set (4.2): 1x1024, 2x512, 1x256, 4x128, 2x64, 2x32, 4x16, in rank
/// order (rank 0 = most important tile).
pub const THESIS_RESOLUTIONS: [u32; TILE_COUNT] = [1024, 512, 512, 256, 128, 128, 128, 128, 64, 64, 32, 32, 16, 16, 16, 16];

/// Bytes per texel of the shadow buffer (thesis 3.2: 32-bit floats).
pub const TEXEL_BYTES: u64 = 4;

/// Orthonormal light basis (right, up, dir) for a light travelling along `dir`.
pub fn light_basis(dir: Vec3) -> (Vec3, Vec3, Vec3) {
    let d = dir.normalize();
    let helper = if d.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let right = helper.cross(d).normalize();
    let up = d.cross(right).normalize();
    (right, up, d)
}

/// The light frustum square of one frame, split into 4x4 equal tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub right: Vec3,
    pub up: Vec3,
    pub dir: Vec3,
    /// Light-space (x, y) of the square's minimum corner.
    pub origin: Vec2,
    /// Side of the square, world units.
    pub size: f32,
}

/// How the square is placed relative to the camera.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// Thesis Figure 3.1: the camera on the circle inscribed in the square, the square ahead of
    /// it along the camera's forward direction projected onto the light plane.
    Circle,
    /// The suggested fix of thesis chapter 5: as `Circle`, then shifted by less than half a tile
    /// so that the camera sits at the centre of a tile (never at a four-tile corner).
    TileCentre,
}

/// Places the square of side `size` for a camera at `cam` looking along `forward` (thesis 3.2).
/// With `snap`, the square moves in steps of the coarsest texel of any tile (tile / 16 for the
/// thesis set), so every tile's texel grid stays put while the camera moves (no shimmering;
/// not in the thesis).
pub fn place(light_dir: Vec3, cam: Vec3, forward: Vec3, size: f32, snap_step: Option<f32>, anchor: Anchor) -> Placement {
    let (right, up, dir) = light_basis(light_dir);
    let c = Vec2::new(cam.dot(right), cam.dot(up));
    let f = Vec2::new(forward.dot(right), forward.dot(up));
    // Looking straight along the light: the camera at the centre.
    let f = if f.length() > 1e-6 { f.normalize() } else { Vec2::ZERO };
    let half = 0.5 * size;
    let mut origin = c + f * half - Vec2::splat(half);
    if anchor == Anchor::TileCentre {
        let tile = size / TILES_PER_SIDE as f32;
        // camera at the centre of the tile it falls in
        let rel = (c - origin) / tile;
        let cell = rel.floor().clamp(Vec2::ZERO, Vec2::splat(TILES_PER_SIDE as f32 - 1.0));
        origin = c - (cell + 0.5) * tile;
    }
    if let Some(step) = snap_step.filter(|s| *s > 0.0) {
        origin = (origin / step).round() * step;
    }
    Placement { right, up, dir, origin, size }
}

impl Placement {
    pub fn tile_size(&self) -> f32 {
        self.size / TILES_PER_SIDE as f32
    }
    /// (x, y, depth) in light space.
    pub fn to_light(&self, p: Vec3) -> Vec3 {
        Vec3::new(p.dot(self.right), p.dot(self.up), p.dot(self.dir))
    }
    /// Buffer coordinates of a world point (outside [0, 1]^2 when outside the square).
    pub fn uv(&self, p: Vec3) -> Vec2 {
        let l = self.to_light(p);
        let s = (l.truncate() - self.origin) / self.size;
        Vec2::new(s.x, 1.0 - s.y)
    }
    /// Light-space (x, y) rectangle (min, max) of tile `t`.
    pub fn tile_rect(&self, t: usize) -> (Vec2, Vec2) {
        let n = TILES_PER_SIDE as usize;
        let (tx, ty) = ((t % n) as f32, (t / n) as f32);
        let ts = self.tile_size();
        let min = self.origin + Vec2::new(tx * ts, (n as f32 - 1.0 - ty) * ts);
        (min, min + Vec2::splat(ts))
    }
    /// World -> clip of tile `t`'s orthographic frustum between light depths `near` and `far`:
    /// x, y in [-1, 1] over the tile (y up), z = (depth - near) / (far - near) in [0, 1].
    pub fn tile_matrix(&self, t: usize, near: f32, far: f32) -> Mat4 {
        let (min, max) = self.tile_rect(t);
        let sx = 2.0 / (max.x - min.x);
        let sy = 2.0 / (max.y - min.y);
        let sz = 1.0 / (far - near).max(1e-6);
        let r0 = (self.right * sx).extend(-min.x * sx - 1.0);
        let r1 = (self.up * sy).extend(-min.y * sy - 1.0);
        let r2 = (self.dir * sz).extend(-near * sz);
        Mat4::from_cols(r0, r1, r2, Vec4::W).transpose()
    }
}

/// Importance of one view sample at view depth `w` (thesis equation 3.1), with the bracket
/// clamped to [0, 1] as the thesis requires: 1 + m for w = 0, falling linearly to 1 at w >= k.
pub fn importance(w: f32, m: f32, k: f32) -> f32 {
    1.0 + m * (1.0 - w / k).clamp(0.0, 1.0)
}

/// Tile indices by rank (thesis 3.4): non-empty tiles first by importance descending, ties by
/// tile index ascending; then the empty tiles in index order. Deterministic for any input.
pub fn rank(importance: &[f64; TILE_COUNT], empty: &[bool; TILE_COUNT]) -> [usize; TILE_COUNT] {
    let mut order: [usize; TILE_COUNT] = std::array::from_fn(|i| i);
    order.sort_by(|&a, &b| empty[a].cmp(&empty[b]).then_with(|| importance[b].total_cmp(&importance[a])).then_with(|| a.cmp(&b)));
    order
}

/// Per-tile resolution: the tile of rank i gets `set[i]` (`set` sorted descending).
pub fn assign(order: &[usize; TILE_COUNT], set: &[u32; TILE_COUNT]) -> [u32; TILE_COUNT] {
    let mut res = [0; TILE_COUNT];
    for (r, &t) in order.iter().enumerate() {
        res[t] = set[r];
    }
    res
}

/// Accumulated offsets of the linear layout (thesis 3.6): tile n starts at sum_{i<n} r_i^2.
pub fn offsets(res: &[u32; TILE_COUNT]) -> [u32; TILE_COUNT] {
    let mut off = [0; TILE_COUNT];
    let mut acc = 0u32;
    for (o, r) in off.iter_mut().zip(res) {
        *o = acc;
        acc += r * r;
    }
    off
}

/// Total texels of a resolution set.
pub fn texels(set: &[u32; TILE_COUNT]) -> u64 {
    set.iter().map(|&r| r as u64 * r as u64).sum()
}

/// Equations 3.2 and 3.3: the tile of buffer coordinates `uv` in [0, 1)^2 (n = 4 tiles per
/// side; the thesis's p_f d / t with p_f in [0, 1] is p_f n). Returns (tile index, p_t).
pub fn tile_of(uv: Vec2) -> (usize, [u32; 2]) {
    let n = TILES_PER_SIDE as f32;
    let pt = (uv * n).floor().clamp(Vec2::ZERO, Vec2::splat(n - 1.0));
    let (x, y) = (pt.x as u32, pt.y as u32);
    ((y * TILES_PER_SIDE + x) as usize, [x, y])
}

/// Equations 3.4 and 3.5: index in the linear buffer of `uv` for tile resolutions `res` and
/// offsets `off`. The thesis prints p_b = floor((p_f - p_t d / t) n r); with p_f in [0, 1] the
/// tile's corner is p_t t / d = p_t / n, which is what is used here (p_b = floor((p_f n - p_t) r)).
pub fn texel_index(uv: Vec2, res: &[u32; TILE_COUNT], off: &[u32; TILE_COUNT]) -> u32 {
    let (t, pt) = tile_of(uv);
    let r = res[t];
    let n = TILES_PER_SIDE as f32;
    let local = uv * n - Vec2::new(pt[0] as f32, pt[1] as f32);
    let pb = (local * r as f32).floor().clamp(Vec2::ZERO, Vec2::splat(r as f32 - 1.0));
    off[t] + pb.x as u32 + pb.y as u32 * r
}

/// Listing 3.1: index written by a fragment at pixel `frag` (viewport = the tile, r x r) of tile
/// `t`: i0 + floor(y) r + floor(x).
pub fn fragment_index(frag: Vec2, r: u32, i0: u32) -> u32 {
    i0 + frag.y.floor() as u32 * r + frag.x.floor() as u32
}

/// The conventional alternative to the linear buffer: the 16 tiles as squares in one depth
/// atlas of 2 r0 x r0 texels (r0 = the largest resolution), placed by buddy allocation (powers
/// of two, largest first). Returns (width, height, top-left corner per rank), or None when the
/// set is not powers of two or does not fit.
pub fn atlas_layout(set: &[u32; TILE_COUNT]) -> Option<(u32, u32, [[u32; 2]; TILE_COUNT])> {
    let s0 = set[0];
    if set.iter().any(|r| !r.is_power_of_two()) || set.windows(2).any(|w| w[0] < w[1]) {
        return None;
    }
    // free squares (x, y, side)
    let mut free = vec![(0u32, 0u32, s0), (s0, 0, s0)];
    let mut out = [[0u32; 2]; TILE_COUNT];
    for (i, &r) in set.iter().enumerate() {
        let best = free.iter().enumerate().filter(|(_, f)| f.2 >= r).min_by_key(|(_, f)| (f.2, f.1, f.0))?.0;
        let (x, y, mut side) = free.swap_remove(best);
        while side > r {
            side /= 2;
            free.extend([(x + side, y, side), (x, y + side, side), (x + side, y + side, side)]);
        }
        out[i] = [x, y];
    }
    Some((2 * s0, s0, out))
}

/// Which of `boxes` (light-space (x, y, depth) min/max) overlap tile `t`'s column: the four side
/// planes (thesis 3.5, near and far ignored).
pub fn cull(p: &Placement, t: usize, boxes: &[(Vec3, Vec3)]) -> Vec<usize> {
    let (min, max) = p.tile_rect(t);
    boxes.iter().enumerate().filter(|(_, (a, b))| a.x <= max.x && b.x >= min.x && a.y <= max.y && b.y >= min.y).map(|(i, _)| i).collect()
}

/// Light-space AABB (x, y, depth) of a world AABB.
pub fn light_box(p: &Placement, min: Vec3, max: Vec3) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for i in 0..8 {
        let c = Vec3::new(
            if i & 1 == 0 { min.x } else { max.x },
            if i & 2 == 0 { min.y } else { max.y },
            if i & 4 == 0 { min.z } else { max.z },
        );
        let l = p.to_light(c);
        lo = lo.min(l);
        hi = hi.max(l);
    }
    (lo, hi)
}

/// Merges sorted chunk indices into contiguous runs [start, end).
pub fn runs(chunks: &[usize]) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    for &c in chunks {
        match out.last_mut() {
            Some(r) if r.1 == c => r.1 = c + 1,
            _ => out.push((c, c + 1)),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thesis_set_memory_is_exact() {
        assert_eq!(texels(&THESIS_RESOLUTIONS), 1_715_200);
        assert_eq!(texels(&THESIS_RESOLUTIONS) * TEXEL_BYTES, 6_860_800);
        assert!(THESIS_RESOLUTIONS.windows(2).all(|w| w[0] >= w[1]));
    }

    #[test]
    fn importance_is_clamped() {
        assert_eq!(importance(0.0, 4.0, 10.0), 5.0);
        assert_eq!(importance(5.0, 4.0, 10.0), 3.0);
        assert_eq!(importance(10.0, 4.0, 10.0), 1.0);
        assert_eq!(importance(50.0, 4.0, 10.0), 1.0);
        assert_eq!(importance(-1.0, 4.0, 10.0), 5.0);
    }

    #[test]
    fn ranking_and_assignment_hand_case() {
        let mut imp = [0.0; 16];
        let mut empty = [true; 16];
        // tiles 5 > 6 = 9 > 10 > 1 (ties 6/9 broken by index), the rest empty
        for (t, v) in [(5, 90.0), (6, 40.0), (9, 40.0), (10, 30.0), (1, 2.0)] {
            imp[t] = v;
            empty[t] = false;
        }
        let order = rank(&imp, &empty);
        assert_eq!(order, [5, 6, 9, 10, 1, 0, 2, 3, 4, 7, 8, 11, 12, 13, 14, 15]);
        let res = assign(&order, &THESIS_RESOLUTIONS);
        assert_eq!(res[5], 1024);
        assert_eq!((res[6], res[9]), (512, 512));
        assert_eq!(res[10], 256);
        assert_eq!(res[1], 128);
        assert_eq!([res[0], res[2], res[3]], [128, 128, 128]);
        assert_eq!([res[4], res[7], res[8], res[11]], [64, 64, 32, 32]);
        assert_eq!([res[12], res[13], res[14], res[15]], [16; 4]);
        assert_eq!(texels(&res), texels(&THESIS_RESOLUTIONS));
    }

    #[test]
    fn all_empty_and_all_tied_frames_keep_index_order() {
        let order = rank(&[0.0; 16], &[true; 16]);
        assert_eq!(order, std::array::from_fn(|i| i));
        let order = rank(&[7.0; 16], &[false; 16]);
        assert_eq!(order, std::array::from_fn(|i| i));
        assert_eq!(assign(&order, &THESIS_RESOLUTIONS), THESIS_RESOLUTIONS);
        // an empty tile never outranks a non-empty one, whatever its stale importance
        let mut imp = [1.0; 16];
        imp[0] = 1e9;
        let mut empty = [false; 16];
        empty[0] = true;
        assert_eq!(rank(&imp, &empty)[15], 0);
    }

    #[test]
    fn offsets_accumulate_squares() {
        let off = offsets(&THESIS_RESOLUTIONS);
        let mut acc = 0;
        for i in 0..16 {
            assert_eq!(off[i], acc);
            acc += THESIS_RESOLUTIONS[i] * THESIS_RESOLUTIONS[i];
        }
        assert_eq!(off[1], 1024 * 1024);
        assert_eq!(off[3], 1024 * 1024 + 2 * 512 * 512);
        assert_eq!(off[15] as u64 + 16 * 16, 1_715_200);
    }

    /// Reference: build each tile as an r x r image, lay the images out one after another, and
    /// look a buffer point up by brute-force geometry.
    #[test]
    fn texel_index_matches_reference_and_is_a_bijection() {
        let order = rank(&std::array::from_fn(|i| ((i * 7) % 16) as f64), &[false; 16]);
        let res = assign(&order, &THESIS_RESOLUTIONS);
        let off = offsets(&res);
        let mut seen = vec![false; texels(&res) as usize];
        for t in 0..16 {
            let (tx, ty) = (t % 4, t / 4);
            let r = res[t];
            for y in 0..r {
                for x in 0..r {
                    // the centre of texel (x, y) of tile t in buffer coordinates
                    let uv = Vec2::new((tx as f32 + (x as f32 + 0.5) / r as f32) / 4.0, (ty as f32 + (y as f32 + 0.5) / r as f32) / 4.0);
                    let want = off[t] + y * r + x;
                    assert_eq!(tile_of(uv).0, t);
                    let got = texel_index(uv, &res, &off);
                    assert_eq!(got, want, "tile {t} texel ({x},{y})");
                    assert_eq!(fragment_index(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), r, off[t]), want);
                    assert!(!seen[got as usize]);
                    seen[got as usize] = true;
                }
            }
        }
        assert!(seen.iter().all(|s| *s));
        // edges clamp into the last tile / texel
        assert_eq!(texel_index(Vec2::ONE, &res, &off), off[15] + res[15] * res[15] - 1);
    }

    #[test]
    fn placement_puts_camera_on_inscribed_circle_ahead() {
        let light = Vec3::new(0.2, -1.0, 0.1);
        for a in 0..12 {
            let ang = a as f32 * 0.5;
            let fwd = Vec3::new(ang.cos(), -0.2, ang.sin());
            let cam = Vec3::new(3.0, 2.0, -1.0);
            let p = place(light, cam, fwd, 40.0, None, Anchor::Circle);
            let centre = p.origin + Vec2::splat(20.0);
            let c = Vec2::new(cam.dot(p.right), cam.dot(p.up));
            assert!(((c - centre).length() - 20.0).abs() < 1e-3);
            // centre ahead of the camera (projected forward)
            let f = Vec2::new(fwd.dot(p.right), fwd.dot(p.up)).normalize();
            assert!((centre - c).normalize().dot(f) > 0.9999);
            // the camera's own uv lies inside the square
            let uv = p.uv(cam);
            assert!(uv.min_element() >= -1e-4 && uv.max_element() <= 1.0 + 1e-4, "{uv}");
        }
    }

    #[test]
    fn tile_centre_anchor_and_snapping() {
        let light = Vec3::new(0.3, -1.0, 0.2);
        let cam = Vec3::new(1.3, 2.0, 4.7);
        for a in 0..16 {
            let ang = a as f32 * 0.4;
            let fwd = Vec3::new(ang.cos(), 0.0, ang.sin());
            let p = place(light, cam, fwd, 32.0, None, Anchor::TileCentre);
            let uv = p.uv(cam) * 4.0;
            let frac = uv - uv.floor();
            assert!((frac - Vec2::splat(0.5)).abs().max_element() < 1e-3, "{frac}");
            let s = place(light, cam, fwd, 32.0, Some(0.5), Anchor::Circle);
            let q = s.origin / 0.5;
            assert!((q - q.round()).abs().max_element() < 1e-3);
            let c = place(light, cam, fwd, 32.0, None, Anchor::Circle);
            assert!((s.origin - c.origin).abs().max_element() <= 0.25 + 1e-4);
        }
    }

    #[test]
    fn tile_matrix_maps_tile_rect_and_depth() {
        let p = place(Vec3::new(0.3, -1.0, 0.2), Vec3::new(1.0, 2.0, 3.0), Vec3::X, 16.0, None, Anchor::Circle);
        for t in 0..16 {
            let (min, max) = p.tile_rect(t);
            let m = p.tile_matrix(t, -5.0, 15.0);
            let world = |x: f32, y: f32, d: f32| p.right * x + p.up * y + p.dir * d;
            let a = m * world(min.x, min.y, -5.0).extend(1.0);
            let b = m * world(max.x, max.y, 15.0).extend(1.0);
            assert!((a - Vec4::new(-1.0, -1.0, 0.0, 1.0)).abs().max_element() < 1e-4, "{a}");
            assert!((b - Vec4::new(1.0, 1.0, 1.0, 1.0)).abs().max_element() < 1e-4, "{b}");
            // the tile's centre is in tile t by equations 3.2/3.3
            let c = world(0.5 * (min.x + max.x), 0.5 * (min.y + max.y), 0.0);
            assert_eq!(tile_of(p.uv(c)).0, t);
        }
    }

    #[test]
    fn atlas_layout_packs_without_overlap() {
        let (w, h, pos) = atlas_layout(&THESIS_RESOLUTIONS).unwrap();
        assert_eq!((w, h), (2048, 1024));
        let mut used = vec![false; (w * h) as usize];
        for (i, p) in pos.iter().enumerate() {
            let r = THESIS_RESOLUTIONS[i];
            assert!(p[0] + r <= w && p[1] + r <= h);
            assert!(p[0] % r == 0 && p[1] % r == 0, "aligned like a buddy block");
            for y in p[1]..p[1] + r {
                for x in p[0]..p[0] + r {
                    assert!(!std::mem::replace(&mut used[(y * w + x) as usize], true), "overlap at {x},{y}");
                }
            }
        }
        assert_eq!(used.iter().filter(|u| **u).count() as u64, texels(&THESIS_RESOLUTIONS));
        assert_eq!(pos[0], [0, 0]);
        assert!(atlas_layout(&[1024, 512, 512, 256, 128, 128, 128, 128, 64, 64, 32, 32, 16, 16, 16, 12]).is_none());
        assert!(atlas_layout(&[1024; 16]).is_none(), "16 x 1024 does not fit in 2048 x 1024");
    }

    #[test]
    fn culling_and_runs() {
        let p = Placement { right: Vec3::X, up: Vec3::Z, dir: Vec3::NEG_Y, origin: Vec2::ZERO, size: 4.0 };
        // tile 12 = bottom-left = light x in [0,1], y in [0,1]
        assert_eq!(p.tile_rect(12), (Vec2::ZERO, Vec2::ONE));
        let boxes = [
            (Vec3::new(0.2, 0.2, 0.0), Vec3::new(0.4, 0.4, 1.0)),
            (Vec3::new(2.2, 0.2, 0.0), Vec3::new(2.4, 0.4, 1.0)),
            (Vec3::new(-1.0, -1.0, 0.0), Vec3::new(5.0, 5.0, 1.0)),
        ];
        assert_eq!(cull(&p, 12, &boxes), vec![0, 2]);
        assert_eq!(cull(&p, 14, &boxes), vec![1, 2]);
        assert_eq!(cull(&p, 0, &boxes), vec![2]);
        assert_eq!(runs(&[0, 1, 2, 5, 6, 9]), vec![(0, 3), (5, 7), (9, 10)]);
        assert!(runs(&[]).is_empty());
    }
}
