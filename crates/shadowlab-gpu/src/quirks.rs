//! Driver quirks, worked around in one place.
//!
//! **Uniforms on lavapipe.** Mesa's software Vulkan driver inlines the values of uniform
//! buffers that steer an `if` or end a loop into a specialised copy of the shader. Mesa 22.3
//! (Debian 12's, this project's CI) makes that copy again on every bind of the pipeline and never
//! frees it: resident memory grew by 0.2 MB (`sm`) to 76 MB (`dpsm`) per frame, so a long camera
//! path or viewer session ran out of memory (BENCHMARKS.md, "Memory over long runs").
//! Storage buffers are not inlined. On lavapipe shadowlab therefore binds every uniform buffer
//! as a read-only storage buffer: the WGSL's `var<uniform>` becomes `var<storage, read>`
//! ([`wgsl`], applied by [`crate::Gpu::shader`]) and the layouts' uniform bindings read-only
//! storage bindings ([`binding_type`], applied by [`crate::binding::layout`]). A WGSL struct has
//! the same layout in both address spaces, so buffers and their contents are unchanged (uniform
//! buffers carry `STORAGE` usage everywhere, [`crate::Gpu::uniform`]). Every other adapter,
//! WebGPU included, keeps real uniform buffers.

use std::borrow::Cow;

use wgpu::{BindingType, BufferBindingType};

/// Whether uniform buffers are bound as read-only storage on the adapter `info` (lavapipe).
pub fn uniforms_as_storage(info: &wgpu::AdapterInfo) -> bool {
    info.backend == wgpu::Backend::Vulkan && info.driver.eq_ignore_ascii_case("llvmpipe")
}

/// `source` with every `var<uniform>` declared `var<storage, read>` when `as_storage`.
pub fn wgsl(source: &str, as_storage: bool) -> Cow<'_, str> {
    if as_storage && source.contains("var<uniform>") {
        Cow::Owned(source.replace("var<uniform>", "var<storage, read>"))
    } else {
        Cow::Borrowed(source)
    }
}

/// A layout entry's type: a uniform buffer becomes a read-only storage buffer when `as_storage`.
pub fn binding_type(ty: BindingType, as_storage: bool) -> BindingType {
    match ty {
        BindingType::Buffer { ty: BufferBindingType::Uniform, has_dynamic_offset, min_binding_size } if as_storage => {
            BindingType::Buffer { ty: BufferBindingType::Storage { read_only: true }, has_dynamic_offset, min_binding_size }
        }
        other => other,
    }
}

/// Layout entries with [`binding_type`] applied for `device`'s adapter.
pub fn entries(device: &wgpu::Device, entries: &[wgpu::BindGroupLayoutEntry]) -> Vec<wgpu::BindGroupLayoutEntry> {
    let as_storage = uniforms_as_storage(&device.adapter_info());
    entries.iter().map(|e| wgpu::BindGroupLayoutEntry { ty: binding_type(e.ty, as_storage), ..*e }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn info(driver: &str, backend: wgpu::Backend) -> wgpu::AdapterInfo {
        wgpu::AdapterInfo {
            name: "x".into(),
            vendor: 0,
            device: 0,
            device_type: wgpu::DeviceType::Cpu,
            device_pci_bus_id: String::new(),
            driver: driver.into(),
            driver_info: String::new(),
            backend,
            subgroup_min_size: 4,
            subgroup_max_size: 4,
            transient_saves_memory: None,
            limit_bucket: None,
        }
    }

    #[test]
    fn only_lavapipe_binds_uniforms_as_storage() {
        assert!(uniforms_as_storage(&info("llvmpipe", wgpu::Backend::Vulkan)));
        assert!(!uniforms_as_storage(&info("llvmpipe", wgpu::Backend::Gl)));
        assert!(!uniforms_as_storage(&info("NVIDIA", wgpu::Backend::Vulkan)));
        assert!(!uniforms_as_storage(&info("", wgpu::Backend::BrowserWebGpu)));
    }

    #[test]
    fn uniform_declarations_and_bindings_become_read_only_storage() {
        let src = "@group(0) @binding(0) var<uniform> a: A;\n@group(0) @binding(1) var<storage, read_write> b: array<u32>;";
        assert_eq!(wgsl(src, false), src);
        let s = wgsl(src, true);
        assert!(s.contains("var<storage, read> a: A;") && !s.contains("var<uniform>") && s.contains("read_write> b"));
        let u = crate::binding::uniform();
        assert_eq!(binding_type(u, false), u);
        assert_eq!(binding_type(u, true), crate::binding::storage(true));
        assert_eq!(binding_type(crate::binding::storage(false), true), crate::binding::storage(false));
    }
}
