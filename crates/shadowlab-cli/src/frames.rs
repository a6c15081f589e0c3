//! The frame loop of `compare`: the reference and every technique over the views of a camera
//! path (or one view), per-frame metrics, and their summaries.
//!
//! One frame (`--frames 1`, the default): each technique runs once to warm up, then `repeat`
//! times timed (median per stage). Several frames: each technique is created once and sees the
//! frames in order, once each (techniques with history, such as temporal masks or delayed
//! analysis, see a real sequence); times are medians over frames 1.. (frame 0 is the warm-up),
//! quality figures are means over all frames, flicker is the mean over consecutive pairs.
//! Moving objects move with the frames: frame k is at animation time `--time` + k (frames).

use std::collections::BTreeMap;

use anyhow::{Context, Result};
use indicatif::ProgressBar;
use serde::Serialize;
use shadowlab_core::camera::{path_cameras, Camera};
use shadowlab_core::metrics::{compare as metrics_of, edge_pixels, flicker_pct, ErrorMetrics};
use shadowlab_gpu::lab::{Instance, Lab, Run, View};
use shadowlab_gpu::timing::median;

use crate::config::RunConfig;

type Previous = (Vec<f32>, Vec<u32>, Vec<Vec<f32>>);

/// One technique on one frame.
#[derive(Clone, Debug, Serialize)]
pub struct FrameRecord {
    pub frame: usize,
    pub wrong_pct: f64,
    pub false_lit_pct: f64,
    pub false_shadow_pct: f64,
    pub mae: f64,
    pub evaluated_pixels: u64,
    /// Rays the technique traced this frame (ray-assisted techniques).
    pub rays_traced: Option<f64>,
    /// Pixels within one pixel of an `rt` visibility edge this frame (the rays' lower bound).
    pub edge_pixels: u64,
    /// % of pixels flipping against the previous frame while `rt` does not (None on frame 0).
    pub flicker_pct: Option<f64>,
    pub total_ms: f64,
    pub stages_ms: BTreeMap<String, f64>,
}

/// The reference on one frame.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceFrame {
    pub frame: usize,
    /// Animation time of the frame (frames; `--time` + frame).
    pub time: f32,
    pub evaluated_pixels: u64,
    pub edge_pixels: u64,
    pub rays_traced: Option<f64>,
    pub total_ms: f64,
}

pub struct TechniqueFrames {
    /// The last frame's run (its pictures and report go to the outputs).
    pub last: Run,
    pub frames: Vec<FrameRecord>,
    /// Per-stage ms of one profiled frame (a wait per stage) after the last frame, on adapters
    /// without sane timestamps; empty on the others (their timed frames carry stage times).
    pub breakdown_ms: BTreeMap<String, f64>,
}

pub struct PathRun {
    pub cameras: Vec<Camera>,
    /// The last frame's view and reference.
    pub view: View,
    pub rt: Run,
    pub reference: Vec<ReferenceFrame>,
    /// `rt`'s profiled breakdown (see [`TechniqueFrames::breakdown_ms`]).
    pub rt_breakdown_ms: BTreeMap<String, f64>,
    pub techniques: Vec<TechniqueFrames>,
}

/// Runs the reference and `cfg.specs` over `frames` views along the configured camera path.
pub fn run(lab: &Lab, cfg: &RunConfig, frames: usize, repeat: usize, pb: &ProgressBar) -> Result<PathRun> {
    let frames = frames.max(1);
    let cameras = if frames == 1 { vec![cfg.camera] } else { path_cameras(&cfg.camera, &cfg.camera_path, frames) };
    let (warm_up, timed) = if frames == 1 { (true, repeat) } else { (false, 1) };
    let light = cfg.light();
    let mut rt_inst = lab.instantiate(&shadowlab_gpu::registry::reference(), light)?;
    let mut insts: Vec<Instance> = Vec::new();
    for spec in &cfg.specs {
        insts.push(lab.instantiate(spec, light).with_context(|| format!("technique '{}'", spec.label))?);
    }
    let mut reference = Vec::new();
    let mut records: Vec<Vec<FrameRecord>> = vec![Vec::new(); insts.len()];
    // previous frame: rt's visibility, the mask, each technique's visibility
    let mut prev: Option<Previous> = None;
    let mut last = None;
    for (f, cam) in cameras.iter().enumerate() {
        let prev_cam = if f == 0 { cam } else { &cameras[f - 1] };
        // moving objects: frame f at time + f; frame 0's motion vectors are zero like its camera's
        let t = cfg.time + f as f32;
        lab.set_time(t, if f == 0 { t } else { t - 1.0 })?;
        pb.set_message(format!("frame {}/{frames}: G-buffer", f + 1));
        let view = lab.view(cam, prev_cam, light, cfg.width, cfg.height)?;
        pb.set_message(format!("frame {}/{frames}: rt (reference)", f + 1));
        let rt = lab.step(&view, &mut rt_inst, warm_up, timed)?;
        let edges = edge_pixels(&rt.visibility, &view.mask, cfg.width as usize, cfg.height as usize);
        let evaluated = view.mask.iter().filter(|m| **m != 0).count() as u64;
        reference.push(ReferenceFrame {
            frame: f,
            time: t,
            evaluated_pixels: evaluated,
            edge_pixels: edges,
            rays_traced: rt.report.counters.get("rays_traced").copied(),
            total_ms: rt.total_ms,
        });
        pb.inc(1);
        let mut runs = Vec::new();
        for (k, inst) in insts.iter_mut().enumerate() {
            pb.set_message(format!("frame {}/{frames}: {}", f + 1, inst.label));
            let run = lab.step(&view, inst, warm_up, timed).with_context(|| format!("technique '{}', frame {f}", inst.label))?;
            let m: ErrorMetrics = metrics_of(&run.visibility, &rt.visibility, &view.mask);
            let flicker = prev.as_ref().map(|(prev_rt, prev_mask, prev_v)| {
                flicker_pct(&prev_v[k], &run.visibility, prev_rt, &rt.visibility, prev_mask, &view.mask)
            });
            records[k].push(FrameRecord {
                frame: f,
                wrong_pct: m.wrong_pct,
                false_lit_pct: m.false_lit_pct,
                false_shadow_pct: m.false_shadow_pct,
                mae: m.mae,
                evaluated_pixels: m.evaluated_pixels,
                rays_traced: run.report.counters.get("rays_traced").copied(),
                edge_pixels: edges,
                flicker_pct: flicker,
                total_ms: run.total_ms,
                stages_ms: run.stages_ms.clone(),
            });
            runs.push(run);
            pb.inc(1);
        }
        let this_v: Vec<Vec<f32>> = runs.iter().map(|r| r.visibility.clone()).collect();
        prev = Some((rt.visibility.clone(), view.mask.clone(), this_v));
        last = Some((view, rt, runs));
    }
    let (view, rt, runs) = last.expect("at least one frame");
    // the breakdown: one more frame each, profiled, after the measured ones (it advances
    // techniques with history by a frame, so it comes last)
    let timestamps = lab.gpu.gpu_timestamps;
    let profile = |inst: &mut Instance| if timestamps { Ok(BTreeMap::new()) } else { lab.profile(&view, inst) };
    pb.set_message("profiled breakdown");
    let rt_breakdown_ms = profile(&mut rt_inst)?;
    let mut techniques = Vec::new();
    for ((last, frames), inst) in runs.into_iter().zip(records).zip(insts.iter_mut()) {
        let breakdown_ms = profile(inst).with_context(|| format!("technique '{}', profiled frame", inst.label))?;
        techniques.push(TechniqueFrames { last, frames, breakdown_ms });
    }
    Ok(PathRun { cameras, view, rt, reference, rt_breakdown_ms, techniques })
}

/// Top-level figures of a technique over its frames.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub wrong_pct: f64,
    pub false_lit_pct: f64,
    pub false_shadow_pct: f64,
    pub mae: f64,
    /// Mean over the frames, rounded.
    pub evaluated_pixels: u64,
    pub rays_traced: Option<f64>,
    /// Mean over consecutive pairs; None with one frame.
    pub flicker_pct: Option<f64>,
    pub total_ms: f64,
    pub stages_ms: BTreeMap<String, f64>,
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (mut s, mut n) = (0.0, 0usize);
    for x in v {
        s += x;
        n += 1;
    }
    (n > 0).then(|| s / n as f64)
}

/// Means of the quality figures over all frames; times: medians over frames 1.. (frame 0 is
/// the warm-up; with one frame, its own median over the repetitions).
pub fn summarize(frames: &[FrameRecord]) -> Summary {
    let q = |f: fn(&FrameRecord) -> f64| mean(frames.iter().map(f)).unwrap_or(0.0);
    let timed: &[FrameRecord] = if frames.len() > 1 { &frames[1..] } else { frames };
    let mut stages: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in timed {
        for (k, v) in &r.stages_ms {
            stages.entry(k.clone()).or_default().push(*v);
        }
    }
    Summary {
        wrong_pct: q(|r| r.wrong_pct),
        false_lit_pct: q(|r| r.false_lit_pct),
        false_shadow_pct: q(|r| r.false_shadow_pct),
        mae: q(|r| r.mae),
        evaluated_pixels: q(|r| r.evaluated_pixels as f64).round() as u64,
        rays_traced: if frames.iter().all(|r| r.rays_traced.is_some()) { mean(frames.iter().filter_map(|r| r.rays_traced)) } else { None },
        flicker_pct: mean(frames.iter().filter_map(|r| r.flicker_pct)),
        total_ms: median(&timed.iter().map(|r| r.total_ms).collect::<Vec<_>>()),
        stages_ms: stages.into_iter().map(|(k, v)| (k, median(&v))).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    fn rec(frame: usize, wrong: f64, ms: f64, flicker: Option<f64>) -> FrameRecord {
        FrameRecord {
            frame,
            wrong_pct: wrong,
            false_lit_pct: wrong,
            false_shadow_pct: 0.0,
            mae: wrong / 100.0,
            evaluated_pixels: 100,
            rays_traced: None,
            edge_pixels: 3,
            flicker_pct: flicker,
            total_ms: ms,
            stages_ms: BTreeMap::from([("a".to_string(), ms)]),
        }
    }
    #[test]
    fn summary_means_quality_and_medians_times_after_the_warm_up() {
        let s =
            summarize(&[rec(0, 1.0, 100.0, None), rec(1, 2.0, 5.0, Some(1.0)), rec(2, 3.0, 7.0, Some(3.0)), rec(3, 6.0, 6.0, Some(2.0))]);
        assert_eq!(s.wrong_pct, 3.0);
        assert_eq!(s.flicker_pct, Some(2.0));
        assert_eq!(s.total_ms, 6.0, "frame 0 (100 ms warm-up) is not timed");
        assert_eq!(s.stages_ms["a"], 6.0);
        assert_eq!(s.rays_traced, None);
        let one = summarize(&[rec(0, 4.0, 9.0, None)]);
        assert_eq!((one.wrong_pct, one.total_ms, one.flicker_pct), (4.0, 9.0, None));
    }
}
