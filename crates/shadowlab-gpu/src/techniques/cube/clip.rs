//! cube-notw's per-face scenes: the scene's triangles clipped to each face's frustum (CPU,
//! `shadowlab_core::cube::clip_to_face`), drawn with the scene's own materials and texels. The
//! warped depth pass of `warp` moves each vertex by the warp of its projection, which is
//! undefined for vertices behind the light; clipping at a near plane in front of it keeps every
//! vertex inside the face's frustum. Done once per technique instance (static light, static
//! triangles; moving triangles would need this per frame).

use bytemuck::Zeroable;
use glam::Vec3;
use shadowlab_core::cube::clip_to_face;
use shadowlab_core::scene::Vertex;

use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::{binding, Gpu};

pub const SCENE_COPY_WGSL: &str = include_str!("scene_copy.wgsl");

pub fn scene_copy_src() -> String {
    compose(SCENE_COPY_WGSL, true)
}

/// The scene with the triangles of each face (+x .. -z): clipped at `near` along the face's
/// axis and to a square of half-width `tan_half`.
pub fn face_scenes(gpu: &Gpu, scene: &GpuScene, light: Vec3, near: f32, tan_half: f32) -> Vec<GpuScene> {
    let d = &gpu.device;
    let st = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
    let rw = binding::storage(false);
    let layout = binding::layout(d, "cube-notw.scene_copy", wgpu::ShaderStages::COMPUTE, &[rw, rw, rw, rw]);
    let src = scene_copy_src();
    let lengths = gpu.compute_pipeline("cube-notw.scene_lengths", &src, "lengths", &[&layout, &scene.layout]);
    let copy = gpu.compute_pipeline("cube-notw.scene_copy", &src, "copy", &[&layout, &scene.layout]);
    let run = |bufs: [&wgpu::Buffer; 4], pipeline: &wgpu::ComputePipeline, groups: u32| {
        let g = binding::group(d, "cube-notw.scene_copy", &layout, &bufs.map(|b| b.as_entire_binding()));
        let mut enc = d.create_command_encoder(&Default::default());
        {
            let mut pass = enc.begin_compute_pass(&Default::default());
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &g, &[]);
            pass.set_bind_group(1, &scene.group, &[]);
            pass.dispatch_workgroups(groups.clamp(1, 65535), groups.div_ceil(65535).max(1), 1);
        }
        gpu.queue.submit([enc.finish()]);
    };
    let len = gpu.buffer_init("cube-notw.scene_len", &[0u8; 16], st);
    let small = [0, 1, 2].map(|_| gpu.buffer_init("cube-notw.scene_dummy", &[0u8; 64], st));
    run([&len, &small[0], &small[1], &small[2]], &lengths, 1);
    let n: Vec<u32> = gpu.read_buffer_as(&len, 3);
    let sized = |count: u32, size: u64| gpu.buffer_init("cube-notw.scene_part", &vec![0u8; (count.max(1) as u64 * size) as usize], st);
    let (verts, mats, texels) = (sized(n[0], 48), sized(n[1], 48), sized(n[2], 4));
    run([&len, &verts, &mats, &texels], &copy, n.iter().max().unwrap().div_ceil(64));
    let all: Vec<Vertex> = gpu.read_buffer_as(&verts, n[0] as usize);
    let empty = gpu.buffer_init("cube-notw.no_bvh", &[0u8; 32], wgpu::BufferUsages::STORAGE);
    (0..6)
        .map(|f| {
            let mut clipped: Vec<Vertex> =
                all.chunks_exact(3).flat_map(|t| clip_to_face(&[t[0], t[1], t[2]], light, f, near, tan_half)).flatten().collect();
            if clipped.is_empty() {
                clipped = vec![Vertex::zeroed(); 3];
            }
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX;
            let vertices = gpu.buffer_init(&format!("cube-notw.face{f}.vertices"), bytemuck::cast_slice(&clipped), usage);
            let group = binding::group(
                d,
                "cube-notw.face_scene",
                &scene.layout,
                &[
                    vertices.as_entire_binding(),
                    mats.as_entire_binding(),
                    texels.as_entire_binding(),
                    empty.as_entire_binding(),
                    empty.as_entire_binding(),
                ],
            );
            let tris = clipped.len() as u32 / 3;
            GpuScene {
                vertices,
                layout: scene.layout.clone(),
                group,
                triangle_count: tris,
                dynamic_first: tris,
                bounds: scene.bounds,
                eps: scene.eps,
                bvh_bytes: 0,
                texel_bytes: scene.texel_bytes,
            }
        })
        .collect()
}
