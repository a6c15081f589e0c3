//! `iasm:fit=view`: the square fitted to the view samples (seed 001, 3.2 and chapter 5's
//! suggestion; CPU rule in `shadowlab_core::techniques::iasm::fit`). The light-space x/y bounds
//! of every evaluated sample come from `sdsm`'s bounds reduction (`csm/sdsm_bounds.wgsl`,
//! ordered-uint atomics: deterministic) run with one cascade in iasm's light basis, read back
//! with one sync (`iasm.fit.readback`, 320 bytes) before the importance analysis, which needs
//! the square. With `delayed`, the previous frame's bounds are read without a stall (frame 0,
//! or a frame whose predecessor has not finished: this frame's, with the sync).

use glam::{Mat4, Vec3, Vec4};
use shadowlab_core::techniques::iasm::fit::fit_square;
use shadowlab_core::techniques::iasm::{light_basis, Placement};
use shadowlab_core::techniques::sdsm::SampleBounds;

use crate::record::{DelayedRead, Recorder};
use crate::technique::FrameInputs;
use crate::techniques::csm::{decode_bounds, BoundsReduce, SdsmReduce, SDSM_BOUNDS_BYTES, SDSM_OUT_WORDS};
use crate::Gpu;

/// Where a frame's square came from (the `fit_source` counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitSource {
    /// No evaluated sample: the thesis's fixed placement.
    Fixed = 0,
    /// This frame's samples (after the sync).
    ThisFrame = 1,
    /// The previous frame's samples (delayed, no sync).
    PreviousFrame = 2,
}

pub(super) struct ViewFit {
    reduce: BoundsReduce,
    uniform: wgpu::Buffer,
    /// The reduction's [min, max] view depth input: zero (unused with one cascade).
    depth_mm: wgpu::Buffer,
    out: wgpu::Buffer,
    delayed: Option<DelayedRead>,
    light_dir: Vec3,
    margin: f32,
    min_side: f32,
    snap: bool,
    /// The side fitted last frame (the snapped side's hysteresis).
    prev: Option<f32>,
    pub bounds: Option<SampleBounds>,
    pub source: FitSource,
}

/// Bytes the fit keeps on the GPU beyond the shadow data (reduction output and its input).
pub const FIT_BYTES: u64 = SDSM_BOUNDS_BYTES + 8;

impl ViewFit {
    pub fn new(gpu: &Gpu, light_dir: Vec3, margin: f32, min_side: f32, snap: bool, delayed: bool) -> ViewFit {
        let (right, up, dir) = light_basis(light_dir);
        let basis = Mat4::from_cols(right.extend(0.0), up.extend(0.0), dir.extend(0.0), Vec4::W).transpose();
        let params = SdsmReduce {
            light_view: basis.to_cols_array_2d(),
            near: 0.0,
            far: 1.0,
            count: 1.0,
            lambda: 1.0,
            steps: 8.0,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        ViewFit {
            reduce: BoundsReduce::new(gpu, "iasm.fit"),
            uniform: gpu.uniform("iasm.fit", &params),
            depth_mm: gpu.storage("iasm.fit.depth", 8),
            out: gpu.storage("iasm.fit", SDSM_BOUNDS_BYTES),
            delayed: delayed.then(|| DelayedRead::new(gpu, "iasm.fit.delayed", SDSM_BOUNDS_BYTES)),
            light_dir,
            margin,
            min_side,
            snap,
            prev: None,
            bounds: None,
            source: FitSource::Fixed,
        }
    }

    fn record(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        rec.stage("iasm.fit", |enc| self.reduce.record(gpu, enc, "iasm.fit", f, &self.uniform, &self.depth_mm, &self.out));
    }

    /// This frame's square: fitted to the previous frame's bounds (delayed, when finished) or
    /// to this frame's (one sync). None when no sample was evaluated (the caller places it by
    /// the fixed rule).
    pub fn place(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Option<Placement> {
        let prev = self.delayed.as_mut().and_then(|d| d.take::<u32>(gpu, SDSM_OUT_WORDS));
        let (words, source) = match prev {
            Some(w) => (w, FitSource::PreviousFrame),
            None => {
                self.record(gpu, f, rec);
                let t0 = std::time::Instant::now();
                let w: Vec<u32> = rec.read_buffer_as(&self.out, SDSM_OUT_WORDS, "iasm.fit.readback");
                rec.cpu("iasm.fit.readback", t0.elapsed().as_secs_f64() * 1e3);
                (w, FitSource::ThisFrame)
            }
        };
        self.bounds = decode_bounds(&words, 0);
        let Some(b) = self.bounds else {
            self.source = FitSource::Fixed;
            return None;
        };
        self.source = source;
        let (p, side) = fit_square(self.light_dir, b.lo.truncate(), b.hi.truncate(), self.margin, self.min_side, self.snap, self.prev);
        self.prev = Some(side);
        Some(p)
    }

    /// Delayed: reduces this frame's samples for the next frame, read back without a stall.
    pub fn record_for_next(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        if self.delayed.is_some() {
            self.record(gpu, f, rec);
            if let Some(d) = self.delayed.as_mut() {
                d.record(rec, &self.out);
            }
        }
    }
}
