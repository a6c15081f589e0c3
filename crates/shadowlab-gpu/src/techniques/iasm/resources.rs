//! `iasm`'s construction, stage 3: the frame uniform, the analysis's statistics (and their
//! delayed readback), the linear shadow buffer, the per-texel counts, the tiles' uniforms and
//! the buffer passes' dummy colour target. (store=atlas adds the depth atlas, atlas.rs.)

use bytemuck::Zeroable;
use shadowlab_core::techniques::iasm::{self as core, TILE_COUNT};

use super::plan::READ_WORDS;
use super::setup::Setup;
use super::tiles::dummy_target;
use super::uniforms::{IasmParams, TILE_STRIDE};
use crate::record::DelayedRead;
use crate::Gpu;

pub(super) struct Resources {
    /// The frame's `IasmParams`.
    pub params_buf: wgpu::Buffer,
    /// The analysis's output (`STATS_WORDS`) and the fit's square after it (`READ_WORDS`).
    pub stats_buf: wgpu::Buffer,
    /// store=buffer: the tiles' depth in the linear per-tile layout.
    pub shadow: wgpu::Buffer,
    /// View samples per texel (the lab's analysis).
    pub counts: wgpu::Buffer,
    /// Each tile's `TileParams`, `TILE_STRIDE` apart.
    pub tile_buf: wgpu::Buffer,
    /// The colour target of the buffer passes (nothing written; sized for the largest tile).
    pub dummy: wgpu::TextureView,
    /// Delayed mode: the previous frame's statistics, read back without a stall.
    pub delayed_read: DelayedRead,
}

impl Resources {
    pub fn new(gpu: &Gpu, s: &Setup) -> Resources {
        let stats_bytes = READ_WORDS as u64 * 4;
        Resources {
            params_buf: gpu.uniform("iasm.params", &IasmParams::zeroed()),
            stats_buf: gpu.storage("iasm.stats", stats_bytes),
            shadow: gpu.storage("iasm.shadow", s.texels * core::TEXEL_BYTES),
            counts: gpu.storage("iasm.counts", s.texels * 4),
            tile_buf: gpu.buffer(&wgpu::BufferDescriptor {
                label: Some("iasm.tiles"),
                size: TILE_STRIDE * TILE_COUNT as u64,
                // STORAGE: bound as read-only storage on lavapipe (crate::quirks)
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            dummy: dummy_target(gpu),
            delayed_read: DelayedRead::new(gpu, "iasm.delayed", stats_bytes),
        }
    }
}
