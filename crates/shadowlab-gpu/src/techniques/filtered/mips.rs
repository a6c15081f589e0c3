//! `mips=true`: a box-filtered mip chain of the moment map, read trilinearly by the evaluation.

use crate::{binding, Gpu, GpuError};

const MIPS_WGSL: &str = include_str!("mips.wgsl");

pub fn source(wgsl_format: &str) -> String {
    format!("alias MipTarget = texture_storage_2d<{wgsl_format}, write>;\n{MIPS_WGSL}")
}

/// Levels of a full chain for a `res` x `res` map (down to 1x1).
pub fn levels(res: u32) -> u32 {
    32 - res.leading_zeros()
}

/// Bytes of a full chain of `res` x `res` texels of `bytes_per_texel`.
pub fn chain_bytes(res: u32, bytes_per_texel: u64) -> u64 {
    (0..levels(res)).map(|l| ((res >> l).max(1) as u64).pow(2) * bytes_per_texel).sum()
}

/// One downsample dispatch per level.
pub struct MipChain {
    pipeline: wgpu::ComputePipeline,
    groups: Vec<(wgpu::BindGroup, u32)>,
}

impl MipChain {
    pub fn new(gpu: &Gpu, label: &str, tex: &wgpu::Texture) -> Result<MipChain, GpuError> {
        let format = tex.format();
        let wgsl_format = match format {
            wgpu::TextureFormat::R32Float => "r32float",
            wgpu::TextureFormat::Rg32Float => "rg32float",
            wgpu::TextureFormat::Rgba32Float => "rgba32float",
            f => return Err(GpuError::Invalid(format!("{label}: no mip chain for {f:?}"))),
        };
        let d = &gpu.device;
        let storage = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let layout = binding::layout(d, label, wgpu::ShaderStages::COMPUTE, &[binding::texture_float(), storage]);
        let pipeline = gpu.compute_pipeline(label, &source(wgsl_format), "main", &[&layout]);
        let level =
            |l: u32| tex.create_view(&wgpu::TextureViewDescriptor { base_mip_level: l, mip_level_count: Some(1), ..Default::default() });
        let groups = (1..tex.mip_level_count())
            .map(|l| {
                let (src, dst) = (level(l - 1), level(l));
                let g = binding::group(
                    gpu,
                    label,
                    &layout,
                    &[wgpu::BindingResource::TextureView(&src), wgpu::BindingResource::TextureView(&dst)],
                );
                (g, (tex.width() >> l).max(1))
            })
            .collect();
        Ok(MipChain { pipeline, groups })
    }

    pub fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, label: &str) {
        for (g, size) in &self.groups {
            gpu.dispatch_2d(enc, label, &self.pipeline, &[g], *size, *size);
        }
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn chain_sizes() {
        assert_eq!(super::levels(512), 10);
        assert_eq!(super::levels(1), 1);
        // 512^2 + 256^2 + ... + 1 texels
        assert_eq!(super::chain_bytes(512, 4), 4 * (0..10).map(|l| (512u64 >> l).pow(2)).sum::<u64>());
        assert_eq!(super::chain_bytes(4, 16), 16 * (16 + 4 + 1));
    }
}
