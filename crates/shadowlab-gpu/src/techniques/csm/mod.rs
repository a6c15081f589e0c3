//! `csm`: cascaded shadow maps for directional lights (Engel 2006; seed 001 chapter 2.3 and its
//! CSM comparison in chapter 4). The view frustum is split along the view depth (practical
//! scheme or manual distances), each slice gets an orthographic map in one depth texture array,
//! fitted around the slice's bounding sphere, extended towards the light over the scene bounds,
//! texel-snapped; optionally only the depth range present in the G-buffer is split.
//! Stored depth: orthographic (linear), 0 = near the light.
//!
//! Per frame: `prepare` (with `tighten`) reduces the G-buffer's linear depth to [min, max] on
//! the GPU and reads it back (one device sync, timed as `csm.readback`), then fits the boxes to
//! the view's camera on the CPU (`shadowlab_core::techniques::csm`); `render` draws
//! the scene once per cascade; `evaluate` picks the cascade per pixel by view depth.
//!
//! `sdsm` (techniques/sdsm) renders and evaluates through a [`Cascaded`] whose boxes it fits to
//! the view samples instead, with the sample-bounds reduction of bounds.rs (which `iasm` uses
//! too).

mod bounds;
mod params;
mod report;

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use shadowlab_core::light::Light;
use shadowlab_core::params::{ParamSet, ParamTable};
use shadowlab_core::scene::Bounds;
use shadowlab_core::techniques::csm::{self as cascades, CascadeBox, Fit, ViewFrustum, MAX_CASCADES};

pub(crate) use bounds::{decode_bounds, source as bounds_source, BoundsReduce, OUT_WORDS as SDSM_OUT_WORDS};
pub use bounds::{SdsmReduce, OUT_BYTES as SDSM_BOUNDS_BYTES};
pub use params::*;

use crate::record::{DelayedRead, Recorder};
use crate::reduce::{decode, MinMax};
use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::technique::{compose_view, counted_evaluation, view_layout, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{binding, raster, Gpu, GpuError};

const DEPTH_WGSL: &str = include_str!("depth.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("csm/depth.wgsl", compose_depth(DEPTH_WGSL)), ("csm/eval.wgsl", compose_view(EVAL_WGSL, false))]
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "csm",
    summary: "cascaded shadow maps: the view frustum split in depth, one snapped orthographic map per slice, cascade chosen per pixel",
    cost: "one G-buffer depth reduction + readback (a sync), one scene pass per cascade, N^2 fetches per pixel (x2 in the blend band)",
    quality: "texel size grows with distance like the view's footprint; seams at cascade switches; no shimmer when snapped",
    source: "Engel 2006; Zhang et al. 2006 (practical splits); seed 001 chapter 2.3 and 4; SDSM (Lauritzen 2011) for tightening",
    lights: &["directional"],
    params: ParamTable::of::<CsmSettings>(),
    stalls:
        "with tighten=true (default): csm.readback, the view depth range read back before the fit; tighten=false, or delayed=true (the previous frame's range), records without a stall",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(Cascaded::new(gpu, scene, &CsmSettings::from_values(p), light)?)),
};

/// WGSL `Cascade` (eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CascadeU {
    pub view_proj: [[f32; 4]; 4],
    /// x: world texel size, y/z: slice near/far view depth.
    pub info: [f32; 4],
}

/// WGSL `CsmParams` (eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CsmParams {
    pub cascades: [CascadeU; MAX_CASCADES],
    /// Cascades in use.
    pub count: f32,
    pub res: f32,
    pub pcf: f32,
    /// Blend band (fraction of a slice).
    pub blend: f32,
    /// Texels.
    pub bias: f32,
    /// Texels.
    pub normal_offset: f32,
    pub max_slope: f32,
    pub pad0: f32,
}

/// Bytes of the probe buffer the CPU reads each frame with `tighten`: the min/max words.
const PROBE_BYTES: u64 = 8;

pub struct Cascaded {
    pub(crate) groups: crate::binding::GroupCache,
    /// `csm` or `sdsm`: the stage names' prefix.
    name: &'static str,
    count: usize,
    res: u32,
    lambda: f32,
    manual: Vec<f32>,
    snap: bool,
    fit: Fit,
    tighten: bool,
    /// With `tighten`: the previous frame's range, read back without a stall.
    delayed: Option<DelayedRead>,
    pcf: u32,
    dir: Vec3,
    params: CsmParams,
    boxes: Vec<CascadeBox>,
    depth_range: Option<(f32, f32)>,
    maps: wgpu::Texture,
    /// Views of `maps`, made once: the array (evaluation), each layer (its depth pass).
    maps_view: wgpu::TextureView,
    layer_views: Vec<wgpu::TextureView>,
    counts: wgpu::Buffer,
    /// Per pixel cascade tags of the last evaluation, with its size.
    chosen: Option<(wgpu::Buffer, u32, u32)>,
    uniform: wgpu::Buffer,
    depth_uniforms: Vec<wgpu::Buffer>,
    depth_groups: Vec<wgpu::BindGroup>,
    depth_pipeline: wgpu::RenderPipeline,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    eval_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    reduce: MinMax,
    probe: wgpu::Buffer,
}

/// The settings `csm` and `sdsm` both declare, as [`Cascaded::build`] reads them.
pub(crate) struct Shared<'a> {
    pub maps: &'a CascadeMaps,
    pub lookup: &'a CascadeLookup,
    pub lambda: f64,
    pub blend: f64,
    pub snap: bool,
}

fn texture_depth_array() -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Depth,
        view_dimension: wgpu::TextureViewDimension::D2Array,
        multisampled: false,
    }
}

impl Cascaded {
    /// `csm` (settings that break [`CsmSettings`]'s rules are an error).
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &CsmSettings, light: &Light) -> Result<Cascaded, GpuError> {
        p.validate().map_err(|e| GpuError::Invalid(format!("csm: {e}")))?;
        let shared = Shared { maps: &p.maps, lookup: &p.lookup, lambda: p.lambda, blend: p.blend, snap: p.snap };
        let mut t = Cascaded::build(gpu, scene, light, "csm", shared)?;
        t.manual = p.manual_splits().into_iter().map(|(_, d)| d).collect();
        t.fit = p.fit.into();
        t.tighten = p.tighten;
        t.delayed = (t.tighten && p.delayed).then(|| DelayedRead::new(gpu, "csm.delayed", PROBE_BYTES));
        Ok(t)
    }

    /// What `csm` and `sdsm` share, from the parameters both declare; `name` prefixes the stage
    /// names.
    pub(crate) fn build(gpu: &Gpu, scene: &GpuScene, light: &Light, name: &'static str, p: Shared) -> Result<Cascaded, GpuError> {
        let Light::Directional { direction } = *light else {
            return Err(GpuError::Invalid(format!("{name} supports directional lights only (got a {} light)", light.kind())));
        };
        let count = p.maps.cascades as usize;
        let res = p.maps.res;
        gpu.check_size(res, res, "cascade map")?;
        let d = &gpu.device;
        let maps = raster::depth_target(gpu, "csm.maps", res, res, count as u32, wgpu::TextureUsages::empty());
        let params = CsmParams {
            cascades: [CascadeU::zeroed(); MAX_CASCADES],
            count: count as f32,
            res: res as f32,
            pcf: p.lookup.pcf as f32,
            blend: p.blend as f32,
            bias: p.lookup.bias as f32,
            normal_offset: p.lookup.normal_offset as f32,
            max_slope: p.lookup.max_slope as f32,
            pad0: 0.0,
        };
        let uniform = gpu.uniform("csm.params", &params);
        let depth_layout = binding::layout(d, "csm.depth", wgpu::ShaderStages::VERTEX, &[binding::uniform()]);
        let depth_uniforms: Vec<_> = (0..count).map(|_| gpu.uniform("csm.cascade", &Mat4::IDENTITY.to_cols_array_2d())).collect();
        let depth_groups =
            depth_uniforms.iter().map(|u| binding::group(gpu, "csm.depth", &depth_layout, &[u.as_entire_binding()])).collect();
        let depth_pipeline =
            raster::depth_pipeline(gpu, "csm.depth", &compose_depth(DEPTH_WGSL), &[&depth_layout, &scene.layout], scene.has_cutouts);
        let eval_layout = view_layout(
            gpu,
            "csm.eval",
            &[binding::uniform(), texture_depth_array(), binding::comparison_sampler(), binding::storage(false), binding::storage(false)],
        );
        let eval = crate::technique::EvalPipelines::new(gpu, "csm.eval", &compose_view(EVAL_WGSL, false), &eval_layout, &[]);
        let sampler = raster::comparison_sampler(gpu, "csm.cmp");
        let counts = gpu.storage("csm.counts", count as u64 * res as u64 * res as u64 * 4);
        Ok(Cascaded {
            groups: Default::default(),
            name,
            count,
            res,
            lambda: p.lambda as f32,
            manual: Vec::new(),
            snap: p.snap,
            fit: Fit::Box,
            tighten: false,
            delayed: None,
            pcf: p.lookup.pcf,
            dir: direction,
            params,
            boxes: Vec::new(),
            depth_range: None,
            maps_view: maps
                .create_view(&wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() }),
            layer_views: (0..count as u32).map(|c| layer_view(&maps, c)).collect(),
            maps,
            counts,
            chosen: None,
            uniform,
            depth_uniforms,
            depth_groups,
            depth_pipeline,
            eval,
            eval_layout,
            sampler,
            reduce: MinMax::new(gpu, "csm.reduce", 3),
            probe: gpu.storage("csm.probe", PROBE_BYTES),
        })
    }

    /// The boxes of the last frame (for tests and leak tracing).
    pub fn boxes(&self) -> &[CascadeBox] {
        &self.boxes
    }

    /// Cascades in use.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// Side of each cascade's map (texels).
    pub(crate) fn res(&self) -> u32 {
        self.res
    }

    /// Whether the boxes are snapped (`snap`).
    pub(crate) fn snap(&self) -> bool {
        self.snap
    }

    /// The split blend (`lambda`).
    pub(crate) fn lambda(&self) -> f32 {
        self.lambda
    }

    /// The light's direction.
    pub(crate) fn light_dir(&self) -> Vec3 {
        self.dir
    }

    /// The G-buffer's min/max view-depth reduction.
    pub(crate) fn depth_reduce(&self) -> &MinMax {
        &self.reduce
    }

    /// The boxes of the view slices between `splits` (n + 1 view depths), fitted by `fit` and
    /// extended over `scene`, with this map's light, size and snapping.
    pub(crate) fn slice_boxes(&self, frustum: &ViewFrustum, scene: &Bounds, splits: &[f32], fit: Fit) -> Vec<CascadeBox> {
        cascades::fit_cascades(frustum, self.dir, scene, splits, self.res, self.snap, fit)
    }

    /// A frame's fit from outside (`sdsm`): the G-buffer's depth range (None: not known), the
    /// slice boxes (what [`Cascaded::boxes`] reports), and the (world -> light clip, texel size)
    /// of each cascade as the depth passes and the evaluation use it, between `splits`.
    pub(crate) fn set_fit(
        &mut self,
        rec: &mut Recorder,
        depth_range: Option<(f32, f32)>,
        slices: Vec<CascadeBox>,
        used: &[(Mat4, f32)],
        splits: &[f32],
    ) {
        self.depth_range = depth_range;
        self.upload(rec, used, splits);
        self.boxes = slices;
    }
}

/// A view of one layer of `maps` (a cascade's depth target).
fn layer_view(maps: &wgpu::Texture, layer: u32) -> wgpu::TextureView {
    maps.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2),
        base_array_layer: layer,
        array_layer_count: Some(1),
        ..Default::default()
    })
}

impl Technique for Cascaded {
    /// Depth reduction on the GPU and one readback (with `tighten`), the fit on the CPU.
    fn prepare(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.depth_range = None;
        if let Some(d) = self.delayed.as_mut() {
            // the previous frame's range (None on the first frame: the whole frustum), then this
            // frame's reduction for the next one
            self.depth_range = d.take::<u32>(gpu, 2).and_then(|w| decode([w[0], w[1]]));
            rec.stage("csm.analyze", |enc| self.reduce.record(gpu, enc, "csm.reduce", f.gbuffer.position_input(), &f.gbuffer.mask));
            d.record(rec, &self.reduce.result);
        } else if self.tighten {
            rec.stage("csm.analyze", |enc| {
                self.reduce.record(gpu, enc, "csm.reduce", f.gbuffer.position_input(), &f.gbuffer.mask);
                enc.copy_buffer_to_buffer(&self.reduce.result, 0, &self.probe, 0, PROBE_BYTES);
            });
            let t0 = web_time::Instant::now();
            let words: Vec<u32> = rec.read_buffer_as(&self.probe, 2, "csm.readback");
            rec.cpu("csm.readback", t0.elapsed().as_secs_f64() * 1e3);
            self.depth_range = decode([words[0], words[1]]);
        }

        let t0 = web_time::Instant::now();
        let view_proj = f.camera.view_proj(f.gbuffer.width, f.gbuffer.height);
        let frustum = ViewFrustum::from_view_proj(view_proj, f.camera.position)
            .ok_or_else(|| GpuError::Invalid("csm: the view's projection is not a perspective frustum".into()))?;
        let (near, far) = cascades::depth_range(frustum.near, frustum.far, self.depth_range);
        let splits = if self.manual.is_empty() {
            cascades::practical_splits(near, far, self.count, self.lambda)
        } else {
            cascades::manual_splits(frustum.near, frustum.far, &self.manual).map_err(|e| GpuError::Invalid(format!("csm: {e}")))?
        };
        self.boxes = self.slice_boxes(&frustum, &f.scene.bounds, &splits, self.fit);
        let boxes: Vec<(Mat4, f32)> = self.boxes.iter().map(|b| (b.view_proj, b.texel)).collect();
        self.upload(rec, &boxes, &splits);
        rec.cpu("csm.fit", t0.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    fn render(&mut self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let stage = format!("{}.render", self.name);
        rec.stage(&stage, |enc| {
            for (c, view) in self.layer_views.iter().enumerate() {
                let mut pass = raster::begin_pass(enc, &stage, &[], view);
                pass.set_pipeline(&self.depth_pipeline);
                pass.set_bind_group(0, &self.depth_groups[c], &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                pass.draw(0..f.scene.triangle_count * 3, 0..1);
            }
        });
        Ok(())
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        report::report(self, gpu)
    }
}

impl Cascaded {
    /// Writes the cascades' (world -> light clip, world texel size) and their slices of view
    /// depth (`splits`, n + 1) into the evaluation's and the depth passes' uniforms.
    fn upload(&mut self, rec: &mut Recorder, boxes: &[(Mat4, f32)], splits: &[f32]) {
        for (i, (view_proj, texel)) in boxes.iter().enumerate() {
            self.params.cascades[i] = CascadeU { view_proj: view_proj.to_cols_array_2d(), info: [*texel, splits[i], splits[i + 1], 0.0] };
            rec.write_buffer(&self.depth_uniforms[i], 0, bytemuck::bytes_of(&view_proj.to_cols_array_2d()));
        }
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.params));
    }

    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let (w, h) = (f.gbuffer.width, f.gbuffer.height);
        if !matches!(self.chosen, Some((_, cw, ch)) if cw == w && ch == h) {
            self.chosen = Some((gpu.storage("csm.chosen", w as u64 * h as u64 * 4), w, h));
        }
        let chosen = &self.chosen.as_ref().expect("allocated above").0;
        let group = f.view_group(
            gpu,
            &self.groups,
            "csm.eval",
            &self.eval_layout,
            &[
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&self.maps_view),
                wgpu::BindingResource::Sampler(&self.sampler),
                self.counts.as_entire_binding(),
                chosen.as_entire_binding(),
            ],
        );
        self.eval.record(gpu, rec, &format!("{}.evaluate", self.name), &self.counts, &group, w, h, counting);
        Ok(())
    }
}
