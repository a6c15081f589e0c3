//! World bounds of fixed-size chunks of a triangle range, on the GPU (iasm's bounds.wgsl with a
//! first-triangle offset): `virtual` bounds its static chunks once and its moving chunks every
//! frame, recorded into the frame's encoder and read back with the page requests.

use shadowlab_core::scene::Bounds;

use crate::scene_gpu::GpuScene;
use crate::shaders::compose;
use crate::techniques::iasm::plan::unkey;
use crate::techniques::iasm::BOUNDS_WGSL;
use crate::{binding, Gpu};

pub(super) struct ChunkBounds {
    pub first: u32,
    pub end: u32,
    pub count: u32,
    pub boxes: wgpu::Buffer,
    init: wgpu::Buffer,
    group: wgpu::BindGroup,
    pipeline: wgpu::ComputePipeline,
}

/// Chunks of `chunk` triangles over `first..end` (at least one).
pub(super) fn chunk_count(first: u32, end: u32, chunk: u32) -> u32 {
    (end - first).div_ceil(chunk).max(1)
}

impl ChunkBounds {
    /// Chunks of `chunk` triangles over `first..end` of `scene` (at least one chunk).
    pub fn new(gpu: &Gpu, scene: &GpuScene, label: &str, first: u32, end: u32, chunk: u32) -> ChunkBounds {
        let count = chunk_count(first, end, chunk);
        let d = &gpu.device;
        let words: Vec<u32> = (0..count).flat_map(|_| [u32::MAX, u32::MAX, u32::MAX, 0, 0, 0]).collect();
        let init = gpu.buffer_init(label, bytemuck::cast_slice(&words), wgpu::BufferUsages::COPY_SRC);
        let boxes = gpu.storage(label, count as u64 * 24);
        let cp = gpu.uniform(label, &[chunk, end, first, 0]);
        let layout = binding::layout(d, label, wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::storage(false)]);
        let group = binding::group(gpu, label, &layout, &[cp.as_entire_binding(), boxes.as_entire_binding()]);
        let pipeline = gpu.compute_pipeline(label, &compose(BOUNDS_WGSL, true), "main", &[&layout, &scene.layout]);
        ChunkBounds { first, end, count, boxes, init, group, pipeline }
    }

    /// Resets and recomputes the boxes.
    pub fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, scene: &GpuScene) {
        enc.copy_buffer_to_buffer(&self.init, 0, &self.boxes, 0, self.count as u64 * 24);
        let groups = (self.end - self.first).div_ceil(64).max(1);
        let mut pass = enc.begin_compute_pass(&Default::default());
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.group, &[]);
        pass.set_bind_group(1, &scene.group, &[]);
        gpu.dispatch(&mut pass, [groups.min(65535), groups.div_ceil(65535), 1]);
    }

    /// The boxes from their words (an empty chunk reads as an empty box).
    pub fn parse(words: &[u32]) -> Vec<Bounds> {
        words
            .chunks_exact(6)
            .map(|c| Bounds {
                min: glam::Vec3::new(unkey(c[0]), unkey(c[1]), unkey(c[2])),
                max: glam::Vec3::new(unkey(c[3]), unkey(c[4]), unkey(c[5])),
            })
            .collect()
    }
}
