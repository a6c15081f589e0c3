//! Computing the pending points of one setup: the scene on the GPU once, the G-buffer and the
//! reference `rt` once per view (frame), reused by every pending spec. One view: each point is
//! finished, and handed to `done` (which stores it), as soon as its technique has run; a camera
//! path: all the setup's pending specs run along the path together ([`Lab::run_path`]) and are
//! finished at its end.

use anyhow::{anyhow, Context, Result};
use indicatif::ProgressBar;
use shadowlab_core::flip::flip_rgba8;
use shadowlab_core::metrics::{compare as metrics_of, edge_pixels};
use shadowlab_gpu::lab::path::{cameras, PathSpec, Progress};
use shadowlab_gpu::lab::{summarize, FrameRecord, Lab, Run};
use shadowlab_gpu::registry::{self, Resolved};
use shadowlab_gpu::Gpu;

use super::plan::SetupPlan;
use super::record::Row;

/// What the progress bar counts for a setup with `pending` points: per frame, the view
/// (G-buffer + reference) and each point.
pub fn steps(frames: usize, pending: usize) -> u64 {
    if pending == 0 {
        0
    } else {
        (frames * (1 + pending)) as u64
    }
}

fn row(
    sp: &SetupPlan,
    spec: usize,
    run: &Run,
    frames: &[FrameRecord],
    breakdown: Option<&std::collections::BTreeMap<String, f64>>,
    gpu: &Gpu,
) -> Row {
    let m = summarize(frames);
    Row {
        setup: sp.info.name.clone(),
        setup_source: sp.info.source.clone(),
        label: run.label.clone(),
        technique: run.technique.to_string(),
        params: run.params.clone(),
        quality: m.quality,
        flip_mean: m.flip_mean,
        flicker_pct: m.flicker_pct,
        total_ms: m.total_ms,
        stages_ms: breakdown.cloned().unwrap_or(m.stages_ms),
        setup_ms: run.setup_ms,
        shadow_data_bytes: run.report.shadow_data_bytes,
        counters: run.report.counters.clone(),
        degraded: run.report.degraded.clone(),
        submits_per_frame: run.submits_per_frame,
        stalls: run.stalls.clone(),
        adapter: gpu.adapter_summary(),
        software_adapter: gpu.info.device_type == wgpu::DeviceType::Cpu,
        timer: gpu.timer_name().to_string(),
        stages_timer: gpu.stages_timer_name().to_string(),
        key: sp.keys[spec].0.clone(),
    }
}

/// Runs the specs `pending` (indices into `sp.cfg.specs`) of one setup; `done(spec, row)` is
/// called for each finished point. Returns the number of views computed.
pub fn run_setup(
    gpu: &Gpu,
    sp: &SetupPlan,
    pending: &[usize],
    frames: usize,
    repeat: usize,
    pb: &ProgressBar,
    done: &mut dyn FnMut(usize, Row) -> Result<()>,
) -> Result<usize> {
    if pending.is_empty() {
        return Ok(0);
    }
    let cfg = &sp.cfg;
    let name = &sp.info.name;
    pb.set_message(format!("{name}: BVH + upload"));
    let lab = Lab::new(gpu, &cfg.scene).with_context(|| format!("setup '{name}'"))?;
    let light = *cfg.light();
    if frames == 1 {
        lab.set_time(cfg.time, cfg.time)?;
        pb.set_message(format!("{name}: G-buffer + rt"));
        let view = lab.view(&cfg.camera, &cfg.camera, &light, cfg.width, cfg.height)?;
        let mut rt_inst = lab.instantiate(&registry::reference(), &light)?;
        let rt = lab.step(&view, &mut rt_inst, true, repeat)?;
        let edges = edge_pixels(&rt.visibility, &view.mask, cfg.width as usize, cfg.height as usize);
        pb.inc(1);
        for &k in pending {
            let spec: &Resolved = &cfg.specs[k];
            pb.set_message(format!("{name}: {}", spec.label));
            // run_resolved: created, one warm-up, `repeat` timed frames, then (software adapters)
            // the profiled breakdown frame, as `compare` does
            let run = lab.run_resolved(&view, spec, repeat).map_err(|e| anyhow!("setup '{name}', technique '{}': {e}", spec.label))?;
            let m = metrics_of(&run.visibility, &rt.visibility, &view.mask);
            let flip = flip_rgba8(&rt.shaded, &run.shaded, cfg.width, cfg.height);
            let rec = FrameRecord {
                frame: 0,
                quality: m,
                flip_mean: flip.mean(),
                rays_traced: run.report.counters.get("rays_traced").copied(),
                edge_pixels: edges,
                flicker_pct: None,
                total_ms: run.total_ms,
                stages_ms: run.stages_ms.clone(),
            };
            done(k, row(sp, k, &run, &[rec], None, gpu))?;
            pb.inc(1);
        }
        return Ok(1);
    }
    let specs: Vec<Resolved> = pending.iter().map(|&k| cfg.specs[k].clone()).collect();
    let path = PathSpec {
        cameras: cameras(&cfg.camera, &cfg.camera_path, frames),
        light,
        width: cfg.width,
        height: cfg.height,
        start_time: cfg.time,
        animate: true,
        specs: &specs,
        repeat,
    };
    let run = lab
        .run_path(&path, &mut |p| match p {
            Progress::Stage(s) => pb.set_message(format!("{name}: {s}")),
            Progress::Step => pb.inc(1),
            Progress::Frame { .. } => {}
        })
        .map_err(|e| anyhow::Error::new(e).context(format!("setup '{name}'")))?;
    for (t, &k) in run.techniques.iter().zip(pending) {
        let breakdown = (!gpu.gpu_timestamps).then_some(&t.breakdown_ms);
        done(k, row(sp, k, &t.last, &t.frames, breakdown, gpu))?;
    }
    Ok(frames)
}
