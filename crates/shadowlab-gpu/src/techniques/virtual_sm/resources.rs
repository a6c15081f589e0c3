//! `virtual`'s construction, stage 3: the atlas (the physical pool) and the static pool, the
//! per-page copy offsets, the uniform, the request flags, the page table, the pages'
//! view-projections, the per-level sample counts and the readback's staging (requests and the
//! moving chunks' boxes).

use super::setup::Setup;
use super::uniforms::{VirtualParams, MAX_LEVELS};
use crate::{raster, Gpu};

pub(super) struct Resources {
    /// The physical pool: `cols x rows` page slots.
    pub atlas: wgpu::Texture,
    /// `atlas`'s view, made once.
    pub atlas_view: wgpu::TextureView,
    /// The static copies of pages under moving geometry (at least one slot, unused without).
    pub static_atlas: wgpu::Texture,
    /// Per rendered page: its static slot's origin minus its atlas slot's origin (texels).
    pub copy_offsets: wgpu::Buffer,
    pub uniform: wgpu::Buffer,
    /// mark.wgsl's flags and sample counts per page-table entry.
    pub requests: wgpu::Buffer,
    pub page_table: wgpu::Buffer,
    /// Per rendered page: its view-projection (page.wgsl's instance).
    pub page_mats: wgpu::Buffer,
    /// Samples per level, and unresolved (eval.wgsl, the lab's analysis).
    pub counts: wgpu::Buffer,
    /// What `prepare` reads back: the requests, then the moving chunks' boxes.
    pub probe: wgpu::Buffer,
}

impl Resources {
    pub fn new(gpu: &Gpu, s: &Setup, params: &VirtualParams) -> Resources {
        let (pr, p) = (s.page_res, &s.pool);
        let atlas = raster::depth_target(gpu, "virtual.atlas", p.cols * pr, p.rows * pr, 1, wgpu::TextureUsages::empty());
        let static_atlas = raster::depth_target(
            gpu,
            "virtual.static_atlas",
            p.static_cols * pr,
            p.static_rows.max(1) * pr,
            1,
            wgpu::TextureUsages::empty(),
        );
        let slots = (p.cols * p.rows) as u64;
        Resources {
            atlas_view: atlas.create_view(&Default::default()),
            atlas,
            static_atlas,
            copy_offsets: gpu.storage("virtual.copy_offsets", slots * 16),
            uniform: gpu.uniform("virtual.params", params),
            requests: gpu.storage("virtual.requests", s.table_len * 4),
            page_table: gpu.storage("virtual.page_table", s.table_len * 4),
            page_mats: gpu.storage("virtual.page_view_proj", slots * 64),
            counts: gpu.storage("virtual.counts", (MAX_LEVELS as u64 + 1) * 4),
            probe: gpu.storage("virtual.probe", s.table_len * 4 + s.dynamic_chunks as u64 * 24),
        }
    }
}
