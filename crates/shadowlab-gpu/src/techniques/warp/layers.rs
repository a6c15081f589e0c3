//! Maps evaluated together (`cube-notw`'s six faces): each map keeps its own passes, but its
//! warps and depth map are one layer of shared array textures, and its DV bounds and sample
//! counts one slice of shared buffers, so that one evaluation pass reads every map
//! (cube/eval_notw.wgsl) instead of one pass a map over the whole view.

use super::Warped;
use crate::{raster, Gpu};

/// The shared targets of `count` NoTW maps of `res` (one function a row and a column, so both
/// warps are `res x res` a layer).
pub struct Layers {
    pub(super) res: u32,
    count: u32,
    pub(super) warp_x: wgpu::Texture,
    pub(super) warp_y: wgpu::Texture,
    pub(super) map: wgpu::Texture,
    /// 8 words of DV bounds a layer, at `dv_stride` bytes (the storage offset alignment).
    pub(super) dv: wgpu::Buffer,
    pub(super) dv_stride: u64,
    /// The analysis variant's samples per warped texel, `res^2` words a layer.
    pub(super) counts: wgpu::Buffer,
}

impl Layers {
    pub fn notw(gpu: &Gpu, name: &str, res: u32, count: u32) -> Layers {
        let dv_stride = (gpu.limits.min_storage_buffer_offset_alignment as u64).max(32);
        let n = res as u64 * res as u64;
        Layers {
            res,
            count,
            warp_x: r32_array(gpu, &format!("{name}.warp_x"), res, res, count),
            warp_y: r32_array(gpu, &format!("{name}.warp_y"), res, res, count),
            map: raster::depth_target(gpu, &format!("{name}.map"), res, res, count, wgpu::TextureUsages::empty()),
            dv: gpu.storage(&format!("{name}.dv"), dv_stride * count as u64),
            dv_stride,
            counts: gpu.storage(&format!("{name}.counts"), n * 4 * count as u64),
        }
    }

    /// The layers' count.
    pub fn count(&self) -> u32 {
        self.count
    }

    /// Array views of the row warps, the column warps and the depth maps.
    pub fn array_views(&self) -> [wgpu::TextureView; 3] {
        let d = wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
        [&self.warp_x, &self.warp_y, &self.map].map(|t| t.create_view(&d))
    }

    /// Every layer's DV bounds (`dv_stride()` bytes apart).
    pub fn dv(&self) -> &wgpu::Buffer {
        &self.dv
    }

    pub fn dv_stride(&self) -> u64 {
        self.dv_stride
    }

    /// Every layer's sample counts of the analysis variant (`res^2` words a layer).
    pub fn counts(&self) -> &wgpu::Buffer {
        &self.counts
    }
}

fn r32_array(gpu: &Gpu, label: &str, w: u32, h: u32, layers: u32) -> wgpu::Texture {
    gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::R32Float,
        usage: wgpu::TextureUsages::STORAGE_BINDING | wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    })
}

impl Warped {
    /// The DV bounds as this map's passes bind them (its slice of a shared buffer when layered).
    pub(super) fn dv_binding(&self) -> wgpu::BindingResource<'_> {
        wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer: &self.dv, offset: self.dv_offset, size: wgpu::BufferSize::new(32) })
    }

    /// The sample counts as the evaluation binds them.
    pub(super) fn counts_binding(&self) -> wgpu::BindingResource<'_> {
        let n = self.res as u64 * self.res as u64;
        wgpu::BindingResource::Buffer(wgpu::BufferBinding { buffer: &self.counts, offset: self.counts_offset, size: wgpu::BufferSize::new(n * 4) })
    }

    /// The uniform as written at creation (the layered evaluation gathers the faces').
    pub fn params(&self) -> &super::WarpParams {
        &self.params
    }
}
