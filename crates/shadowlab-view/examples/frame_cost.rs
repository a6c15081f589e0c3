//! The viewer's frame cost without a window: `frames` moving frames (the camera orbits one
//! degree per frame) of each technique at a size, then how long a still view takes to have its
//! reference current. The window's own cost (egui, present) is not in these figures.
//!
//!     cargo run --release -p shadowlab-view --example frame_cost -- [SCENE] [WxH] [FRAMES] [SPEC...]

use shadowlab_core::builtin::builtin;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;
use shadowlab_view::fly::orbit;
use shadowlab_view::render::{Look, Pose, RefStatus, Renderer, Right, Show};
use shadowlab_view::widgets::resolve_text;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_name = args.first().map_or("courtyard", |s| s.as_str());
    let size = args.get(1).map_or("1280x720", |s| s.as_str());
    let frames: usize = args.get(2).map_or(Ok(20), |s| s.parse())?;
    let specs: Vec<&str> = if args.len() > 3 { args[3..].iter().map(|s| s.as_str()).collect() } else { vec!["sm", "csm", "lt"] };
    let (w, h) = size.split_once('x').ok_or("size WxH")?;
    let (w, h): (u32, u32) = (w.parse()?, h.parse()?);
    let scene = builtin(scene_name).ok_or("unknown built-in scene")?;
    let gpu = Gpu::new()?;
    println!("{} at {w}x{h}, {} ({})", scene_name, gpu.adapter_summary(), gpu.timer_name());
    for spec in specs {
        let lab = Lab::new(&gpu, &scene)?;
        let light = scene.lights[0];
        let mut r = Renderer::new(lab, w, h, &light, resolve_text(spec)?, None)?;
        let look = Look { show: Show::Shaded, right: Right::None, divider: 0.5 };
        let mut cam = scene.camera;
        let mut ms = Vec::new();
        for i in 0..frames + 2 {
            let next = orbit(&cam, 1.0);
            let info = r.frame(&Pose { camera: next, prev_camera: cam, light, time: 0.0, prev_time: 0.0 }, &look, false)?;
            cam = next;
            if i >= 2 {
                ms.push(info.frame_ms);
            }
        }
        ms.sort_by(f64::total_cmp);
        let median = ms[ms.len() / 2];
        let t0 = std::time::Instant::now();
        let pose = Pose { camera: cam, prev_camera: cam, light, time: 0.0, prev_time: 0.0 };
        let mut n = 0;
        while r.frame(&pose, &look, true)?.reference != RefStatus::Current || r.evaluation().is_none() {
            n += 1;
        }
        println!(
            "{spec:>6}: moving {median:7.1} ms/frame ({:.1} fps); still: reference and evaluation current after {:.0} ms ({} frames)",
            1000.0 / median,
            t0.elapsed().as_secs_f64() * 1e3,
            n + 1
        );
    }
    Ok(())
}
