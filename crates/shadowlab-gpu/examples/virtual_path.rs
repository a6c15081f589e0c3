//! Page traffic of `virtual` along a built-in scene's camera path with its moving objects
//! (time = frame), one instance kept across the frames: per frame the pages marked, rendered,
//! cached, invalidated and fallen back, and the share rendered after frame 2; of the rendered
//! pages, those drawn whole and those rebuilt from their static copy, and the triangles drawn.
//!
//! `cargo run --release -p shadowlab-gpu --example virtual_path -- [scene] [frames] [size] [spec] [still]`
//! (defaults: foliage, 60, 1024, `virtual`; `still` holds the camera at frame 0's).

use shadowlab_core::builtin::builtin;
use shadowlab_core::camera::path_cameras;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::registry;
use shadowlab_gpu::Gpu;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_name = args.first().map(String::as_str).unwrap_or("foliage");
    let frames: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(60);
    let size: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1024);
    let spec = args.get(3).map(String::as_str).unwrap_or("virtual");
    let still = args.get(4).is_some_and(|s| s == "still");
    let gpu = Gpu::new()?;
    let scene = builtin(scene_name).ok_or("no such built-in scene")?;
    let lab = Lab::new(&gpu, &scene)?;
    let light = scene.lights[0];
    let mut cams = path_cameras(&scene.camera, &scene.camera_path, frames);
    if still {
        cams = vec![cams[0]; frames];
    }
    let r = registry::resolve(&TechniqueSpec::parse(spec)?, Some(&light))?;
    let mut inst = lab.instantiate(&r, &light)?;
    println!("{scene_name} {spec}, {frames} frames at {size}x{size}, camera {}", if still { "still" } else { "on the path" });
    println!("frame marked rendered whole from_copy cached invalidated fallen_back triangles ms");
    let (mut marked_sum, mut rendered_sum, mut worst) = (0.0, 0.0, 0.0f64);
    let (mut whole_sum, mut tri_sum, mut worst_whole) = (0.0, 0.0, 0.0f64);
    for (f, cam) in cams.iter().enumerate() {
        let t = f as f32;
        lab.set_time(t, (t - 1.0).max(0.0))?;
        let prev = cams[f.saturating_sub(1)];
        let v = lab.view(cam, &prev, &light, size, size)?;
        let run = lab.step(&v, &mut inst, false, 1)?;
        let c = &run.report.counters;
        let (m, rd) = (c["pages_marked"], c["pages_rendered"]);
        // drawn whole: with all their geometry (a static copy drawn counts: it is the page's)
        let whole = c["pages_drawn_whole"] + c["static_copies_drawn"];
        println!(
            "{f} {m} {rd} {whole} {} {} {} {} {} {:.1}",
            c["pages_from_static_copy"],
            c["pages_cached"],
            c["pages_invalidated"],
            c["pages_fallen_back"],
            c["triangles_drawn"],
            run.total_ms
        );
        if f >= 2 {
            marked_sum += m;
            rendered_sum += rd;
            worst = worst.max(rd / m.max(1.0));
            whole_sum += whole;
            tri_sum += c["triangles_drawn"];
            worst_whole = worst_whole.max(whole / m.max(1.0));
        }
    }
    println!(
        "after frame 2: rendered / marked = {:.2} % overall, worst frame {:.2} %",
        100.0 * rendered_sum / marked_sum.max(1.0),
        100.0 * worst
    );
    println!(
        "after frame 2: drawn whole / marked = {:.2} % overall, worst frame {:.2} %; triangles drawn per frame {:.0}",
        100.0 * whole_sum / marked_sum.max(1.0),
        100.0 * worst_whole,
        tri_sum / (frames.saturating_sub(2)).max(1) as f64
    );
    Ok(())
}
