//! G-buffer pass (position + linear depth, geometric normal, albedo, motion) and the evaluation
//! mask for one light.

use wgpu::TextureFormat as F;

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::{compose, flag};
use crate::{binding, raster, Gpu};

const GBUFFER_WGSL: &str = include_str!("gbuffer.wgsl");
const MASK_WGSL: &str = include_str!("mask.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("gbuffer.wgsl", compose(GBUFFER_WGSL, true)), ("mask.wgsl", compose(MASK_WGSL, false))]
}

pub const POSITION_FORMAT: F = F::Rgba32Float;
pub const NORMAL_FORMAT: F = F::Rgba32Float;
pub const ALBEDO_FORMAT: F = F::Rgba8Unorm;
pub const MOTION_FORMAT: F = F::Rg32Float;

/// The G-buffer of one view. Position `w` is the linear view depth (0 where empty). Cloning
/// shares the targets (wgpu handles); the viewer's progressive reference swaps in its own mask.
#[derive(Clone)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub position: wgpu::Texture,
    pub normal: wgpu::Texture,
    pub albedo: wgpu::Texture,
    pub motion: wgpu::Texture,
    pub depth: wgpu::Texture,
    /// u32 per pixel: 1 = evaluated for the current light.
    pub mask: wgpu::Buffer,
    pub position_view: wgpu::TextureView,
    pub normal_view: wgpu::TextureView,
    pub albedo_view: wgpu::TextureView,
    pub motion_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
}

impl GBuffer {
    pub fn new(gpu: &Gpu, w: u32, h: u32) -> GBuffer {
        let c = wgpu::TextureUsages::COPY_SRC;
        let position = raster::render_target(gpu, "gbuffer.position", w, h, POSITION_FORMAT, c);
        let normal = raster::render_target(gpu, "gbuffer.normal", w, h, NORMAL_FORMAT, c);
        let depth = raster::render_target(gpu, "gbuffer.depth", w, h, raster::DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let albedo = raster::render_target(gpu, "gbuffer.albedo", w, h, ALBEDO_FORMAT, c);
        let motion = raster::render_target(gpu, "gbuffer.motion", w, h, MOTION_FORMAT, c);
        GBuffer {
            width: w,
            height: h,
            position_view: position.create_view(&Default::default()),
            normal_view: normal.create_view(&Default::default()),
            position,
            normal,
            albedo_view: albedo.create_view(&Default::default()),
            motion_view: motion.create_view(&Default::default()),
            albedo,
            motion,
            depth_view: depth.create_view(&Default::default()),
            depth,
            mask: gpu.storage("gbuffer.mask", (w * h * 4) as u64),
        }
    }
    pub fn pixels(&self) -> usize {
        (self.width * self.height) as usize
    }
    /// The position target's view with its size (what a reduction over the samples reads).
    pub fn position_input(&self) -> (&wgpu::TextureView, u32, u32) {
        (&self.position_view, self.width, self.height)
    }
}

/// The G-buffer's colour targets, in attachment order.
pub const TARGET_FORMATS: [F; 4] = [POSITION_FORMAT, NORMAL_FORMAT, ALBEDO_FORMAT, MOTION_FORMAT];

/// Bytes per sample of the G-buffer's colour attachments as WebGPU counts them (each target's
/// cost, aligned to its component size): 48, above WebGPU's default limit of 32.
pub fn bytes_per_sample() -> u32 {
    TARGET_FORMATS.iter().fold(0, |total, f| {
        let align = f.target_component_alignment().expect("a colour format");
        total.div_ceil(align) * align + f.target_pixel_byte_cost().expect("a colour format")
    })
}

/// Refuses a device whose colour-attachment limit the G-buffer exceeds, naming the limit (a
/// browser at WebGPU's default limits: nothing can be compared there).
pub fn check_limits(limits: &wgpu::Limits) -> Result<(), crate::GpuError> {
    let (need, have) = (bytes_per_sample(), limits.max_color_attachment_bytes_per_sample);
    if need > have {
        return Err(crate::GpuError::Invalid(format!(
            "the G-buffer needs {need} colour attachment bytes per sample, this device offers {have} (max_color_attachment_bytes_per_sample)"
        )));
    }
    Ok(())
}

/// Pipelines for the G-buffer and mask passes.
pub struct GBufferPass {
    raster: wgpu::RenderPipeline,
    frame_layout: wgpu::BindGroupLayout,
    groups: binding::GroupCache,
    mask: MaskPass,
}

/// The evaluation mask pass alone (a host draws its own G-buffer).
pub struct MaskPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    groups: binding::GroupCache,
}

impl MaskPass {
    pub fn new(gpu: &Gpu) -> MaskPass {
        let layout = binding::layout(
            &gpu.device,
            "mask",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::uniform(), binding::texture_float(), binding::texture_float(), binding::storage(false)],
        );
        let pipeline = gpu.compute_pipeline("mask", &compose(MASK_WGSL, false), "main", &[&layout]);
        MaskPass { pipeline, layout, groups: Default::default() }
    }

    /// Writes `g.mask` for one light (stage `mask`).
    pub fn record(&self, gpu: &Gpu, rec: &mut Recorder, frame: &wgpu::Buffer, light: &wgpu::Buffer, g: &GBuffer) {
        let group = self.groups.get(
            gpu,
            "mask",
            &self.layout,
            &[
                frame.as_entire_binding(),
                light.as_entire_binding(),
                wgpu::BindingResource::TextureView(&g.position_view),
                wgpu::BindingResource::TextureView(&g.normal_view),
                g.mask.as_entire_binding(),
            ],
        );
        rec.stage("mask", |enc| gpu.dispatch_2d(enc, "mask", &self.pipeline, &[&group], g.width, g.height));
    }
}

impl GBufferPass {
    pub fn new(gpu: &Gpu, scene: &GpuScene) -> GBufferPass {
        let d = &gpu.device;
        let vf = wgpu::ShaderStages::VERTEX_FRAGMENT;
        let frame_layout = binding::layout(d, "gbuffer.frame", vf, &[binding::uniform()]);
        let targets: Vec<Option<wgpu::ColorTargetState>> = TARGET_FORMATS.iter().map(|f| Some((*f).into())).collect();
        // nothing to discard: the same fragments survive, without shading the hidden ones
        let discards = flag(scene.has_cutouts || scene.single_sided);
        let raster = raster::scene_pipeline_constants(
            gpu,
            "gbuffer",
            &compose(GBUFFER_WGSL, true),
            &[&frame_layout, &scene.layout],
            &targets,
            &[("DISCARDS", discards)],
        );
        GBufferPass { raster, frame_layout, groups: Default::default(), mask: MaskPass::new(gpu) }
    }

    /// Rasterises the scene into `g` (stage `gbuffer`).
    pub fn render(&self, gpu: &Gpu, rec: &mut Recorder, scene: &GpuScene, frame: &wgpu::Buffer, g: &GBuffer) {
        let group = self.groups.get(gpu, "gbuffer.frame", &self.frame_layout, &[frame.as_entire_binding()]);
        rec.stage("gbuffer", |enc| {
            let colors = [&g.position_view, &g.normal_view, &g.albedo_view, &g.motion_view];
            let mut pass = raster::begin_pass(enc, "gbuffer", &colors, &g.depth_view);
            pass.set_pipeline(&self.raster);
            pass.set_bind_group(0, &group, &[]);
            pass.set_bind_group(1, &scene.group, &[]);
            pass.draw(0..scene.triangle_count * 3, 0..1);
        });
    }

    /// Writes `g.mask` for one light (stage `mask`).
    pub fn mask(&self, gpu: &Gpu, rec: &mut Recorder, frame: &wgpu::Buffer, light: &wgpu::Buffer, g: &GBuffer) {
        self.mask.record(gpu, rec, frame, light, g);
    }
}
