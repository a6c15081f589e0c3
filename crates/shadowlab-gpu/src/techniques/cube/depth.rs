//! `cube`'s depth pass (`cube.render`, depth.wgsl): the six faces drawn one after another into
//! the layers of one depth array, each face's static triangles from a list culled once on the
//! CPU, moving triangles culled per face in the vertex stage.

use glam::Vec3;
use shadowlab_core::techniques::cube::face_view_proj;

use super::{CubeFace, CubeMap, FACES_WGSL};
use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::{compose_depth, flag};
use crate::technique::FrameInputs;
use crate::{binding, raster, Gpu};

const DEPTH_WGSL: &str = include_str!("depth.wgsl");

pub(super) fn source() -> String {
    compose_depth(&format!("{FACES_WGSL}{DEPTH_WGSL}"))
}

/// The faces' uniforms and groups, their two pipelines and their static triangle lists.
pub(super) struct FacePasses {
    pub groups: Vec<wgpu::BindGroup>,
    pub pipeline: wgpu::RenderPipeline,
    pub static_pipeline: wgpu::RenderPipeline,
    pub indices: Vec<(wgpu::Buffer, u32)>,
}

impl FacePasses {
    /// The faces of a light at `pos` with depth range [`near`, `far`]; `hardware`: reversed
    /// rasteriser depth (`depth=hardware`).
    pub fn new(gpu: &Gpu, scene: &GpuScene, pos: Vec3, near: f32, far: f32, hardware: bool) -> FacePasses {
        let d = &gpu.device;
        let face_layout = binding::layout(d, "cube.depth", wgpu::ShaderStages::VERTEX_FRAGMENT, &[binding::uniform()]);
        let groups = (0..6)
            .map(|f| {
                let u = CubeFace {
                    view_proj: face_view_proj(pos, f, near, far).to_cols_array_2d(),
                    light: pos.extend(far).into(),
                    face: [f as u32, near.to_bits(), 0, 0],
                };
                let buf = gpu.uniform(&format!("cube.face{f}"), &u);
                binding::group(gpu, "cube.depth", &face_layout, &[buf.as_entire_binding()])
            })
            .collect();
        let layouts = [&face_layout, &scene.layout];
        let module = gpu.shader("cube.render", &source());
        let pipeline = face_pipeline(gpu, &module, "cube.render", &layouts, hardware, true, scene.has_cutouts);
        let static_pipeline = face_pipeline(gpu, &module, "cube.render.static", &layouts, hardware, false, scene.has_cutouts);
        let indices = static_face_lists(gpu, scene, pos);
        FacePasses { groups, pipeline, static_pipeline, indices }
    }
}

impl CubeMap {
    /// The `cube.render` stage: per face, its static triangles, then the moving ones.
    pub(super) fn render_faces(&self, f: &FrameInputs, rec: &mut Recorder) {
        let views: Vec<wgpu::TextureView> = (0..6)
            .map(|layer| {
                self.map.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..Default::default()
                })
            })
            .collect();
        // reversed depth clears to 0 (empty = farthest)
        let clear = if self.hardware { 0.0 } else { 1.0 };
        rec.stage("cube.render", |enc| {
            for ((view, group), (indices, n)) in views.iter().zip(&self.face_groups).zip(&self.face_indices) {
                let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("cube.render"),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                        view,
                        depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store }),
                        stencil_ops: None,
                    }),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                pass.set_bind_group(0, group, &[]);
                pass.set_bind_group(1, &f.scene.group, &[]);
                if *n > 0 {
                    pass.set_pipeline(&self.static_pipeline);
                    pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..*n, 0, 0..1);
                }
                if f.scene.dynamic_first < f.scene.triangle_count {
                    pass.set_pipeline(&self.depth_pipeline);
                    pass.draw(f.scene.dynamic_first * 3..f.scene.triangle_count * 3, 0..1);
                }
            }
        });
    }
}

/// Per face, the vertex indices of the static triangles not wholly outside it
/// (`cube::outside_face`): the faces then draw about a sixth of the scene each, with no per-face
/// test in the vertex stage. The light of a technique instance never moves.
fn static_face_lists(gpu: &Gpu, scene: &GpuScene, light: Vec3) -> Vec<(wgpu::Buffer, u32)> {
    let verts = scene.read_vertices(gpu);
    (0..6)
        .map(|f| {
            let idx: Vec<u32> = (0..scene.dynamic_first)
                .filter(|&t| {
                    let v = &verts[3 * t as usize..3 * t as usize + 3];
                    !shadowlab_core::techniques::cube::outside_face(&[v[0].pos.into(), v[1].pos.into(), v[2].pos.into()], light, f)
                })
                .flat_map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
                .collect();
            let n = idx.len() as u32;
            (gpu.buffer_init(&format!("cube.face{f}.indices"), bytemuck::cast_slice(&idx), wgpu::BufferUsages::INDEX), n)
        })
        .collect()
}

/// A face pipeline: `distance` writes the linear distance in the fragment stage (`fs_main`);
/// `hardware` keeps the rasteriser's reversed depth (test `Greater`), with a fragment stage
/// only for the cut-out test. `cull_in_vs`: the vertex stage's per-face test (moving triangles).
fn face_pipeline(
    gpu: &Gpu,
    module: &wgpu::ShaderModule,
    label: &str,
    layouts: &[&wgpu::BindGroupLayout],
    hardware: bool,
    cull_in_vs: bool,
    cutouts: bool,
) -> wgpu::RenderPipeline {
    let constants = [("CULL_IN_VS", flag(cull_in_vs)), ("HW_DEPTH", flag(hardware))];
    let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let fragment = match (hardware, cutouts) {
        (false, _) => Some("fs_main"),
        (true, true) => Some("fs_cut_out"),
        (true, false) => None,
    };
    gpu.device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(&gpu.pipeline_layout(label, layouts)),
        vertex: wgpu::VertexState { module, entry_point: Some("vs_main"), compilation_options: options.clone(), buffers: &[] },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: raster::DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(if hardware { wgpu::CompareFunction::Greater } else { wgpu::CompareFunction::Less }),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        fragment: fragment.map(|entry| wgpu::FragmentState {
            module,
            entry_point: Some(entry),
            compilation_options: options,
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}
