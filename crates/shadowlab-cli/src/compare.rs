//! `render` and `compare`: one view, the reference, the techniques, metrics and outputs.

use std::path::Path;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;
use shadowlab_core::metrics::{edge_pixels, error_image};
use shadowlab_gpu::lab::path::{cameras, PathRun, PathSpec, Progress};
use shadowlab_gpu::lab::{reference_total_ms, summarize, Lab, Run};
use shadowlab_gpu::Gpu;

use crate::config::{resolve, RunConfig};
use crate::output::{slug, StagedDir};
use crate::{export, report, RunArgs};

fn progress(quiet: bool, len: u64) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    pb.set_style(ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} {msg}").unwrap());
    pb
}

pub fn render(args: &RunArgs, out: &Path) -> Result<()> {
    anyhow::ensure!(args.frames == 1, "render draws one view; use compare --frames {} for a camera path", args.frames);
    let cfg = resolve(args, &["rt".to_string()])?;
    anyhow::ensure!(cfg.specs.len() == 1, "render takes one technique (got {}); use compare for several", cfg.specs.len());
    let gpu = Gpu::new()?;
    let lab = Lab::new(&gpu, &cfg.scene)?;
    lab.set_time(cfg.time, cfg.time)?;
    let view = lab.view(&cfg.camera, &cfg.camera, cfg.light(), cfg.width, cfg.height)?;
    let run = lab.run_resolved(&view, &cfg.specs[0], args.repeat)?;
    let tmp = out.with_extension("partial.png");
    export::png(&tmp, cfg.width, cfg.height, &run.shaded)?;
    std::fs::rename(&tmp, out)?;
    if !args.quiet {
        println!("{} -> {} ({:.1} ms, {})", run.label, out.display(), run.total_ms, gpu.timer_name());
    }
    Ok(())
}

pub fn compare(args: &RunArgs, out: &Path, export_raw: bool) -> Result<()> {
    anyhow::ensure!(args.frames >= 1, "--frames must be at least 1");
    let cfg = resolve(args, &shadowlab_gpu::registry::default_compare())?;
    // before any work: never replace what shadowlab did not write
    crate::output::check_target(out)?;
    let t_start = std::time::Instant::now();
    let gpu = Gpu::new()?;
    let frames = args.frames.max(1);
    let pb = progress(args.quiet, 1 + frames as u64 * (cfg.specs.len() as u64 + 1));
    pb.set_message("BVH + upload");
    let lab = Lab::new(&gpu, &cfg.scene)?;
    pb.inc(1);
    let path = run_path(&lab, &cfg, frames, args.repeat, &pb)?;
    pb.finish_and_clear();
    let (view, rt) = (&path.view, &path.rt);

    let dir = StagedDir::new(out)?;
    let (w, h) = (cfg.width, cfg.height);
    export::png(&dir.path("rt.png"), w, h, &rt.shaded)?;
    let edges = edge_pixels(&rt.visibility, &view.mask, w as usize, h as usize);
    let mut techniques = Vec::new();
    for t in &path.techniques {
        let run = &t.last;
        let s = slug(&run.label);
        let m = summarize(&t.frames);
        export::png(&dir.path(&format!("{s}.png")), w, h, &run.shaded)?;
        export::png(
            &dir.path(&format!("{s}-error.png")),
            w,
            h,
            &error_image(&rt.shaded, &run.visibility, &rt.visibility, &view.mask, false),
        )?;
        export::png(
            &dir.path(&format!("{s}-error-split.png")),
            w,
            h,
            &error_image(&rt.shaded, &run.visibility, &rt.visibility, &view.mask, true),
        )?;
        let mut images = Vec::new();
        for (k, img) in run.report.images.iter().enumerate() {
            let file = format!("{s}-extra{k}.png");
            export::png(&dir.path(&file), img.width, img.height, &img.rgba)?;
            images.push(json!({"name": img.name, "file": file}));
        }
        techniques.push(json!({
            "label": run.label,
            "technique": run.technique,
            "params": run.params,
            "wrong_pct": m.wrong_pct,
            "false_lit_pct": m.false_lit_pct,
            "false_shadow_pct": m.false_shadow_pct,
            "mae": m.mae,
            "evaluated_pixels": m.evaluated_pixels,
            "flicker_pct": m.flicker_pct,
            "shadow_data_bytes": run.report.shadow_data_bytes,
            "stages_ms": if gpu.gpu_timestamps { &m.stages_ms } else { &t.breakdown_ms },
            "total_ms": m.total_ms,
            "submits_per_frame": run.submits_per_frame,
            "stalls": run.stalls,
            "setup_ms": run.setup_ms,
            "counters": run.report.counters,
            "sampling": run.report.sampling,
            "images": {"shaded": format!("{s}.png"), "error": format!("{s}-error.png"), "error_split": format!("{s}-error-split.png"), "extra": images},
            "visibility_npy": export_raw.then(|| format!("visibility/{s}.npy")),
            "frames": t.frames,
        }));
    }
    let runs: Vec<&Run> = path.techniques.iter().map(|t| &t.last).collect();
    let rt_total = reference_total_ms(&path.reference);
    let metrics = json!({
        "scene": cfg.scene.name,
        "scene_source": cfg.source,
        "scene_transform": row_major(&cfg.scene.transform),
        "triangles": cfg.scene.triangle_count(),
        "has_cutouts": cfg.scene.has_cutouts(),
        "load_report": cfg.scene.report,
        "camera": cfg.camera,
        "lights": cfg.lights,
        "light_index": cfg.light_index,
        "width": w,
        "height": h,
        "adapter": gpu.adapter_summary(),
        "timer": gpu.timer_name(),
        "stages_timer": gpu.stages_timer_name(),
        "repeat": args.repeat,
        "animation": animation_json(&cfg, &lab),
        "bvh": {"gpu_bytes": lab.gscene.bvh_bytes, "nodes": lab.bvh.nodes.len(), "bytes": lab.bvh.bytes(), "bytes_per_triangle": lab.bvh.bytes() as f64 / cfg.scene.triangle_count() as f64, "depth": lab.bvh.depth, "build_ms": lab.bvh.build_ms},
        "gbuffer_ms": view.frame_ms,
        "gbuffer_stages_ms": view.stages_ms,
        "frames": frames,
        "cameras": path.cameras,
        "reference": {
            "label": "rt",
            "evaluated_pixels": view.mask.iter().filter(|m| **m != 0).count(),
            "edge_pixels": edges,
            "stages_ms": if gpu.gpu_timestamps { &rt.stages_ms } else { &path.rt_breakdown_ms },
            "total_ms": rt_total,
            "counters": rt.report.counters,
            "frames": path.reference,
        },
        "techniques": techniques,
        "peak_rss_mib": crate::bench::peak_rss_mib(),
    });
    std::fs::write(dir.path("metrics.json"), serde_json::to_string_pretty(&metrics)?)?;
    std::fs::write(dir.path("metrics.csv"), csv(&metrics))?;
    if export_raw {
        export::gbuffer(&dir.tmp, w, h, &view.position, &view.normal, &view.mask)?;
        std::fs::create_dir_all(dir.path("visibility"))?;
        export::npy(&dir.path("visibility/rt.npy"), &[h as u64, w as u64], &rt.visibility)?;
        for run in &runs {
            export::npy(&dir.path(&format!("visibility/{}.npy", slug(&run.label))), &[h as u64, w as u64], &run.visibility)?;
        }
    }
    std::fs::write(dir.path("index.html"), report::html(&metrics)?)?;
    let final_dir = dir.commit()?;
    if !args.quiet {
        summary(&cfg, &metrics);
        println!("report: {} ({:.1} s)", final_dir.join("index.html").display(), t_start.elapsed().as_secs_f64());
    }
    Ok(())
}

/// Moving objects: how many triangles move (0 = a still scene), which, how, and the times.
fn animation_json(cfg: &RunConfig, lab: &Lab) -> serde_json::Value {
    let s = &cfg.scene;
    json!({
        "dynamic_triangles": s.triangle_count() - s.dynamic_first(),
        "dynamic_first": lab.gscene.dynamic_first,
        "time_unit": "frames",
        "start_time": cfg.time,
        "animations": s.animations.iter().map(|a| json!({"name": a.name, "triangles": a.count, "motion": a.motion})).collect::<Vec<_>>(),
    })
}

/// The reference and `cfg.specs` over `frames` views along the configured camera path (see
/// [`shadowlab_gpu::lab::path`] for what is timed and averaged), driving the progress bar.
fn run_path(lab: &Lab, cfg: &RunConfig, frames: usize, repeat: usize, pb: &ProgressBar) -> Result<PathRun> {
    let spec = PathSpec {
        cameras: cameras(&cfg.camera, &cfg.camera_path, frames),
        light: *cfg.light(),
        width: cfg.width,
        height: cfg.height,
        start_time: cfg.time,
        animate: true,
        specs: &cfg.specs,
        repeat,
    };
    Ok(lab.run_path(&spec, &mut |p| match p {
        Progress::Stage(s) => pb.set_message(s.to_string()),
        Progress::Step => pb.inc(1),
        Progress::Frame { .. } => {}
    })?)
}

fn row_major(m: &glam::Mat4) -> [[f32; 4]; 4] {
    m.transpose().to_cols_array_2d()
}

const CSV_COLUMNS: &[&str] =
    &["wrong_pct", "false_lit_pct", "false_shadow_pct", "mae", "flicker_pct", "evaluated_pixels", "shadow_data_bytes", "total_ms"];

fn csv(metrics: &serde_json::Value) -> String {
    let mut s = format!("label,technique,{},fetches_per_pixel,rays_traced\n", CSV_COLUMNS.join(","));
    for t in metrics["techniques"].as_array().into_iter().flatten() {
        let q = |k: &str| t["counters"].get(k).map(|v| v.to_string()).unwrap_or_default();
        let cols: Vec<String> = CSV_COLUMNS.iter().map(|k| if t[*k].is_null() { String::new() } else { t[*k].to_string() }).collect();
        s += &format!(
            "\"{}\",{},{},{},{}\n",
            t["label"].as_str().unwrap_or("").replace('"', "\"\""),
            t["technique"].as_str().unwrap_or(""),
            cols.join(","),
            q("fetches_per_pixel"),
            q("rays_traced")
        );
    }
    s
}

fn summary(cfg: &RunConfig, m: &serde_json::Value) {
    println!(
        "{} ({} triangles), {}x{}, light {} ({}), {}",
        cfg.scene.name,
        cfg.scene.triangle_count(),
        cfg.width,
        cfg.height,
        cfg.light_index,
        cfg.light().kind(),
        m["adapter"].as_str().unwrap_or("")
    );
    println!("{:<28} {:>8} {:>9} {:>9} {:>8} {:>10} {:>12}", "technique", "wrong%", "f-lit%", "f-shad%", "mae", "ms", "bytes");
    println!(
        "{:<28} {:>8} {:>9} {:>9} {:>8} {:>10.2} {:>12}",
        "rt (reference)",
        "-",
        "-",
        "-",
        "-",
        m["reference"]["total_ms"].as_f64().unwrap_or(0.0),
        m["bvh"]["bytes"]
    );
    for t in m["techniques"].as_array().into_iter().flatten() {
        let f = |k: &str| t[k].as_f64().unwrap_or(f64::NAN);
        println!(
            "{:<28} {:>8.3} {:>9.3} {:>9.3} {:>8.4} {:>10.2} {:>12}",
            t["label"].as_str().unwrap_or(""),
            f("wrong_pct"),
            f("false_lit_pct"),
            f("false_shadow_pct"),
            f("mae"),
            f("total_ms"),
            t["shadow_data_bytes"]
        );
    }
    println!("times: median of {} frames, {}", m["repeat"], m["timer"].as_str().unwrap_or(""));
    for t in m["techniques"].as_array().into_iter().flatten() {
        if let Some(s) = t["stalls"].as_array().filter(|s| !s.is_empty()) {
            let names: Vec<&str> = s.iter().filter_map(|v| v.as_str()).collect();
            println!("  {} stalls mid-frame: {}", t["label"].as_str().unwrap_or(""), names.join(", "));
        }
    }
}
