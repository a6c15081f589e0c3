//! Resources beyond the device's limits are refused, naming the limit, never a panic or a bare
//! validation error: the output size, a map's size, per-pixel and per-map buffers, a warped
//! map's piece capacity and a scene's data. The device is lavapipe opened with small limits
//! (a texture side of 1024, 1 MiB storage bindings, 4 MiB buffers), so each limit is reached
//! at sizes a test can afford.

use shadowlab_core::builtin::builtin;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::scene::Scene;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::{registry, Gpu};

use crate::common;

const SIDE: u32 = 1024;
const BINDING: u64 = 1 << 20;
const BUFFER: u64 = 4 << 20;

fn small() -> Option<Gpu> {
    common::gpu()?;
    let gpu = Gpu::new_with(|d| {
        d.required_limits.max_texture_dimension_2d = SIDE;
        d.required_limits.max_storage_buffer_binding_size = BINDING;
        d.required_limits.max_buffer_size = BUFFER;
    })
    .expect("lavapipe with smaller limits");
    assert_eq!((gpu.limits.max_texture_dimension_2d, gpu.limits.max_storage_buffer_binding_size), (SIDE, BINDING));
    Some(gpu)
}

/// Scene and light a technique runs on: planebox's sun, or room's point light.
fn stage(name: &str) -> (Scene, usize) {
    let info = registry::REGISTRY.iter().find(|i| i.name == name).unwrap();
    if info.lights.contains(&"directional") {
        (builtin("planebox").unwrap(), 0)
    } else {
        (builtin("room").unwrap(), 1)
    }
}

/// One frame of `spec` at `size`^2: Ok, or the error text (a panic fails the test).
fn attempt(gpu: &Gpu, spec: &str, size: u32) -> Result<(), String> {
    let name = spec.split(':').next().unwrap();
    let (scene, light) = stage(name);
    let lab = Lab::new(gpu, &scene).map_err(|e| e.to_string())?;
    let v = lab.view(&scene.camera, &scene.camera, &scene.lights[light], size, size).map_err(|e| e.to_string())?;
    gpu.take_error().map_err(|e| e.to_string())?;
    let r = lab.run(&v, &TechniqueSpec::parse(spec).unwrap(), 1).map_err(|e| e.to_string());
    gpu.take_error().map_err(|e| e.to_string())?;
    r.map(|_| ())
}

/// A refusal names a limit and a size; a bare device error does not.
fn names_a_limit(e: &str) -> bool {
    !e.contains("Validation Error") && (e.contains("max_") || e.contains(&SIDE.to_string()))
}

#[test]
fn an_output_over_the_texture_limit_is_refused() {
    let Some(gpu) = small() else { return };
    let scene = builtin("planebox").unwrap();
    let lab = Lab::new(&gpu, &scene).unwrap();
    let e = lab.view(&scene.camera, &scene.camera, &scene.lights[0], SIDE + 1, 8).err().expect("refused").to_string();
    assert!(e.contains("output size") && e.contains("1025x8") && e.contains("1024"), "{e}");
}

#[test]
fn an_output_whose_buffers_exceed_the_limits_is_refused_by_name() {
    let Some(gpu) = small() else { return };
    // 1024^2 fits the texture limit; the mask's 4 bytes a pixel (4 MiB) do not fit a 1 MiB binding
    let e = attempt(&gpu, "sm:res=256", SIDE).err().expect("refused");
    assert!(e.contains("max_storage_buffer_binding_size") && e.contains("MiB") && e.contains("smaller output"), "{e}");
    // the device is still usable at a size that fits
    attempt(&gpu, "sm:res=256", 64).unwrap();
}

#[test]
fn a_map_over_the_texture_limit_is_refused_for_every_technique() {
    let Some(gpu) = small() else { return };
    for info in registry::REGISTRY.iter().filter(|i| i.params().iter().any(|p| p.key == "res")) {
        let spec = format!("{}:res={}", info.name, 2 * SIDE);
        let e = attempt(&gpu, &spec, 32).err().unwrap_or_else(|| panic!("{spec} ran"));
        assert!(names_a_limit(&e) && e.contains(&(2 * SIDE).to_string()), "{spec}: {e}");
    }
}

/// At 512x512 and 512^2 maps every technique either runs or is refused with the limit named:
/// per-pixel buffers (lt's history: 8 bytes a pixel), per-map buffers (cube's six faces), iasm's
/// shadow buffer.
#[test]
fn every_technique_runs_or_names_the_limit_it_would_exceed() {
    let Some(gpu) = small() else { return };
    let mut refused = Vec::new();
    for info in registry::REGISTRY.iter() {
        let spec = if info.params().iter().any(|p| p.key == "res") { format!("{}:res=512", info.name) } else { info.name.to_string() };
        if let Err(e) = attempt(&gpu, &spec, 512) {
            assert!(names_a_limit(&e), "{spec}: {e}");
            refused.push(info.name);
        }
    }
    // the cases this test is for: lt's per-pixel history (2 MiB) and cube's faces (6 MiB)
    for must in ["lt", "cube"] {
        assert!(refused.contains(&must), "{must} fits these limits now: {refused:?}");
    }
    assert!(refused.len() < registry::REGISTRY.len(), "nothing ran: {refused:?}");
}

#[test]
fn a_piece_capacity_over_the_binding_limit_is_refused() {
    let Some(gpu) = small() else { return };
    let e = attempt(&gpu, "notw:res=256,subdiv_capacity=4000000", 32).err().expect("refused");
    assert!(e.contains("subdiv_capacity=4000000") && e.contains("max_storage_buffer_binding_size") && e.contains("at most"), "{e}");
    // the automatic capacity takes what the device holds
    attempt(&gpu, "notw:res=256", 32).unwrap();
}

#[test]
fn a_scene_over_the_binding_limit_is_refused() {
    let Some(gpu) = small() else { return };
    // eaves: 65 k roof tiles, about 10 MB of vertex data
    let scene = builtin("eaves").unwrap();
    let e = Lab::new(&gpu, &scene).err().expect("refused").to_string();
    assert!(e.contains("vertex data") && e.contains(&BINDING.to_string()), "{e}");
}
