//! Maps evaluated together (`cube-notw`'s six faces, `dpsm`'s two hemispheres): each map keeps
//! its own passes over its map, but its warps, depth map and occluder map are one layer of
//! shared array textures, and its DV bounds, count map and sample counts one slice of shared
//! buffers, so that one pass over the view reduces every map's desired view (dv_layers.wgsl),
//! one counts every map's view samples (count_layers.wgsl), one dispatch a step builds every
//! map's NoTW warps (analyze_layers.wgsl) and one pass evaluates every map (eval_layers.wgsl),
//! instead of a pass a map ([`LayerPasses`]); one subdivision can cut every map's triangles
//! (subdiv_layers.rs, with the maps' pyramids here).

use super::{
    base_constants, eval, Knobs, Variant, WarpParams, Warped, COUNT_WGSL, DV_WGSL, EVAL_FNS_WGSL, LOOKUP_FNS_WGSL, NOTW_WGSL, PARAMS_WGSL,
    SMOOTH_BLOCK,
};
use crate::record::Recorder;
use crate::shaders::compose;
use crate::technique::{compose_view, view_layout, EvalPipelines, FrameInputs};
use crate::{binding, raster, Gpu};

/// The layers' uniforms and DV bounds in a pass over every layer (count, evaluation,
/// subdivision), and their warps (evaluation, subdivision).
pub(super) const LAYER_BIND_WGSL: &str = include_str!("layer_bind.wgsl");
pub(super) const LAYER_WARPS_WGSL: &str = include_str!("layer_warps.wgsl");
const EVAL_LAYERS_WGSL: &str = include_str!("eval_layers.wgsl");
const DV_LAYERS_WGSL: &str = include_str!("dv_layers.wgsl");
const COUNT_LAYERS_WGSL: &str = include_str!("count_layers.wgsl");
const ANALYZE_LAYERS_WGSL: &str = include_str!("analyze_layers.wgsl");

/// The shared targets of `count` maps of one kind of knobs.
pub struct Layers {
    pub(super) res: u32,
    count: u32,
    /// The maps' desired views are reduced and their count maps counted together
    /// ([`LayerPasses::reduce_dv`], [`LayerPasses::count`]), not by each map.
    pub(super) owner_reads_view: bool,
    /// The maps are subdivided together ([`super::LayerSubdivision`]), not by each map.
    pub(super) owner_subdivides: bool,
    /// Every layer draws the whole scene, subdivided by the owner as one copy a layer
    /// ([`Layers::repeating_scene`]).
    pub(super) repeats_scene: bool,
    pub(super) warp_x: wgpu::Texture,
    pub(super) warp_y: wgpu::Texture,
    pub(super) map: wgpu::Texture,
    /// 8 words of DV bounds a layer, at `dv_stride` bytes (the storage offset alignment).
    pub(super) dv: wgpu::Buffer,
    pub(super) dv_stride: u64,
    /// The analysis variant's samples per warped texel, `res^2` words a layer.
    pub(super) counts: wgpu::Buffer,
    /// NoTW maps analysed by their owner: the count maps and the analysis's scratch,
    /// `work_stride` and `fwork_stride` bytes apart (rounded up to the storage offset alignment).
    pub(super) work: Option<wgpu::Buffer>,
    pub(super) work_stride: u64,
    pub(super) fwork: Option<wgpu::Buffer>,
    pub(super) fwork_stride: u64,
    /// The occluder maps (`edge_importance`, `cull_hidden`), or a 1x1 stand-in.
    pub(super) occluders: wgpu::Texture,
    /// Subdivided by the owner with `cull_hidden`: the occluder maps' pyramids, `hzb_stride`
    /// bytes apart (each its map's own otherwise).
    pub(super) hzb: Option<wgpu::Buffer>,
    pub(super) hzb_stride: u64,
}

impl Layers {
    /// `count` layers for maps made with `k`; with `owner_reads_view` the caller reduces every
    /// layer's desired view ([`LayerPasses::reduce_dv`]) and, for NoTW, counts every layer's
    /// view samples ([`LayerPasses::count`], after the occluder maps) and builds every layer's
    /// warps ([`LayerPasses::analyze`]) before the maps' subdivision and depth passes; with
    /// `owner_subdivides` the caller subdivides every map ([`super::LayerSubdivision`]) and the
    /// maps draw its pieces.
    pub fn new(gpu: &Gpu, name: &str, k: &Knobs, count: u32, owner_reads_view: bool, owner_subdivides: bool) -> Layers {
        let res = k.res;
        let align = gpu.limits.min_storage_buffer_offset_alignment as u64;
        let dv_stride = align.max(32);
        let n = res as u64 * res as u64;
        let [wx, wy] = k.variant.warp_sizes(res);
        let aligned = |words: u64| (words * 4).div_ceil(align) * align;
        let [work_words, fwork_words] = k.variant.work_words(res);
        let (work_stride, fwork_stride) = (aligned(work_words), aligned(fwork_words));
        let counted = owner_reads_view && k.variant == Variant::Notw;
        let occ = if k.cull_hidden || k.edge_importance > 0 { res } else { 1 };
        let hzb_stride = aligned(super::occluders::pyramid_len(res));
        let pyramids = owner_subdivides && k.cull_hidden && k.subdiv > 0.0;
        Layers {
            res,
            count,
            owner_reads_view,
            owner_subdivides,
            repeats_scene: false,
            hzb: pyramids.then(|| gpu.storage(&format!("{name}.hzb"), hzb_stride * count as u64)),
            hzb_stride,
            work: counted.then(|| gpu.storage(&format!("{name}.work"), work_stride * count as u64)),
            work_stride,
            fwork: counted.then(|| gpu.storage(&format!("{name}.fwork"), fwork_stride * count as u64)),
            fwork_stride,
            occluders: raster::depth_target(gpu, &format!("{name}.occluders"), occ, occ, count, wgpu::TextureUsages::empty()),
            warp_x: r32_array(gpu, &format!("{name}.warp_x"), wx, count),
            warp_y: r32_array(gpu, &format!("{name}.warp_y"), wy, count),
            map: raster::depth_target(gpu, &format!("{name}.map"), res, res, count, wgpu::TextureUsages::empty()),
            dv: gpu.storage(&format!("{name}.dv"), dv_stride * count as u64),
            dv_stride,
            counts: gpu.storage(&format!("{name}.counts"), n * 4 * count as u64),
        }
    }

    /// Every layer draws the whole scene (`dpsm`'s hemispheres): the owner's subdivision
    /// ([`super::LayerSubdivision`]) numbers layer k's triangle t as k * triangles + t, the
    /// scene stays the frame's (cube-notw's faces instead draw one scene of their clipped
    /// triangles, a range each).
    pub fn repeating_scene(mut self) -> Layers {
        self.repeats_scene = true;
        self
    }

    /// The layers' count.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Texels of the layers whose triangles are their own, for the owner's subdivision's
    /// capacity (subdiv::capacity; 0 with [`Layers::repeating_scene`]: a copy of the scene a
    /// layer is sized by its triangles, as one map's).
    pub(super) fn listed_texels(&self) -> u64 {
        if self.repeats_scene {
            0
        } else {
            self.texels()
        }
    }

    /// Texels of all layers' maps.
    pub fn texels(&self) -> u64 {
        self.count as u64 * self.res as u64 * self.res as u64
    }

    /// Every layer's DV bounds (`dv_stride()` bytes apart).
    pub fn dv(&self) -> &wgpu::Buffer {
        &self.dv
    }

    pub fn dv_stride(&self) -> u64 {
        self.dv_stride
    }
}

/// An R32Float texture of `layers` layers that passes write as storage and read as a texture.
pub(super) fn r32_array(gpu: &Gpu, label: &str, (w, h): (u32, u32), layers: u32) -> wgpu::Texture {
    let usage = wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC;
    raster::texture_2d(gpu, label, w, h, layers, wgpu::TextureFormat::R32Float, usage)
}

/// The evaluation of a [`LayerPasses`]: `prelude` (what `select` calls), the warped map's
/// evaluation over layers, and `select`, which defines `LAYERS`, `layer_of` and `light_axis`
/// (eval_layers.wgsl).
pub fn layered_eval_source(prelude: &str, select: &str) -> String {
    compose_view(
        &format!("{prelude}{PARAMS_WGSL}{LAYER_BIND_WGSL}{LAYER_WARPS_WGSL}{LOOKUP_FNS_WGSL}{EVAL_FNS_WGSL}{EVAL_LAYERS_WGSL}{select}"),
        false,
    )
}

/// The desired views of a [`LayerPasses`] (dv_layers.wgsl), with the same `prelude` and
/// `select`.
pub fn layered_dv_source(prelude: &str, select: &str) -> String {
    compose_view(&format!("{prelude}{PARAMS_WGSL}{DV_WGSL}{DV_LAYERS_WGSL}{select}"), false)
}

/// The count maps of a [`LayerPasses`] (count_layers.wgsl), with the same `prelude` and
/// `select`.
pub fn layered_count_source(prelude: &str, select: &str) -> String {
    compose_view(&format!("{prelude}{PARAMS_WGSL}{LAYER_BIND_WGSL}{COUNT_WGSL}{COUNT_LAYERS_WGSL}{select}"), false)
}

/// NoTW's analysis of `layers` layers at once (analyze_layers.wgsl).
pub fn layered_analysis_source(layers: u32) -> String {
    compose(&format!("const LAYERS: u32 = {layers}u;\n{PARAMS_WGSL}{NOTW_WGSL}{ANALYZE_LAYERS_WGSL}"), false)
}

/// NoTW's analysis passes, in order (notw.wgsl).
const ANALYSIS: [&str; 5] = ["functions_rows", "smooth_rows", "rebuild", "functions_cols", "smooth_cols"];

/// The passes over every layer of a [`Layers`] at once: the evaluation (stage
/// `{name}.final_pass`) and, where the layers' owner reads the view, the reduction of their
/// desired views (stage `{name}.desired_view`) and of NoTW maps their count maps and warps
/// (stage `{name}.importance_map`).
pub struct LayerPasses {
    name: &'static str,
    /// The layers' uniforms, in layer order.
    pub(super) params: wgpu::Buffer,
    /// Array views of the warps and maps.
    pub(super) views: [wgpu::TextureView; 3],
    sampler: wgpu::Sampler,
    layout: wgpu::BindGroupLayout,
    eval: EvalPipelines,
    groups: binding::GroupCache,
    /// The desired views' pass (`Layers::owner_reads_view`): its layout and pipeline.
    dv: Option<(wgpu::BindGroupLayout, wgpu::ComputePipeline)>,
    dv_groups: binding::GroupCache,
    /// The count maps' pass (NoTW layers with `Layers::owner_reads_view`) and the occluder maps'
    /// array view it reads.
    count: Option<(wgpu::BindGroupLayout, wgpu::ComputePipeline)>,
    count_groups: binding::GroupCache,
    occluders: wgpu::TextureView,
    /// NoTW's analysis passes over every layer (with the count pass) and their group.
    analysis: Option<(wgpu::BindGroupLayout, [wgpu::ComputePipeline; 5])>,
    analysis_groups: binding::GroupCache,
}

impl LayerPasses {
    /// `maps[i]` draws layer i of `layers` (made with the same knobs); `prelude` and `select`
    /// as [`layered_eval_source`] takes them.
    pub fn new(gpu: &Gpu, name: &'static str, layers: &Layers, maps: &[&Warped], prelude: &str, select: &str) -> LayerPasses {
        assert_eq!(maps.len() as u32, layers.count(), "{name}: one map a layer");
        assert!(maps.iter().enumerate().all(|(i, m)| m.layered && m.layer == i as u32), "{name}: map i draws layer i");
        let params: Vec<WarpParams> = maps.iter().map(|m| m.params).collect();
        let array = |sample_type| wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let float = array(wgpu::TextureSampleType::Float { filterable: false });
        let label = format!("{name}.final_pass");
        let layout = view_layout(
            gpu,
            &label,
            &[
                binding::uniform(),
                binding::storage(true),
                float,
                float,
                array(wgpu::TextureSampleType::Depth),
                binding::comparison_sampler(),
                binding::storage(false),
            ],
        );
        // the layers share the knobs that choose code paths
        let stride = ("DV_STRIDE", (layers.dv_stride / 4) as f64);
        let mut constants = eval::constants(&params[0]);
        constants.push(stride);
        let dv = layers.owner_reads_view.then(|| {
            let label = format!("{name}.desired_view");
            let layout = view_layout(gpu, &label, &[binding::uniform(), binding::storage(false)]);
            let mut c = base_constants(&params[0]);
            c.push(stride);
            let pipeline = gpu.compute_pipeline_with(&label, &layered_dv_source(prelude, select), "dv_layers", &[&layout], &c);
            (layout, pipeline)
        });
        let count = layers.work.as_ref().map(|_| {
            let label = format!("{name}.count");
            let depth = array(wgpu::TextureSampleType::Depth);
            let layout = view_layout(gpu, &label, &[binding::uniform(), binding::storage(true), binding::storage(false), depth]);
            let mut c = base_constants(&params[0]);
            c.extend([stride, ("WORK_STRIDE", (layers.work_stride / 4) as f64)]);
            let pipeline = gpu.compute_pipeline_with(&label, &layered_count_source(prelude, select), "count_layers", &[&layout], &c);
            (layout, pipeline)
        });
        let analysis = layers.work.as_ref().map(|_| {
            let label = format!("{name}.analyze");
            let store = wgpu::BindingType::StorageTexture {
                access: wgpu::StorageTextureAccess::WriteOnly,
                format: wgpu::TextureFormat::R32Float,
                view_dimension: wgpu::TextureViewDimension::D2Array,
            };
            let (ro, rw) = (binding::storage(true), binding::storage(false));
            let layout = binding::layout(&gpu.device, &label, wgpu::ShaderStages::COMPUTE, &[binding::uniform(), ro, rw, rw, store, store]);
            let mut c = base_constants(&params[0]);
            c.extend([
                stride,
                ("WORK_STRIDE", (layers.work_stride / 4) as f64),
                ("FWORK_STRIDE", (layers.fwork_stride / 4) as f64),
                ("SMOOTH_BLOCK", SMOOTH_BLOCK as f64),
            ]);
            let src = layered_analysis_source(layers.count);
            let pipelines = ANALYSIS.map(|e| gpu.compute_pipeline_with(&format!("{label}.{e}"), &src, e, &[&layout], &c));
            (layout, pipelines)
        });
        let source = layered_eval_source(prelude, select);
        let d = wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
        LayerPasses {
            name,
            params: gpu.uniform_array(&format!("{name}.layers"), &params),
            views: [&layers.warp_x, &layers.warp_y, &layers.map].map(|t| t.create_view(&d)),
            occluders: layers.occluders.create_view(&d),
            sampler: eval::sampler(gpu),
            eval: EvalPipelines::new(gpu, &label, &source, &layout, &constants),
            layout,
            groups: Default::default(),
            dv,
            dv_groups: Default::default(),
            count,
            count_groups: Default::default(),
            analysis,
            analysis_groups: Default::default(),
        }
    }

    /// Every layer's desired view from the view samples in one pass (stage
    /// `{name}.desired_view`), each sample counted by the layer that evaluates it; the sixth
    /// word of each slice counts its samples. Only for layers whose owner reduces them.
    pub fn reduce_dv(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, layers: &Layers) {
        let (layout, pipeline) = self.dv.as_ref().expect("the layers' owner reduces their desired views");
        let label = format!("{}.desired_view", self.name);
        let group = f.view_group(gpu, &self.dv_groups, &label, layout, &[self.params.as_entire_binding(), layers.dv.as_entire_binding()]);
        // every slice empty: min at the top, max and count 0
        let stride = (layers.dv_stride / 4) as usize;
        let mut empty = vec![0u32; layers.count as usize * stride];
        for slice in empty.chunks_mut(stride) {
            slice[..2].fill(u32::MAX);
        }
        rec.write_buffer(&layers.dv, 0, bytemuck::cast_slice(&empty));
        rec.stage(&label, |enc| gpu.dispatch_2d(enc, &label, pipeline, &[&group], f.gbuffer.width, f.gbuffer.height));
    }

    /// Every NoTW layer's count map from the view samples in one pass (stage
    /// `{name}.importance_map`), each sample counted by the layer that evaluates it, after their
    /// desired views and, with `edge_importance`, their occluder maps
    /// ([`Warped::draw_occluders`]). Only for layers whose owner reads the view.
    pub fn count(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, layers: &Layers) {
        let (layout, pipeline) = self.count.as_ref().expect("the layers' owner counts NoTW maps");
        let work = layers.work.as_ref().expect("made with the count pass");
        let label = format!("{}.count", self.name);
        let extra = [
            self.params.as_entire_binding(),
            layers.dv.as_entire_binding(),
            work.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.occluders),
        ];
        let group = f.view_group(gpu, &self.count_groups, &label, layout, &extra);
        rec.stage(&format!("{}.importance_map", self.name), |enc| {
            enc.clear_buffer(work, 0, None);
            gpu.dispatch_2d(enc, &label, pipeline, &[&group], f.gbuffer.width, f.gbuffer.height);
        });
    }

    /// Every NoTW layer's warps from its count map ([`LayerPasses::count`]), one dispatch a step
    /// over all layers (stage `{name}.importance_map`; layers without view samples are left as
    /// they were). Only for layers whose owner reads the view.
    pub fn analyze(&self, gpu: &Gpu, rec: &mut Recorder, layers: &Layers) {
        let (layout, pipelines) = self.analysis.as_ref().expect("the layers' owner analyses NoTW maps");
        let (work, fwork) = (layers.work.as_ref().expect("with the analysis"), layers.fwork.as_ref().expect("with the analysis"));
        let label = format!("{}.analyze", self.name);
        let entries = [
            self.params.as_entire_binding(),
            layers.dv.as_entire_binding(),
            work.as_entire_binding(),
            fwork.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.views[0]),
            wgpu::BindingResource::TextureView(&self.views[1]),
        ];
        let entries: Vec<wgpu::BindGroupEntry> =
            entries.into_iter().enumerate().map(|(i, resource)| wgpu::BindGroupEntry { binding: i as u32, resource }).collect();
        let group = self.analysis_groups.entries(gpu, &label, layout, &entries);
        let (res, n) = (layers.res, layers.count);
        let functions = [res.div_ceil(64), 1, n];
        let smooth = [res.div_ceil(8), res.div_ceil(SMOOTH_BLOCK).div_ceil(8), n];
        rec.stage(&format!("{}.importance_map", self.name), |enc| {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(&label), timestamp_writes: None });
            pass.set_bind_group(0, &group, &[]);
            for (pipeline, groups) in pipelines.iter().zip([functions, smooth, functions, functions, smooth]) {
                pass.set_pipeline(pipeline);
                gpu.dispatch(&mut pass, groups);
            }
        });
    }

    /// The evaluation over the view; with `counting` the lab's analysis variant (each layer's
    /// samples per warped texel, in its slice of the counts).
    pub fn record(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, layers: &Layers, counting: bool) {
        let extra = [
            self.params.as_entire_binding(),
            layers.dv.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.views[0]),
            wgpu::BindingResource::TextureView(&self.views[1]),
            wgpu::BindingResource::TextureView(&self.views[2]),
            wgpu::BindingResource::Sampler(&self.sampler),
            layers.counts.as_entire_binding(),
        ];
        let label = format!("{}.final_pass", self.name);
        let group = f.view_group(gpu, &self.groups, &label, &self.layout, &extra);
        self.eval.record(gpu, rec, &label, &layers.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
    }
}

impl Warped {
    /// The DV bounds as this map's passes bind them (its slice of a shared buffer when layered).
    pub(super) fn dv_binding(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer: &self.dv, offset: self.dv_offset, size: wgpu::BufferSize::new(32) })
    }

    /// The sample counts as the evaluation binds them.
    pub(super) fn counts_binding(&self) -> wgpu::BindingResource<'_> {
        let n = self.res as u64 * self.res as u64;
        wgpu::BindingResource::Buffer(wgpu::BufferBinding {
            buffer: &self.counts,
            offset: self.counts_offset,
            size: wgpu::BufferSize::new(n * 4),
        })
    }
}
