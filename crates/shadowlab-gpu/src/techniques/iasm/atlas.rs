//! `store=atlas`, the conventional alternative to the linear buffer (issue 6): the same tiles,
//! frusta and depths as squares of one Depth32Float atlas (buddy-packed by rank, see
//! `shadowlab_core::techniques::iasm::atlas_layout`), rendered with the hardware depth test
//! (atlas.wgsl) and read with `textureLoad` in eval_atlas.wgsl.

use shadowlab_core::techniques::iasm::TILE_COUNT;

use super::eval::EvalPass;
use super::plan::Plan;
use super::setup::AtlasLayout;
use crate::record::Recorder;
use crate::shaders::compose_depth;
use crate::technique::FrameInputs;
use crate::{raster, Gpu};

const ATLAS_WGSL: &str = include_str!("atlas.wgsl");

pub(super) fn source() -> String {
    compose_depth(ATLAS_WGSL)
}

/// The conventional alternative: the tiles in a depth atlas (store=atlas).
pub struct Atlas {
    pub texture: wgpu::Texture,
    pub(super) view: wgpu::TextureView,
    /// Top-left corner per rank.
    pub slots: [[u32; 2]; TILE_COUNT],
}

impl Atlas {
    pub(super) fn new(gpu: &Gpu, l: &AtlasLayout) -> Atlas {
        let texture = raster::depth_target(gpu, "iasm.atlas", l.width, l.height, 1, wgpu::TextureUsages::empty());
        let view = texture.create_view(&Default::default());
        Atlas { texture, view, slots: l.slots }
    }
}

/// The atlas's tile passes and its evaluation.
pub(super) struct AtlasPass {
    pipeline: wgpu::RenderPipeline,
    pub eval: EvalPass,
}

impl AtlasPass {
    /// `layouts`: the tiles' (tiles.rs) and the scene's.
    pub fn new(gpu: &Gpu, layouts: &[&wgpu::BindGroupLayout], has_cutouts: bool) -> AtlasPass {
        let pipeline = raster::depth_pipeline(gpu, "iasm.atlas", &source(), layouts, has_cutouts);
        AtlasPass { pipeline, eval: EvalPass::atlas(gpu) }
    }

    /// `iasm.shadows.clear`, then one stage `iasm.shadows.tNN` per non-empty tile NN, drawn into
    /// its rank's square with its group of `tile_groups`.
    pub fn render(&self, rec: &mut Recorder, f: &FrameInputs, a: &Atlas, plan: &Plan, tile_groups: &[wgpu::BindGroup]) {
        rec.stage("iasm.shadows.clear", |enc| {
            drop(raster::begin_pass(enc, "iasm.shadows.clear", &[], &a.view));
        });
        for (rank, &t) in plan.order.iter().enumerate() {
            if plan.empty[t] {
                continue;
            }
            let (r, [x, y]) = (plan.res[t], a.slots[rank]);
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
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &tile_groups[t], &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                pass.set_viewport(x as f32, y as f32, r as f32, r as f32, 0.0, 1.0);
                pass.set_scissor_rect(x, y, r, r);
                for &(a, b) in &plan.draws[t] {
                    pass.draw(a..b, 0..1);
                }
            });
        }
    }
}
