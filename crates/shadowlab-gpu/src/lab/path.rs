//! The camera-path loop: the reference and every technique over the views of a camera path (or
//! one view), with per-frame metrics ([`FrameRecord`], [`ReferenceFrame`]; summaries in
//! [`super::summary`]). `shadowlab compare` and the path examples all run it.
//!
//! One frame: each technique runs once to warm up, then `repeat` times timed (median per stage).
//! Several frames: each technique is created once and sees the frames in order, once each
//! (techniques with history, such as temporal masks or delayed analysis, see a real sequence);
//! times are medians over frames 1.. (frame 0 is the warm-up), quality figures are means over
//! all frames (FLIP too: each frame's shaded images against `rt`'s), flicker is the mean over
//! consecutive pairs. Moving objects move with the frames:
//! frame k is at animation time `start_time` + k (frames) when [`PathSpec::animate`] is set.
//! On adapters without sane timestamps, one more frame per technique, profiled (a wait per
//! stage), runs after the measured frames for the per-stage breakdown.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use shadowlab_core::camera::{path_cameras, Camera, CameraKey};
use shadowlab_core::flip::{flip_each, FlipMap};
use shadowlab_core::light::Light;
use shadowlab_core::metrics::{compare as metrics_of, edge_pixels, flicker_pct, ErrorMetrics};

use super::{Instance, Lab, Run, View};
use crate::registry::{self, Resolved};
use crate::GpuError;

/// What [`Lab::run_path`] runs.
pub struct PathSpec<'a> {
    /// One camera per frame (see [`cameras`]).
    pub cameras: Vec<Camera>,
    pub light: Light,
    pub width: u32,
    pub height: u32,
    /// Animation time of frame 0 (frames).
    pub start_time: f32,
    /// Frame k at `start_time` + k (motion vectors against the previous frame's time); false:
    /// every frame at `start_time`, the moving objects held still.
    pub animate: bool,
    /// The techniques, in order (the reference `rt` runs as well, first, on every frame).
    pub specs: &'a [Resolved],
    /// Timed repetitions of a single frame (several frames: each is timed once).
    pub repeat: usize,
}

/// Frames one camera path may have: each keeps its figures (a record per technique, about a
/// kilobyte with its stage times, and a line of metrics.json), so a run's memory and output
/// are bounded; longer studies run as several paths.
pub const MAX_FRAMES: usize = 100_000;

/// Refuses a frame count of 0 or above [`MAX_FRAMES`], naming the limit.
pub fn check_frames(frames: usize) -> Result<(), GpuError> {
    if frames == 0 || frames > MAX_FRAMES {
        return Err(GpuError::Invalid(format!(
            "--frames {frames}: must be between 1 and {MAX_FRAMES} (each frame keeps its figures; run a longer study as several paths)"
        )));
    }
    Ok(())
}

/// The cameras of `frames` frames: the camera itself for one, else along the keyframes `keys`
/// ([`path_cameras`]; the camera holds still without keys).
pub fn cameras(camera: &Camera, keys: &[CameraKey], frames: usize) -> Vec<Camera> {
    if frames <= 1 {
        vec![*camera]
    } else {
        path_cameras(camera, keys, frames)
    }
}

/// What [`Lab::run_path`] reports while it runs.
pub enum Progress<'a> {
    /// What runs next (e.g. a progress bar's message).
    Stage(&'a str),
    /// One unit done: the reference or one technique on one frame (1 + techniques per frame).
    Step,
    /// A frame is done: its view, the reference's run and each technique's (in spec order).
    Frame { index: usize, view: &'a View, rt: &'a Run, runs: &'a [Run] },
}

/// A failure in [`Lab::run_path`], with what was running (`technique 'x', frame 3`) if known.
#[derive(Debug)]
pub struct PathError {
    pub context: Option<String>,
    pub error: GpuError,
}

impl std::fmt::Display for PathError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.context {
            Some(c) => f.write_str(c),
            None => self.error.fmt(f),
        }
    }
}

impl std::error::Error for PathError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.context.as_ref().map(|_| &self.error as _)
    }
}

impl From<GpuError> for PathError {
    fn from(error: GpuError) -> Self {
        PathError { context: None, error }
    }
}

fn within<T>(r: Result<T, GpuError>, what: impl FnOnce() -> String) -> Result<T, PathError> {
    r.map_err(|error| PathError { context: Some(what()), error })
}

/// One technique on one frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameRecord {
    pub frame: usize,
    /// wrong / false lit / false shadow %, MAE, evaluated pixels of this frame.
    #[serde(flatten)]
    pub quality: ErrorMetrics,
    /// Mean FLIP (LDR, [`shadowlab_core::flip`]) of the technique's shaded image against
    /// `rt`'s, over all pixels of the image.
    pub flip_mean: f64,
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceFrame {
    pub frame: usize,
    /// Animation time of the frame (frames; `start_time` + frame).
    pub time: f32,
    pub evaluated_pixels: u64,
    pub edge_pixels: u64,
    pub rays_traced: Option<f64>,
    pub total_ms: f64,
}

pub struct TechniqueFrames {
    /// The last frame's run (its pictures and report go to the outputs).
    pub last: Run,
    /// The last frame's FLIP error map against `rt` (its mean is the last record's `flip_mean`).
    pub last_flip: FlipMap,
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

/// The previous frame: rt's visibility, the mask, each technique's visibility.
type Previous = (Vec<f32>, Vec<u32>, Vec<Vec<f32>>);

impl Lab<'_> {
    /// Runs the reference and `p.specs` over the frames of `p.cameras` (see the module's docs).
    pub fn run_path(&self, p: &PathSpec, progress: &mut dyn FnMut(Progress)) -> Result<PathRun, PathError> {
        let frames = p.cameras.len();
        check_frames(frames)?;
        let (warm_up, timed) = if frames == 1 { (true, p.repeat) } else { (false, 1) };
        let light = &p.light;
        let mut rt_inst = self.instantiate(&registry::reference(), light)?;
        let mut insts: Vec<Instance> = Vec::new();
        for spec in p.specs {
            insts.push(within(self.instantiate(spec, light), || format!("technique '{}'", spec.label))?);
        }
        let mut reference = Vec::new();
        let mut records: Vec<Vec<FrameRecord>> = vec![Vec::new(); insts.len()];
        let mut prev: Option<Previous> = None;
        let mut last = None;
        for (f, cam) in p.cameras.iter().enumerate() {
            let prev_cam = if f == 0 { cam } else { &p.cameras[f - 1] };
            // moving objects: frame f at time + f; frame 0's motion vectors are zero like its camera's
            let t = if p.animate { p.start_time + f as f32 } else { p.start_time };
            self.set_time(t, if f == 0 || !p.animate { t } else { t - 1.0 })?;
            progress(Progress::Stage(&format!("frame {}/{frames}: G-buffer", f + 1)));
            let view = self.view(cam, prev_cam, light, p.width, p.height)?;
            progress(Progress::Stage(&format!("frame {}/{frames}: rt (reference)", f + 1)));
            let rt = self.step(&view, &mut rt_inst, warm_up, timed)?;
            let edges = edge_pixels(&rt.visibility, &view.mask, p.width as usize, p.height as usize);
            reference.push(ReferenceFrame {
                frame: f,
                time: t,
                evaluated_pixels: view.mask.iter().filter(|m| **m != 0).count() as u64,
                edge_pixels: edges,
                rays_traced: rt.report.counters.get("rays_traced").copied(),
                total_ms: rt.total_ms,
            });
            progress(Progress::Step);
            let mut runs = Vec::new();
            for (k, inst) in insts.iter_mut().enumerate() {
                progress(Progress::Stage(&format!("frame {}/{frames}: {}", f + 1, inst.label)));
                let label = inst.label.clone();
                let run = within(self.step(&view, inst, warm_up, timed), || format!("technique '{label}', frame {f}"))?;
                let m: ErrorMetrics = metrics_of(&run.visibility, &rt.visibility, &view.mask);
                let flicker = prev.as_ref().map(|(prev_rt, prev_mask, prev_v)| {
                    flicker_pct(&prev_v[k], &run.visibility, prev_rt, &rt.visibility, prev_mask, &view.mask)
                });
                records[k].push(FrameRecord {
                    frame: f,
                    quality: m,
                    flip_mean: 0.0, // below, once the frame's images are all there
                    rays_traced: run.report.counters.get("rays_traced").copied(),
                    edge_pixels: edges,
                    flicker_pct: flicker,
                    total_ms: run.total_ms,
                    stages_ms: run.stages_ms.clone(),
                });
                runs.push(run);
                progress(Progress::Step);
            }
            // FLIP on the CPU, the frame's techniques in parallel (the GPU is idle meanwhile)
            progress(Progress::Stage(&format!("frame {}/{frames}: FLIP", f + 1)));
            let shaded: Vec<&[u8]> = runs.iter().map(|r| r.shaded.as_slice()).collect();
            let flips = flip_each(&rt.shaded, &shaded, p.width, p.height);
            for (rec, map) in records.iter_mut().zip(&flips) {
                rec.last_mut().expect("this frame's record").flip_mean = map.mean();
            }
            progress(Progress::Frame { index: f, view: &view, rt: &rt, runs: &runs });
            let this_v: Vec<Vec<f32>> = runs.iter().map(|r| r.visibility.clone()).collect();
            prev = Some((rt.visibility.clone(), view.mask.clone(), this_v));
            last = Some((view, rt, runs, flips));
        }
        let (view, rt, runs, flips) = last.expect("at least one frame");
        // the breakdown: one more frame each, profiled, after the measured ones (it advances
        // techniques with history by a frame, so it comes last)
        let timestamps = self.gpu.gpu_timestamps;
        let profile = |inst: &mut Instance| if timestamps { Ok(BTreeMap::new()) } else { self.profile(&view, inst) };
        progress(Progress::Stage("profiled breakdown"));
        let rt_breakdown_ms = profile(&mut rt_inst)?;
        let mut techniques = Vec::new();
        for (((last, last_flip), frames), inst) in runs.into_iter().zip(flips).zip(records).zip(insts.iter_mut()) {
            let label = inst.label.clone();
            let breakdown_ms = within(profile(inst), || format!("technique '{label}', profiled frame"))?;
            techniques.push(TechniqueFrames { last, last_flip, frames, breakdown_ms });
        }
        Ok(PathRun { cameras: p.cameras.clone(), view, rt, reference, rt_breakdown_ms, techniques })
    }
}
