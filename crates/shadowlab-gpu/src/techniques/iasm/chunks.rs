//! Culling units of `iasm`: fixed-size chunks of the scene's triangles in vertex order, their
//! world bounds computed once on the GPU (bounds.wgsl). Chunks holding moving triangles
//! (`GpuScene::dynamic_first..`) get the scene's bounds over the whole animation instead, so
//! they are never culled from a tile their objects move into.

use glam::Vec3;

use super::plan::unkey;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::{binding, Gpu, GpuError};

/// Also `virtual`'s chunk bounds (with a first-triangle offset).
pub(crate) const BOUNDS_WGSL: &str = include_str!("bounds.wgsl");

pub(super) fn source() -> String {
    compose(BOUNDS_WGSL, true)
}

/// World AABBs of chunks of `chunk` triangles in vertex order, computed once on the GPU (the
/// lab keeps no CPU copy of the vertices). Returns the boxes; a chunk with a moving triangle
/// gets `scene.bounds` (swept over the animation).
pub(super) fn chunk_bounds(gpu: &Gpu, scene: &GpuScene, chunk: u32) -> Result<Vec<(Vec3, Vec3)>, GpuError> {
    let n = scene.triangle_count.div_ceil(chunk).max(1) as usize;
    let d = &gpu.device;
    let init: Vec<u32> = (0..n).flat_map(|_| [u32::MAX, u32::MAX, u32::MAX, 0, 0, 0]).collect();
    let boxes = gpu.buffer_init(
        "iasm.chunks",
        bytemuck::cast_slice(&init),
        wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
    );
    let cp = gpu.uniform("iasm.chunk_params", &[chunk, scene.triangle_count, 0, 0]);
    let layout = binding::layout(d, "iasm.bounds", wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::storage(false)]);
    let group = binding::group(gpu, "iasm.bounds", &layout, &[cp.as_entire_binding(), boxes.as_entire_binding()]);
    let pipeline = gpu.compute_pipeline("iasm.bounds", &source(), "main", &[&layout, &scene.layout]);
    let groups = scene.triangle_count.div_ceil(64).max(1);
    let mut enc = d.create_command_encoder(&Default::default());
    {
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &group, &[]);
        pass.set_bind_group(1, &scene.group, &[]);
        gpu.dispatch(&mut pass, [groups.min(65535), groups.div_ceil(65535), 1]);
    }
    gpu.submit(enc.finish());
    gpu.take_error()?;
    let w: Vec<u32> = gpu.read_buffer_as(&boxes, n * 6);
    Ok(w.chunks_exact(6)
        .enumerate()
        .map(|(i, c)| {
            if scene.dynamic_first < scene.triangle_count && (i as u32 + 1) * chunk > scene.dynamic_first {
                return (scene.bounds.min, scene.bounds.max);
            }
            let lo = Vec3::new(unkey(c[0]), unkey(c[1]), unkey(c[2]));
            let hi = Vec3::new(unkey(c[3]), unkey(c[4]), unkey(c[5]));
            (lo, hi)
        })
        .collect())
}
