//! The technique trait and the frame types every technique and every host shares: what a
//! technique reads for one view ([`FrameInputs`]), what it reports ([`TechniqueReport`]), how
//! `shadowlab techniques` describes it ([`TechniqueInfo`]), and the view bindings of a
//! visibility pass (`techniques/view.wgsl`). The list of techniques is [`crate::registry`].

use std::collections::BTreeMap;

use serde::Serialize;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::SamplingStats;
use shadowlab_core::params::{ParamDef, ParamTable, ParamValues};

use crate::gbuffer::GBuffer;
use crate::record::{Recorded, Recorder};
use crate::scene_gpu::GpuScene;
use crate::{Gpu, GpuError};

/// Everything a technique reads for one view and one light; it writes `visibility`
/// (f32 per pixel, 1 lit, 0 shadowed) for the pixels where `gbuffer.mask` is 1.
pub struct FrameInputs<'a> {
    pub scene: &'a GpuScene,
    pub gbuffer: &'a GBuffer,
    pub light: Light,
    /// The view's camera (CPU copy of what `frame` holds; the output size is `gbuffer.width/height`),
    /// for techniques that fit their maps to the view frustum (cascades, tiles).
    pub camera: Camera,
    /// The previous frame's camera (equal to `camera` on a single view).
    pub prev_camera: Camera,
    /// `LightUniform` of `light`.
    pub light_buf: &'a wgpu::Buffer,
    /// `FrameUniform` of the view.
    pub frame: &'a wgpu::Buffer,
    pub visibility: &'a wgpu::Buffer,
}

/// The view inputs of `view.wgsl`: group 0 bindings 0-5, prepended to visibility shaders.
pub const VIEW_WGSL: &str = include_str!("techniques/view.wgsl");

/// `common.wgsl` (+ `scene.wgsl`) + `view.wgsl` + `body`.
pub fn compose_view(body: &str, with_scene: bool) -> String {
    crate::shaders::compose(&format!("{VIEW_WGSL}{body}"), with_scene)
}

/// Bind group layout for a visibility pass: the six view bindings of `view.wgsl`, then `extra`
/// numbered from 6.
pub fn view_layout(gpu: &Gpu, label: &str, extra: &[wgpu::BindingType]) -> wgpu::BindGroupLayout {
    use crate::binding::{storage, texture_float, uniform};
    let mut types = vec![uniform(), uniform(), texture_float(), texture_float(), storage(true), storage(false)];
    types.extend_from_slice(extra);
    crate::binding::layout(&gpu.device, label, wgpu::ShaderStages::COMPUTE, &types)
}

impl FrameInputs<'_> {
    /// Bind group for [`view_layout`]: the view inputs, then `extra` from binding 6; kept in
    /// `cache` while they are the same objects (no bind group per frame).
    pub fn view_group(
        &self,
        gpu: &Gpu,
        cache: &crate::binding::GroupCache,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        extra: &[wgpu::BindingResource],
    ) -> wgpu::BindGroup {
        let mut res = vec![
            self.frame.as_entire_binding(),
            self.light_buf.as_entire_binding(),
            wgpu::BindingResource::TextureView(&self.gbuffer.position_view),
            wgpu::BindingResource::TextureView(&self.gbuffer.normal_view),
            self.gbuffer.mask.as_entire_binding(),
            self.visibility.as_entire_binding(),
        ];
        res.extend_from_slice(extra);
        cache.get(gpu, label, layout, &res)
    }
}

/// A technique's evaluation and its analysis variant: the same shader compiled twice, once as
/// shipped and once with `COUNT_SAMPLES` (the view samples counted per texel, lab only).
pub struct EvalPipelines {
    timed: wgpu::ComputePipeline,
    counting: wgpu::ComputePipeline,
}

impl EvalPipelines {
    /// Both pipelines of `source`'s `main` over `layout`, with `constants` (and `COUNT_SAMPLES`).
    pub fn new(gpu: &Gpu, label: &str, source: &str, layout: &wgpu::BindGroupLayout, constants: &[(&str, f64)]) -> EvalPipelines {
        let timed = gpu.compute_pipeline_with(label, source, "main", &[layout], constants);
        let mut with_counts = constants.to_vec();
        with_counts.extend_from_slice(crate::context::COUNTING);
        let counting = gpu.compute_pipeline_with(label, source, "main", &[layout], &with_counts);
        EvalPipelines { timed, counting }
    }

    /// Records the evaluation over the `w x h` view as stage `stage`; with `counting`, the
    /// analysis variant after clearing `counts`.
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        gpu: &Gpu,
        rec: &mut Recorder,
        stage: &str,
        counts: &wgpu::Buffer,
        group: &wgpu::BindGroup,
        w: u32,
        h: u32,
        counting: bool,
    ) {
        rec.stage(stage, |enc| {
            if counting {
                enc.clear_buffer(counts, 0, None);
            }
            gpu.dispatch_2d(enc, stage, if counting { &self.counting } else { &self.timed }, &[group], w, h)
        });
    }
}

/// Inside an `impl Technique for T`: [`Technique::evaluate`] and [`Technique::analyze`] as the
/// two variants of one evaluation, `T::eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec:
/// &mut Recorder, counting: bool) -> Result<(), GpuError>`: `evaluate` records it as shipped
/// (`counting` false), `analyze` the lab's variant that also counts the view samples per texel
/// (`counting` true, [`EvalPipelines`]).
macro_rules! counted_evaluation {
    () => {
        fn evaluate(
            &mut self,
            gpu: &$crate::Gpu,
            f: &$crate::technique::FrameInputs,
            rec: &mut $crate::record::Recorder,
        ) -> Result<(), $crate::GpuError> {
            self.eval_pass(gpu, f, rec, false)
        }

        fn analyze(
            &mut self,
            gpu: &$crate::Gpu,
            f: &$crate::technique::FrameInputs,
            rec: &mut $crate::record::Recorder,
        ) -> Result<(), $crate::GpuError> {
            self.eval_pass(gpu, f, rec, true)
        }
    };
}
pub(crate) use counted_evaluation;

/// An RGBA8 picture a technique offers the report (shadow maps, count maps, warps).
#[derive(Clone, Debug)]
pub struct NamedImage {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct TechniqueReport {
    /// GPU memory the technique keeps per light (maps, warps, tiles, masks; the BVH for `rt`).
    pub shadow_data_bytes: u64,
    /// Hardware-independent counters: `fetches_per_pixel`, `rays_traced`, ...
    pub counters: BTreeMap<String, f64>,
    /// How view samples land in the shadow map (shadow-map techniques).
    pub sampling: Option<SamplingStats>,
    /// Where the technique hit a capacity limit and gave a coarser (but deterministic) result,
    /// one line each; empty when the result is complete. The counters carry the numbers.
    pub degraded: Vec<String>,
    #[serde(skip)]
    pub images: Vec<NamedImage>,
}

/// One shadow technique for one light. Per frame the caller calls [`prepare`](Technique::prepare)
/// (analysis of the view samples, e.g. a warp), [`render`](Technique::render) (the shadow data)
/// and [`evaluate`](Technique::evaluate) (the visibility buffer), each recording its passes into
/// the caller's encoder through `rec` under stage names `<technique>.<stage>`; none of them
/// submits or waits, except at the mid-frame readbacks the technique declares in
/// [`TechniqueInfo::stalls`] ([`Recorder::sync`]). The caller submits the frame.
///
/// The lab then, outside the timed frame, calls [`analyze`](Technique::analyze) (the analysis
/// passes only the lab needs: view samples counted per texel) and [`report`](Technique::report).
pub trait Technique {
    /// Per-frame analysis of the view before the shadow data is rendered (default: none).
    fn prepare(&mut self, _gpu: &Gpu, _f: &FrameInputs, _rec: &mut Recorder) -> Result<(), GpuError> {
        Ok(())
    }
    /// Renders the shadow data (maps, warps, tiles...) for this frame.
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError>;
    /// Writes `f.visibility` for every evaluated pixel.
    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError>;
    /// Lab-only instrumentation of the last frame (sampling statistics, counters), recorded
    /// after the frame and outside its timing. It reads the frame's shadow data and must not
    /// change the visibility (tests check it bit for bit). Default: none.
    fn analyze(&mut self, _gpu: &Gpu, _f: &FrameInputs, _rec: &mut Recorder) -> Result<(), GpuError> {
        Ok(())
    }
    /// Memory, counters, sampling statistics and pictures of the last frame (after `analyze`).
    fn report(&mut self, gpu: &Gpu) -> TechniqueReport;
}

/// prepare, render, evaluate: one frame, recorded.
pub fn run_frame(t: &mut dyn Technique, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
    t.prepare(gpu, f, rec)?;
    t.render(gpu, f, rec)?;
    t.evaluate(gpu, f, rec)
}

/// Records one frame of `t` into a fresh encoder and submits it once, without waiting; for
/// tests and simple callers. Returns the recorded frame's stalls.
pub fn submit_frame(t: &mut dyn Technique, gpu: &Gpu, f: &FrameInputs) -> Result<Recorded, GpuError> {
    let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
    let mut rec = Recorder::new(gpu, &mut enc);
    run_frame(t, gpu, f, &mut rec)?;
    let done = rec.finish();
    gpu.submit(enc.finish());
    Ok(done)
}

pub type CreateFn = fn(&Gpu, &GpuScene, &ParamValues, &Light) -> Result<Box<dyn Technique>, GpuError>;

/// What `shadowlab techniques` lists, and how to make one.
pub struct TechniqueInfo {
    pub name: &'static str,
    pub summary: &'static str,
    pub cost: &'static str,
    pub quality: &'static str,
    pub source: &'static str,
    /// Light types it supports.
    pub lights: &'static [&'static str],
    /// Its parameter set (`ParamTable::of::<Settings>()`): the rows listed, the rules checked.
    pub params: ParamTable,
    /// Mid-frame readbacks (the frame is submitted and waited for at that point), and any
    /// delayed mode that avoids them; empty when a frame records without a stall.
    pub stalls: &'static str,
    /// Device features and limits needed beyond WebGPU's defaults (empty: none).
    pub needs: &'static str,
    /// The most storage buffers one shader stage of it binds (WebGPU's default limit is 8):
    /// a device that offers fewer cannot run it ([`TechniqueInfo::check_limits`]).
    pub storage_buffers: u32,
    /// The specs `compare` runs when it is given none, as arguments (`""` = the defaults,
    /// `"pcf=3"` = `name:pcf=3`); empty: not in the default set (the reference, variants the
    /// default set already covers).
    pub compare: &'static [&'static str],
    /// (file name, composed source) of the shaders it uses, for the naga validation test
    /// (variants of one folder share the list).
    pub shaders: fn() -> Vec<(&'static str, String)>,
    pub create: CreateFn,
}

impl TechniqueInfo {
    /// Refuses a device whose limits the technique exceeds, naming the limit (before anything
    /// is made: a browser's adapter may offer WebGPU's default 8 storage buffers a stage).
    pub fn check_limits(&self, limits: &wgpu::Limits) -> Result<(), crate::GpuError> {
        let have = limits.max_storage_buffers_per_shader_stage;
        if self.storage_buffers > have {
            return Err(crate::GpuError::Invalid(format!(
                "'{}' is unavailable on this device: it needs {} storage buffers per shader stage, the device offers {have} (max_storage_buffers_per_shader_stage)",
                self.name, self.storage_buffers
            )));
        }
        Ok(())
    }

    /// The parameter table, in listing order.
    pub fn params(&self) -> &'static [ParamDef] {
        (self.params.defs)()
    }

    /// Applies the set's rules to `values` (all keys treated as defaults: none reported as
    /// ineffective), then creates the technique.
    pub fn create(&self, gpu: &Gpu, scene: &GpuScene, values: &ParamValues, light: &Light) -> Result<Box<dyn Technique>, GpuError> {
        (self.params.check)(values, &[]).map_err(|e| GpuError::Invalid(format!("technique '{}': {e}", self.name)))?;
        (self.create)(gpu, scene, values, light)
    }
}
