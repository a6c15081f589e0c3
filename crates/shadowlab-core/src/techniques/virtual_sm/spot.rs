//! What the light kind decides in `virtual`: the projection into light coordinates, the page
//! windows, the depth, and each page's view-projection (point lights' six faces: `cube.rs`).
//!
//! Spot lights: one perspective virtual map of the cone, in the light basis of the spot's
//! direction (`iasm::light_basis`), half-angle = the cone's, so every sample inside the cone
//! lands inside the map. Light coordinates `u = x_ndc + 1`, `w = 1 - y_ndc` in [0, 2] (rows
//! grow downwards), so with `extent0 = 2` the clipmap's texel math holds unchanged: level k has
//! `virtual_res / 2^k` texels a side (a mip chain, as UE5 uses for local lights), its window is
//! the whole level (origin 0, `N / 2^k` pages a side), and a sample picks the level whose texel
//! at its light depth best matches its pixel footprint. Coordinates past the map's edge clamp
//! to it (as `sm`'s clamp-to-edge sampler). Stored depth: post-projective as `sm`'s spot maps,
//! `f (z - n) / ((f - n) z)` for light-view depth z, 0 = near.

use glam::{IVec2, Mat4, Vec2, Vec3, Vec4};

use super::{Clipmap, PageKey};
use crate::light::Light;
use crate::scene::Bounds;
use crate::techniques::iasm::light_basis;

/// How world points become light coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Directional: `(p . right, -p . up)` in world units.
    Ortho,
    /// Spot: perspective from `position` with `tan(half-angle) = tan_half`.
    Persp { position: Vec3, tan_half: f32 },
    /// Point: six 90-degree perspective maps from `position`, one per cube face (`cube.rs`).
    Cube { position: Vec3 },
}

/// The mip levels of a spot map: `levels`, at most down to one page (`log2(N) + 1`).
pub fn spot_levels(levels: u32, virtual_res: u32, page_res: u32) -> u32 {
    let n = (virtual_res / page_res).max(1);
    levels.min(n.ilog2() + 1).max(1)
}

impl Clipmap {
    /// The clipmap (directional), mip chain (spot) or six faces' mip chains (point) of `light`.
    pub fn for_light(light: &Light, bounds: &Bounds, eye: Vec3, levels: u32, virtual_res: u32, page_res: u32, extent0: f32) -> Clipmap {
        match *light {
            Light::Directional { direction } => Clipmap::new(direction, bounds, eye, levels, virtual_res, page_res, extent0),
            Light::Spot { position, direction, cone_deg } => {
                Clipmap::spot(position, direction, cone_deg, bounds, levels, virtual_res, page_res)
            }
            Light::Point { position } => Clipmap::cube(position, bounds, levels, virtual_res, page_res),
        }
    }

    /// The mip chain of a spot light at `position` shining along `direction`; near and far as
    /// `sm`'s spot maps (far: the farthest corner of `bounds`; near: far / 1000).
    pub fn spot(position: Vec3, direction: Vec3, cone_deg: f32, bounds: &Bounds, levels: u32, virtual_res: u32, page_res: u32) -> Clipmap {
        assert!(page_res.is_power_of_two() && virtual_res % page_res == 0, "page_res: a power of two dividing virtual_res");
        let (right, up, dir) = light_basis(direction);
        let far = far_from(position, bounds);
        let levels = spot_levels(levels, virtual_res, page_res);
        Clipmap {
            projection: Projection::Persp { position, tan_half: cone_deg.to_radians().tan() },
            right,
            up,
            dir,
            levels,
            mips: levels,
            virtual_res,
            page_res,
            extent0: 2.0,
            z_near: (far * 1e-3).max(1e-4),
            z_far: far,
            origins: vec![IVec2::ZERO; levels as usize],
        }
    }

    /// The perspective's centre and `tan(half-angle)` (spot, or 1 for a cube face); None for
    /// the orthographic clipmap.
    pub fn persp(&self) -> Option<(Vec3, f32)> {
        match self.projection {
            Projection::Ortho => None,
            Projection::Persp { position, tan_half } => Some((position, tan_half)),
            Projection::Cube { position } => Some((position, 1.0)),
        }
    }

    /// Pages a side of level k's window: N (clipmap), or `N / 2^mip`, at least 1 (spot, cube).
    pub fn side(&self, k: u32) -> i32 {
        let n = self.pages_per_side() as i32;
        match self.projection {
            Projection::Ortho => n,
            _ => (n >> self.mip(k)).max(1),
        }
    }

    /// The page of level k under global texel coordinates g: `page_of`, clamped to the map for
    /// a spot light.
    pub fn page_at(&self, k: u32, g: Vec2) -> IVec2 {
        let pg = self.page_of(g);
        match self.projection {
            Projection::Ortho => pg,
            _ => pg.clamp(IVec2::ZERO, IVec2::splat(self.side(k) - 1)),
        }
    }

    /// Level-0 light coordinates of p before the texel scale, on p's own face (pages.wgsl
    /// `light_coords`).
    pub fn light_coords(&self, p: Vec3) -> Vec2 {
        self.light_coords_face(self.face_of(p), p)
    }

    /// Level-0 light coordinates of p on face f (0 unless a cube).
    pub fn light_coords_face(&self, f: u32, p: Vec3) -> Vec2 {
        let (right, up, dir) = self.axes(f);
        match self.persp() {
            None => Vec2::new(p.dot(right), -p.dot(up)),
            Some((position, tan_half)) => {
                let v = p - position;
                let s = v.dot(dir) * tan_half;
                Vec2::new(v.dot(right) / s + 1.0, 1.0 - v.dot(up) / s)
            }
        }
    }

    /// [`light_coords_face`](Self::light_coords_face), None for a point at or behind the plane
    /// of a perspective face.
    pub fn light_coords_in_front(&self, f: u32, p: Vec3) -> Option<Vec2> {
        match self.persp() {
            Some((position, _)) if (p - position).dot(self.axes(f).2) <= 0.0 => None,
            _ => Some(self.light_coords_face(f, p)),
        }
    }

    /// Light depth of p in [0, 1] on p's own face, 0 near the light: linear (directional) or
    /// post-projective (spot, cube).
    pub fn depth(&self, p: Vec3) -> f32 {
        self.depth_face(self.face_of(p), p)
    }

    /// Light depth of p in face f's projection (pages.wgsl `light_depth`).
    pub fn depth_face(&self, f: u32, p: Vec3) -> f32 {
        let (n, far) = (self.z_near, self.z_far);
        let dir = self.axes(f).2;
        match self.persp() {
            None => (p.dot(dir) - n) / (far - n),
            Some((position, _)) => {
                let z = (p - position).dot(dir);
                ((z - n) / (far - n)) * (far / z)
            }
        }
    }

    /// World size of a level-0 texel (directional), or per unit of light-view depth (spot,
    /// cube): the uniform's `right.w`.
    pub fn texel0_scale(&self) -> f32 {
        match self.persp() {
            None => self.texel(0),
            Some((_, tan_half)) => self.texel(0) * tan_half,
        }
    }

    /// World size of a level-0 texel at p (pages.wgsl `texel0_at`).
    pub fn texel0_at(&self, p: Vec3) -> f32 {
        match self.persp() {
            None => self.texel0_scale(),
            Some((position, _)) => self.texel0_scale() * (p - position).dot(self.axes(self.face_of(p)).2),
        }
    }

    /// A perspective page's view-projection: the spot's (or the page's cube face's) frustum
    /// narrowed to the page's square (NDC y = +1 at its top row), depth post-projective in
    /// [0, 1] as [`depth_face`](Self::depth_face).
    pub(super) fn spot_page_view_proj(&self, key: PageKey) -> Mat4 {
        let (position, tan_half) = self.persp().expect("perspective pages only");
        let (right, up, dir) = self.axes(self.face(key.level));
        let s = self.texel(key.level) * self.page_res as f32;
        let (cu, cw, h) = ((key.x as f32 + 0.5) * s, (key.y as f32 + 0.5) * s, 0.5 * s);
        let (n, f) = (self.z_near, self.z_far);
        let row = |a: Vec3| a.extend(-a.dot(position));
        let (rx, ry, rw) = (row(right / tan_half), row(up / tan_half), row(dir));
        let a = f / (f - n);
        let rz = rw * a + Vec4::new(0.0, 0.0, 0.0, -f * n / (f - n));
        let x = (rx + rw * (1.0 - cu)) / h;
        let y = (ry + rw * (cw - 1.0)) / h;
        Mat4::from_cols(x, y, rz, rw).transpose()
    }
}

/// The distance from `position` to the farthest corner of `bounds` (at least 1e-3 of its
/// diagonal): a perspective map's far plane.
pub(super) fn far_from(position: Vec3, bounds: &Bounds) -> f32 {
    let diag = bounds.diagonal().max(1e-6);
    bounds.corners().iter().map(|p| (*p - position).length()).fold(0.0f32, f32::max).max(diag * 1e-3)
}
