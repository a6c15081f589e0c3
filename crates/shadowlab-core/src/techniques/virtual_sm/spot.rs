//! What the light kind decides in `virtual`: the projection into light coordinates, the page
//! windows, the depth, and each page's view-projection.
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
}

/// The mip levels of a spot map: `levels`, at most down to one page (`log2(N) + 1`).
pub fn spot_levels(levels: u32, virtual_res: u32, page_res: u32) -> u32 {
    let n = (virtual_res / page_res).max(1);
    levels.min(n.ilog2() + 1).max(1)
}

impl Clipmap {
    /// The clipmap (directional) or mip chain (spot) of `light`; None for point lights.
    pub fn for_light(
        light: &Light,
        bounds: &Bounds,
        eye: Vec3,
        levels: u32,
        virtual_res: u32,
        page_res: u32,
        extent0: f32,
    ) -> Option<Clipmap> {
        match *light {
            Light::Directional { direction } => Some(Clipmap::new(direction, bounds, eye, levels, virtual_res, page_res, extent0)),
            Light::Spot { position, direction, cone_deg } => {
                Some(Clipmap::spot(position, direction, cone_deg, bounds, levels, virtual_res, page_res))
            }
            Light::Point { .. } => None,
        }
    }

    /// The mip chain of a spot light at `position` shining along `direction`; near and far as
    /// `sm`'s spot maps (far: the farthest corner of `bounds`; near: far / 1000).
    pub fn spot(position: Vec3, direction: Vec3, cone_deg: f32, bounds: &Bounds, levels: u32, virtual_res: u32, page_res: u32) -> Clipmap {
        assert!(page_res.is_power_of_two() && virtual_res % page_res == 0, "page_res: a power of two dividing virtual_res");
        let (right, up, dir) = light_basis(direction);
        let diag = bounds.diagonal().max(1e-6);
        let far = bounds.corners().iter().map(|p| (*p - position).length()).fold(0.0f32, f32::max).max(diag * 1e-3);
        let levels = spot_levels(levels, virtual_res, page_res);
        Clipmap {
            projection: Projection::Persp { position, tan_half: cone_deg.to_radians().tan() },
            right,
            up,
            dir,
            levels,
            virtual_res,
            page_res,
            extent0: 2.0,
            z_near: (far * 1e-3).max(1e-4),
            z_far: far,
            origins: vec![IVec2::ZERO; levels as usize],
        }
    }

    /// Pages a side of level k's window: N (clipmap), or `N / 2^k`, at least 1 (spot).
    pub fn side(&self, k: u32) -> i32 {
        let n = self.pages_per_side() as i32;
        match self.projection {
            Projection::Ortho => n,
            Projection::Persp { .. } => (n >> k).max(1),
        }
    }

    /// The page of level k under global texel coordinates g: `page_of`, clamped to the map for
    /// a spot light.
    pub fn page_at(&self, k: u32, g: Vec2) -> IVec2 {
        let pg = self.page_of(g);
        match self.projection {
            Projection::Ortho => pg,
            Projection::Persp { .. } => pg.clamp(IVec2::ZERO, IVec2::splat(self.side(k) - 1)),
        }
    }

    /// Level-0 light coordinates of p before the texel scale (pages.wgsl `light_coords`).
    pub fn light_coords(&self, p: Vec3) -> Vec2 {
        match self.projection {
            Projection::Ortho => Vec2::new(p.dot(self.right), -p.dot(self.up)),
            Projection::Persp { position, tan_half } => {
                let v = p - position;
                let s = v.dot(self.dir) * tan_half;
                Vec2::new(v.dot(self.right) / s + 1.0, 1.0 - v.dot(self.up) / s)
            }
        }
    }

    /// [`light_coords`](Self::light_coords), None for a point at or behind a spot light's plane.
    pub fn light_coords_in_front(&self, p: Vec3) -> Option<Vec2> {
        match self.projection {
            Projection::Persp { position, .. } if (p - position).dot(self.dir) <= 0.0 => None,
            _ => Some(self.light_coords(p)),
        }
    }

    /// Light depth of p in [0, 1], 0 near the light: linear (directional) or post-projective (spot).
    pub fn depth(&self, p: Vec3) -> f32 {
        let (n, f) = (self.z_near, self.z_far);
        match self.projection {
            Projection::Ortho => (p.dot(self.dir) - n) / (f - n),
            Projection::Persp { position, .. } => {
                let z = (p - position).dot(self.dir);
                ((z - n) / (f - n)) * (f / z)
            }
        }
    }

    /// World size of a level-0 texel (directional), or per unit of light-view depth (spot): the
    /// uniform's `right.w`.
    pub fn texel0_scale(&self) -> f32 {
        match self.projection {
            Projection::Ortho => self.texel(0),
            Projection::Persp { tan_half, .. } => self.texel(0) * tan_half,
        }
    }

    /// World size of a level-0 texel at p (pages.wgsl `texel0_at`).
    pub fn texel0_at(&self, p: Vec3) -> f32 {
        match self.projection {
            Projection::Ortho => self.texel0_scale(),
            Projection::Persp { position, .. } => self.texel0_scale() * (p - position).dot(self.dir),
        }
    }

    /// A spot page's perspective view-projection: the spot's frustum narrowed to the page's
    /// square (NDC y = +1 at its top row), depth post-projective in [0, 1] as [`depth`](Self::depth).
    pub(super) fn spot_page_view_proj(&self, key: PageKey) -> Mat4 {
        let Projection::Persp { position, tan_half } = self.projection else { unreachable!("spot pages only") };
        let s = self.texel(key.level) * self.page_res as f32;
        let (cu, cw, h) = ((key.x as f32 + 0.5) * s, (key.y as f32 + 0.5) * s, 0.5 * s);
        let (n, f) = (self.z_near, self.z_far);
        let row = |a: Vec3| a.extend(-a.dot(position));
        let (rx, ry, rw) = (row(self.right / tan_half), row(self.up / tan_half), row(self.dir));
        let a = f / (f - n);
        let rz = rw * a + Vec4::new(0.0, 0.0, 0.0, -f * n / (f - n));
        let x = (rx + rw * (1.0 - cu)) / h;
        let y = (ry + rw * (cw - 1.0)) / h;
        Mat4::from_cols(x, y, rz, rw).transpose()
    }
}
