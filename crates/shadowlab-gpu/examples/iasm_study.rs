//! The `iasm` studies of docs/bench/iasm.md (issue 6): along a scene's camera path, wrong pixels
//! and temporal flicker against `rt` for several specs (techniques keep state across frames, [`Lab::run_path`]);
//! and the tile-corner study (thesis Figures 4.3/4.4): the camera turned in steps about the
//! vertical axis, with the error in the camera's near field (samples within 0.4 tile of the
//! camera across the light) for the thesis placement and the tile-centre fix.
//!
//!     cargo run -p shadowlab-gpu --example iasm_study -- <builtin scene | setup.toml> <size> <frames> <spec>...
//!
//! `frames` 0 skips the path study; the corner study runs the first two `iasm...` specs given
//! (IASM_NO_CORNERS=1 skips it).

use glam::{Vec2, Vec3};
use shadowlab_core::builtin::builtin;
use shadowlab_core::camera::{path_cameras, Camera};
use shadowlab_core::metrics::compare;
use shadowlab_core::params::{ParamSet, TechniqueSpec};
use shadowlab_core::scene::Scene;
use shadowlab_core::setup::{SceneSource, Setup};
use shadowlab_core::techniques::iasm::{self as core, Anchor};
use shadowlab_gpu::lab::{Lab, PathSpec};
use shadowlab_gpu::registry::{self, Resolved};
use shadowlab_gpu::techniques::iasm::IasmSettings;
use shadowlab_gpu::Gpu;

type Res = Result<(), Box<dyn std::error::Error>>;

fn load(arg: &str) -> Result<(Scene, Camera), Box<dyn std::error::Error>> {
    if let Some(s) = builtin(arg) {
        let cam = s.camera;
        return Ok((s, cam));
    }
    let setup = Setup::load(std::path::Path::new(arg))?;
    let SceneSource::File(p) = setup.scene_source()? else { return Err("setup without a scene file".into()) };
    let mut scene = shadowlab_core::loaders::load(&p, &setup.transform())?;
    if !setup.lights.is_empty() {
        scene.lights = setup.lights.clone();
    }
    let cam = setup.camera.as_ref().map(|c| c.camera()).unwrap_or(scene.camera);
    scene.camera = cam;
    Ok((scene, cam))
}

fn main() -> Res {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 4 {
        return Err("usage: iasm_study <scene|setup.toml> <size> <frames> <spec>...".into());
    }
    let (scene, cam) = load(&args[0])?;
    let size: u32 = args[1].parse()?;
    let frames: usize = args[2].parse()?;
    let specs = &args[3..];
    let gpu = Gpu::new()?;
    let lab = Lab::new(&gpu, &scene)?;
    let light = scene.lights[0];
    println!("# {} ({} triangles), {size}x{size}, {}", scene.name, scene.triangle_count(), gpu.adapter_summary());
    if frames > 0 {
        path_study(&lab, &scene, &cam, size, frames, specs)?;
    }
    let iasm: Vec<&String> = specs.iter().filter(|s| s.starts_with("iasm")).take(2).collect();
    if !iasm.is_empty() && std::env::var_os("IASM_NO_CORNERS").is_none() {
        corner_study(&lab, &cam, &light, size, &iasm)?;
    }
    Ok(())
}

fn path_study(lab: &Lab, scene: &Scene, cam: &Camera, size: u32, frames: usize, specs: &[String]) -> Res {
    let light = scene.lights[0];
    let mut resolved: Vec<Resolved> = Vec::new();
    for s in specs {
        resolved.push(registry::resolve(&TechniqueSpec::parse(s)?, Some(&light))?);
    }
    // the scene held at t = 0 (moving objects still), each frame timed once
    let path = PathSpec {
        cameras: path_cameras(cam, &scene.camera_path, frames),
        light,
        width: size,
        height: size,
        start_time: 0.0,
        animate: false,
        specs: &resolved,
        repeat: 1,
    };
    let run = lab.run_path(&path, &mut |_| {})?;
    println!("\n## path: {frames} frames along the scene's camera path");
    println!("| spec | wrong % (mean) | wrong % (max) | flicker % (mean) | flicker % (max) |");
    println!("|---|---|---|---|---|");
    for (spec, t) in specs.iter().zip(&run.techniques) {
        let wrong: Vec<f64> = t.frames.iter().map(|r| r.quality.wrong_pct).collect();
        let flick: Vec<f64> = t.frames.iter().filter_map(|r| r.flicker_pct).collect();
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
        let max = |v: &[f64]| v.iter().cloned().fold(0.0, f64::max);
        println!("| `{spec}` | {:.3} | {:.3} | {:.3} | {:.3} |", mean(&wrong), max(&wrong), mean(&flick), max(&flick));
    }
    Ok(())
}

/// Distance (in tiles, across the light) from the camera to the nearest interior four-tile
/// corner of the square `p`.
fn corner_distance(p: &core::Placement, pos: Vec3) -> f32 {
    let c = (Vec2::new(pos.dot(p.right), pos.dot(p.up)) - p.origin) / p.tile_size();
    let mut best = f32::INFINITY;
    for i in 1..4 {
        for j in 1..4 {
            best = best.min((c - Vec2::new(i as f32, j as f32)).length());
        }
    }
    best
}

fn corner_study(lab: &Lab, cam: &Camera, light: &shadowlab_core::light::Light, size: u32, specs: &[&String]) -> Res {
    let shadowlab_core::light::Light::Directional { direction } = *light else { return Ok(()) };
    println!("\n## tile corners: camera turned about the vertical, near field = samples within 0.4 tile of the camera");
    print!("| yaw | corner dist. (tiles, thesis placement) |");
    for s in specs {
        print!(" `{s}` wrong % | near-field wrong % | near-field tiles (res) |");
    }
    println!();
    println!("|---|---|{}", "---|---|---|".repeat(specs.len()));
    let dir = cam.target - cam.position;
    for step in 0..12 {
        let yaw = step as f32 * 30.0;
        let rot = glam::Quat::from_rotation_y(yaw.to_radians());
        let c = Camera { target: cam.position + rot * dir, ..*cam };
        let v = lab.view(&c, &c, light, size, size)?;
        let rt = lab.reference(&v, 1)?;
        let mut row = format!("| {yaw:.0} |");
        let mut first = true;
        for s in specs {
            let run = lab.run(&v, &TechniqueSpec::parse(s)?, 0)?;
            let side = run.report.counters["square_side"] as f32;
            let settings = IasmSettings::from_values(&run.params);
            let anchor = Anchor::from(settings.anchor);
            let snap = settings.snap.then_some(side / 64.0);
            let p = core::place(direction, c.position, (c.target - c.position).normalize(), side, snap, anchor);
            if first {
                let thesis = core::place(direction, c.position, (c.target - c.position).normalize(), side, snap, Anchor::Circle);
                row += &format!(" {:.2} |", corner_distance(&thesis, c.position));
                first = false;
            }
            // near field: samples within 0.4 tile of the camera across the light
            let cpos = Vec2::new(c.position.dot(p.right), c.position.dot(p.up));
            let mut near_mask = v.mask.clone();
            let mut tiles = std::collections::BTreeSet::new();
            for (i, m) in near_mask.iter_mut().enumerate() {
                let q = Vec3::from_slice(&v.position[i][..3]);
                let d = (Vec2::new(q.dot(p.right), q.dot(p.up)) - cpos).length();
                if *m != 0 && d > 0.4 * p.tile_size() {
                    *m = 0;
                } else if *m != 0 {
                    let (t, _) = core::tile_of(p.uv(q));
                    tiles.insert((t, run.report.counters[&format!("tile{t:02}.res")] as u32));
                }
            }
            let all = compare(&run.visibility, &rt.visibility, &v.mask);
            let near = compare(&run.visibility, &rt.visibility, &near_mask);
            let ts: Vec<String> = tiles.iter().map(|(t, r)| format!("{t}:{r}")).collect();
            row += &format!(" {:.3} | {:.3} ({} px) | {} |", all.wrong_pct, near.wrong_pct, near.evaluated_pixels, ts.join(" "));
        }
        println!("{row}");
    }
    Ok(())
}
