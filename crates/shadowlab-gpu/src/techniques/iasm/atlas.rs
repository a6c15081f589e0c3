//! `store=atlas`, the conventional alternative to the linear buffer (issue 6): the same tiles,
//! frusta and depths as squares of one Depth32Float atlas (buddy-packed by rank, see
//! `shadowlab_core::techniques::iasm::atlas_layout`), rendered with the hardware depth test and read with
//! `textureLoad` in eval_atlas.wgsl.

use shadowlab_core::techniques::iasm::{self as core, THESIS_RESOLUTIONS, TILE_COUNT};

use super::gpu::Iasm;
use super::{eval_atlas_src, ATLAS_WGSL};
use crate::record::Recorder;
use crate::shaders::compose_depth;
use crate::technique::{view_layout, FrameInputs};
use crate::{binding, raster, Gpu, GpuError};

/// The conventional alternative: the tiles in a depth atlas (store=atlas).
pub struct Atlas {
    pub texture: wgpu::Texture,
    pub(super) view: wgpu::TextureView,
    /// Top-left corner per rank.
    pub slots: [[u32; 2]; TILE_COUNT],
    pipeline: wgpu::RenderPipeline,
    pub(super) eval_layout: wgpu::BindGroupLayout,
    pub(super) eval: wgpu::ComputePipeline,
    pub(super) eval_count: wgpu::ComputePipeline,
}

pub(super) fn make_atlas(gpu: &Gpu, layouts: &[&wgpu::BindGroupLayout], has_cutouts: bool) -> Result<Atlas, GpuError> {
    let (w, h, slots) =
        core::atlas_layout(&THESIS_RESOLUTIONS).ok_or_else(|| GpuError::Invalid("iasm: resolution set does not fit an atlas".into()))?;
    gpu.check_size(w, h, "iasm atlas")?;
    let texture = raster::depth_target(gpu, "iasm.atlas", w, h, 1, wgpu::TextureUsages::empty());
    let view = texture.create_view(&Default::default());
    let pipeline = raster::depth_pipeline(gpu, "iasm.atlas", &compose_depth(ATLAS_WGSL), layouts, has_cutouts);
    let eval_layout = view_layout(gpu, "iasm.eval_atlas", &[binding::uniform(), binding::texture_depth(), binding::storage(false)]);
    let eval = gpu.compute_pipeline("iasm.evaluate", &eval_atlas_src(), "main", &[&eval_layout]);
    let eval_count = gpu.compute_pipeline_with("iasm.evaluate", &eval_atlas_src(), "main", &[&eval_layout], crate::context::COUNTING);
    Ok(Atlas { texture, view, slots, pipeline, eval_layout, eval, eval_count })
}

impl Iasm {
    pub(super) fn render_atlas(&self, _gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, a: &Atlas) {
        rec.stage("iasm.shadows.clear", |enc| {
            drop(raster::begin_pass(enc, "iasm.shadows.clear", &[], &a.view));
        });
        for (rank, &t) in self.plan.order.iter().enumerate() {
            if self.plan.empty[t] {
                continue;
            }
            let (r, [x, y]) = (self.plan.res[t], a.slots[rank]);
            rec.stage(&format!("iasm.shadows.t{t:02}"), |enc| {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("iasm.shadows"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view: &a.view,
                        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&a.pipeline);
                pass.set_bind_group(0, &self.tile_groups[t], &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                pass.set_viewport(x as f32, y as f32, r as f32, r as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, r, r);
                for &(a, b) in &self.plan.draws[t] {
                    pass.draw(a..b, 0..1);
                }
            });
        }
    }
}
