//! Leak tracing's construction, stage 3: the maps (one layer per level), the raster's depth
//! target, the per-level raster uniforms, classify's uniform and its gather sampler. The
//! screen-sized buffers wait for the first frame (screen.rs).

use super::setup::Setup;
use crate::{raster, Gpu};

pub(super) struct Resources {
    /// One layer per hybrid level.
    pub static_map: wgpu::Texture,
    pub dynamic_map: Option<wgpu::Texture>,
    /// Array views of the static and the dynamic map (the static one again without a dynamic
    /// map), made once.
    pub map_views: [wgpu::TextureView; 2],
    /// The raster's depth target, shared by every layer's draw.
    pub depth: wgpu::Texture,
    /// Per level: the raster's `FilteredParams`.
    pub map_uniforms: Vec<wgpu::Buffer>,
    /// classify.wgsl's `LtParams`.
    pub uniform: wgpu::Buffer,
    pub sampler: wgpu::Sampler,
}

impl Resources {
    pub fn new(gpu: &Gpu, s: &Setup) -> Resources {
        let name = s.mode.name();
        let d = &gpu.device;
        use wgpu::TextureUsages as U;
        let map = |label: &str| {
            d.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: s.res, height: s.res, depth_or_array_layers: s.levels as u32 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: wgpu::TextureFormat::R32Float,
                usage: U::RENDER_ATTACHMENT | U::TEXTURE_BINDING | U::COPY_SRC,
                view_formats: &[],
            })
        };
        let static_map = map(&format!("{name}.static_map"));
        let dynamic_map = s.dynamic.then(|| map(&format!("{name}.dynamic_map")));
        let depth = raster::render_target(gpu, &format!("{name}.raster_depth"), s.res, s.res, raster::DEPTH_FORMAT, U::empty());
        let map_uniforms = (0..s.levels)
            .map(|l| {
                let mut mp = s.map_params;
                mp.light_view_proj = s.params.levels[l].view_proj;
                gpu.uniform(&format!("{name}.map_params"), &mp)
            })
            .collect();
        let sampler = d.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("lt.gather"),
            address_mode_u: wgpu::AddressMode::ClampToEdge,
            address_mode_v: wgpu::AddressMode::ClampToEdge,
            ..Default::default()
        });
        let uniform = gpu.uniform(&format!("{name}.params"), &s.params);
        let array = wgpu::TextureViewDescriptor { dimension: Some(wgpu::TextureViewDimension::D2Array), ..Default::default() };
        let map_views = [static_map.create_view(&array), dynamic_map.as_ref().unwrap_or(&static_map).create_view(&array)];
        Resources { static_map, dynamic_map, map_views, depth, map_uniforms, uniform, sampler }
    }
}
