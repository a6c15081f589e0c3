//! `iasm`: Irregular Adaptive Shadow Maps (seed 001, chapter 3) for directional lights. One
//! orthographic light square ahead of the camera (the camera on its inscribed circle), split
//! into 4x4 tiles of equal area; a compute pass sums each tile's view-sample importance
//! (equation 3.1) and light-depth range; the CPU ranks the tiles and hands out a fixed set of 16
//! resolutions by rank; every non-empty tile is rasterized with its own frustum (culled chunks
//! of the scene) into one linear storage buffer by atomic max on the inverted depth
//! (Listing 3.1, `store=buffer`) or into its square of a depth atlas (`store=atlas`, the
//! default: faster here, see DEFAULT_STORE); the evaluation finds tile and texel by equations
//! 3.2-3.5. Depth z = (light depth - near_t) / (far_t - near_t), linear, 0 = the tile's near
//! plane (nearest the light); the buffer stores the bits of 1 - z (cleared 0 reads z = 1), the
//! atlas stores z (cleared to 1). A cleared texel is lit.
//! CPU logic (placement, ranking, layout, indices, culling) is in `shadowlab_core::techniques::iasm`.
//! Stage names (timing keys): `iasm.fit` (fit=view: the samples' bounds and the square, on the
//! GPU), `iasm.importance` (analysis pass), `iasm.readback` (waiting for and mapping the 16
//! tiles' stats and the fitted square: the sync cost, one a frame), `iasm.shadows.clear`,
//! `iasm.shadows.tNN` (tile NN), `iasm.evaluate`.
//!
//! Files: `params.rs` the parameter table; `uniforms.rs` the structs shared with WGSL;
//! construction in stages, `setup.rs` (the settings read and checked, the chunks' boxes) then
//! `resources.rs` (buffers) then each pass's pipelines; `plan.rs` the per-frame plan; the
//! passes `chunks.rs` (bounds, once), `fit.rs` (fit=view), `analysis.rs` (importance),
//! `tiles.rs` (store=buffer) or `atlas.rs` (store=atlas), `eval.rs`, `probe.rs` (tests);
//! `images.rs` the report.

mod analysis;
mod atlas;
mod chunks;
mod eval;
mod fit;
mod images;
mod params;
pub(crate) mod plan;
mod probe;
mod resources;
mod setup;
mod tiles;
mod uniforms;

use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamSet, ParamTable};
use shadowlab_core::techniques::iasm::{self as core, Placement, THESIS_RESOLUTIONS, TILE_COUNT};

use analysis::AnalysisPass;
use atlas::{Atlas, AtlasPass};
pub(crate) use chunks::BOUNDS_WGSL;
use eval::EvalPass;
use fit::ViewFit;
pub use fit::{FitParams, FitSource, FIT_BYTES};
pub use params::*;
use plan::{Plan, TileStats, READ_WORDS, STATS_WORDS};
use resources::Resources;
use setup::Setup;
use tiles::TilePass;
pub use uniforms::{IasmParams, TileParams};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::{FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("iasm/analysis.wgsl", analysis::source()),
        ("iasm/render.wgsl", tiles::source()),
        ("iasm/eval.wgsl", eval::source()),
        ("iasm/bounds.wgsl", chunks::source()),
        ("iasm/probe.wgsl", probe::source()),
        ("iasm/atlas.wgsl", atlas::source()),
        ("iasm/eval_atlas.wgsl", eval::atlas_source()),
        ("iasm/fit.wgsl", fit::source()),
    ]
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "iasm",
    summary:
        "Irregular Adaptive Shadow Maps: 4x4 tiles on the square fitted to the view samples (or the thesis's fixed one ahead of the camera), resolutions 1x1024..4x16 by importance rank, in a depth atlas (default) or the thesis's linear buffer",
    cost: "importance pass + 512-byte readback, up to 16 culled tile passes (atlas: depth test; buffer: atomic max), 1 fetch per pixel",
    quality: "resolution follows the camera; tile seams where neighbours differ (four-tile corners, thesis Fig. 4.4)",
    source: "seed 001 (IASM thesis) chapter 3",
    lights: &["directional"],
    params: ParamTable::of::<IasmSettings>(),
    stalls: "iasm.readback: the tile statistics are read back for the plan, with fit=view's square (placed on the GPU) in the same readback; delayed=true plans with the previous frame's statistics and square, read back without a stall (a sync only on the first frame, or when the previous frame has not finished)",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Iasm::new(gpu, scene, &IasmSettings::from_values(p), light)?)),
};

pub struct Iasm {
    /// The settings as read and what creation derived from them (setup.rs).
    setup: Setup,
    pub placement: Placement,
    pub plan: Plan,
    pub atlas: Option<Atlas>,
    /// `fit=view`: the square from the view samples' bounds (None: the thesis's fixed rule).
    fit: Option<ViewFit>,
    /// Delayed: the analysis of the previous frame is in `stats_buf`, made over `analysed`.
    pending: bool,
    analysed: Placement,
    /// Delayed: this frame's own placement, analysed after the shadows for the next frame.
    current: Placement,
    /// The parameters this frame was evaluated with (the analysis pass evaluates with them
    /// again; delayed mode has overwritten the buffer for the next frame by then).
    evaluated: Option<IasmParams>,
    res: Resources,
    tiles: TilePass,
    analysis: AnalysisPass,
    eval: EvalPass,
    /// store=atlas: the atlas's tile passes and evaluation (beside `atlas`).
    atlas_pass: Option<AtlasPass>,
}

impl Iasm {
    /// In stages: the settings read and checked (setup.rs), the buffers (resources.rs) and the
    /// atlas, then the passes' pipelines and bind groups.
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &IasmSettings, light: &Light) -> Result<Iasm, GpuError> {
        let setup = setup::plan(gpu, scene, p, light)?;
        let res = Resources::new(gpu, &setup);
        let atlas = setup.atlas.as_ref().map(|l| Atlas::new(gpu, l));
        let tiles = TilePass::new(gpu, scene, &res.tile_buf, &res.shadow);
        let analysis = AnalysisPass::new(gpu);
        let eval = EvalPass::buffer(gpu);
        let atlas_pass = atlas.is_some().then(|| AtlasPass::new(gpu, &[&tiles.layout, &scene.layout], scene.has_cutouts));
        let fit = setup.fit_margin.map(|margin| {
            let (params, stats) = (&res.params_buf, &res.stats_buf);
            ViewFit::new(gpu, setup.light_dir, margin, 1e-3 * setup.size, setup.snap, setup.k <= 0.0, params, stats)
        });
        Ok(Iasm {
            placement: setup.basis,
            plan: Plan::default(),
            atlas,
            fit,
            pending: false,
            analysed: setup.basis,
            current: setup.basis,
            evaluated: None,
            res,
            tiles,
            analysis,
            eval,
            atlas_pass,
            setup,
        })
    }

    pub fn size(&self) -> f32 {
        self.setup.size
    }

    /// The uniform of this frame (placement and plan).
    pub fn params(&self) -> IasmParams {
        let (s, p) = (&self.setup, &self.placement);
        let k = if s.k > 0.0 { s.k } else { 0.5 * p.size };
        let res = std::array::from_fn(|t| if self.plan.empty[t] { 0 } else { self.plan.res[t] });
        let mut slot = [0; TILE_COUNT];
        if let Some(a) = &self.atlas {
            for (rank, &t) in self.plan.order.iter().enumerate() {
                slot[t] = a.slots[rank][0] | a.slots[rank][1] << 16;
            }
        }
        IasmParams {
            right: p.right.extend(p.origin.x).into(),
            up: p.up.extend(p.origin.y).into(),
            dir: p.dir.extend(p.size).into(),
            imp: [s.m, k, s.bias, s.normal_offset],
            res,
            off: self.plan.off,
            near: self.plan.near,
            far: self.plan.far,
            slot,
        }
    }

    /// Ranks, assigns, lays out, sets planes and culls (thesis 3.4, 3.5) from `stats` (plan.rs).
    pub fn make_plan(&mut self, stats: TileStats) {
        let s = &self.setup;
        self.plan = plan::make_plan(stats, &self.placement, &s.boxes, s.chunk, s.triangles);
    }

    /// The GPU's texel index and tile (equations 3.2-3.5 in eval.wgsl) of buffer coordinates
    /// `uvs` for resolutions `res` (offsets accumulated from them). For tests.
    pub fn probe_indices(&self, gpu: &Gpu, res: &[u32; TILE_COUNT], uvs: &[glam::Vec2]) -> Vec<(u32, u32)> {
        probe::probe_indices(gpu, self.params(), res, uvs)
    }

    /// The thesis's square for the camera of `f` (and `fit=view`'s when no sample was
    /// evaluated).
    fn fixed_placement(&self, f: &FrameInputs) -> Placement {
        let (s, cam) = (&self.setup, &f.camera);
        let forward = (cam.target - cam.position).normalize_or_zero();
        let min_res = *THESIS_RESOLUTIONS.iter().min().unwrap_or(&16) as f32;
        let step = s.snap.then_some(s.size / core::TILES_PER_SIDE as f32 / min_res);
        core::place(s.light_dir, cam.position, forward, s.size, step, s.anchor)
    }

    /// Records the analysis of `f` over `self.placement`, with `fit=view` placing the square on
    /// the GPU first (over `f`'s samples): `IasmParams` and the statistics (and the square
    /// after them) in `stats_buf`.
    fn analyse(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, fit_first: bool) {
        let (params, stats) = (&self.res.params_buf, &self.res.stats_buf);
        self.analysis.clear(rec, &self.params(), params, stats);
        if let Some(v) = self.fit.as_ref().filter(|_| fit_first) {
            v.record(gpu, f, rec);
        }
        self.analysis.dispatch(gpu, f, rec, params, stats);
    }

    /// The square read back after the statistics in `words` (`fit=view`, from `source`'s
    /// samples), or the fixed one when there is none.
    fn square(&mut self, f: &FrameInputs, words: &[u32], source: FitSource) -> Placement {
        match self.fit.as_mut().and_then(|v| v.apply(&words[STATS_WORDS..], source)) {
            Some(p) => p,
            None => self.fixed_placement(f),
        }
    }

    /// The evaluation of the store in use and its bind group.
    fn eval_group(&self, gpu: &Gpu, f: &FrameInputs) -> (&EvalPass, wgpu::BindGroup) {
        let (params, counts) = (&self.res.params_buf, &self.res.counts);
        match (&self.atlas, &self.atlas_pass) {
            (Some(a), Some(pass)) => (&pass.eval, pass.eval.group(gpu, f, params, wgpu::BindingResource::TextureView(&a.view), counts)),
            _ => (&self.eval, self.eval.group(gpu, f, params, self.res.shadow.as_entire_binding(), counts)),
        }
    }
}

impl Technique for Iasm {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let words = if self.setup.delayed && self.pending {
            // the previous frame's analysis and its square for this one (recorded after its
            // shadows), without a stall when that frame has finished
            let words = match self.res.delayed_read.take::<u32>(gpu, READ_WORDS) {
                Some(w) => w,
                None => analysis::read_stats(rec, &self.res.stats_buf),
            };
            self.current = self.square(f, &words, FitSource::PreviousFrame);
            // the analysis belongs to the previous frame's square: keep both together, so
            // every tile's planes and resolution describe that tile's region
            self.placement = self.analysed;
            words
        } else {
            // this frame's square and analysis, read back together: the frame's one sync
            self.placement = self.fixed_placement(f);
            self.analyse(gpu, f, rec, true);
            let words = analysis::read_stats(rec, &self.res.stats_buf);
            self.placement = self.square(f, &words, FitSource::ThisFrame);
            self.current = self.placement;
            words
        };
        self.make_plan(TileStats::parse(&words));
        tiles::write_tiles(rec, &self.res.tile_buf, &self.placement, &self.plan);
        rec.write_buffer(&self.res.params_buf, 0, bytemuck::bytes_of(&self.params()));
        self.evaluated = Some(self.params());
        Ok(())
    }

    /// The tiles into the atlas (atlas.rs) or the linear buffer (tiles.rs).
    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        match (&self.atlas, &self.atlas_pass) {
            (Some(a), Some(pass)) => pass.render(rec, f, a, &self.plan, &self.tiles.groups),
            _ => self.tiles.render(rec, f, &self.plan, &self.res.shadow, &self.res.dummy),
        }
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let (pass, group) = self.eval_group(gpu, f);
        pass.evaluate(gpu, f, rec, &group);
        if self.setup.delayed {
            // this frame's analysis, over this frame's square, feeds the next frame (thesis 4.3:
            // copied after the shadows), and with fit=view the square of this frame's samples
            // (placed after the analysis, which keeps this frame's square)
            self.placement = self.current;
            self.analyse(gpu, f, rec, false);
            if let Some(v) = &self.fit {
                v.record(gpu, f, rec);
            }
            self.res.delayed_read.record(rec, &self.res.stats_buf);
            self.analysed = self.current;
            self.pending = true;
        }
        Ok(())
    }

    /// The evaluation again with the view samples counted per texel. In delayed mode the tile
    /// planes the frame was evaluated with are the previous analysis's: they are still set
    /// (the next frame's are written in its `prepare`).
    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        if let Some(p) = self.evaluated {
            rec.write_buffer(&self.res.params_buf, 0, bytemuck::bytes_of(&p));
        }
        let (pass, group) = self.eval_group(gpu, f);
        pass.count(gpu, f, rec, &group, &self.res.counts);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        let atlas = self.atlas.as_ref();
        images::report(gpu, &self.plan, &self.placement, atlas, self.fit.as_ref(), &self.res.shadow, &self.res.counts)
    }
}
