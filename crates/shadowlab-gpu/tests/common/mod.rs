//! Helpers shared by the GPU integration test files (`mod common;`).
#![allow(dead_code)]

use shadowlab_core::metrics::{compare, error_image};
use shadowlab_core::scene::Scene;
use shadowlab_gpu::lab::{Lab, Run, View};
use shadowlab_gpu::Gpu;

/// The device, or None (test returns early) when SHADOWLAB_SKIP_GPU_TESTS=1. A missing adapter
/// otherwise fails the test; CI never sets the variable.
pub fn gpu() -> Option<Gpu> {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        eprintln!("SHADOWLAB_SKIP_GPU_TESTS=1: GPU test not run");
        return None;
    }
    Some(Gpu::new().unwrap_or_else(|e| panic!("{e} (set SHADOWLAB_SKIP_GPU_TESTS=1 to skip GPU tests)")))
}

pub fn view(lab: &Lab, scene: &Scene, light: usize, size: u32) -> View {
    lab.view(&scene.camera, &scene.camera, &scene.lights[light], size, size).unwrap()
}

pub fn agreement(a: &[f32], b: &[f32], mask: &[u32]) -> f64 {
    100.0 - compare(a, b, mask).wrong_pct
}

/// On a failed image comparison, keeps `<name>-actual.png`, `<name>-expected.png` and
/// `<name>-difference.png` (wrong pixels in red) under target/test-output for inspection.
pub fn save_images(name: &str, v: &View, actual: &Run, expected: &Run) -> String {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/test-output");
    std::fs::create_dir_all(&dir).unwrap();
    let diff = error_image(&expected.shaded, &actual.visibility, &expected.visibility, &v.mask, true);
    for (suffix, px) in [("actual", &actual.shaded), ("expected", &expected.shaded), ("difference", &diff)] {
        let p = dir.join(format!("{name}-{suffix}.png"));
        image::save_buffer(&p, px, v.width, v.height, image::ExtendedColorType::Rgba8).unwrap();
    }
    format!("images in {}", dir.display())
}
