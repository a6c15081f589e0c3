//! The map of a frame (render.wgsl): `<name>.render` rasterises the scene from the light writing
//! b(z) per texel, `<name>.blur` pre-filters it (`blur` > 1, not with sd), `<name>.mips` builds
//! its mip chain (`mips`, mips.rs).

use super::{Filtered, MOMENTS_WGSL, PARAMS_WGSL};
use crate::blur::mip0;
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::technique::FrameInputs;
use crate::{binding, raster, Gpu};

const RENDER_WGSL: &str = include_str!("render.wgsl");

/// The composed moments raster (`FilteredParams` at group 0; leak tracing renders its sd maps with it).
pub fn render_source() -> String {
    compose(&format!("{MOMENTS_WGSL}{PARAMS_WGSL}{RENDER_WGSL}"), true)
}

/// The moments raster into a `format` target and its group (the uniform at binding 0).
pub(super) fn pipeline(
    gpu: &Gpu,
    scene: &GpuScene,
    name: &str,
    format: wgpu::TextureFormat,
    uniform: &wgpu::Buffer,
) -> (wgpu::RenderPipeline, wgpu::BindGroup) {
    let d = &gpu.device;
    let layout = binding::layout(d, name, wgpu::ShaderStages::VERTEX_FRAGMENT, &[binding::uniform()]);
    let group = binding::group(gpu, name, &layout, &[uniform.as_entire_binding()]);
    let target = wgpu::ColorTargetState { format, blend: None, write_mask: wgpu::ColorWrites::ALL };
    let pipeline = raster::scene_pipeline(gpu, &format!("{name}.render"), &render_source(), &[&layout, &scene.layout], &[Some(target)]);
    (pipeline, group)
}

impl Filtered {
    /// The `render`, `blur` and `mips` stages.
    pub(super) fn render_map(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        let name = self.kind.name();
        let map_view = mip0(&self.map);
        let depth_view = self.depth.create_view(&Default::default());
        rec.stage(&format!("{name}.render"), |enc| {
            let label = format!("{name}.render");
            let mut pass = raster::begin_pass_with(enc, &label, &[&map_view], self.clear, &depth_view, wgpu::StoreOp::Discard);
            pass.set_pipeline(&self.render_pipeline);
            pass.set_bind_group(0, &self.render_group, &[]);
            pass.set_bind_group(1, &f.scene.group, &[]);
            pass.draw(0..f.scene.triangle_count * 3, 0..1);
        });
        if let Some(blur) = &self.blur {
            let label = format!("{name}.blur");
            rec.stage(&label, |enc| blur.record(gpu, enc, &label));
        }
        if let Some(m) = &self.mips {
            let label = format!("{name}.mips");
            rec.stage(&label, |enc| m.record(gpu, enc, &label));
        }
    }
}
