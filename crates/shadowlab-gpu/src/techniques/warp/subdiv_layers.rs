//! One subdivision for every layer of a [`Layers`] (`cube-notw`'s faces, `dpsm`'s hemispheres),
//! instead of one a map: the layers' triangles are one scene (each layer a range of it; with
//! [`Layers::repeating_scene`] a copy of the frame's scene each), every piece is tested with
//! its layer's uniform, DV bounds, warps and pyramid (subdiv_layers.wgsl over subdiv.wgsl), and
//! the finished pieces are listed by layer (subdiv_scatter.wgsl; the lists follow the pieces in
//! their buffer, a word an entry), so that each layer's depth pass draws its triangles' own
//! slots and its list ([`LayerDraw`], two indirect draws). The dispatches of a frame are those
//! of one map's subdivision and one more (the scatter), for any number of layers; the pieces of
//! all layers live at once (the capacity: `subdiv::capacity`, for layers of their own
//! triangles 3 pieces a texel of all layers at least).

use super::layers::{LAYER_BIND_WGSL, LAYER_WARPS_WGSL};
use super::occluders::Pyramid;
use super::subdiv::{self, Buffers, SUBDIV_WGSL, TESS_WGSL};
use super::{report, LayerPasses, Layers, WarpParams, Warped, LOOKUP_FNS_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::{compose, flag};
use crate::technique::TechniqueReport;
use crate::{binding, Gpu, GpuError};

const SUBDIV_LAYERS_WGSL: &str = include_str!("subdiv_layers.wgsl");
const SUBDIV_SCATTER_WGSL: &str = include_str!("subdiv_scatter.wgsl");
const TRIANGLE_LAYER_WGSL: &str = include_str!("triangle_layer.wgsl");

/// Whether maps of `p` list their flat pieces apart (`exact_tol` with exact depth, planar): the
/// pieces whose interpolated depth is close enough, drawn without the exact-depth stage.
pub(super) fn flat_split(p: &WarpParams) -> bool {
    p.exact_depth != 0 && p.exact_tol > 0.0 && p.projection == 0
}

/// The layers' triangle ranges as triangle_layer.wgsl reads them: `ends[l]` is one past layer
/// l's last triangle.
fn header(ends: &[u32]) -> String {
    let list: Vec<String> = ends.iter().map(|e| format!("{e}u")).collect();
    format!(
        "const LAYERS: u32 = {}u;\nconst LAYER_END = array<u32, {}>({});\n{TRIANGLE_LAYER_WGSL}",
        ends.len(),
        ends.len(),
        list.join(", ")
    )
}

/// The subdivision over layers ending at `ends` (subdiv.wgsl with subdiv_layers.wgsl).
pub fn layered_subdivision_source(ends: &[u32]) -> String {
    let h = header(ends);
    compose(
        &format!("{h}{PARAMS_WGSL}{LAYER_BIND_WGSL}{LAYER_WARPS_WGSL}{LOOKUP_FNS_WGSL}{SUBDIV_WGSL}{TESS_WGSL}{SUBDIV_LAYERS_WGSL}"),
        true,
    )
}

/// The scatter of the finished pieces to the layers' lists.
pub fn layered_scatter_source(ends: &[u32]) -> String {
    format!("{}{SUBDIV_SCATTER_WGSL}", header(ends))
}

/// Words of the counters after subdiv.wgsl's (triangle_layer.wgsl): two a layer, the
/// scatter's dispatch, twelve a layer of draw arguments.
fn layer_words(layers: u32) -> u64 {
    2 * layers as u64 + 3 + 12 * layers as u64
}

/// Byte offset of layer `l`'s draw arguments in the counters of `layers` layers.
fn draw_args_at(layers: u64, l: u64) -> u64 {
    (1048 + 2 * layers + 3 + 12 * l) * 4
}

/// A layer's share of its owner's subdivision, as its depth pass draws it: the pieces (and the
/// lists after them) and the counters holding its three draws' arguments at `args` (its
/// triangles' slots, its list, its list's flat pieces).
#[derive(Clone)]
pub struct LayerDraw {
    pub(super) pieces: wgpu::Buffer,
    pub(super) counters: wgpu::Buffer,
    pub(super) args: u64,
}

impl LayerDraw {
    /// The layer's pieces, drawn into the pass (its pipeline and groups set); the flat ones
    /// (`exact_tol`) with `flat`, the pipeline without the exact-depth fragment stage (none: not
    /// drawn, as the report's count of inversions wants).
    pub(super) fn draw(&self, pass: &mut wgpu::RenderPass, flat: Option<&wgpu::RenderPipeline>) {
        pass.draw_indirect(&self.counters, self.args);
        pass.draw_indirect(&self.counters, self.args + 16);
        if let Some(p) = flat {
            pass.set_pipeline(p);
            pass.draw_indirect(&self.counters, self.args + 32);
        }
    }
}

/// The subdivision of every layer of a [`Layers`] at once (`{name}.subdivide`).
pub struct LayerSubdivision {
    name: &'static str,
    ends: Vec<u32>,
    triangles: u32,
    /// The first layer's uniform with this subdivision's capacity (the report's knobs).
    params: WarpParams,
    /// The pieces' slots (the triangles', then the pieces they add), then the layers' lists.
    pieces: wgpu::Buffer,
    queues: [wgpu::Buffer; 2],
    counters: wgpu::Buffer,
    dispatch: wgpu::Buffer,
    /// The subdivision's passes (subdiv::entries); one group a level (0: the root).
    split: Vec<wgpu::ComputePipeline>,
    groups: Vec<wgpu::BindGroup>,
    scatter: wgpu::ComputePipeline,
    scatter_group: wgpu::BindGroup,
    /// `cull_hidden`: every layer's occluder pyramid, built before the subdivision.
    pyramids: Option<Pyramid>,
}

impl LayerSubdivision {
    /// The subdivision of `maps` (map i draws layer i of `layers`, made over `scene`, so that
    /// their piece capacity is this subdivision's), whose triangles below `ends[i]` (and from
    /// `ends[i - 1]`) are map i's (of `scene`'s, or with [`Layers::repeating_scene`] of as many
    /// copies of it, one a layer); it binds `passes`' uniforms and warps.
    pub fn new(
        gpu: &Gpu,
        name: &'static str,
        layers: &Layers,
        passes: &LayerPasses,
        maps: &[&Warped],
        scene: &GpuScene,
        ends: &[u32],
    ) -> Result<LayerSubdivision, GpuError> {
        assert!(layers.owner_subdivides && maps.len() == ends.len() && ends.len() as u32 == layers.count(), "{name}: one map a layer");
        let copies = if layers.repeats_scene { layers.count() } else { 1 };
        let triangles = scene.triangle_count * copies;
        assert!(ends.windows(2).all(|w| w[0] <= w[1]) && ends.last() == Some(&triangles), "{name}: the layers' ranges");
        let params: Vec<_> = maps.iter().map(|m| m.params).collect();
        // the maps were planned for it (build.rs: subdiv::capacity with their layers' texels)
        let extra = params[0].extra_capacity;
        assert!(params.iter().all(|p| (p.triangles, p.extra_capacity) == (triangles, extra)), "{name}: maps planned for this subdivision");
        let max_binding = gpu.limits.max_storage_buffer_binding_size;
        let queue = subdiv::queue_capacity(triangles, max_binding, Some(layers.listed_texels()));
        let levels = subdiv::level_count(&params[0]);
        let array = wgpu::BindingType::Texture {
            sample_type: wgpu::TextureSampleType::Float { filterable: false },
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let (ro, rw) = (binding::storage(true), binding::storage(false));
        let entries = [
            (6, binding::uniform()),
            (7, ro),
            (8, array),
            (9, array),
            (10, rw),
            (11, rw),
            (12, rw),
            (13, rw),
            (14, binding::uniform()),
            (15, ro),
        ];
        let layout = super::layout_at(gpu, &format!("{name}.subdivide"), wgpu::ShaderStages::COMPUTE, &entries);
        let mut constants = subdiv::constants(&params[0], triangles, extra);
        constants.extend([
            ("DV_STRIDE", (layers.dv_stride / 4) as f64),
            ("HZB_STRIDE", (layers.hzb_stride / 4) as f64),
            ("FLAT_SPLIT", flag(flat_split(&params[0]))),
        ]);
        let src = layered_subdivision_source(ends);
        let split = subdiv::entries(&params[0])
            .iter()
            .map(|e| gpu.compute_pipeline_with(&format!("{name}.{e}"), &src, e, &[&layout, &scene.layout], &constants))
            .collect();
        let scatter_layout = binding::layout(&gpu.device, &format!("{name}.scatter"), wgpu::ShaderStages::COMPUTE, &[rw, rw]);
        let scatter = gpu.compute_pipeline_with(
            &format!("{name}.scatter"),
            &layered_scatter_source(ends),
            "scatter",
            &[&scatter_layout],
            &[("TRIANGLES", triangles as f64), ("EXTRA_CAPACITY", extra as f64)],
        );
        let pieces =
            gpu.storage(&format!("{name}.pieces"), (triangles as u64 + extra as u64) * 16 + (extra as u64 * 4).next_multiple_of(16));
        let queue_bytes = subdiv::queue_bytes(&WarpParams { extra_capacity: extra, ..params[0] }, queue, max_binding);
        let queues = [0, 1].map(|i| gpu.storage(&format!("{name}.queue{i}"), queue_bytes));
        let counters = subdiv::counters_buffer(gpu, &format!("{name}.counters"), layer_words(layers.count()));
        let level_uniforms = subdiv::level_uniforms(gpu, name, levels, queue);
        // the pyramids (`cull_hidden`), or a stand-in never read
        let hzb = layers.hzb.as_ref().unwrap_or(&layers.dv);
        // level l reads queue (l + 1) % 2 and writes the other; the root writes queue 0
        let groups = (0..=levels as usize)
            .map(|l| {
                let qi = (l + 1) % 2;
                let resources = [
                    passes.params.as_entire_binding(),
                    layers.dv.as_entire_binding(),
                    wgpu::BindingResource::TextureView(&passes.views[0]),
                    wgpu::BindingResource::TextureView(&passes.views[1]),
                    pieces.as_entire_binding(),
                    counters.as_entire_binding(),
                    queues[qi].as_entire_binding(),
                    queues[1 - qi].as_entire_binding(),
                    level_uniforms[l.saturating_sub(1)].as_entire_binding(),
                    hzb.as_entire_binding(),
                ];
                let e: Vec<_> =
                    resources.into_iter().zip(6..).map(|(resource, binding)| wgpu::BindGroupEntry { binding, resource }).collect();
                gpu.bind_group(&wgpu::BindGroupDescriptor { label: Some(&format!("{name}.subdivide")), layout: &layout, entries: &e })
            })
            .collect();
        let scatter_group =
            binding::group(gpu, &format!("{name}.scatter"), &scatter_layout, &[pieces.as_entire_binding(), counters.as_entire_binding()]);
        let pyramids = layers.hzb.as_ref().map(|b| {
            let d = wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
            let constants = super::base_constants(&params[0]);
            let shared = Some((b, layers.count(), layers.hzb_stride));
            Pyramid::new(gpu, name, layers.res, &constants, &layers.occluders.create_view(&d), shared)
        });
        Ok(LayerSubdivision {
            pyramids,
            name,
            ends: ends.to_vec(),
            triangles,
            params: WarpParams { extra_capacity: extra, ..params[0] },
            dispatch: subdiv::dispatch_buffer(gpu, &format!("{name}.dispatch")),
            pieces,
            queues,
            counters,
            split,
            groups,
            scatter,
            scatter_group,
        })
    }

    /// Layer `l`'s draws.
    pub fn draw(&self, l: usize) -> LayerDraw {
        LayerDraw { pieces: self.pieces.clone(), counters: self.counters.clone(), args: draw_args_at(self.ends.len() as u64, l as u64) }
    }

    /// The `subdivide` stage over the scene of `scene_group` (after the layers' warps and, with
    /// `cull_hidden`, their occluder maps): the levels, then the finished pieces listed by layer.
    pub fn record(&self, gpu: &Gpu, rec: &mut Recorder, scene_group: &wgpu::BindGroup) {
        let b = Buffers { counters: &self.counters, dispatch: &self.dispatch };
        rec.stage(&format!("{}.subdivide", self.name), |enc| {
            if let Some(p) = &self.pyramids {
                p.record(gpu, enc);
            }
            subdiv::record_passes(gpu, enc, &self.split, &self.groups, scene_group, b, self.triangles);
            // the scatter's groups (triangle_layer.wgsl SCATTER_ARGS_AT)
            enc.copy_buffer_to_buffer(&self.counters, (1048 + 2 * self.ends.len() as u64) * 4, &self.dispatch, 0, 12);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("scatter"), timestamp_writes: None });
            pass.set_pipeline(&self.scatter);
            pass.set_bind_group(0, &self.scatter_group, &[]);
            gpu.dispatch_indirect(&mut pass, &self.dispatch, 0);
        });
    }

    /// The last frame's subdivision counters into `r` (as one map's, over `texels` texels of
    /// all layers), and per layer the pieces it drew (its triangles' slots and its finished
    /// pieces; 0 for a layer that drew nothing).
    pub fn report(&self, gpu: &Gpu, texels: usize, r: &mut TechniqueReport) -> Vec<u32> {
        let n = self.ends.len();
        let words: Vec<u32> = gpu.read_buffer_as(&self.counters, 1048 + layer_words(n as u32) as usize);
        let drawn: Vec<u32> = (0..n)
            .map(|l| {
                let d = (draw_args_at(n as u64, l as u64) / 4) as usize;
                (words[d] + words[d + 4] + words[d + 8]) / 3
            })
            .collect();
        report::subdivision_counters(&words[..24], drawn.iter().sum(), texels, &self.params, r);
        drawn
    }

    /// Bytes of its buffers (pieces and lists, queues, the layers' pyramids).
    pub fn bytes(&self) -> u64 {
        self.pieces.size() + self.queues.iter().map(|q| q.size()).sum::<u64>() + self.pyramids.as_ref().map_or(0, |p| p.buffer().size())
    }
}
