//! `virtual`'s struct shared with WGSL: `VirtualParams` (pages.wgsl, the prelude of mark.wgsl
//! and eval.wgsl), its part fixed at creation and its part placed every frame.

use bytemuck::{Pod, Zeroable};
use shadowlab_core::techniques::virtual_sm::{Clipmap, Projection};

use super::params::VirtualSettings;

pub(super) const PAGES_WGSL: &str = include_str!("pages.wgsl");

/// Levels the uniform holds (WGSL `origins`).
pub const MAX_LEVELS: usize = 24;

/// WGSL `VirtualParams` (pages.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VirtualParams {
    /// xyz: light x axis; w: world size of a level-0 texel (spot: per unit of light depth).
    pub right: [f32; 4],
    /// xyz: light y axis; w: level-0 texels per world unit.
    pub up: [f32; 4],
    /// xyz: light direction; w: light depth of depth 0.
    pub dir: [f32; 4],
    /// x: light depth of depth 1, y: pixel angle, z: 2^resolution_bias, w: marking reach (texels).
    pub view: [f32; 4],
    /// levels, pages per side, page side, atlas columns.
    pub dims: [u32; 4],
    /// bias, slope_bias, normal_offset, max_slope.
    pub bias: [f32; 4],
    /// x: PCF width, y: projection (0 orthographic, 1 spot, 2 cube), z: mips per face, w: faces.
    pub pcf: [u32; 4],
    /// Spot, cube: xyz position, w tan(half-angle) (1 for a cube face).
    pub spot: [f32; 4],
    /// Cube: each face's right, up and travel direction (`Clipmap::axes`), 3 per face.
    pub face_axes: [[f32; 4]; 18],
    /// xy: window origins per level (pages).
    pub origins: [[i32; 4]; MAX_LEVELS],
}

impl VirtualParams {
    /// The part fixed at creation: dims (`n` pages per side, `cols` atlas columns), bias, PCF,
    /// projection, the spot's or cube's position and the cube's face axes; the rest zero.
    pub(super) fn zeroed_for(p: &VirtualSettings, proto: &Clipmap, n: u32, page_res: u32, cols: u32) -> VirtualParams {
        let levels = proto.levels;
        let mut v: VirtualParams = bytemuck::Zeroable::zeroed();
        v.dims = [levels, n, page_res, cols];
        v.bias = p.bias.packed();
        v.pcf = [p.pcf, 0, proto.mips, proto.faces()];
        if let Some((position, tan_half)) = proto.persp() {
            v.pcf[1] = if matches!(proto.projection, Projection::Cube { .. }) { 2 } else { 1 };
            v.spot = position.extend(tan_half).into();
        }
        for f in 0..proto.faces() {
            let (r, u, d) = proto.axes(f);
            for (i, a) in [r, u, d].iter().enumerate() {
                v.face_axes[3 * f as usize + i] = a.extend(0.0).into();
            }
        }
        v
    }

    /// The part placed every frame, from this frame's clipmap `c`: axes, depth range, the view's
    /// `pixel_angle`, `bias_scale`, the marking `reach` and the levels' window origins.
    pub(super) fn place(&mut self, c: &Clipmap, pixel_angle: f32, bias_scale: f32, reach: f32) {
        self.right = c.right.extend(c.texel0_scale()).into();
        self.up = c.up.extend(c.inv_texel(0)).into();
        self.dir = c.dir.extend(c.z_near).into();
        self.view = [c.z_far, pixel_angle, bias_scale, reach];
        // (a perspective map's origins are all 0: WGSL reads only the clipmap's, at most 24)
        for (k, o) in c.origins.iter().take(MAX_LEVELS).enumerate() {
            self.origins[k] = [o.x, o.y, 0, 0];
        }
    }
}
