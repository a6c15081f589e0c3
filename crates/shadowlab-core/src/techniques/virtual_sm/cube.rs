//! Point lights in `virtual`: six perspective virtual maps, one per cube face, each a 90-degree
//! square frustum (`tan(half-angle) = 1`) with the spot's mip chain (`spot.rs`). Level index
//! `k = mip * 6 + face`: the page table, the pool, the allocation and the cache see the six
//! faces' mip chains as one list of levels, so the faces share one pool and its priority
//! (coarser mips first, whatever the face); one level coarser is `k + 6` (`faces()`).
//! A sample uses the face of its major axis from the light (ties to the lower axis: x, y, z),
//! in the order of [`CUBE_DIRS`]; a PCF kernel that reaches past the face's edge clamps to
//! it, as a spot map does (no lookup across faces).

use glam::{IVec2, Vec3};

use super::spot::{far_from, spot_levels};
use super::{Clipmap, Projection};
use crate::scene::Bounds;
use crate::techniques::iasm::light_basis;

/// Face directions (the light travels along them): +x, -x, +y, -y, +z, -z.
pub const CUBE_DIRS: [Vec3; 6] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

/// The face of direction v from the light: its major axis (ties to x, then y), the sign picks
/// the positive or negative face (pages.wgsl `face_of` does the same comparisons).
pub fn cube_face(v: Vec3) -> u32 {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        if v.x >= 0.0 {
            0
        } else {
            1
        }
    } else if a.y >= a.z {
        if v.y >= 0.0 {
            2
        } else {
            3
        }
    } else if v.z >= 0.0 {
        4
    } else {
        5
    }
}

impl Clipmap {
    /// The six faces' mip chains of a point light at `position`; near and far as a spot's.
    pub fn cube(position: Vec3, bounds: &Bounds, levels: u32, virtual_res: u32, page_res: u32) -> Clipmap {
        assert!(page_res.is_power_of_two() && virtual_res % page_res == 0, "page_res: a power of two dividing virtual_res");
        let (right, up, dir) = light_basis(CUBE_DIRS[0]);
        let far = far_from(position, bounds);
        let mips = spot_levels(levels, virtual_res, page_res);
        Clipmap {
            projection: Projection::Cube { position },
            right,
            up,
            dir,
            levels: 6 * mips,
            mips,
            virtual_res,
            page_res,
            extent0: 2.0,
            z_near: (far * 1e-3).max(1e-4),
            z_far: far,
            origins: vec![IVec2::ZERO; 6 * mips as usize],
        }
    }

    /// Faces: 6 for a point light, 1 otherwise.
    pub fn faces(&self) -> u32 {
        self.levels / self.mips
    }

    /// The mip (clipmap level) of level index k.
    pub fn mip(&self, k: u32) -> u32 {
        k / self.faces()
    }

    /// The face of level index k (0 unless a cube).
    pub fn face(&self, k: u32) -> u32 {
        k % self.faces()
    }

    /// Level index of `mip` on face f.
    pub fn level_index(&self, f: u32, mip: u32) -> u32 {
        mip * self.faces() + f
    }

    /// The face whose map holds world point p (0 unless a cube).
    pub fn face_of(&self, p: Vec3) -> u32 {
        match self.projection {
            Projection::Cube { position } => cube_face(p - position),
            _ => 0,
        }
    }

    /// Right, up and travel direction of face f (the light's basis unless a cube).
    pub fn axes(&self, f: u32) -> (Vec3, Vec3, Vec3) {
        match self.projection {
            Projection::Cube { .. } => light_basis(CUBE_DIRS[f as usize]),
            _ => (self.right, self.up, self.dir),
        }
    }
}
