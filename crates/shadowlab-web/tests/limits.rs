//! Each technique's declared storage buffers per shader stage (`TechniqueInfo::storage_buffers`)
//! is what it binds: on the same adapter opened with exactly that limit it runs; with one less
//! (where it declares more than WebGPU's default 8) the device refuses its layouts. The lab
//! refuses a technique before making anything on a device below its need, naming the limit
//! (a browser's adapter may offer only the default 8; BENCHMARKS.md lists what runs where).
//!
//! It runs on SwiftShader's Vulkan driver (Chromium's, as tests/page.rs): lavapipe binds
//! uniforms as storage buffers (shadowlab_gpu::quirks), which would count them too. Its own
//! binary, so that setting VK_ICD_FILENAMES touches no other test's device.

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::{registry, Gpu};

const SWIFTSHADER_ICD: &str = "/usr/lib/chromium/vk_swiftshader_icd.json";

/// The test adapter again, its device limited to `n` storage buffers per shader stage.
fn gpu_with_storage_buffers(gpu: &Gpu, n: u32) -> Gpu {
    let other = Gpu::new_with(|d| d.required_limits.max_storage_buffers_per_shader_stage = n).unwrap_or_else(|e| panic!("{n}: {e}"));
    assert_eq!(other.info.name, gpu.info.name, "the same adapter");
    other
}

/// One frame of `name` on `gpu` (planebox's sun, or room's point light for point-only
/// techniques), with the device's errors.
fn frame(gpu: &Gpu, name: &str) -> Result<(), String> {
    let info = registry::REGISTRY.iter().find(|i| i.name == name).unwrap();
    let (scene_name, light) = if info.lights.contains(&"directional") { ("planebox", 0) } else { ("room", 1) };
    let scene = builtin(scene_name).unwrap();
    let lab = Lab::new(gpu, &scene).map_err(|e| e.to_string())?;
    let v = lab.view(&scene.camera, &scene.camera, &scene.lights[light], 32, 32).map_err(|e| e.to_string())?;
    let r = lab.run(&v, &TechniqueSpec::parse(name).unwrap(), 1).map_err(|e| e.to_string());
    gpu.take_error().map_err(|e| e.to_string())?;
    r.map(|_| ())
}

/// Whether making `name`'s pipelines on `gpu` (no frame) raises a device error.
fn makes_without_error(gpu: &Gpu, name: &str) -> Result<(), String> {
    let info = registry::REGISTRY.iter().find(|i| i.name == name).unwrap();
    let directional = info.lights.contains(&"directional");
    let scene = builtin(if directional { "planebox" } else { "room" }).unwrap();
    let lab = Lab::new(gpu, &scene).map_err(|e| e.to_string())?;
    let light = &scene.lights[if directional { 0 } else { 1 }];
    let spec = registry::resolve(&TechniqueSpec::parse(name).unwrap(), Some(light)).unwrap();
    let made = spec.info.create(gpu, &lab.gscene, &spec.values, light).map(|_| ()).map_err(|e| e.to_string());
    made.and_then(|_| gpu.take_error().map_err(|e| e.to_string()))
}

/// Points this process's Vulkan loader at SwiftShader (once, before any device: the two tests
/// run on threads of one process); false when GPU tests are skipped.
fn on_swiftshader() -> bool {
    static ONCE: std::sync::Once = std::sync::Once::new();
    if std::env::var_os("SHADOWLAB_SKIP_GPU_TESTS").is_some() {
        return false;
    }
    assert!(std::path::Path::new(SWIFTSHADER_ICD).exists(), "{SWIFTSHADER_ICD} missing: Debian's chromium package ships it");
    ONCE.call_once(|| std::env::set_var("VK_ICD_FILENAMES", SWIFTSHADER_ICD));
    true
}

#[test]
fn each_technique_binds_the_storage_buffers_it_declares() {
    if !on_swiftshader() {
        return;
    }
    let gpu = Gpu::new().expect("SwiftShader's Vulkan device");
    assert!(!shadowlab_gpu::quirks::uniforms_as_storage(&gpu.info), "{}", gpu.adapter_summary());
    let max = gpu.limits.max_storage_buffers_per_shader_stage;
    let mut wrong = Vec::new();
    for info in registry::REGISTRY.iter() {
        let (name, n) = (info.name, info.storage_buffers);
        // at its declared limit it runs a frame (above this adapter's most: checked on lavapipe's
        // larger limit by the GPU suite, which runs every technique)
        if n <= max {
            let at = gpu_with_storage_buffers(&gpu, n);
            if let Err(e) = frame(&at, name) {
                wrong.push(format!("{name} fails with its declared {n}: {e}"));
            }
        }
        // one below (or this adapter's most), the lab refuses it by name, and its own layouts
        // overflow: it declares no more than it binds
        if n > 8 {
            let below = gpu_with_storage_buffers(&gpu, (n - 1).min(max));
            match info.check_limits(&below.limits) {
                Err(e) => assert!(e.to_string().contains(&format!("needs {n} storage buffers per shader stage")), "{e}"),
                Ok(()) => wrong.push(format!("{name}: the lab accepts a device below its {n}")),
            }
            if makes_without_error(&below, name).is_ok() {
                wrong.push(format!(
                    "{name} declares {n} but makes its pipelines with {}",
                    below.limits.max_storage_buffers_per_shader_stage
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// What a browser at WebGPU's default limits can do. Nothing: the G-buffer's four targets need
/// 48 colour attachment bytes per sample (the default is 32), which the lab says by name. With
/// that one limit raised and every other at its default (8 storage buffers a stage, 128 MiB
/// bindings, ...), every technique that declares at most 8 storage buffers runs, the
/// reference among them.
#[test]
fn techniques_within_the_default_storage_buffers_run_under_webgpus_default_limits() {
    if !on_swiftshader() {
        return;
    }
    let plain = Gpu::new_with(|d| d.required_limits = wgpu::Limits::default()).expect("SwiftShader at WebGPU's default limits");
    let scene = builtin("planebox").unwrap();
    let refused = Lab::new(&plain, &scene).err().expect("the G-buffer exceeds the default colour limit").to_string();
    assert!(refused.contains("48 colour attachment bytes per sample") && refused.contains("offers 32"), "{refused}");
    let gpu = Gpu::new_with(|d| {
        d.required_limits = wgpu::Limits { max_color_attachment_bytes_per_sample: 48, ..wgpu::Limits::default() };
    })
    .expect("SwiftShader at the default limits but colour bytes");
    assert_eq!(gpu.limits.max_storage_buffers_per_shader_stage, 8);
    let mut ran = Vec::new();
    for info in registry::REGISTRY.iter().filter(|i| i.storage_buffers <= 8) {
        frame(&gpu, info.name).unwrap_or_else(|e| panic!("{} under the default limits: {e}", info.name));
        ran.push(info.name);
    }
    assert!(ran.contains(&"rt") && ran.contains(&"sm") && ran.contains(&"csm"), "{ran:?}");
    eprintln!("at WebGPU's default limits, colour bytes 48: {ran:?}");
}
