//! Separable Gaussian blur in compute (shared plumbing): filterable shadow maps pre-filter their
//! moments with it, and leak tracing can reuse it. Works on `R32Float`, `Rg32Float` and
//! `Rgba32Float` textures (read as 4-channel floats, written in their own format). Kernel: odd
//! width `k`, sigma = (k - 1) / 4 (`shadowlab_core::techniques::filtered::gaussian_kernel`); `k = 1` is no blur.

use bytemuck::{Pod, Zeroable};

use crate::{binding, Gpu, GpuError};

const BLUR_WGSL: &str = include_str!("blur.wgsl");

/// Formats the blur writes, with their WGSL storage format names.
const FORMATS: &[(wgpu::TextureFormat, &str)] = &[
    (wgpu::TextureFormat::R32Float, "r32float"),
    (wgpu::TextureFormat::Rg32Float, "rg32float"),
    (wgpu::TextureFormat::Rgba32Float, "rgba32float"),
];

fn source(wgsl_format: &str) -> String {
    format!("alias BlurTarget = texture_storage_2d<{wgsl_format}, write>;\n{BLUR_WGSL}")
}

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("blur/blur.wgsl (r32float)", source("r32float")), ("blur/blur.wgsl (rgba32float)", source("rgba32float"))]
}

/// WGSL `BlurParams`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BlurParams {
    pub dir: [i32; 2],
    pub half: i32,
    pub sigma: f32,
}

/// A blur of one texture in place (through a scratch texture of the same size and format).
pub struct Blur {
    pipeline: wgpu::ComputePipeline,
    scratch: wgpu::Texture,
    groups: [wgpu::BindGroup; 2],
    width: u32,
    height: u32,
}

impl Blur {
    /// Blur of mip 0 of `tex` (which needs TEXTURE_BINDING | STORAGE_BINDING) with kernel width `k`
    /// (odd, >= 3; 1 needs no blur). The scratch texture is allocated here.
    pub fn new(gpu: &Gpu, label: &str, tex: &wgpu::Texture, k: u32) -> Result<Blur, GpuError> {
        if k < 3 || k.is_multiple_of(2) {
            return Err(GpuError::Invalid(format!("{label}: blur kernel width {k} must be odd and at least 3")));
        }
        let format = tex.format();
        let wgsl_format = FORMATS
            .iter()
            .find(|(f, _)| *f == format)
            .map(|(_, n)| *n)
            .ok_or_else(|| GpuError::Invalid(format!("{label}: blur does not support {format:?}")))?;
        let d = &gpu.device;
        let scratch = d.create_texture(&wgpu::TextureDescriptor {
            label: Some(&format!("{label}.scratch")),
            size: wgpu::Extent3d { width: tex.width(), height: tex.height(), depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::STORAGE_BINDING,
            view_formats: &[],
        });
        let storage = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let layout = binding::layout(d, label, wgpu::ShaderStages::COMPUTE, &[binding::uniform(), binding::texture_float(), storage]);
        let pipeline = gpu.compute_pipeline(label, &source(wgsl_format), "main", &[&layout]);
        let half = (k / 2) as i32;
        let sigma = (k as f32 - 1.0) / 4.0;
        let (tv, sv) = (mip0(tex), scratch.create_view(&Default::default()));
        let group = |dir: [i32; 2], src: &wgpu::TextureView, dst: &wgpu::TextureView| {
            let u = gpu.uniform(label, &BlurParams { dir, half, sigma });
            binding::group(
                gpu,
                label,
                &layout,
                &[u.as_entire_binding(), wgpu::BindingResource::TextureView(src), wgpu::BindingResource::TextureView(dst)],
            )
        };
        let groups = [group([1, 0], &tv, &sv), group([0, 1], &sv, &tv)];
        Ok(Blur { pipeline, scratch, groups, width: tex.width(), height: tex.height() })
    }

    /// Records the horizontal then the vertical pass.
    pub fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, label: &str) {
        for g in &self.groups {
            gpu.dispatch_2d(enc, label, &self.pipeline, &[g], self.width, self.height);
        }
    }

    /// Bytes of the scratch texture.
    pub fn scratch_bytes(&self) -> u64 {
        let bpp = self.scratch.format().block_copy_size(None).unwrap_or(16) as u64;
        self.width as u64 * self.height as u64 * bpp
    }
}

/// A view of mip level 0 only (storage and render-target bindings take one level).
pub fn mip0(tex: &wgpu::Texture) -> wgpu::TextureView {
    tex.create_view(&wgpu::TextureViewDescriptor { mip_level_count: Some(1), ..Default::default() })
}
