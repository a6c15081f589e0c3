//! `render` and `compare`: one view, the reference, the techniques, metrics and outputs.

use std::path::Path;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use shadowlab_core::metrics::{edge_pixels, error_image};
use shadowlab_gpu::lab::path::{cameras, PathRun, PathSpec, Progress};
use shadowlab_gpu::lab::{reference_total_ms, summarize, Lab, TechniqueFrames};
use shadowlab_gpu::Gpu;

use crate::config::{resolve, RunConfig};
use crate::metrics::{AnimatedObject, Animation, Bvh, ExtraImage, Images, Metrics, Reference, Technique, SCHEMA_VERSION};
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
    shadowlab_gpu::lab::path::check_frames(args.frames)?;
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
    let mut techniques = Vec::new();
    for t in &path.techniques {
        let run = &t.last;
        let s = slug(&run.label);
        export::png(&dir.path(&format!("{s}.png")), w, h, &run.shaded)?;
        for (file, split) in [(format!("{s}-error.png"), false), (format!("{s}-error-split.png"), true)] {
            export::png(&dir.path(&file), w, h, &error_image(&rt.shaded, &run.visibility, &rt.visibility, &view.mask, split))?;
        }
        export::png(&dir.path(&format!("{s}-flip.png")), w, h, &t.last_flip.magma_rgba())?;
        let mut extra = Vec::new();
        for (k, img) in run.report.images.iter().enumerate() {
            let file = format!("{s}-extra{k}.png");
            export::png(&dir.path(&file), img.width, img.height, &img.rgba)?;
            extra.push(ExtraImage { name: img.name.clone(), file });
        }
        let images = Images {
            shaded: format!("{s}.png"),
            error: format!("{s}-error.png"),
            error_split: format!("{s}-error-split.png"),
            flip: format!("{s}-flip.png"),
            extra,
        };
        techniques.push(technique(t, gpu.gpu_timestamps, images, export_raw.then(|| format!("visibility/{s}.npy"))));
    }
    let metrics = Metrics {
        schema_version: SCHEMA_VERSION,
        scene: cfg.scene.name.clone(),
        scene_source: cfg.source.clone(),
        scene_transform: row_major(&cfg.scene.transform),
        triangles: cfg.scene.triangle_count(),
        has_cutouts: cfg.scene.has_cutouts(),
        load_report: cfg.scene.report.clone(),
        camera: cfg.camera,
        lights: cfg.lights.clone(),
        light_index: cfg.light_index,
        width: w,
        height: h,
        adapter: gpu.adapter_summary(),
        timer: gpu.timer_name().into(),
        stages_timer: gpu.stages_timer_name().into(),
        repeat: args.repeat,
        animation: animation(&cfg, &lab),
        bvh: Bvh {
            gpu_bytes: lab.gscene.bvh_bytes,
            nodes: lab.bvh.nodes.len(),
            bytes: lab.bvh.bytes(),
            bytes_per_triangle: lab.bvh.bytes() as f64 / cfg.scene.triangle_count() as f64,
            depth: lab.bvh.depth,
            build_ms: lab.bvh.build_ms,
        },
        gbuffer_ms: view.frame_ms,
        gbuffer_stages_ms: view.stages_ms.clone(),
        frames,
        cameras: path.cameras.clone(),
        reference: Reference {
            label: "rt".into(),
            evaluated_pixels: view.mask.iter().filter(|m| **m != 0).count(),
            edge_pixels: edge_pixels(&rt.visibility, &view.mask, w as usize, h as usize),
            stages_ms: if gpu.gpu_timestamps { rt.stages_ms.clone() } else { path.rt_breakdown_ms.clone() },
            total_ms: reference_total_ms(&path.reference),
            counters: rt.report.counters.clone(),
            frames: path.reference.clone(),
        },
        techniques,
        peak_rss_mib: crate::bench::peak_rss_mib(),
        warnings: crate::metrics::run_warnings(&path.reference),
    };
    std::fs::write(dir.path("metrics.json"), metrics.to_json()?)?;
    std::fs::write(dir.path("metrics.csv"), crate::metrics::csv(&metrics))?;
    if export_raw {
        export::gbuffer(&dir.tmp, w, h, &view.position, &view.normal, &view.mask)?;
        std::fs::create_dir_all(dir.path("visibility"))?;
        export::npy(&dir.path("visibility/rt.npy"), &[h as u64, w as u64], &rt.visibility)?;
        for t in &path.techniques {
            export::npy(&dir.path(&format!("visibility/{}.npy", slug(&t.last.label))), &[h as u64, w as u64], &t.last.visibility)?;
        }
    }
    std::fs::write(dir.path("index.html"), report::html(&metrics)?)?;
    let final_dir = dir.commit()?;
    crate::metrics::warnings(&metrics);
    if !args.quiet {
        crate::metrics::summary(&metrics);
        println!("report: {} ({:.1} s)", final_dir.join("index.html").display(), t_start.elapsed().as_secs_f64());
    }
    Ok(())
}

/// One technique's entry: its summary over the frames, the last frame's report.
fn technique(t: &TechniqueFrames, gpu_timestamps: bool, images: Images, visibility_npy: Option<String>) -> Technique {
    let run = &t.last;
    let m = summarize(&t.frames);
    Technique {
        label: run.label.clone(),
        technique: run.technique.into(),
        params: run.params.clone(),
        quality: m.quality,
        flip_mean: m.flip_mean,
        flicker_pct: m.flicker_pct,
        shadow_data_bytes: run.report.shadow_data_bytes,
        stages_ms: if gpu_timestamps { m.stages_ms } else { t.breakdown_ms.clone() },
        total_ms: m.total_ms,
        submits_per_frame: run.submits_per_frame,
        stalls: run.stalls.clone(),
        setup_ms: run.setup_ms,
        counters: run.report.counters.clone(),
        sampling: run.report.sampling,
        degraded: run.report.degraded.clone(),
        images,
        visibility_npy,
        frames: t.frames.clone(),
    }
}

/// Moving objects: how many triangles move (0 = a still scene), which, how, and the times.
fn animation(cfg: &RunConfig, lab: &Lab) -> Animation {
    let s = &cfg.scene;
    Animation {
        dynamic_triangles: s.triangle_count() - s.dynamic_first(),
        dynamic_first: lab.gscene.dynamic_first,
        time_unit: "frames".into(),
        start_time: cfg.time,
        animations: s.animations.iter().map(|a| AnimatedObject { name: a.name.clone(), triangles: a.count, motion: a.motion }).collect(),
    }
}

fn row_major(m: &glam::Mat4) -> [[f32; 4]; 4] {
    m.transpose().to_cols_array_2d()
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
