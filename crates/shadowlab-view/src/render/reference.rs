//! The reference while the camera is still: `rt` traced a band of rows per frame into the
//! reference buffers, then the techniques evaluated against it with the lab's functions, then
//! (a frame later) their profiled breakdown.

use std::collections::BTreeMap;

use shadowlab_core::metrics::{compare, error_image};
use shadowlab_gpu::record::{self, Clock};
use shadowlab_gpu::technique::run_frame;
use shadowlab_gpu::GpuError;

use super::{Evaluation, Pose, RefStatus, Renderer, SideEval, REFERENCE_BAND_PIXELS};

/// Progress of the reference for one view key.
pub(super) struct Progress {
    pub key: String,
    pub done: u32,
    pub of: u32,
    pub ms: f64,
}

impl Renderer<'_> {
    /// One band of the reference (its own submit), or the evaluation once all bands are done.
    pub(super) fn refine(&mut self, pose: &Pose, view_key: &str) -> Result<RefStatus, GpuError> {
        let gpu = self.gpu;
        let (w, h) = self.size();
        let rows_per_band = (REFERENCE_BAND_PIXELS / w).clamp(1, h);
        if self.progress.as_ref().is_none_or(|p| p.key != view_key) {
            self.progress = Some(Progress { key: view_key.to_string(), done: 0, of: h.div_ceil(rows_per_band), ms: 0.0 });
        }
        let p = self.progress.as_mut().expect("set above");
        if p.done < p.of {
            let t0 = std::time::Instant::now();
            let (r0, r1) = (p.done * rows_per_band, ((p.done + 1) * rows_per_band).min(h));
            let (off, len) = (r0 as u64 * w as u64 * 4, (r1 - r0) as u64 * w as u64 * 4);
            let (t, lab, rt, shade) = (&self.t, &self.lab, &mut self.rt, &self.shade);
            let last = p.done + 1 == p.of;
            record::drive(gpu, "view.reference", Clock::Wall, |rec| {
                rec.encoder().clear_buffer(&t.band_g.mask, 0, None);
                rec.encoder().copy_buffer_to_buffer(&t.g.mask, off, &t.band_g.mask, off, len);
                let inputs = t.inputs(lab, pose, &t.band_g, &t.band_vis);
                run_frame(rt.tech.as_mut(), gpu, &inputs, rec)?;
                rec.encoder().copy_buffer_to_buffer(&t.band_vis, off, &t.ref_vis, off, len);
                if last {
                    shade.record(gpu, rec, &t.inputs(lab, pose, &t.g, &t.ref_vis), &t.ref_color);
                }
                Ok(())
            })?;
            gpu.take_error()?;
            p.done += 1;
            p.ms += t0.elapsed().as_secs_f64() * 1e3;
            if p.done < p.of {
                return Ok(RefStatus::Refining { done: p.done, of: p.of });
            }
        }
        let ms = p.ms;
        let key = self.eval_key(view_key);
        if self.eval.as_ref().is_none_or(|(k, _)| *k != key) {
            let e = self.evaluate(pose, ms)?;
            self.eval = Some((key, e));
        } else if self.eval.as_ref().is_some_and(|(_, e)| !e.profiled) {
            self.profile(pose)?;
        }
        Ok(RefStatus::Current)
    }

    /// One profiled frame of each technique (each stage submitted and waited for alone): the
    /// per-stage breakdown on adapters without sane timestamps.
    fn profile(&mut self, pose: &Pose) -> Result<(), GpuError> {
        let gpu = self.gpu;
        let t = &self.t;
        let mut out = Vec::new();
        for s in std::iter::once(&mut self.a).chain(self.b.as_mut()) {
            let inputs = t.inputs(&self.lab, pose, &t.g, &s.vis);
            let tech = s.inst.tech.as_mut();
            out.push(record::drive(gpu, "view.profiled", Clock::Profiled, |rec| run_frame(tech, gpu, &inputs, rec))?.profile_ms);
        }
        gpu.take_error()?;
        let (_, e) = self.eval.as_mut().expect("profiled after an evaluation");
        let mut it = out.into_iter();
        e.a.stages_ms = it.next().unwrap_or_default();
        if let Some(b) = &mut e.b {
            b.stages_ms = it.next().unwrap_or_default();
        }
        e.profiled = true;
        Ok(())
    }

    /// The techniques against the complete reference: error images and metrics by the lab's own
    /// functions, then the lab-only analysis and the report.
    fn evaluate(&mut self, pose: &Pose, reference_ms: f64) -> Result<Evaluation, GpuError> {
        let gpu = self.gpu;
        let n = self.t.g.pixels();
        let mask: Vec<u32> = gpu.read_buffer_as(&self.t.g.mask, n);
        let v_rt: Vec<f32> = gpu.read_buffer_as(&self.t.ref_vis, n);
        let rt_shaded = gpu.read_buffer(&self.t.ref_color)[..n * 4].to_vec();
        let mut sides = Vec::new();
        let with_b = self.b.is_some();
        for right in [false, true] {
            if right && !with_b {
                break;
            }
            let t = &self.t;
            let s = if right { self.b.as_mut().expect("checked") } else { &mut self.a };
            let v: Vec<f32> = gpu.read_buffer_as(&s.vis, n);
            let error = error_image(&rt_shaded, &v, &v_rt, &mask, true);
            gpu.queue.write_buffer(&s.error, 0, &error);
            let inputs = t.inputs(&self.lab, pose, &t.g, &s.vis);
            let tech = s.inst.tech.as_mut();
            record::drive(gpu, "view.analysis", Clock::Wall, |rec| tech.analyze(gpu, &inputs, rec))?;
            let report = tech.report(gpu);
            gpu.take_error()?;
            sides.push(SideEval {
                label: s.spec.label.clone(),
                metrics: compare(&v, &v_rt, &mask),
                error,
                report,
                stages_ms: BTreeMap::new(),
            });
        }
        let b = if with_b { sides.pop() } else { None };
        let a = sides.pop().expect("technique A is evaluated");
        self.evals += 1;
        Ok(Evaluation { id: self.evals, a, b, reference_ms, profiled: gpu.gpu_timestamps })
    }
}
