//! Terse bind group layouts: entries are numbered 0.. in the order given.

use wgpu::{BindingType, BufferBindingType, ShaderStages};

pub fn uniform() -> BindingType {
    BindingType::Buffer { ty: BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None }
}
pub fn storage(read_only: bool) -> BindingType {
    BindingType::Buffer { ty: BufferBindingType::Storage { read_only }, has_dynamic_offset: false, min_binding_size: None }
}
/// An unfilterable float texture read with `textureLoad` (G-buffer targets).
pub fn texture_float() -> BindingType {
    BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: false },
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}
pub fn texture_depth() -> BindingType {
    BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Depth,
        view_dimension: wgpu::TextureViewDimension::D2,
        multisampled: false,
    }
}
/// A write-only R32Float storage texture (the host's visibility texture).
pub fn storage_texture_r32f() -> BindingType {
    BindingType::StorageTexture {
        access: wgpu::StorageTextureAccess::WriteOnly,
        format: wgpu::TextureFormat::R32Float,
        view_dimension: wgpu::TextureViewDimension::D2,
    }
}
pub fn comparison_sampler() -> BindingType {
    BindingType::Sampler(wgpu::SamplerBindingType::Comparison)
}

/// The layout of `types`, numbered 0.., all visible to `vis` (uniform buffers as the adapter
/// binds them, [`crate::quirks`]).
pub fn layout(device: &wgpu::Device, label: &str, vis: ShaderStages, types: &[BindingType]) -> wgpu::BindGroupLayout {
    let entries: Vec<_> = types
        .iter()
        .enumerate()
        .map(|(i, ty)| wgpu::BindGroupLayoutEntry { binding: i as u32, visibility: vis, ty: *ty, count: None })
        .collect();
    entries_layout(device, label, &entries)
}

/// The layout of explicit `entries` (uniform buffers as the adapter binds them, [`crate::quirks`]).
pub fn entries_layout(device: &wgpu::Device, label: &str, entries: &[wgpu::BindGroupLayoutEntry]) -> wgpu::BindGroupLayout {
    let entries = crate::quirks::entries(device, entries);
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries })
}

/// A bind group of `resources` at bindings 0, 1, ... (counted, [`crate::Gpu::bind_group`]).
pub fn group(gpu: &crate::Gpu, label: &str, layout: &wgpu::BindGroupLayout, resources: &[wgpu::BindingResource]) -> wgpu::BindGroup {
    let entries: Vec<_> =
        resources.iter().enumerate().map(|(i, r)| wgpu::BindGroupEntry { binding: i as u32, resource: r.clone() }).collect();
    gpu.bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// One resource of a bind group by identity (wgpu handles compare by object).
#[derive(PartialEq, Eq)]
enum Bound {
    Buffer(wgpu::Buffer, u64, Option<wgpu::BufferSize>),
    View(wgpu::TextureView),
    Sampler(wgpu::Sampler),
}

fn bound(r: &wgpu::BindingResource) -> Option<Bound> {
    match r {
        wgpu::BindingResource::Buffer(b) => Some(Bound::Buffer(b.buffer.clone(), b.offset, b.size)),
        wgpu::BindingResource::TextureView(v) => Some(Bound::View((*v).clone())),
        wgpu::BindingResource::Sampler(s) => Some(Bound::Sampler((*s).clone())),
        _ => None,
    }
}

/// A bind group kept while its layout and resources stay the same objects, so that a pass
/// whose inputs do not change makes no bind group after its first frame (tests/hygiene.rs).
/// One per call site (an array of them where a site binds several sets in turn); a change of
/// any resource (another view, a resized target) makes the group again. Resources held here
/// live as long as the cache (its pass) or until replaced.
#[derive(Default)]
pub struct GroupCache(std::sync::Mutex<Option<Kept>>);

/// A kept group with what it was made of: its layout and its resources by binding.
type Kept = (wgpu::BindGroupLayout, Vec<(u32, Bound)>, wgpu::BindGroup);

impl GroupCache {
    /// The group of `resources` at bindings 0, 1, ... over `layout`: the kept one when they are
    /// the same, else a new one ([`group`]), kept.
    pub fn get(
        &self,
        gpu: &crate::Gpu,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        resources: &[wgpu::BindingResource],
    ) -> wgpu::BindGroup {
        let entries: Vec<_> =
            resources.iter().enumerate().map(|(i, r)| wgpu::BindGroupEntry { binding: i as u32, resource: r.clone() }).collect();
        self.entries(gpu, label, layout, &entries)
    }

    /// [`GroupCache::get`] with explicit binding numbers.
    pub fn entries(
        &self,
        gpu: &crate::Gpu,
        label: &str,
        layout: &wgpu::BindGroupLayout,
        entries: &[wgpu::BindGroupEntry],
    ) -> wgpu::BindGroup {
        let key: Option<Vec<(u32, Bound)>> = entries.iter().map(|e| bound(&e.resource).map(|b| (e.binding, b))).collect();
        let mut slot = self.0.lock().unwrap();
        if let (Some(k), Some((l, kept, g))) = (&key, slot.as_ref()) {
            if l == layout && k == kept {
                return g.clone();
            }
        }
        let g = gpu.bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries });
        *slot = key.map(|k| (layout.clone(), k, g.clone()));
        g
    }
}
