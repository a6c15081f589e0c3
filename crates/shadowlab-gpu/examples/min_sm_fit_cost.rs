//! What the minimal shadow frustum costs on the CPU, three ways, for one 1024x1024 view:
//! (a) read back the whole position G-buffer and take the hull of every projected sample;
//! (b) the same read-back, reduced on the CPU to per-band extremes first;
//! (c) `min-sm`'s way: GPU reduction, 8 KB read back, hull of the band corners.
//! `cargo run -p shadowlab-gpu --example min_sm_fit_cost [scene] [size]` (built-in scene).

use std::time::Instant;

use glam::{DVec2, Vec3};
use shadowlab_core::builtin::builtin;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::techniques::min_sm::frustum::{light_frame, Reduction};
use shadowlab_core::techniques::min_sm::{convex_hull, min_area_rect};
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("courtyard", |s| s.as_str());
    let size: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let gpu = Gpu::new().expect("GPU");
    let scene = builtin(name).expect("built-in scene");
    let lab = Lab::new(&gpu, &scene).unwrap();
    let light = scene.lights[0];
    let v = lab.view(&scene.camera, &scene.camera, &light, size, size).unwrap();
    let frame = light_frame(&light, &lab.gscene.bounds).expect("directional or spot light");
    let best = |f: &mut dyn FnMut() -> f64| (0..5).map(|_| f()).fold(f64::INFINITY, f64::min);

    let readback = best(&mut || {
        let t = Instant::now();
        let bytes = gpu.read_texture(&v.gbuffer.position, 16);
        std::hint::black_box(bytes.len());
        let _ = gpu.read_buffer(&v.gbuffer.mask);
        ms(t)
    });
    let samples: Vec<(DVec2, f64)> = v
        .position
        .iter()
        .zip(&v.mask)
        .filter(|(_, m)| **m != 0)
        .map(|(p, _)| frame.project(Vec3::new(p[0], p[1], p[2]).as_dvec3()))
        .collect();
    let mut full_area = 0.0;
    let full = best(&mut || {
        let t = Instant::now();
        let pts: Vec<DVec2> = samples.iter().map(|s| s.0).collect();
        full_area = min_area_rect(&convex_hull(&pts)).unwrap().area();
        ms(t)
    });
    let mut reduced_area = 0.0;
    let cpu_bands = best(&mut || {
        let t = Instant::now();
        let red = Reduction::from_samples(&samples, 1024, None).unwrap();
        reduced_area = min_area_rect(&convex_hull(&red.points())).unwrap().area();
        ms(t)
    });
    let run = lab.run(&v, &TechniqueSpec::parse("min-sm").unwrap(), 5).unwrap();
    let c = &run.report.counters;
    println!("{name} {size}x{size}, {} evaluated samples, {}", samples.len(), gpu.adapter_summary());
    println!("(a) read-back of position + mask: {readback:.2} ms; hull + calipers of all samples: {full:.2} ms (CPU)");
    println!(
        "(b) CPU band reduction (1024 bands) + hull + calipers: {cpu_bands:.2} ms (CPU), area {:.5} of the exact",
        reduced_area / full_area
    );
    println!(
        "(c) min-sm: GPU reduce {:.2} ms ({}), read-back {:.3} ms, CPU fit {:.3} ms, {} reduced points, {} hull points",
        run.stages_ms["min-sm.reduce"],
        gpu.timer_name(),
        run.stages_ms["min-sm.readback"],
        c["cpu_fit_ms"],
        c["reduced_points"],
        c["hull_points"]
    );
}
