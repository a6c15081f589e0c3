//! Leak tracing's `<name>.render` pass: the static triangles into the static map's layers that
//! need it, the moving ones into every layer of the dynamic map (filtered/'s render.wgsl in
//! single-depth mode: linear light depth into R32Float, cleared to the farthest depth).

use std::ops::Range;

use super::resources::Resources;
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::technique::FrameInputs;
use crate::techniques::filtered::render_source;
use crate::{binding, raster, Gpu};

pub(super) struct MapPass {
    /// Per level: the bind group of its raster uniform.
    groups: Vec<wgpu::BindGroup>,
    pipeline: wgpu::RenderPipeline,
}

impl MapPass {
    /// The raster over `uniforms` (one per level).
    pub fn new(gpu: &Gpu, scene: &GpuScene, name: &str, uniforms: &[wgpu::Buffer]) -> MapPass {
        let d = &gpu.device;
        let layout = binding::layout(d, name, wgpu::ShaderStages::VERTEX_FRAGMENT, &[binding::uniform()]);
        let groups = uniforms.iter().map(|u| binding::group(gpu, name, &layout, &[u.as_entire_binding()])).collect();
        let target = wgpu::ColorTargetState { format: wgpu::TextureFormat::R32Float, blend: None, write_mask: wgpu::ColorWrites::ALL };
        let pipeline = raster::scene_pipeline(gpu, &format!("{name}.render"), &render_source(), &[&layout, &scene.layout], &[Some(target)]);
        MapPass { groups, pipeline }
    }

    /// Stage `label`: the static triangles into the static map's layers `redraw`, then the
    /// moving triangles `dynamic` (if any) into every layer of the dynamic map.
    pub fn record(&self, rec: &mut Recorder, label: &str, f: &FrameInputs, r: &Resources, redraw: &[usize], dynamic: Option<Range<u32>>) {
        rec.stage(label, |enc| {
            for &l in redraw {
                self.draw(enc, label, f, r, &r.static_map, l, 0..f.scene.dynamic_first);
            }
            if let (Some(range), Some(map)) = (&dynamic, &r.dynamic_map) {
                for l in 0..self.groups.len() {
                    self.draw(enc, label, f, r, map, l, range.clone());
                }
            }
        });
    }

    #[allow(clippy::too_many_arguments)]
    fn draw(
        &self,
        enc: &mut wgpu::CommandEncoder,
        label: &str,
        f: &FrameInputs,
        r: &Resources,
        target: &wgpu::Texture,
        layer: usize,
        tris: Range<u32>,
    ) {
        let view = target.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2),
            base_array_layer: layer as u32,
            array_layer_count: Some(1),
            ..Default::default()
        });
        let depth_view = r.depth.create_view(&Default::default());
        // cleared to the farthest depth where nothing is drawn
        let mut pass = raster::begin_pass_with(enc, label, &[&view], wgpu::Color::WHITE, &depth_view, wgpu::StoreOp::Discard);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.groups[layer], &[]);
        pass.set_bind_group(1, &f.scene.group, &[]);
        pass.draw(tris.start * 3..tris.end * 3, 0..1);
    }
}
