//! The scene on the GPU: vertex triples, materials, packed texels and the BVH, as one bind
//! group (group 1 of every pass, `scene.wgsl`).

use bytemuck::{Pod, Zeroable};
use shadowlab_core::bvh::Bvh;
use shadowlab_core::scene::{Bounds, Scene};
use wgpu::BufferUsages;

use crate::{binding, Gpu, GpuError};

/// WGSL `Material` (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub base_color: [f32; 4],
    pub tex_offset: u32,
    pub tex_width: u32,
    pub tex_height: u32,
    pub flags: u32,
    pub alpha_cutoff: f32,
    pub _pad: [u32; 3],
}

pub const MAT_TEXTURED: u32 = 1;
pub const MAT_MASKED: u32 = 2;
pub const MAT_DOUBLE_SIDED: u32 = 4;

pub struct GpuScene {
    pub vertices: wgpu::Buffer,
    pub layout: wgpu::BindGroupLayout,
    pub group: wgpu::BindGroup,
    pub triangle_count: u32,
    /// Triangles `dynamic_first..triangle_count` are dynamic (moved by the scene's animations,
    /// rewritten every frame); `0..dynamic_first` are static. Equal to `triangle_count` for a
    /// scene without moving objects.
    pub dynamic_first: u32,
    pub bounds: Bounds,
    pub eps: f32,
    pub bvh_bytes: usize,
    pub texel_bytes: usize,
}

impl GpuScene {
    pub fn new(gpu: &Gpu, scene: &Scene, bvh: &Bvh) -> Result<GpuScene, GpuError> {
        let mut texels: Vec<u32> = Vec::new();
        let mut offsets = Vec::new();
        for t in &scene.textures {
            offsets.push(texels.len() as u32);
            texels.extend(t.rgba.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])));
        }
        let materials: Vec<GpuMaterial> = scene
            .materials
            .iter()
            .map(|m| {
                let (off, w, h) = m.texture.map_or((0, 1, 1), |t| {
                    let tex = &scene.textures[t as usize];
                    (offsets[t as usize], tex.width, tex.height)
                });
                let bit = |on: bool, b: u32| if on { b } else { 0 };
                let flags = bit(m.texture.is_some(), MAT_TEXTURED)
                    | bit(m.alpha_cutoff.is_some(), MAT_MASKED)
                    | bit(m.double_sided, MAT_DOUBLE_SIDED);
                GpuMaterial {
                    base_color: m.base_color,
                    tex_offset: off,
                    tex_width: w,
                    tex_height: h,
                    flags,
                    alpha_cutoff: m.alpha_cutoff.unwrap_or(0.0),
                    _pad: [0; 3],
                }
            })
            .collect();
        let max = gpu.limits.max_storage_buffer_binding_size as usize;
        let vbytes = std::mem::size_of_val(scene.vertices.as_slice());
        for (what, bytes) in [("vertex data", vbytes), ("texture data", texels.len() * 4), ("BVH", bvh.nodes.len() * 32)] {
            if bytes > max {
                return Err(GpuError::Invalid(format!("scene {what} is {bytes} bytes, over this device's storage binding limit of {max}")));
            }
        }
        let st = BufferUsages::STORAGE | BufferUsages::COPY_DST;
        let vertices = gpu.buffer_init("scene.vertices", bytemuck::cast_slice(&scene.vertices), st | BufferUsages::VERTEX);
        let mats = gpu.buffer_init("scene.materials", bytemuck::cast_slice(&materials), st);
        let tex = gpu.buffer_init("scene.texels", bytemuck::cast_slice(&texels), st);
        let nodes = gpu.buffer_init("scene.bvh_nodes", bytemuck::cast_slice(&bvh.nodes), st);
        let prims = gpu.buffer_init("scene.prim_indices", bytemuck::cast_slice(&bvh.prim_indices), st);
        let vis = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = binding::layout(&gpu.device, "scene", vis, &[binding::storage(true); 5]);
        let group = binding::group(
            &gpu.device,
            "scene",
            &layout,
            &[
                vertices.as_entire_binding(),
                mats.as_entire_binding(),
                tex.as_entire_binding(),
                nodes.as_entire_binding(),
                prims.as_entire_binding(),
            ],
        );
        Ok(GpuScene {
            vertices,
            layout,
            group,
            triangle_count: scene.triangle_count() as u32,
            dynamic_first: scene.triangle_count() as u32,
            bounds: scene.bounds(),
            eps: scene.ray_epsilon(),
            bvh_bytes: bvh.bytes(),
            texel_bytes: texels.len() * 4,
        })
    }
}
