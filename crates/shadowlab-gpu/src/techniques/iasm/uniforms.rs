//! `iasm`'s structs shared with WGSL: the frame's `IasmParams` (params.wgsl, the prelude of
//! analysis.wgsl, eval.wgsl, eval_atlas.wgsl and probe.wgsl) and a tile's `TileParams`
//! (render.wgsl, atlas.wgsl).

use bytemuck::{Pod, Zeroable};

pub(super) const PARAMS_WGSL: &str = include_str!("params.wgsl");

/// Bytes between the tiles' `TileParams` in the tile uniform buffer (each bound at its offset,
/// which the uniform offset alignment rounds up to 256).
pub(super) const TILE_STRIDE: u64 = 256;

/// WGSL `IasmParams` (params.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct IasmParams {
    pub right: [f32; 4],
    pub up: [f32; 4],
    pub dir: [f32; 4],
    pub imp: [f32; 4],
    pub res: [u32; 16],
    pub off: [u32; 16],
    pub near: [f32; 16],
    pub far: [f32; 16],
    /// store=atlas: top-left corner of each tile's square, x | y << 16.
    pub slot: [u32; 16],
}

/// WGSL `TileParams` (render.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct TileParams {
    pub view_proj: [[f32; 4]; 4],
    pub tile: [u32; 4],
}
