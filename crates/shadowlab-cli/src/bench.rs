//! `shadowlab bench`: per-stage times (median of several frames, wall clock with a device wait
//! per stage) on the built-in scenes and, when present, sponza and conference; peak resident
//! memory; BVH bytes per triangle.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{anyhow, Result};
use shadowlab_core::builtin::BUILTIN_SCENES;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::setup::Setup;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::timing::median;
use shadowlab_gpu::Gpu;

use crate::config::{load_scene, parse_size};
use crate::output::write_atomic;

/// Setups benchmarked besides the built-in scenes, when their scene files exist.
const REAL_SETUPS: &[&str] = &["setups/sponza.toml", "setups/conference.toml"];

/// Peak resident set size of this process (VmHWM), in MiB.
pub fn peak_rss_mib() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

pub fn bench(setups: &[PathBuf], size: &str, frames: usize, out: Option<&Path>) -> Result<()> {
    let (w, h) = parse_size(size)?;
    let frames = frames.max(1);
    let mut jobs: Vec<(String, Setup)> = Vec::new();
    if setups.is_empty() {
        for s in BUILTIN_SCENES.iter().filter(|s| s.name != "planebox") {
            jobs.push((s.name.into(), Setup::parse(&format!("[scene]\nbuiltin = \"{}\"", s.name)).map_err(|e| anyhow!(e))?));
        }
        for p in REAL_SETUPS {
            let setup = Setup::load(Path::new(p)).map_err(|e| anyhow!(e))?;
            match setup.scene.path.as_ref() {
                Some(sp) if sp.exists() => jobs.push((p.to_string(), setup)),
                _ => eprintln!("bench: skipping {p} (scene file not present)"),
            }
        }
    } else {
        for p in setups {
            jobs.push((p.display().to_string(), Setup::load(p).map_err(|e| anyhow!(e))?));
        }
    }
    let gpu = Gpu::new()?;
    let spec = TechniqueSpec::parse("sm:res=512").map_err(|e| anyhow!(e))?;
    let mut md = format!(
        "Machine: {} ({} cores); adapter {}; {w}x{h} output, sm 512x512; median of {frames} frames; {}.\n\n\
         | scene | triangles | load ms | BVH build ms | BVH B/tri | G-buffer ms | rt ms | sm render ms | sm evaluate ms | peak RSS MiB |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        cpu_name(),
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1),
        gpu.adapter_summary(),
        gpu.timer_name()
    );
    for (name, setup) in &jobs {
        eprintln!("bench: {name}");
        let t0 = Instant::now();
        let mut scene = load_scene(&setup.scene_source().map_err(|e| anyhow!(e))?, &setup.transform())?;
        shadowlab_core::anim::apply(&mut scene, &setup.animations).map_err(|e| anyhow!("{name}: [[animations]]: {e}"))?;
        let load_ms = t0.elapsed().as_secs_f64() * 1e3;
        let camera = setup.camera.as_ref().map(|c| c.camera()).unwrap_or(scene.camera);
        let light = setup.lights.first().copied().unwrap_or(scene.lights[0]);
        let lab = Lab::new(&gpu, &scene)?;
        let mut gb = Vec::new();
        let mut view = None;
        for _ in 0..frames {
            let v = lab.view(&camera, &camera, &light, w, h)?;
            gb.push(v.stages_ms["gbuffer"]);
            view = Some(v);
        }
        let view = view.unwrap();
        let rt = lab.reference(&view, frames)?;
        let sm = if light.kind() == "point" { None } else { Some(lab.run(&view, &spec, frames)?) };
        let st = |k: &str| sm.as_ref().map(|r| format!("{:.2}", r.stages_ms[k])).unwrap_or_else(|| "-".into());
        md += &format!(
            "| {} | {} | {:.0} | {:.0} | {:.1} | {:.2} | {:.2} | {} | {} | {:.0} |\n",
            scene.name,
            scene.triangle_count(),
            load_ms,
            lab.bvh.build_ms,
            lab.bvh.bytes() as f64 / scene.triangle_count() as f64,
            median(&gb),
            rt.total_ms,
            st("sm.render"),
            st("sm.evaluate"),
            peak_rss_mib().unwrap_or(f64::NAN)
        );
    }
    print!("{md}");
    if let Some(p) = out {
        write_atomic(p, md.as_bytes())?;
    }
    Ok(())
}

fn cpu_name() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| s.lines().find(|l| l.starts_with("model name")).and_then(|l| l.split(':').nth(1)).map(|s| s.trim().to_string()))
        .unwrap_or_else(|| "unknown CPU".into())
}
