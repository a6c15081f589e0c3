//! Shading pass: turns a visibility buffer into a picture (RGBA8, sRGB).

use crate::gbuffer::GBuffer;
use crate::shaders::compose;
use crate::timing::StageTimer;
use crate::{binding, Gpu};

const SHADE_WGSL: &str = include_str!("shade.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("shade.wgsl", compose(SHADE_WGSL, false))]
}

pub struct ShadePass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    out: wgpu::Buffer,
}

impl ShadePass {
    pub fn new(gpu: &Gpu, g: &GBuffer) -> ShadePass {
        use binding::*;
        let layout = layout(
            &gpu.device,
            "shade",
            wgpu::ShaderStages::COMPUTE,
            &[uniform(), uniform(), texture_float(), texture_float(), texture_float(), storage(true), storage(true), storage(false)],
        );
        let pipeline = gpu.compute_pipeline("shade", &compose(SHADE_WGSL, false), "main", &[&layout]);
        ShadePass { pipeline, layout, out: gpu.storage("shade.color", g.pixels() as u64 * 4) }
    }

    /// Shades `visibility` and returns RGBA8 pixels (stage `shade`).
    pub fn shade(
        &self,
        gpu: &Gpu,
        timer: &mut StageTimer,
        frame: &wgpu::Buffer,
        light: &wgpu::Buffer,
        g: &GBuffer,
        visibility: &wgpu::Buffer,
    ) -> Vec<u8> {
        let views: Vec<_> = [&g.position, &g.normal, &g.albedo].iter().map(|t| t.create_view(&Default::default())).collect();
        let group = binding::group(
            &gpu.device,
            "shade",
            &self.layout,
            &[
                frame.as_entire_binding(),
                light.as_entire_binding(),
                wgpu::BindingResource::TextureView(&views[0]),
                wgpu::BindingResource::TextureView(&views[1]),
                wgpu::BindingResource::TextureView(&views[2]),
                g.mask.as_entire_binding(),
                visibility.as_entire_binding(),
                self.out.as_entire_binding(),
            ],
        );
        timer.stage(gpu, "shade", |enc| gpu.dispatch_2d(enc, "shade", &self.pipeline, &[&group], g.width, g.height));
        gpu.read_buffer(&self.out)[..g.pixels() * 4].to_vec()
    }
}
