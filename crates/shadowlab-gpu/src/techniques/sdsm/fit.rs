//! `sdsm`'s `prepare`: the G-buffer's depth range and the per-cascade sample bounds reduced in
//! one stage (`sdsm.analyze`: csm's min/max and sample-bounds reductions), read back this frame
//! (`sdsm.readback`, one sync) or, with `delayed`, the previous frame's without a stall; then on
//! the CPU the splits, the frustum-slice boxes, and each cascade's box fitted to its samples
//! (`sdsm.fit`). Also the fit's report counters.

use std::collections::BTreeMap;

use glam::{Mat4, Vec3};
use shadowlab_core::camera::Camera;
use shadowlab_core::techniques::csm::{light_view, CascadeBox, Fit, ViewFrustum, DEPTH_STEPS_PER_OCTAVE};
use shadowlab_core::techniques::sdsm::{self as cpu, CameraMotion, FittedBox, SampleBounds};

use super::SdsmSettings;
use crate::record::{DelayedRead, Recorder};
use crate::reduce::{decode, MinMax};
use crate::technique::FrameInputs;
use crate::techniques::csm::{
    decode_bounds, BoundsReduce, Cascaded, SdsmReduce, SDSM_BOUNDS_BYTES as OUT_BYTES, SDSM_OUT_WORDS as OUT_WORDS,
};
use crate::{Gpu, GpuError};

/// Where a frame's boxes came from (the `bounds_source` counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Source {
    /// No reduction available (delayed frame 0, or no evaluated pixel): the frustum-slice fit.
    SliceFit = 0,
    /// This frame's samples (after the sync).
    ThisFrame = 1,
    /// The previous frame's samples (delayed, no sync).
    PreviousFrame = 2,
}

/// SDSM's part of the technique: the bounds reduction and the last fit.
pub(super) struct SampleFit {
    reduce: BoundsReduce,
    reduce_params: SdsmReduce,
    uniform: wgpu::Buffer,
    out: wgpu::Buffer,
    delayed: Option<DelayedRead>,
    /// Texels around the samples' bounds: 1 for snapping (the origin moves by at most half a
    /// texel), the normal offset (the evaluation looks up the sample moved that far along its
    /// normal), half the PCF kernel, and 1 for rounding.
    margin: f32,
    /// The last frame's frustum-slice boxes are `Cascaded::boxes`; these are its sample
    /// bounds and fitted boxes (None: no sample, the slice box is used).
    bounds: Vec<Option<SampleBounds>>,
    fitted: Vec<Option<FittedBox>>,
    source: Source,
    /// `reach` (delayed only: 0 otherwise).
    reach: f32,
    /// The camera of the frame whose reduction the delayed copy holds.
    read_camera: Option<Camera>,
    /// The last frame's sweep of each cascade's bounds (light view, world units; the
    /// `reach_i_*` counters).
    swept: Vec<Vec3>,
}

/// What a frame's reduction hands the fit.
struct Reduced {
    /// The reduction's words (None: none read back yet, delayed frame 0).
    words: Option<Vec<u32>>,
    source: Source,
    /// Delayed: the camera of the frame the words were reduced for.
    camera: Option<Camera>,
}

/// One readback, decoded.
struct Readback {
    range: (f32, f32),
    splits: Vec<f32>,
    bounds: Vec<Option<SampleBounds>>,
}

/// The reduction's words (layout in sdsm_bounds.wgsl), or None when no sample was reduced.
fn decode_out(w: &[u32], count: usize) -> Option<Readback> {
    if w[2] as usize != count {
        return None;
    }
    let range = decode([w[0], w[1]])?;
    let splits = (0..=count).map(|i| f32::from_bits(w[4 + i])).collect();
    let bounds = (0..count).map(|c| decode_bounds(w, c)).collect();
    Some(Readback { range, splits, bounds })
}

impl SampleFit {
    /// The fit of `count` cascades of a light along `dir`.
    pub(super) fn new(gpu: &Gpu, p: &SdsmSettings, dir: Vec3, count: usize) -> SampleFit {
        let reduce_params = SdsmReduce {
            light_view: light_view(dir).to_cols_array_2d(),
            near: 0.0,
            far: 0.0,
            count: count as f32,
            lambda: p.lambda as f32,
            steps: DEPTH_STEPS_PER_OCTAVE,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        SampleFit {
            reduce: BoundsReduce::new(gpu, "sdsm.bounds"),
            uniform: gpu.uniform("sdsm.bounds", &reduce_params),
            reduce_params,
            out: gpu.storage("sdsm.bounds", OUT_BYTES),
            delayed: p.delayed.then(|| DelayedRead::new(gpu, "sdsm.delayed", OUT_BYTES)),
            margin: 2.0 + p.lookup.normal_offset as f32 + 0.5 * (p.lookup.pcf as f32 - 1.0),
            bounds: Vec::new(),
            fitted: Vec::new(),
            source: Source::SliceFit,
            reach: if p.delayed { p.reach as f32 } else { 0.0 },
            read_camera: None,
            swept: Vec::new(),
        }
    }

    /// Records the bounds reduction (after `depth`'s min/max reduction of the same frame).
    fn record(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, f: &FrameInputs, depth: &MinMax) {
        depth.record(gpu, enc, "sdsm.reduce", f.gbuffer.position_input(), &f.gbuffer.mask);
        self.reduce.record(gpu, enc, "sdsm.bounds", f, &self.uniform, &depth.result, &self.out);
    }

    /// The reductions (and this frame's readback, or the previous frame's), the splits and the
    /// boxes of `c`.
    pub(super) fn prepare(&mut self, c: &mut Cascaded, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        let view_proj = f.camera.view_proj(f.gbuffer.width, f.gbuffer.height);
        let frustum = ViewFrustum::from_view_proj(view_proj, f.camera.position)
            .ok_or_else(|| GpuError::Invalid("sdsm: the view's projection is not a perspective frustum".into()))?;
        self.reduce_params.near = frustum.near;
        self.reduce_params.far = frustum.far;
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&self.reduce_params));
        let reduced = self.reduce_and_read(gpu, f, rec, c.depth_reduce());
        let t0 = web_time::Instant::now();
        self.fit_boxes(c, rec, f, &frustum, reduced);
        rec.cpu("sdsm.fit", t0.elapsed().as_secs_f64() * 1e3);
        Ok(())
    }

    /// The `sdsm.analyze` stage and the words the fit uses: this frame's after the
    /// `sdsm.readback` sync, or (delayed) the previous frame's, with the camera they were
    /// reduced for.
    fn reduce_and_read(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, depth: &MinMax) -> Reduced {
        if let Some(d) = self.delayed.as_mut() {
            let prev = d.take::<u32>(gpu, OUT_WORDS);
            let read_camera = if prev.is_some() { self.read_camera.take() } else { None };
            rec.stage("sdsm.analyze", |enc| self.record(gpu, enc, f, depth));
            let d = self.delayed.as_mut().expect("delayed");
            d.record(rec, &self.out);
            self.read_camera = Some(f.camera);
            Reduced { words: prev, source: Source::PreviousFrame, camera: read_camera }
        } else {
            rec.stage("sdsm.analyze", |enc| self.record(gpu, enc, f, depth));
            let t0 = web_time::Instant::now();
            let w: Vec<u32> = rec.read_buffer_as(&self.out, OUT_WORDS, "sdsm.readback");
            rec.cpu("sdsm.readback", t0.elapsed().as_secs_f64() * 1e3);
            Reduced { words: Some(w), source: Source::ThisFrame, camera: None }
        }
    }

    /// The splits and the boxes of `c` from the reduction (none, or no sample: the
    /// frustum-slice fit).
    fn fit_boxes(&mut self, c: &mut Cascaded, rec: &mut Recorder, f: &FrameInputs, frustum: &ViewFrustum, reduced: Reduced) {
        let count = c.count();
        let Reduced { words, source, camera: read_camera } = reduced;
        let (range, splits, bounds, source) = match words.and_then(|w| decode_out(&w, count)) {
            Some(r) => {
                // delayed: what the camera's motion since that frame brings into view next to
                // last frame's samples (0 for a still camera: the bounds as read)
                let aspect = f.gbuffer.width as f32 / f.gbuffer.height.max(1) as f32;
                let motion = read_camera.map(|cam| CameraMotion::between(&cam, &f.camera, aspect)).filter(|_| self.reach > 0.0);
                let lv = light_view(c.light_dir());
                self.swept = (0..count)
                    .map(|i| motion.map_or(Vec3::ZERO, |m| lv.transform_vector3(m.displacement(r.splits[i + 1])) * self.reach))
                    .collect();
                let bounds = r.bounds.iter().zip(&self.swept).map(|(b, &d)| b.map(|b| b.swept(d, 0.0))).collect();
                (Some(r.range), r.splits, bounds, source)
            }
            None => {
                self.swept = vec![Vec3::ZERO; count];
                (None, cpu::sample_splits(frustum.near, frustum.far, None, count, c.lambda()), vec![None; count], Source::SliceFit)
            }
        };
        let scene = &f.scene.bounds;
        let slices = c.slice_boxes(frustum, scene, &splits, Fit::Box);
        // the previous frame's sizes, for the snapped sizes' hysteresis
        let prev: Vec<Option<glam::Vec2>> = (0..count).map(|i| self.fitted.get(i).copied().flatten().map(|fb| fb.extent)).collect();
        let (res, snap, margin) = (c.res(), c.snap(), self.margin);
        let fitted: Vec<Option<FittedBox>> = slices
            .iter()
            .zip(&bounds)
            .zip(prev)
            .map(|((sl, b), p)| b.map(|b| cpu::fit_to_samples(sl, &b, scene, res, snap, margin, p)))
            .collect();
        let boxes: Vec<(Mat4, f32)> =
            slices.iter().zip(&fitted).map(|(sl, fb)| fb.map_or((sl.view_proj, sl.texel), |fb| (fb.view_proj, fb.max_texel()))).collect();
        (self.bounds, self.fitted, self.source) = (bounds, fitted, source);
        c.set_fit(rec, range, slices, &boxes, &splits);
    }

    /// The report's SDSM counters: where the boxes came from, and per cascade the samples,
    /// their bounds, the fitted box and its area and texels against the frustum slice's.
    pub(super) fn counters(&self, slices: &[CascadeBox], c: &mut BTreeMap<String, f64>) {
        c.insert("bounds_source".into(), self.source as u32 as f64);
        c.insert("fitted_cascades".into(), self.fitted.iter().flatten().count() as f64);
        c.insert("bounds_bytes".into(), OUT_BYTES as f64);
        for (i, s) in slices.iter().enumerate() {
            let slice_area = (2.0 * s.half as f64).powi(2);
            c.insert(format!("slice_texel_{i}"), s.texel as f64);
            let b = self.bounds.get(i).copied().flatten();
            c.insert(format!("samples_{i}"), b.map_or(0.0, |b| b.samples as f64));
            if self.delayed.is_some() {
                let d = self.swept.get(i).copied().unwrap_or(Vec3::ZERO);
                for (k, v) in [("x", d.x), ("y", d.y), ("z", d.z)] {
                    c.insert(format!("reach_{i}_{k}"), v as f64);
                }
            }
            let Some(fb) = self.fitted.get(i).copied().flatten() else {
                c.insert(format!("area_ratio_{i}"), 1.0);
                continue;
            };
            c.insert(format!("area_ratio_{i}"), fb.area() as f64 / slice_area);
            c.insert(format!("texel_x_{i}"), fb.texel.x as f64);
            c.insert(format!("texel_y_{i}"), fb.texel.y as f64);
            // light-view boxes: the fitted one and the samples' bounds it was fitted to
            let o = fb.origin.as_dvec2();
            let h = fb.half.as_dvec2();
            for (k, v) in [("x0", o.x - h.x), ("x1", o.x + h.x), ("y0", o.y - h.y), ("y1", o.y + h.y)] {
                c.insert(format!("box_{i}_{k}"), v);
            }
            c.insert(format!("box_{i}_znear"), fb.near_z as f64);
            c.insert(format!("box_{i}_zfar"), fb.far_z as f64);
            if let Some(b) = b {
                for (k, v) in [("lo", b.lo), ("hi", b.hi)] {
                    c.insert(format!("bounds_{i}_{k}_x"), v.x as f64);
                    c.insert(format!("bounds_{i}_{k}_y"), v.y as f64);
                    c.insert(format!("bounds_{i}_{k}_z"), v.z as f64);
                }
            }
        }
    }
}
