//! Temporal stability of cascaded shadow maps along a scene's camera path: per technique, the
//! mean wrong-pixel rate and the flicker (GUIDE.md: % of pixels whose thresholded visibility
//! flips between consecutive frames while `rt`'s does not), each technique instance kept across
//! the frames ([`Lab::run_path`], the scene's moving objects held at t = 0).
//!
//! `cargo run -p shadowlab-gpu --example csm_path -- [scene] [frames] [size] [span] [spec...]`
//! (`scene`: a built-in scene, e.g. `city`)
//! (defaults: courtyard, 24, 512, span 1, and csm with/without snapping and tightening, the box
//! fit, sm). `span` < 1 walks only that fraction of the path's first segment: small, sub-texel
//! steps, where the screen barely changes and shimmering shows alone in the flicker; a negative
//! `span` instead turns the camera at the path's first key by |span| degrees per frame about
//! the vertical (the case where a sphere-fitted box keeps its size and a tight box does not).

use shadowlab_core::builtin::builtin;
use shadowlab_core::camera::{path_cameras, Camera, CameraKey};
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::{Lab, PathSpec, Progress};
use shadowlab_gpu::registry;
use shadowlab_gpu::Gpu;

const DEFAULT_SPECS: &[&str] = &[
    "csm",
    "csm:snap=false",
    "csm:tighten=false",
    "csm:snap=false,tighten=false",
    "csm:fit=box",
    "csm:fit=box,tighten=false",
    "sm",
    "sm:res=2048",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let scene_name = args.first().map(String::as_str).unwrap_or("courtyard");
    let frames: usize = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(24);
    let size: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(512);
    let span: f32 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(1.0);
    let specs: Vec<String> = if args.len() > 4 { args[4..].to_vec() } else { DEFAULT_SPECS.iter().map(|s| s.to_string()).collect() };

    let gpu = Gpu::new()?;
    let scene = builtin(scene_name).ok_or("no such built-in scene")?;
    let lab = Lab::new(&gpu, &scene)?;
    let light = scene.lights[0];
    let keys = match (span < 1.0, scene.camera_path.as_slice()) {
        (true, [a, b, ..]) => vec![*a, CameraKey { position: a.position.lerp(b.position, span), target: a.target.lerp(b.target, span) }],
        _ => scene.camera_path.clone(),
    };
    let cams = if span < 0.0 {
        let k = scene.camera_path.first().map(|k| (k.position, k.target)).unwrap_or((scene.camera.position, scene.camera.target));
        (0..frames)
            .map(|f| {
                let rot = glam::Quat::from_rotation_y((-span * f as f32).to_radians());
                Camera { position: k.0, target: k.0 + rot * (k.1 - k.0), ..scene.camera }
            })
            .collect()
    } else {
        path_cameras(&scene.camera, &keys, frames)
    };
    let step = if cams.len() > 1 { (cams[1].position - cams[0].position).length() } else { 0.0 };

    let mut resolved = Vec::new();
    for s in &specs {
        resolved.push(registry::resolve(&TechniqueSpec::parse(s)?, Some(&light))?);
    }
    // the scene held at t = 0 (moving objects still), each frame timed once
    let path = PathSpec { cameras: cams, light, width: size, height: size, start_time: 0.0, animate: false, specs: &resolved, repeat: 1 };
    // how much of the screen the reference itself changes per frame pair (context for the flicker)
    let mut rt_flips = Vec::new();
    let mut prev: Option<(Vec<f32>, Vec<u32>)> = None;
    let run = lab.run_path(&path, &mut |p| {
        if let Progress::Frame { view, rt, .. } = p {
            if let Some((prev_rt, prev_mask)) = &prev {
                let both = prev_mask.iter().zip(&view.mask).filter(|(a, b)| **a != 0 && **b != 0).count().max(1);
                let flips = (0..view.mask.len())
                    .filter(|&i| prev_mask[i] != 0 && view.mask[i] != 0 && (prev_rt[i] >= 0.5) != (rt.visibility[i] >= 0.5))
                    .count();
                rt_flips.push(100.0 * flips as f64 / both as f64);
            }
            prev = Some((rt.visibility.clone(), view.mask.clone()));
        }
    })?;
    let mean = |v: &[f64]| if v.is_empty() { 0.0 } else { v.iter().sum::<f64>() / v.len() as f64 };
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    println!(
        "{scene_name}, {frames} frames of its camera path (span {span}, {step:.4} per frame) at {size}x{size}, {}",
        gpu.adapter_summary()
    );
    println!("rt itself flips {:.3} % of the pixels per frame pair (mean)\n", mean(&rt_flips));
    println!("| technique | wrong % (mean) | wrong % (max) | flicker % (mean) | flicker % (max) |");
    println!("|---|---:|---:|---:|---:|");
    for (spec, t) in resolved.iter().zip(&run.techniques) {
        let wrong: Vec<f64> = t.frames.iter().map(|r| r.quality.wrong_pct).collect();
        let flicker: Vec<f64> = t.frames.iter().filter_map(|r| r.flicker_pct).collect();
        println!("| `{}` | {:.3} | {:.3} | {:.4} | {:.4} |", spec.label, mean(&wrong), max(&wrong), mean(&flicker), max(&flicker));
    }
    Ok(())
}
