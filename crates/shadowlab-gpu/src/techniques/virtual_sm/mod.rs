//! `virtual`: virtual (page-based) shadow maps for directional, spot and point lights, after
//! UE5's design. Directional: clipmap levels around the camera, each a virtual map of
//! `virtual_res` texels a side in pages of `page_res`. Spot: one perspective virtual map of the
//! cone with a mip chain (level k: `virtual_res / 2^k` texels a side) in the same pages. Point:
//! six such maps, one per cube face (90 degrees each), sharing the page table's list of levels
//! and the pool; a PCF kernel clamps at its face's edge (no lookup across faces). Only the pages
//! view samples need are rendered, into slots of one Depth32Float atlas (the physical pool,
//! `pool_mib`), and kept across frames while nothing moved over them. The CPU half (level
//! geometry, projections, page math, the pool) is `shadowlab_core::techniques::virtual_sm`.
//! (The folder is `virtual_sm`: `virtual` is a Rust keyword, and `vsm` is variance shadow
//! maps.) Stored depth: 0 = near; linear (directional) or post-projective (spot, as `sm`).
//!
//! Per frame: `prepare` marks the requested pages on the GPU (mark.wgsl), reads the flags and
//! per-page sample counts back (one stall, `virtual.readback`), and allocates slots on the CPU
//! in a priority order (coarse levels first, then the pages more samples read; a full pool makes
//! the finest pages fall back one level at a time, counted); `render` draws
//! the new pages, each with its own frustum (orthographic, or the spot's narrowed) into its slot, with the scene's chunks
//! culled per page; `evaluate` looks every PCF tap up through the page table (eval.wgsl).
//!
//! Static/dynamic split (UE5's): in scenes with moving geometry, a page that moving chunks lie
//! over also keeps a copy of its static geometry alone in a second, smaller atlas (the static
//! pool, `static_share` of the pool). When the moving geometry sweeps over the page again it
//! is rebuilt from that copy (copy.wgsl) plus the moving chunks, not from all its geometry.
//!
//! Files: `params.rs` the parameter table; `uniforms.rs` the struct shared with WGSL;
//! construction in stages, `setup.rs` (the settings checked, the pool's shape) then
//! `resources.rs` (textures and buffers) then each pass's pipelines, then the culling chunks
//! (`draw.rs`, bounded on the GPU by `bounds.rs`); per frame `mark.rs` (marking and the
//! readback), `allocate.rs` (the pages on the CPU), `render.rs` (the page passes), `eval.rs`;
//! `report.rs` the report.

mod allocate;
mod bounds;
mod draw;
mod eval;
mod mark;
mod params;
mod render;
mod report;
mod resources;
mod setup;
mod uniforms;

use shadowlab_core::light::Light;
use shadowlab_core::params::{Auto, ParamSet, ParamTable};
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::virtual_sm::{
    bias_scale, pixel_angle, Allocation, AutoLod, Build, Clipmap, PageCache, PageKey, StaticCopies,
};

use allocate::Pages;
use draw::Chunks;
pub use draw::{CHUNK_TRIANGLES, DYNAMIC_CHUNK_TRIANGLES};
use eval::EvalPass;
use mark::MarkPass;
pub use params::*;
use render::PagePass;
use resources::Resources;
use setup::Setup;
pub use uniforms::{VirtualParams, MAX_LEVELS};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("virtual_sm/mark.wgsl", mark::source()),
        ("virtual_sm/eval.wgsl", eval::source()),
        ("virtual_sm/page.wgsl", render::page_source()),
        ("virtual_sm/copy.wgsl", render::COPY_WGSL.to_string()),
    ]
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "virtual",
    summary: "virtual shadow maps: clipmap levels (spot: one map's mip chain; point: six faces' chains) of 16K virtual texels in 128^2 pages; only the pages view samples need are rendered, cached across frames",
    cost: "a marking pass, one readback (a sync), per new page one atlas viewport with culled chunks; N^2 page-table lookups per pixel",
    quality: "about one texel per pixel everywhere (resolution_bias); auto picks the finest bias whose pages fit the pool each frame; a fixed bias that overfills the pool falls back to coarser pages (reported)",
    source: "Epic Games, Unreal Engine 5 virtual shadow maps (2021); clipmaps: Tanner, Migdal, Jones 1998",
    lights: &["directional", "spot", "point"],
    params: ParamTable::of::<VirtualSettings>(),
    stalls: "virtual.readback: the page requests read back for the CPU allocation (every frame; with resolution_bias=auto once more per quarter step coarser while the pages do not fit the pool)",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(VirtualShadows::new(gpu, scene, &VirtualSettings::from_values(p), light)?)),
};

pub struct VirtualShadows {
    /// What creation planned (setup.rs): the light, the page geometry, the pool's shape.
    setup: Setup,
    /// The uniform: its fixed part from creation, this frame's placement from `prepare`.
    params: VirtualParams,
    /// The pages on the CPU: the last frame's clipmap, the pool, the allocation, the counters.
    pages: Pages,
    /// The culling chunks, the moving ones bounded every frame.
    chunks: Chunks,
    res: Resources,
    mark: MarkPass,
    render: PagePass,
    eval: EvalPass,
    /// `resolution_bias=auto`'s state across frames.
    auto: AutoLod,
    /// The bias the last frame used and its marking passes.
    last_lod: (f32, u32),
}

impl VirtualShadows {
    /// In stages: the settings checked and the pool planned (setup.rs; settings that break
    /// [`VirtualSettings`]'s rules are an error), the textures and buffers (resources.rs), the
    /// passes' pipelines and bind groups, the culling chunks (bounded on the GPU).
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &VirtualSettings, light: &Light) -> Result<VirtualShadows, GpuError> {
        let setup = setup::plan(gpu, scene, p, light)?;
        let params = VirtualParams::zeroed_for(p, &setup.proto, setup.pages_per_side, setup.page_res, setup.pool.cols);
        let res = Resources::new(gpu, &setup, &params);
        let render = PagePass::new(gpu, scene, setup.page_res, &res);
        let mark = MarkPass::new(gpu);
        let eval = EvalPass::new(gpu);
        let chunks = Chunks::new(gpu, scene, setup.split, &setup.proto)?;
        let last_lod = (0.0, 0);
        Ok(VirtualShadows { pages: Pages::new(&setup), setup, params, chunks, res, mark, render, eval, auto: AutoLod::default(), last_lod })
    }

    /// The clipmap of the last frame.
    pub fn clipmap(&self) -> Option<&Clipmap> {
        self.pages.clipmap.as_ref()
    }

    /// The last frame's allocation (mapped, rendered, cached, fallen-back pages).
    pub fn allocation(&self) -> &Allocation {
        &self.pages.alloc
    }

    /// How each page of the last frame's `allocation().render` was built (drawn whole, or from
    /// a static copy).
    pub fn builds(&self) -> &[Build] {
        &self.pages.builds
    }

    /// The static copies of pages under moving geometry.
    pub fn statics(&self) -> &StaticCopies {
        &self.pages.statics
    }

    /// The page pool and its resident pages.
    pub fn cache(&self) -> &PageCache {
        &self.pages.cache
    }

    /// Resident pages the last frame dropped because a moving chunk swept over them.
    pub fn invalidated(&self) -> usize {
        self.pages.invalidated
    }

    /// The pages requested in the last frame (priority order, from the GPU's marks).
    pub fn requested(&self) -> &[PageKey] {
        &self.pages.requested
    }

    /// Marks the pages at resolution bias `bias` and reads them back (mark.rs).
    fn mark_at(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, c: &Clipmap, bias: f32) -> Vec<u32> {
        let angle = pixel_angle(f.camera.fov_y_deg, f.gbuffer.height);
        self.params.place(c, angle, bias_scale(bias), self.setup.reach);
        rec.write_buffer(&self.res.uniform, 0, bytemuck::bytes_of(&self.params));
        self.mark.record(gpu, f, rec, &self.res, c, self.chunks.dynamic.as_ref())
    }

    /// `resolution_bias=auto`: marks from the bias [`AutoLod`] starts at, one quarter step
    /// coarser each time the requested pages do not fit the pool.
    fn mark_auto(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, c: &Clipmap) -> Vec<u32> {
        let slots = self.pages.cache.slots() as usize;
        let requested = |probe: &[u32]| probe[..c.table_len()].iter().filter(|w| **w & 1 != 0).count();
        let mut bias = self.auto.first();
        let mut probe = self.mark_at(gpu, f, rec, c, bias);
        let mut marks = 1;
        while let Some(coarser) = AutoLod::after(bias, requested(&probe), slots) {
            bias = coarser;
            probe = self.mark_at(gpu, f, rec, c, bias);
            marks += 1;
        }
        self.auto.chose(bias, requested(&probe), slots);
        self.last_lod = (bias, marks);
        probe
    }

    /// Forgets the pages over world box `b` at every level (moving geometry); returns how many
    /// resident pages were dropped.
    pub fn invalidate_box(&mut self, b: &Bounds) -> usize {
        self.pages.invalidate_box(self.setup.levels, b)
    }
}

impl Technique for VirtualShadows {
    /// Marking on the GPU and one readback (mark.rs), the allocation and page table on the CPU
    /// (allocate.rs).
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let s = &self.setup;
        let c = Clipmap::for_light(&s.light, &f.scene.bounds, f.camera.position, s.levels_param, s.virtual_res, s.page_res, s.extent0);
        let probe = match s.lod {
            Auto::Fixed(b) => {
                self.last_lod = (b as f32, 1);
                self.mark_at(gpu, f, rec, &c, b as f32)
            }
            Auto::Auto => self.mark_auto(gpu, f, rec, &c),
        };
        let t0 = web_time::Instant::now();
        let (flags, boxes) = probe.split_at(c.table_len());
        // a chunk that moved invalidates the resident pages its old and new boxes cover
        let swept = self.chunks.update(boxes, &c);
        self.pages.invalidate_swept(&c, &swept);
        let w = self.pages.allocate(&self.setup, &c, flags, &self.chunks);
        rec.write_buffer(&self.res.page_table, 0, bytemuck::cast_slice(&w.table));
        rec.write_buffer(&self.res.page_mats, 0, bytemuck::cast_slice(&w.mats));
        if !w.offsets.is_empty() {
            rec.write_buffer(&self.res.copy_offsets, 0, bytemuck::cast_slice(&w.offsets));
        }
        self.pages.finish(c);
        rec.cpu("virtual.allocate", t0.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// The new pages (render.rs).
    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pages.triangles_drawn = self.render.render(f, rec, &self.pages, &self.chunks, &self.res, &self.setup.pool);
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval.record(gpu, f, rec, &self.res, false);
        Ok(())
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.eval.record(gpu, f, rec, &self.res, true);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let mut r = report::report(gpu, &self.setup, &self.pages, &self.res.counts);
        r.counters.insert("resolution_bias".into(), self.last_lod.0 as f64);
        r.counters.insert("resolution_bias_marks".into(), self.last_lod.1 as f64);
        r
    }
}
