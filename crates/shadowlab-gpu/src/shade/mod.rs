//! Shading pass: turns a visibility buffer into a picture (RGBA8, sRGB).

use crate::gbuffer::GBuffer;
use crate::record::Recorder;
use crate::shaders::compose;
use crate::technique::FrameInputs;
use crate::{binding, Gpu};

const SHADE_WGSL: &str = include_str!("shade.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("shade.wgsl", compose(SHADE_WGSL, false))]
}

/// The shading pipeline, created once per lab; each view brings its own output buffer.
pub struct ShadePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    /// The last group, kept while the view's buffers stay.
    groups: binding::GroupCache,
}

impl ShadePass {
    pub fn new(gpu: &Gpu) -> ShadePass {
        use binding::*;
        let layout = layout(
            &gpu.device,
            "shade",
            wgpu::ShaderStages::COMPUTE,
            &[uniform(), uniform(), texture_float(), texture_float(), texture_float(), storage(true), storage(true), storage(false)],
        );
        let pipeline = gpu.compute_pipeline("shade", &compose(SHADE_WGSL, false), "main", &[&layout]);
        ShadePass { pipeline, layout, groups: Default::default() }
    }

    /// A colour buffer (one packed RGBA8 word per pixel) for views of `g`'s size.
    pub fn output(gpu: &Gpu, g: &GBuffer) -> wgpu::Buffer {
        gpu.storage("shade.color", g.pixels() as u64 * 4)
    }

    /// Records the shading of `f.visibility` into `out` (see [`ShadePass::output`]; stage `shade`).
    pub fn record(&self, gpu: &Gpu, rec: &mut Recorder, f: &FrameInputs, out: &wgpu::Buffer) {
        let g = f.gbuffer;
        let group = self.groups.get(
            gpu,
            "shade",
            &self.layout,
            &[
                f.frame.as_entire_binding(),
                f.light_buf.as_entire_binding(),
                wgpu::BindingResource::TextureView(&g.position_view),
                wgpu::BindingResource::TextureView(&g.normal_view),
                wgpu::BindingResource::TextureView(&g.albedo_view),
                g.mask.as_entire_binding(),
                f.visibility.as_entire_binding(),
                out.as_entire_binding(),
            ],
        );
        rec.stage("shade", |enc| gpu.dispatch_2d(enc, "shade", &self.pipeline, &[&group], g.width, g.height));
    }

    /// Shades `visibility` into `out` (see [`ShadePass::output`]) and returns RGBA8 pixels.
    pub fn shade(&self, gpu: &Gpu, f: &FrameInputs, out: &wgpu::Buffer) -> Vec<u8> {
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("shade") });
        let mut rec = Recorder::new(gpu, &mut enc);
        self.record(gpu, &mut rec, f, out);
        rec.finish();
        gpu.submit(enc.finish());
        gpu.read_buffer(out)[..f.gbuffer.pixels() * 4].to_vec()
    }
}
