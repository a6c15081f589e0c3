//! Point lights in `virtual`: six perspective virtual maps, one per cube face, each a 90-degree
//! square frustum (`tan(half-angle) = 1`) with the spot's mip chain (`spot.rs`). Level index
//! `k = mip * 6 + face`: the page table, the pool, the allocation and the cache see the six
//! faces' mip chains as one list of levels, so the faces share one pool and its priority
//! (coarser mips first, whatever the face); one level coarser is `k + 6` (`faces()`).
//! A sample uses the face of its major axis from the light (`cube::face_of`, `cube`'s faces
//! and their order; the light basis of each face is `iasm::light_basis` of its axis, as a
//! spot's); a PCF kernel that reaches past the face's edge clamps to it, as a spot map does (no
//! lookup across faces).

use glam::{IVec2, Vec3};

use super::spot::{far_from, spot_levels};
use super::{Clipmap, Projection};
use crate::scene::Bounds;
use crate::techniques::cube::{face_of, FACES};
use crate::techniques::iasm::light_basis;

impl Clipmap {
    /// The six faces' mip chains of a point light at `position`; near and far as a spot's.
    pub fn cube(position: Vec3, bounds: &Bounds, levels: u32, virtual_res: u32, page_res: u32) -> Clipmap {
        assert!(page_res.is_power_of_two() && virtual_res % page_res == 0, "page_res: a power of two dividing virtual_res");
        let (right, up, dir) = light_basis(FACES[0].n);
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
            Projection::Cube { position } => face_of(p - position) as u32,
            _ => 0,
        }
    }

    /// Right, up and travel direction of face f (the light's basis unless a cube).
    pub fn axes(&self, f: u32) -> (Vec3, Vec3, Vec3) {
        match self.projection {
            Projection::Cube { .. } => light_basis(FACES[f as usize].n),
            _ => (self.right, self.up, self.dir),
        }
    }
}
