//! CPU half of `virtual`, virtual (page-based) shadow maps after the UE5 design. Directional
//! lights: clipmap levels around the camera, each a virtual map of `virtual_res` texels a side
//! in pages of `page_res` texels; level k covers 2^k times level 0's extent. Spot lights: one
//! perspective virtual map of the cone with a mip chain (level k: `virtual_res / 2^k` texels a
//! side, the same pages), see `spot.rs`. Point lights: six such maps, one per cube face, their
//! mip chains numbered as one list of levels (`cube.rs`); the rest of this file serves all three.
//!
//! Light space (`iasm::light_basis`): `x` = right, `y` = up, depth = distance along the
//! direction the light travels. Global texel coordinates of level k: `gx = x / t_k`,
//! `gy = -y / t_k` (rows grow downwards, like texture rows), `t_k = extent0 2^k / virtual_res`.
//! Page (px, py) of level k holds texels `[px P, (px+1) P) x [py P, (py+1) P)`, P = page_res.
//! Level k's window is the `N x N` pages (N = virtual_res / page_res) starting at its origin,
//! which is snapped to whole pages around the camera, so a page keeps its content (and its
//! cache entry) while the camera moves. The page table slot of a page is
//! `(py mod N) N + (px mod N)` (clipmap wrap: unique inside the window).
//! Stored depth: orthographic, linear, 0 = near the light (spot: post-projective, 0 = near).

mod alloc;
mod cube;
mod lod;
mod spot;
mod statics;
pub use alloc::{with_fallbacks, Allocation, Demand, PageCache, PageKey};
pub use lod::{AutoLod, AUTO_COARSEST, AUTO_FINEST, AUTO_STEP};
pub use spot::{spot_levels, Projection};
pub use statics::{Build, StaticCopies};

use glam::{IVec2, Mat4, Vec2, Vec3, Vec4};

use super::iasm::light_basis;
use crate::scene::Bounds;

/// The clipmap of one directional light (or the mip chain of one spot light, or the six faces'
/// mip chains of one point light) for one view.
#[derive(Clone, Debug, PartialEq)]
pub struct Clipmap {
    /// Orthographic (directional) or the spot's perspective.
    pub projection: Projection,
    pub right: Vec3,
    pub up: Vec3,
    pub dir: Vec3,
    /// Level indices in all: `faces() * mips`.
    pub levels: u32,
    /// Levels per face (clipmap levels or mip levels; `levels` unless a cube).
    pub mips: u32,
    pub virtual_res: u32,
    pub page_res: u32,
    /// World side of level 0 (spot: 2, the NDC side of the map).
    pub extent0: f32,
    /// Light depth range (distance along the light) of the scene, with a margin (spot: the
    /// perspective's near and far planes).
    pub z_near: f32,
    pub z_far: f32,
    /// Per level: global page coordinates of the window's first page (spot: 0).
    pub origins: Vec<IVec2>,
}

impl Clipmap {
    /// The clipmap of a light travelling along `dir` over `bounds`, windows centred on `eye`.
    /// `virtual_res` must be a multiple of `page_res`.
    pub fn new(dir: Vec3, bounds: &Bounds, eye: Vec3, levels: u32, virtual_res: u32, page_res: u32, extent0: f32) -> Clipmap {
        assert!(levels >= 1 && page_res.is_power_of_two() && virtual_res % page_res == 0, "page_res: a power of two dividing virtual_res");
        let (right, up, dir) = light_basis(dir);
        let depths = bounds.corners().map(|c| c.dot(dir));
        let (lo, hi) = depths.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), &d| (a.min(d), b.max(d)));
        let margin = bounds.diagonal().max(1e-6) * 1e-3;
        let mut c = Clipmap {
            projection: Projection::Ortho,
            right,
            up,
            dir,
            levels,
            mips: levels,
            virtual_res,
            page_res,
            extent0,
            z_near: lo - margin,
            z_far: hi + margin,
            origins: Vec::new(),
        };
        c.origins = (0..levels).map(|k| c.origin_around(k, eye)).collect();
        c
    }

    /// Pages per window side.
    pub fn pages_per_side(&self) -> u32 {
        self.virtual_res / self.page_res
    }

    /// Page-table entries (all levels).
    pub fn table_len(&self) -> usize {
        (self.levels * self.pages_per_side() * self.pages_per_side()) as usize
    }

    /// World size of one texel of level k (of its mip: a cube's faces repeat the chain).
    pub fn texel(&self, k: u32) -> f32 {
        self.extent0 * (1u64 << self.mip(k)) as f32 / self.virtual_res as f32
    }

    /// Texels per world unit at level k: `(virtual_res / extent0) 2^-mip` (halving is exact, so
    /// the GPU, given level 0's value, computes the same number).
    pub fn inv_texel(&self, k: u32) -> f32 {
        let mut s = self.virtual_res as f32 / self.extent0;
        for _ in 0..self.mip(k) {
            s *= 0.5;
        }
        s
    }

    /// Global texel coordinates of world point p at level k (continuous), on level k's face.
    pub fn texel_coords(&self, k: u32, p: Vec3) -> Vec2 {
        self.light_coords_face(self.face(k), p) * self.inv_texel(k)
    }

    /// The window origin (in pages) of level k centred on `eye`: the eye's page minus N/2.
    pub fn origin_around(&self, k: u32, eye: Vec3) -> IVec2 {
        let g = self.texel_coords(k, eye) / self.page_res as f32;
        let n = (self.pages_per_side() / 2) as i32;
        IVec2::new(g.x.floor() as i32 - n, g.y.floor() as i32 - n)
    }

    /// The page of global texel coordinates g (continuous) at any level.
    pub fn page_of(&self, g: Vec2) -> IVec2 {
        (g * (1.0 / self.page_res as f32)).floor().as_ivec2()
    }

    /// Whether page `pg` lies in level k's window.
    pub fn in_window(&self, k: u32, pg: IVec2) -> bool {
        let d = pg - self.origins[k as usize];
        let n = self.side(k);
        d.x >= 0 && d.y >= 0 && d.x < n && d.y < n
    }

    /// Page-table index of page `pg` of level k (clipmap wrap).
    pub fn table_index(&self, k: u32, pg: IVec2) -> usize {
        let n = self.pages_per_side() as i32;
        ((k as i32 * n + pg.y.rem_euclid(n)) * n + pg.x.rem_euclid(n)) as usize
    }

    /// The page at table index `i` (inverse of [`table_index`](Self::table_index) inside the window).
    pub fn key_of_index(&self, i: usize) -> PageKey {
        let n = self.pages_per_side() as i32;
        let i = i as i32;
        let (k, sy, sx) = (i / (n * n), (i / n) % n, i % n);
        let o = self.origins[k as usize];
        // the window coordinate d in [0, n) with (o + d) mod n = s
        let x = o.x + (sx - o.x).rem_euclid(n);
        let y = o.y + (sy - o.y).rem_euclid(n);
        PageKey { level: k as u32, x, y }
    }

    /// The pages view sample p marks (as mark.wgsl does): at the level its footprint asks for
    /// (`level_for`), or the first coarser one whose window holds them, the pages under the
    /// corners of the square of `reach` texels around p (the PCF taps after the normal offset);
    /// and the same corners' pages of the coarsest level, so that a sample whose pages fall back
    /// always finds a mapped coarser page. A cube's sample marks only its own face's levels.
    /// Empty where no window holds p.
    pub fn sample_pages(&self, p: Vec3, footprint: f32, scale: f32, reach: f32) -> Vec<PageKey> {
        let corners = |k: u32| {
            let g = self.texel_coords(k, p);
            [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)].map(|(sx, sy)| self.page_at(k, g + Vec2::new(sx, sy) * reach))
        };
        let mut out = Vec::new();
        let face = self.face_of(p);
        let (top, step) = (self.level_index(face, self.mips - 1), self.faces());
        let mut k = self.level_index(face, level_for(footprint, self.texel0_at(p), scale, self.mips));
        while k <= top {
            let c = corners(k);
            if c.iter().all(|pg| self.in_window(k, *pg)) {
                out.extend(c.iter().map(|pg| PageKey { level: k, x: pg.x, y: pg.y }));
                break;
            }
            k += step;
        }
        if k < top {
            out.extend(corners(top).iter().filter(|pg| self.in_window(top, **pg)).map(|pg| PageKey { level: top, x: pg.x, y: pg.y }));
        }
        out.sort();
        out.dedup();
        out
    }

    /// The orthographic view-projection of one page: its light-space square to NDC x/y in
    /// [-1, 1] (NDC y = +1 at the page's top row), depth to [0, 1] as [`depth`](Self::depth).
    pub fn page_view_proj(&self, key: PageKey) -> Mat4 {
        if self.persp().is_some() {
            return self.spot_page_view_proj(key);
        }
        let s = self.texel(key.level) * self.page_res as f32;
        let x0 = key.x as f32 * s;
        let y_top = -(key.y as f32) * s;
        let (cx, cy, h) = (x0 + 0.5 * s, y_top - 0.5 * s, 0.5 * s);
        let dz = self.z_far - self.z_near;
        // rows of the affine map
        let rx = (self.right / h).extend(-cx / h);
        let ry = (self.up / h).extend(-cy / h);
        let rz = (self.dir / dz).extend(-self.z_near / dz);
        Mat4::from_cols(rx, ry, rz, Vec4::new(0.0, 0.0, 0.0, 1.0)).transpose()
    }

    /// Whether page `key` (any level, inside its window or not) overlaps the light-space
    /// rectangle of world box b (closed intervals: touching counts).
    pub fn page_overlaps(&self, key: &PageKey, b: &Bounds) -> bool {
        let Some((lo, hi)) = self.texel_rect(key.level, b) else { return true };
        let (a, z) = (self.page_of(lo), self.page_of(hi));
        (a.x..=z.x).contains(&key.x) && (a.y..=z.y).contains(&key.y)
    }

    /// Pages of level k overlapping the world box b (light-space rectangle of its corners),
    /// limited to the window, in (y, x) order.
    pub fn pages_touching(&self, k: u32, b: &Bounds) -> Vec<PageKey> {
        let n = self.side(k);
        let o = self.origins[k as usize];
        let (p0, p1) = match self.texel_rect(k, b) {
            Some((lo, hi)) => (self.page_of(lo).max(o), self.page_of(hi).min(o + IVec2::splat(n - 1))),
            None => (o, o + IVec2::splat(n - 1)),
        };
        let mut out = Vec::new();
        for y in p0.y..=p1.y {
            for x in p0.x..=p1.x {
                out.push(PageKey { level: k, x, y });
            }
        }
        out
    }

    /// The texel rectangle of level k covered by world box b (its corners' light coordinates),
    /// None where it spans the whole map (a corner behind a perspective map's plane).
    pub fn texel_rect(&self, k: u32, b: &Bounds) -> Option<(Vec2, Vec2)> {
        let (lo, hi) = self.light_rect(self.face(k), b)?;
        let s = self.inv_texel(k);
        Some((lo * s, hi * s))
    }

    /// The light-coordinate rectangle of world box b on face f (see
    /// [`light_coords_face`](Self::light_coords_face)), None where it spans the whole map (a
    /// corner at or behind a perspective map's plane).
    pub fn light_rect(&self, f: u32, b: &Bounds) -> Option<(Vec2, Vec2)> {
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for c in b.corners() {
            let g = self.light_coords_in_front(f, c)?;
            lo = lo.min(g);
            hi = hi.max(g);
        }
        Some((lo, hi))
    }
}

/// The level a view sample asks for: `ceil(log2(footprint / t0) + bias)` (UE5's resolution
/// LOD bias), clamped to the levels; computed without a logarithm so that the GPU gives the
/// same answer: the smallest integer L >= 0 with `t0 2^L >= footprint 2^bias`
/// (`footprint` = the pixel's world size at the sample; `scale` = [`bias_scale`]`(bias)`).
pub fn level_for(footprint: f32, texel0: f32, scale: f32, levels: u32) -> u32 {
    let f = footprint * scale;
    let (mut l, mut t) = (0u32, texel0);
    while l + 1 < levels && t < f {
        t *= 2.0;
        l += 1;
    }
    l
}

/// `2^bias`, the footprint's factor for a resolution bias (negative: finer levels).
pub fn bias_scale(bias: f32) -> f32 {
    bias.exp2()
}

/// World size of one pixel per unit of distance from the eye: `2 tan(fov_y / 2) / height`.
pub fn pixel_angle(fov_y_deg: f32, height: u32) -> f32 {
    2.0 * (fov_y_deg.to_radians() * 0.5).tan() / height as f32
}

#[cfg(test)]
mod cube_tests;
#[cfg(test)]
mod spot_tests;
#[cfg(test)]
mod tests;
