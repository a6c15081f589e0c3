//! `iasm`'s tile passes with store=buffer (render.wgsl, thesis Listing 3.1): every non-empty
//! tile rasterized with its own frustum and its culled chunks into the linear buffer, by atomic
//! max on the inverted depth (no early depth test); the colour target is a dummy with writes
//! masked. Also the tiles' uniforms and bind groups, which store=atlas draws with too.

use shadowlab_core::techniques::iasm::{Placement, THESIS_RESOLUTIONS, TILE_COUNT};

use super::plan::Plan;
use super::uniforms::{TileParams, TILE_STRIDE};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::technique::FrameInputs;
use crate::{binding, Gpu};

const RENDER_WGSL: &str = include_str!("render.wgsl");
const DUMMY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

pub(super) fn source() -> String {
    compose_depth(RENDER_WGSL)
}

/// The colour target the buffer passes draw nothing into, as large as the largest tile.
pub(super) fn dummy_target(gpu: &Gpu) -> wgpu::TextureView {
    let max_res = THESIS_RESOLUTIONS[0];
    gpu.device
        .create_texture(&wgpu::TextureDescriptor {
            label: Some("iasm.dummy"),
            size: wgpu::Extent3d { width: max_res, height: max_res, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DUMMY_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        })
        .create_view(&Default::default())
}

/// Writes every tile's `TileParams` (frustum from its planes, resolution, offset) for `plan`
/// over the square `p`.
pub(super) fn write_tiles(rec: &mut Recorder, tile_buf: &wgpu::Buffer, p: &Placement, plan: &Plan) {
    for t in 0..TILE_COUNT {
        let tp = TileParams {
            view_proj: p.tile_matrix(t, plan.near[t], plan.far[t]).to_cols_array_2d(),
            tile: [plan.res[t], plan.off[t], 0, 0],
        };
        rec.write_buffer(tile_buf, t as u64 * TILE_STRIDE, bytemuck::bytes_of(&tp));
    }
}

pub(super) struct TilePass {
    /// The tile uniform for both stages, the shadow buffer for the fragment stage only.
    pub layout: wgpu::BindGroupLayout,
    /// Per tile: its `TileParams` and the shadow buffer.
    pub groups: Vec<wgpu::BindGroup>,
    pipeline: wgpu::RenderPipeline,
}

impl TilePass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, tile_buf: &wgpu::Buffer, shadow: &wgpu::Buffer) -> TilePass {
        let d = &gpu.device;
        // the tile uniform for both stages, the buffer for the fragment stage only (writable
        // storage in vertex shaders needs a feature)
        let entry = |i: u32, visibility, ty| wgpu::BindGroupLayoutEntry { binding: i, visibility, ty, count: None };
        let layout = binding::entries_layout(
            d,
            "iasm.render",
            &[
                entry(0, wgpu::ShaderStages::VERTEX_FRAGMENT, binding::uniform()),
                entry(1, wgpu::ShaderStages::FRAGMENT, binding::storage(false)),
            ],
        );
        let groups = (0..TILE_COUNT as u64)
            .map(|t| {
                let tb = wgpu::BufferBinding { buffer: tile_buf, offset: t * TILE_STRIDE, size: wgpu::BufferSize::new(80) };
                binding::group(gpu, "iasm.render", &layout, &[wgpu::BindingResource::Buffer(tb), shadow.as_entire_binding()])
            })
            .collect();
        let pipeline = render_pipeline(gpu, &[&layout, &scene.layout]);
        TilePass { layout, groups, pipeline }
    }

    /// `iasm.shadows.clear`, then one stage `iasm.shadows.tNN` per non-empty tile NN.
    pub fn render(&self, rec: &mut Recorder, f: &FrameInputs, plan: &Plan, shadow: &wgpu::Buffer, dummy: &wgpu::TextureView) {
        rec.stage("iasm.shadows.clear", |enc| enc.clear_buffer(shadow, 0, None));
        for t in 0..TILE_COUNT {
            if plan.empty[t] {
                continue;
            }
            let r = plan.res[t];
            rec.stage(&format!("iasm.shadows.t{t:02}"), |enc| {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("iasm.shadows"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: dummy,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Discard },
                    })],
                    depth_stencil_attachment: None,
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &self.groups[t], &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                pass.set_viewport(0.0, 0.0, r as f32, r as f32, 0.0, 1.0);
                for &(a, b) in &plan.draws[t] {
                    pass.draw(a..b, 0..1);
                }
            });
        }
    }
}

fn render_pipeline(gpu: &Gpu, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::RenderPipeline {
    let module = gpu.shader("iasm.render", &source());
    let layout = gpu.pipeline_layout("iasm.render", layouts);
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("iasm.render"),
        layout: Some(&layout),
        vertex: wgpu::VertexState { module: &module, entry_point: Some("vs_main"), compilation_options: Default::default(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::ColorTargetState { format: DUMMY_FORMAT, blend: None, write_mask: wgpu::ColorWrites::empty() })],
        }),
        multiview_mask: None,
        cache: None,
    })
}
