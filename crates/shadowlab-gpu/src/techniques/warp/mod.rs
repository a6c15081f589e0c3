//! Warped shadow maps (seed 000 sections 2.2-3.3, seed 002 chapter 4), one folder, three
//! registry entries sharing every pass:
//! - `notw`: Non-orthogonal Texture Warping. Desired view (DV) by a parallel min/max reduction,
//!   count map at shadow-map resolution by atomic adds, per-row prefix sums, row warps
//!   o(x) = g(x)/N - x smoothed across neighbouring rows weighted by their counts, the count map
//!   rebuilt through them, the same for columns, the final warp of eq. 6; the warps live in two
//!   R32Float textures (8 w^2 bytes per light).
//! - `rtw`: Rectilinear Texture Warping (Rosen 2012), backward analysis: importance map
//!   (desired-view + distance-to-eye), max-collapsed per column and row, blurred, two 1D warps
//!   (w x 1 and 1 x w textures, 8 w bytes).
//! - `notw-dv`: the desired view only, no warping (the seeds' "Ours-DV").
//!
//! The shadow map is rendered with the warp applied per vertex (optionally after subdividing
//! triangles whose warped edges are long, `subdiv`), and evaluated through the same warp. The
//! CPU reference of the math is `shadowlab_core::techniques::warp`. Stored depth: post-projective, 0 = near
//! the light (orthographic: linear), as in `sm`; with `exact_depth` (notw default) each fragment
//! writes its triangle's depth at the warp's preimage of the fragment (depth_exact.wgsl) instead
//! of the depth interpolated between warped vertices.
//!
//! [`Projection::Paraboloid`] makes a `Warped` one hemisphere of a point light's dual-paraboloid
//! maps (`dpsm`, `dpsm-notw` in techniques/dpsm): the same passes over the view samples of that
//! hemisphere, the paraboloid mapping in `base_clip` (params.wgsl).

mod occluders;
mod params;
mod run;

pub use params::*;

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::params::{ParamSet, ParamTable};
use shadowlab_core::techniques::dpsm::Hemisphere;

use crate::prefix_sum::PrefixSum;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::technique::{compose_view, view_layout, TechniqueInfo};
use crate::{binding, raster, Gpu, GpuError};

const PARAMS_WGSL: &str = include_str!("params.wgsl");
const LOOKUP_WGSL: &str = include_str!("lookup.wgsl");
const ANALYZE_WGSL: &str = include_str!("analyze.wgsl");
const DEPTH_WGSL: &str = include_str!("depth.wgsl");
const DEPTH_PLAIN_WGSL: &str = include_str!("depth_plain.wgsl");
const DEPTH_EXACT_WGSL: &str = include_str!("depth_exact.wgsl");
const SUBDIV_WGSL: &str = include_str!("subdiv.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");

fn analyze_src() -> String {
    compose_view(&format!("{PARAMS_WGSL}{ANALYZE_WGSL}"), false)
}
/// The depth pass; `exact`: the fragment stage writes the plane's depth at the inverted warp.
fn depth_src(exact: bool) -> String {
    let fs = if exact { DEPTH_EXACT_WGSL } else { DEPTH_PLAIN_WGSL };
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{DEPTH_WGSL}{fs}"), true)
}
fn subdiv_src() -> String {
    compose(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{SUBDIV_WGSL}"), true)
}
fn eval_src() -> String {
    compose_view(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{EVAL_WGSL}"), false)
}

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("warp/analyze.wgsl", analyze_src()),
        ("warp/depth.wgsl", depth_src(false)),
        ("warp/depth_exact.wgsl", depth_src(true)),
        ("warp/subdiv.wgsl", subdiv_src()),
        ("warp/occluders.wgsl", occluders::occluders_src()),
        ("warp/hzb.wgsl", occluders::hzb_src()),
        ("warp/eval.wgsl", eval_src()),
    ]
}

const LIGHTS: &[&str] = &["directional", "spot"];

pub const NOTW_INFO: TechniqueInfo = TechniqueInfo {
    name: "notw",
    summary: "non-orthogonal texture warping: per-row and per-column warps from the view-sample count map, smoothed, DV crop",
    cost: "DV reduction + count map + 2 prefix-sum passes + 2 rebuilds over the samples; one warped depth pass; 8 w^2 bytes of warps",
    quality: "samples spread evenly over the map; long triangles bend unless subdivided",
    source: "seed 000 section 3, seed 002 chapter 4 (Navratil et al.)",
    lights: LIGHTS,
    params: ParamTable::of::<NotwSettings>(),
    stalls: "",
    needs: "12 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
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
    needs: "12 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
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
    needs: "12 storage buffers per shader stage (WebGPU default: 8): the GPU subdivision (with the hidden-edge pyramid)",
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
    pub pad0: u32,
    pub pad1: u32,
    pub pad2: u32,
}

/// One light's warped shadow map with its warps and scratch buffers.
pub struct Warped {
    variant: Variant,
    /// Prefix of the wgpu labels and stage names.
    label: &'static str,
    res: u32,
    pcf: u32,
    params: WarpParams,
    uniform: wgpu::Buffer,
    /// Reduced DV bounds (fixed point) and the largest eye distance: 8 words.
    dv: wgpu::Buffer,
    work: wgpu::Buffer,
    fwork: wgpu::Buffer,
    warp_x: wgpu::Texture,
    warp_y: wgpu::Texture,
    map: wgpu::Texture,
    counts: wgpu::Buffer,
    /// Subdivision: finished pieces, counters + draw/dispatch args, two queues, one uniform per level.
    pieces: wgpu::Buffer,
    counters: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
    /// Whether `pieces` and `queues` were allocated here (false: lent by another map).
    owns_subdiv: bool,
    /// Indirect dispatch args of the current level (copied from `counters`).
    dispatch: wgpu::Buffer,
    level_uniforms: Vec<wgpu::Buffer>,
    prefix: PrefixSum,
    analyze_layout: wgpu::BindGroupLayout,
    analyze: Vec<(&'static str, wgpu::ComputePipeline)>,
    lookup_layout: wgpu::BindGroupLayout,
    depth_pipeline: wgpu::RenderPipeline,
    /// `cull_hidden`, `edge_importance`: the occluder pass and its pyramid; else none (a
    /// stand-in is bound).
    occluders: Option<occluders::Occluders>,
    split_layout: wgpu::BindGroupLayout,
    /// split_root, split_args, split_level, draw_args.
    split: [wgpu::ComputePipeline; 4],
    eval_layout: wgpu::BindGroupLayout,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    sampler: wgpu::Sampler,
}

fn layout_at(gpu: &Gpu, label: &str, vis: wgpu::ShaderStages, entries: &[(u32, wgpu::BindingType)]) -> wgpu::BindGroupLayout {
    let e: Vec<_> = entries.iter().map(|&(binding, ty)| wgpu::BindGroupLayoutEntry { binding, visibility: vis, ty, count: None }).collect();
    gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &e })
}

fn r32_texture(gpu: &Gpu, label: &str, w: u32, h: u32) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

/// The subdivision buffers of a warped map (finished pieces and the two level queues), its
/// largest scratch: 66 MB at the minimum capacity of 2^21 pieces. Maps whose passes run one after
/// another (`cube-notw`'s faces: each face subdivides and draws before the next starts) can share
/// one set: `Warped::subdiv_scratch` lends it, `Warped::new_sharing` borrows it when it is large
/// enough for the borrower's triangles (otherwise the borrower allocates its own).
#[derive(Clone)]
pub struct SubdivScratch {
    pieces: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
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
    /// A planar warped map of a directional or spot light, with the knobs of `rtw`, `notw` or
    /// `notw-dv` ([`Knobs::rtw`], [`Knobs::notw`], [`Knobs::dv`]).
    pub fn new(gpu: &Gpu, scene: &GpuScene, k: &Knobs, light: &Light) -> Result<Warped, GpuError> {
        Warped::new_sharing(gpu, scene, k, light, None)
    }

    /// `new`, borrowing `shared`'s subdivision buffers when they are large enough.
    pub fn new_sharing(gpu: &Gpu, scene: &GpuScene, k: &Knobs, light: &Light, shared: Option<&SubdivScratch>) -> Result<Warped, GpuError> {
        let name = k.variant.name();
        let res = k.res;
        gpu.check_size(res, res, "shadow map")?;
        let lp = lightspace::fit(light, &scene.bounds, res).ok_or_else(|| {
            GpuError::Invalid(format!("{name} supports directional and spot lights (point lights: cube/paraboloid maps)"))
        })?;
        let mut w = Warped::with_projection(gpu, scene, k, Projection::Planar(lp), name)?;
        if let Some(s) = shared {
            w.borrow_subdiv(s);
        }
        Ok(w)
    }

    /// This map's subdivision buffers, to lend to maps rendered after it.
    pub fn subdiv_scratch(&self) -> SubdivScratch {
        SubdivScratch { pieces: self.pieces.clone(), queues: self.queues.clone() }
    }

    /// Uses `s`'s subdivision buffers instead of this map's own (dropped) if they are at least as
    /// large; bind groups are made per frame, so nothing else refers to the old ones.
    pub fn borrow_subdiv(&mut self, s: &SubdivScratch) {
        if s.pieces.size() >= self.pieces.size() && s.queues.iter().zip(&self.queues).all(|(a, b)| a.size() >= b.size()) {
            self.pieces = s.pieces.clone();
            self.queues = s.queues.clone();
            self.owns_subdiv = false;
        }
    }

    /// Bytes of scratch this map allocated (work buffers, counts, the occluder map and pyramid,
    /// and the subdivision buffers unless borrowed).
    pub fn scratch_bytes(&self) -> u64 {
        let subdiv = if self.owns_subdiv { self.pieces.size() + 2 * self.queues[0].size() } else { 0 };
        let occ = self.occluders.as_ref().map_or(0, |o| o.bytes());
        self.work.size() + self.fwork.size() + self.counts.size() + subdiv + occ
    }

    /// A warped map over `proj`, labelled `name` (wgpu labels, stage names `{name}.<stage>`),
    /// with knobs made for that kind of projection (a paraboloid's: [`Knobs::dpsm`],
    /// [`Knobs::dpsm_notw`]). The knobs also say whether the map is cropped to the desired view:
    /// `dpsm`'s is not (the plain, unwarped paraboloid map, rendered with subdivision). The
    /// caller has checked `res`.
    pub fn with_projection(gpu: &Gpu, scene: &GpuScene, k: &Knobs, proj: Projection, name: &'static str) -> Result<Warped, GpuError> {
        let (variant, res, dv) = (k.variant, k.res, k.crop);
        let (view_proj, texel, perspective, kind) = match proj {
            Projection::Planar(lp) => (lp.view_proj, lp.texel, lp.perspective, 0),
            // 2/res of the map plane per texel: 2 (1 + n.z) / res radians (core techniques::dpsm)
            Projection::Paraboloid { view, hemisphere } => (view, 2.0 / res as f32, false, 1 + (hemisphere == Hemisphere::Back) as u32),
        };
        assert_eq!(k.paraboloid, kind != 0, "{name}: knobs made for another projection");
        let tris = scene.triangle_count;
        let limit = gpu.limits.max_storage_buffer_binding_size / 16;
        let on = k.subdiv > 0.0;
        let auto = (8 * tris as u64).max(1 << 21);
        let wanted = if k.subdiv_capacity > 0 { k.subdiv_capacity as u64 } else { auto };
        // at least one per triangle: the root finishes up to one extra piece per triangle (the
        // second half of a triangle cut by the near plane) before any level can check
        let extra = if on { wanted.max(tris as u64).min(limit.saturating_sub(tris as u64)) as u32 } else { 0 };
        // the root queues up to two pieces per triangle (a triangle cut by the near plane); the
        // triangle index keeps 3 bits free for the split mask
        let queue = if on { (2 * tris as u64).max(1 << 20).min(limit) as u32 } else { 0 };
        if on && (2 * tris as u64 > queue as u64 || tris >= 1 << 29) {
            return Err(GpuError::Invalid(format!(
                "{name}: {tris} triangles need subdivision queues of {} entries, over this device's storage binding limit",
                2 * tris as u64
            )));
        }
        let params = WarpParams {
            light_view_proj: view_proj.to_cols_array_2d(),
            texel_world: texel,
            perspective: perspective as u32 as f32,
            res: res as f32,
            pcf: k.pcf as f32,
            bias: k.bias[0],
            slope_bias: k.bias[1],
            normal_offset: k.bias[2],
            max_slope: k.bias[3],
            dv_margin: k.dv_margin,
            dv_mode: match (dv, k.close_cracks) {
                (false, _) => 0.0,
                (true, false) => DV_CROP,
                (true, true) => DV_CROP_CLOSED,
            },
            warped: (variant != Variant::Dv) as u32 as f32,
            window: k.window as f32,
            w_dv: k.w_dv,
            w_eye: k.w_eye,
            blur: k.blur as f32,
            subdiv: k.subdiv,
            triangles: tris,
            subdiv_levels: k.subdiv_levels,
            extra_capacity: extra,
            rtw_importance: (variant == Variant::Rtw) as u32,
            interp: k.interp as u32,
            mix: k.mix,
            exact_depth: k.exact_depth as u32,
            projection: kind,
            strength: k.strength,
            bias_mode: k.bias_mode as f32,
            footprint_cap: k.footprint_cap,
            depth_clamp: k.depth_clamp as f32,
            min_piece: k.min_piece,
            exact_inverse: if k.exact_inverse { 1.0 } else { 0.0 },
            cull_hidden: if k.cull_hidden { 1.0 } else { 0.0 },
            tent: if k.tent { 1.0 } else { 0.0 },
            edge_importance: k.edge_importance,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        };
        let d = &gpu.device;
        let n = res as u64 * res as u64;
        let (wx, wy) = match variant {
            Variant::Notw => ((res, res), (res, res)),
            Variant::Rtw => ((res, 1), (1, res)),
            Variant::Dv => ((1, 1), (1, 1)),
        };
        let warp_x = r32_texture(gpu, &format!("{name}.warp_x"), wx.0, wx.1);
        let warp_y = r32_texture(gpu, &format!("{name}.warp_y"), wy.0, wy.1);
        let map = d.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{name}.map")),
            size: wgpu::Extent3d { width: res, height: res, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: raster::DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let scratch = variant != Variant::Dv;
        let work = gpu.storage(&format!("{name}.work"), if scratch { (3 * n + 2 * res as u64) * 4 } else { 4 });
        let fwork = gpu.storage(&format!("{name}.fwork"), if scratch { (3 * n + 3 * res as u64) * 4 } else { 4 });
        let pieces = gpu.storage(&format!("{name}.pieces"), (tris as u64 + extra as u64) * 16 * on as u64);
        let queues = [0, 1].map(|i| gpu.storage(&format!("{name}.queue{i}"), queue as u64 * 16));
        let counters = d.create_buffer(&wgpu::BufferDescriptor {
            label: Some(&format!("{name}.counters")),
            size: 1048 * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let levels = params.subdiv_levels;
        let level_uniforms =
            (1..=levels).map(|l| gpu.uniform(&format!("{name}.level{l}"), &[l, (l == levels) as u32, (l + 1) % 2, queue])).collect();
        let ro = binding::storage(true);
        let rw = binding::storage(false);
        let tex = binding::texture_float();
        let store = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::R32Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let analyze_layout = view_layout(gpu, &format!("{name}.analyze"), &[binding::uniform(), rw, rw, rw, store, store, ro]);
        let src = analyze_src();
        let entries: &[&str] = match variant {
            Variant::Notw => {
                &["dv_reduce", "count", "blur_rows", "offsets_rows", "smooth_rows", "rebuild", "blur_cols", "offsets_cols", "smooth_cols"]
            }
            Variant::Rtw => &["dv_reduce", "count", "rtw_collapse", "rtw_blur", "rtw_offsets"],
            Variant::Dv => &["dv_reduce"],
        };
        let constants = [("SMOOTH_BLOCK", SMOOTH_BLOCK as f64)];
        let analyze = entries
            .iter()
            .map(|&e| (e, gpu.compute_pipeline_with(&format!("{name}.{e}"), &src, e, &[&analyze_layout], &constants)))
            .collect();
        let look = [(6, binding::uniform()), (7, ro), (8, tex), (9, tex)];
        let lookup_layout =
            layout_at(gpu, &format!("{name}.depth"), wgpu::ShaderStages::VERTEX_FRAGMENT, &[look[0], look[1], look[2], look[3], (10, ro)]);
        let depth_pipeline =
            raster::scene_pipeline(gpu, &format!("{name}.shadow_map"), &depth_src(k.exact_depth), &[&lookup_layout, &scene.layout], &[]);
        let occluders = (k.cull_hidden || k.edge_importance > 0).then(|| occluders::Occluders::new(gpu, name, res, &lookup_layout, scene));
        let split_layout = layout_at(
            gpu,
            &format!("{name}.subdivide"),
            wgpu::ShaderStages::COMPUTE,
            &[look[0], look[1], look[2], look[3], (10, rw), (11, rw), (12, rw), (13, rw), (14, binding::uniform()), (15, ro)],
        );
        let ssrc = subdiv_src();
        let split = ["split_root", "split_args", "split_level", "draw_args"]
            .map(|e| gpu.compute_pipeline(&format!("{name}.{e}"), &ssrc, e, &[&split_layout, &scene.layout]));
        let eval_layout = view_layout(
            gpu,
            &format!("{name}.final_pass"),
            &[binding::uniform(), ro, tex, tex, binding::texture_depth(), binding::comparison_sampler(), rw],
        );
        let eval = crate::technique::EvalPipelines::new(gpu, &format!("{name}.final_pass"), &eval_src(), &eval_layout, &[]);
        let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("warp.cmp"),
            compare: Some(wgpu::CompareFunction::LessEqual),
            mag_filter: wgpu::FilterMode::Nearest,
            min_filter: wgpu::FilterMode::Nearest,
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            ..Default::default()
        });
        Ok(Warped {
            variant,
            label: name,
            res,
            pcf: k.pcf,
            params,
            uniform: gpu.uniform(&format!("{name}.params"), &params),
            dv: gpu.storage(&format!("{name}.dv"), 32),
            work,
            fwork,
            warp_x,
            warp_y,
            map,
            counts: gpu.storage(&format!("{name}.counts"), n * 4),
            pieces,
            counters,
            queues,
            owns_subdiv: true,
            dispatch: d.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&format!("{name}.dispatch")),
                size: 12,
                usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            level_uniforms,
            prefix: PrefixSum::new(gpu),
            analyze_layout,
            analyze,
            lookup_layout,
            depth_pipeline,
            occluders,
            split_layout,
            split,
            eval_layout,
            eval,
            sampler,
        })
    }
}
