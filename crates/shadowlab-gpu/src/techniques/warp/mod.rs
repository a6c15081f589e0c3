//! Warped shadow maps (seed 000 sections 2.2-3.3, seed 002 chapter 4), one folder, three
//! registry entries sharing every pass:
//! - `notw`: Non-orthogonal Texture Warping. Desired view (DV) by a parallel min/max reduction,
//!   count map at shadow-map resolution by atomic adds, per-row prefix sums (one invocation a
//!   row), row warps o(x) = g(x)/N - x smoothed across neighbouring rows weighted by their
//!   counts, the count map rebuilt through them (each texel's count spread over its image), the
//!   same for columns, the final warp of eq. 6; the warps live in two R32Float textures (8 w^2
//!   bytes per light).
//! - `rtw`: Rectilinear Texture Warping (Rosen 2012), backward analysis: importance map
//!   (desired-view + distance-to-eye), max-collapsed per column and row, blurred, two 1D warps
//!   (w x 1 and 1 x w textures, 8 w bytes).
//! - `notw-dv`: the desired view only, no warping (the seeds' "Ours-DV").
//!
//! The shadow map is rendered with the warp applied per vertex (optionally after subdividing
//! triangles whose warped edges are long, `subdiv`), and evaluated through the same warp. The
//! CPU reference of the math is `shadowlab_core::techniques::warp`. Stored depth: post-projective, 0 = near
//! the light (orthographic: linear), as in `sm`; with `exact_depth` (`cube-notw`'s default) each fragment
//! writes its triangle's depth at the warp's preimage of the fragment (depth_exact.wgsl) instead
//! of the depth interpolated between warped vertices.
//!
//! [`Projection::Paraboloid`] makes a `Warped` one hemisphere of a point light's dual-paraboloid
//! maps (`dpsm`, `dpsm-notw` in techniques/dpsm): the same passes over the view samples of that
//! hemisphere, the paraboloid mapping in `base_clip` (params.wgsl).

mod analyze;
mod build;
mod depth;
mod eval;
mod knobs;
mod layers;
mod occluders;
mod params;
mod report;
mod settings;
mod subdiv;
mod subdiv_layers;

use eval::EVAL_FNS_WGSL;
pub use knobs::Knobs;
pub use layers::{layered_analysis_source, layered_count_source, layered_dv_source, layered_eval_source, LayerPasses, Layers};
pub use params::*;
pub use settings::*;
pub use subdiv_layers::{layered_scatter_source, layered_subdivision_source, LayerDraw, LayerSubdivision};

use bytemuck::{Pod, Zeroable};
use shadowlab_core::lightspace;
use shadowlab_core::params::{ParamSet, ParamTable};
use shadowlab_core::techniques::dpsm::Hemisphere;

use crate::prefix_sum::PrefixSum;
use crate::record::Recorder;
use crate::shaders::{compose, flag};
use crate::technique::{counted_evaluation, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};

/// Every warp shader's prelude: `WarpParams`, the base projection, the DV rule, the offsets.
const PARAMS_WGSL: &str = include_str!("params.wgsl");
/// The desired view's reduction within a workgroup (analyze.wgsl, dv_layers.wgsl).
const DV_WGSL: &str = include_str!("dv.wgsl");
/// A view sample's place and weight in its count map (analyze.wgsl, count_layers.wgsl).
const COUNT_WGSL: &str = include_str!("count.wgsl");
/// NoTW's warps from a count map (analyze.wgsl, analyze_layers.wgsl).
const NOTW_WGSL: &str = include_str!("notw.wgsl");
/// A finished warp applied (depth, subdivision, occluder and evaluation passes): one map's
/// bindings 6-9, then the functions.
const LOOKUP_WGSL: &str = concat!(include_str!("lookup_bind.wgsl"), include_str!("lookup.wgsl"));
/// The lookup's functions alone, for bindings of another shape (eval_layers.wgsl).
const LOOKUP_FNS_WGSL: &str = include_str!("lookup.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("warp/analyze.wgsl", analyze::source()),
        ("warp/depth.wgsl", depth::source(false)),
        ("warp/depth_exact.wgsl", depth::source(true)),
        ("warp/depth_clip.wgsl", depth::clipped_source()),
        ("warp/subdiv.wgsl", subdiv::source()),
        ("warp/occluders.wgsl", occluders::occluders_src()),
        ("warp/hzb.wgsl", occluders::hzb_src()),
        ("warp/eval.wgsl", eval::source()),
    ]
}

const LIGHTS: &[&str] = &["directional", "spot"];

pub const NOTW_INFO: TechniqueInfo = TechniqueInfo {
    name: "notw",
    summary: "non-orthogonal texture warping: per-row and per-column warps from the view-sample count map, smoothed, DV crop",
    cost: "DV reduction + count map over the samples, then per direction one pass a row (column) and the smoothing over the map, the count map rebuilt through the row warps between; one warped depth pass; 8 w^2 bytes of warps",
    quality: "samples spread evenly over the map; long triangles bend unless subdivided",
    source: "seed 000 section 3, seed 002 chapter 4 (Navratil et al.)",
    lights: LIGHTS,
    params: ParamTable::of::<NotwSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Warped::new(gpu, scene, &Knobs::notw(&NotwSettings::from_values(p)), light)?)),
};

pub const RTW_INFO: TechniqueInfo = TechniqueInfo {
    name: "rtw",
    summary: "rectilinear texture warping, backward analysis: importance map max-collapsed to two blurred 1D warps, DV crop",
    cost: "DV reduction + importance map + 1D collapse/blur/scan; one warped depth pass; 8 w bytes of warps",
    quality: "rectilinear grid: a row/column gets the resolution of its most important texel",
    source: "Rosen 2012; seed 000 section 2.2, seed 002 section 3.2.2",
    lights: LIGHTS,
    params: ParamTable::of::<RtwSettings>(),
    stalls: "",
    needs: "11 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
    storage_buffers: 11,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Warped::new(gpu, scene, &Knobs::rtw(&RtwSettings::from_values(p)), light)?)),
};

pub const DV_INFO: TechniqueInfo = TechniqueInfo {
    name: "notw-dv",
    summary: "desired view only: the shadow map cropped to the bounding rectangle of the projected view samples, no warp",
    cost: "DV reduction (parallel min/max) + one depth pass",
    quality: "wins on close-ups; on wide views the crop barely shrinks (seed 000 section 4)",
    source: "seed 000 section 3.2 (\"Ours-DV\"), Rosen 2012's desired view",
    lights: LIGHTS,
    params: ParamTable::of::<DvSettings>(),
    stalls: "",
    // no subdivision, so no subdivision pipelines (made since 2026-12-08 only by maps that
    // subdivide): its passes bind at most 7
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Warped::new(gpu, scene, &Knobs::dv(&DvSettings::from_values(p)), light)?)),
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    Notw,
    Rtw,
    Dv,
}

impl Variant {
    pub fn name(self) -> &'static str {
        match self {
            Variant::Notw => "notw",
            Variant::Rtw => "rtw",
            Variant::Dv => "notw-dv",
        }
    }

    /// Texels of the two warp textures: NoTW one function per row and per column, RTW one 1D
    /// function each way, the DV crop none (a stand-in texel).
    pub(super) fn warp_sizes(self, res: u32) -> [(u32, u32); 2] {
        match self {
            Variant::Notw => [(res, res), (res, res)],
            Variant::Rtw => [(res, 1), (1, res)],
            Variant::Dv => [(1, 1), (1, 1)],
        }
    }

    /// Words of the analysis's two work buffers (analyze.wgsl's layouts): NoTW's counts, then
    /// its rebuilt counts, offsets and totals; RTW's importance and 1D functions; the DV alone:
    /// none.
    pub(super) fn work_words(self, res: u32) -> [u64; 2] {
        let (n, w) = (res as u64 * res as u64, res as u64);
        match self {
            Variant::Notw => [n, 3 * n + w],
            Variant::Rtw => [2 * n + 2 * w, 4 * w],
            Variant::Dv => [1, 1],
        }
    }
}

/// `WarpParams::dv_mode`: the map is cropped to the desired view.
pub const DV_CROP: f32 = 1.0;
/// `WarpParams::dv_mode`: cropped, and subdivision cracks closed by a 3x3 depth minimum.
pub const DV_CROP_CLOSED: f32 = 2.0;

/// NoTW smoothing across functions (analyze.wgsl `smooth_block`): functions per invocation,
/// summed directly once and then slid. 32: a texel costs window / 32 + 2 reads (window + 1
/// before; cube-notw's window 128 made smoothing its largest stage), and the sliding sum
/// rounds over at most 32 steps.
pub(super) const SMOOTH_BLOCK: u32 = 32;

/// WGSL `WarpParams` (params.wgsl): one named field per value (the layout test checks each).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct WarpParams {
    pub light_view_proj: [[f32; 4]; 4],
    pub texel_world: f32,
    pub perspective: f32,
    pub res: f32,
    pub pcf: f32,
    pub bias: f32,
    pub slope_bias: f32,
    pub normal_offset: f32,
    pub max_slope: f32,
    pub dv_margin: f32,
    /// 0: no DV crop, [`DV_CROP`], [`DV_CROP_CLOSED`].
    pub dv_mode: f32,
    /// 1: the warp is on (0: the DV crop only).
    pub warped: f32,
    pub window: f32,
    pub w_dv: f32,
    pub w_eye: f32,
    pub blur: f32,
    pub subdiv: f32,
    pub triangles: u32,
    pub subdiv_levels: u32,
    pub extra_capacity: u32,
    pub rtw_importance: u32,
    pub interp: u32,
    pub mix: f32,
    pub exact_depth: u32,
    /// 0 planar, 1 + [`Hemisphere`] index for a paraboloid hemisphere.
    pub projection: u32,
    pub strength: f32,
    pub bias_mode: f32,
    pub footprint_cap: f32,
    pub depth_clamp: f32,
    /// Smallest warped extent (texels) of an edge that subdivision splits; 0 = no bound.
    pub min_piece: f32,
    /// 1 = exact inversion in the exact depth pass (`exact_inverse`)
    pub exact_inverse: f32,
    /// 1 = subdivision leaves edges hidden behind nearer geometry unsplit (`cull_hidden`)
    pub cull_hidden: f32,
    /// 1 = tent-weighted smoothing across functions (`window_tent`)
    pub tent: f32,
    /// Extra count of a view sample on a shadow edge of the occluder map (`edge_importance`)
    pub edge_importance: u32,
    /// Planar subdivision: split on the perpendicular bend (`subdiv`) and the along-edge
    /// displacement (this); 0 = on the whole displacement against `subdiv` (`depth_split`)
    pub depth_split: f32,
    /// Exact depth: pieces whose corners spread less than this (texels of world size) along the
    /// light keep the interpolated depth (`exact_tol`; 0: none)
    pub exact_tol: f32,
    /// Queue levels before the tessellation (tess.wgsl; 0: the level queue alone, `tessellate`)
    pub tessellate: u32,
    /// The scene's triangles (a subdivision over several maps of one scene numbers map k's
    /// triangle t as k * scene_triangles + t: `dpsm`'s hemispheres)
    pub scene_triangles: u32,
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// One light's warped shadow map with its warps and scratch buffers.
pub struct Warped {
    /// The bind groups, made on the first frame and kept while their resources stay (one per
    /// call site; `level_groups`: one per subdivision level, 0 the root).
    pub(crate) groups: Groups,
    variant: Variant,
    /// Prefix of the wgpu labels and stage names.
    label: &'static str,
    res: u32,
    pcf: u32,
    params: WarpParams,
    uniform: wgpu::Buffer,
    /// Reduced DV bounds (fixed point) and the largest eye distance: 8 words.
    dv: wgpu::Buffer,
    /// The count map (and RTW's importance) and the analysis's scratch: its own, or its slices
    /// of [`Layers`]' (from these byte offsets).
    work: wgpu::Buffer,
    work_offset: u64,
    fwork: wgpu::Buffer,
    fwork_offset: u64,
    warp_x: wgpu::Texture,
    warp_y: wgpu::Texture,
    map: wgpu::Texture,
    /// Views of `warp_x`, `warp_y` and `map` (this map's layer of them), made once.
    views: [wgpu::TextureView; 3],
    /// This map's layer of the three textures, and its byte offsets in `dv` and `counts`: 0
    /// for a map with its own, else [`Layers`]' (one evaluation reads every layer).
    layer: u32,
    dv_offset: u64,
    counts_offset: u64,
    /// A layer of [`Layers`]: evaluated by its owner ([`LayerPasses`]).
    layered: bool,
    /// Its desired view reduced and (NoTW) its count map counted and warps built by its owner
    /// (`Layers::owner_reads_view`): it has no analysis of its own.
    view_by_owner: bool,
    counts: wgpu::Buffer,
    /// Subdivision: finished pieces, counters + draw/dispatch args, two queues, one uniform per level.
    pieces: wgpu::Buffer,
    counters: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
    /// Whether `pieces` and `queues` were allocated here (false: its owner's, `owner_draw`).
    owns_subdiv: bool,
    /// Subdivided by its owner with the other layers ([`LayerSubdivision`]): its share, drawn
    /// instead of its own pieces (its own subdivision buffers and pipelines are not made).
    owner_draw: Option<LayerDraw>,
    /// Its triangles in a scene of several maps' (`cube-notw`'s faces), else the whole scene.
    range: Option<std::ops::Range<u32>>,
    /// Indirect dispatch args of the current level (copied from `counters`).
    dispatch: wgpu::Buffer,
    level_uniforms: Vec<wgpu::Buffer>,
    prefix: PrefixSum,
    analyze_layout: wgpu::BindGroupLayout,
    analyze: Vec<(&'static str, wgpu::ComputePipeline)>,
    lookup_layout: wgpu::BindGroupLayout,
    depth_pipeline: wgpu::RenderPipeline,
    /// Subdivided by its owner with exact depth and `exact_tol`: the depth pipeline without the
    /// exact-depth stage, for the pieces listed flat ([`LayerDraw`]).
    flat_pipeline: Option<wgpu::RenderPipeline>,
    /// The scene's layout and cut-outs, and its last frame's group (the report's redraw).
    scene: depth::SceneBinding,
    /// `cull_hidden`, `edge_importance`: the occluder pass and its pyramid; else none (a
    /// stand-in is bound).
    occluders: Option<occluders::Occluders>,
    /// split_root, split_args, split_level, draw_args (none where the owner subdivides).
    split_layout: Option<wgpu::BindGroupLayout>,
    split: Option<Vec<wgpu::ComputePipeline>>,
    eval_layout: wgpu::BindGroupLayout,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    sampler: wgpu::Sampler,
}

/// The kept bind groups of a warped map's passes.
#[derive(Default)]
pub(crate) struct Groups {
    analyze: crate::binding::GroupCache,
    depth: crate::binding::GroupCache,
    levels: Vec<crate::binding::GroupCache>,
    eval: crate::binding::GroupCache,
}

/// The pipeline constants of every warp shader (params.wgsl): the projection and whether the map
/// warps, from the map's uniform. Each pass adds its own.
fn base_constants(p: &WarpParams) -> Vec<(&'static str, f64)> {
    vec![("PARABOLOID", flag(p.projection != 0)), ("WARPED", flag(p.warped > 0.5))]
}

fn layout_at(gpu: &Gpu, label: &str, vis: wgpu::ShaderStages, entries: &[(u32, wgpu::BindingType)]) -> wgpu::BindGroupLayout {
    let e: Vec<_> = entries.iter().map(|&(binding, ty)| wgpu::BindGroupLayoutEntry { binding, visibility: vis, ty, count: None }).collect();
    crate::binding::entries_layout(&gpu.device, label, &e)
}

/// How a warped map projects the world before the desired view and the warp.
#[derive(Clone, Copy, Debug)]
pub enum Projection {
    /// A directional or spot light's projection (`lightspace::fit`).
    Planar(lightspace::LightProjection),
    /// One hemisphere of a point light's dual-paraboloid maps (seed 002 eq. 3.3-3.10; params.wgsl
    /// `base_clip`): `view` = world -> the hemisphere's light space scaled by 1/far
    /// (`DualParaboloid::view`). Subdivision also follows the paraboloid's bending; `exact_depth`
    /// intersects the fragment's direction with the triangle's plane (also without a warp).
    Paraboloid { view: glam::Mat4, hemisphere: Hemisphere },
}

impl Warped {
    fn name(&self) -> &'static str {
        self.label
    }
}

/// A frame of a warped map: the desired view and the warps fitted to the view samples
/// (analyze.rs), the triangles subdivided where the warp bends them (subdiv.rs) and drawn
/// through the warp (depth.rs), the view evaluated through the same warp (eval.rs).
impl Technique for Warped {
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.fit_warps(gpu, f, rec);
        Ok(())
    }

    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let depth_group = self.depth_group(gpu);
        if self.params.subdiv > 0.0 && self.owner_draw.is_none() {
            self.subdivide(gpu, f, rec);
        }
        self.draw_shadow_map(f, rec, &depth_group);
        Ok(())
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        report::report(self, gpu)
    }
}
