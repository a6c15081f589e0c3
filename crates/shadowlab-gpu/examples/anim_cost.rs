//! What moving objects cost per frame, on a built-in scene with animations, at t = 0:
//! `scene.animate` (CPU transform of the dynamic vertices, dynamic BVH rebuild, upload) and
//! `rt` with two trees (static + dynamic) against `rt` over one tree of the same triangles
//! (the scene with its animations dropped). Medians of `repeat` runs.
//! `cargo run -p shadowlab-gpu --example anim_cost [scene] [size] [repeat]`.

use std::time::Instant;

use shadowlab_core::builtin::builtin;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::timing::median;
use shadowlab_gpu::Gpu;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("foliage", |s| s.as_str());
    let size: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    let repeat: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(7);
    let gpu = Gpu::new().expect("GPU");
    let moving = builtin(name).expect("built-in scene");
    let mut still = moving.clone();
    still.animations.clear();
    let dynamic = moving.triangle_count() - moving.dynamic_first();
    println!(
        "{name}: {} triangles, {dynamic} dynamic; {size}x{size}; median of {repeat}; {}",
        moving.triangle_count(),
        gpu.adapter_summary()
    );
    for (label, scene) in [("one tree (animations dropped)", &still), ("static + dynamic tree", &moving)] {
        let lab = Lab::new(&gpu, scene).unwrap();
        let mut animate = Vec::new();
        for k in 0..repeat {
            let t0 = Instant::now();
            lab.set_time(k as f32 + 1.0, k as f32).unwrap();
            gpu.wait();
            animate.push(t0.elapsed().as_secs_f64() * 1e3);
        }
        lab.set_time(0.0, 0.0).unwrap();
        let v = lab.view(&scene.camera, &scene.camera, &scene.lights[0], size, size).unwrap();
        let rt = lab.reference(&v, repeat).unwrap();
        println!("  {label:32} rt {:7.2} ms   set_time {:6.3} ms   GPU BVH {} bytes", rt.total_ms, median(&animate), lab.gscene.bvh_bytes);
    }
}
