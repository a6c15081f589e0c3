//! `iasm:fit=view`: the square fitted to the view samples (seed 001, 3.2 and chapter 5's
//! suggestion). The light-space x/y bounds of every evaluated sample come from `sdsm`'s bounds
//! reduction (`csm/sdsm_bounds.wgsl`, ordered-uint atomics: deterministic) run with one cascade
//! in iasm's light basis; one GPU thread (fit.wgsl) turns them into the square by the rule of
//! `shadowlab_core::techniques::iasm::fit::fit_square` (the CPU half, which the tests hold it
//! to) and writes it into the frame's `IasmParams` for the importance analysis, and into the
//! statistics' tail
//! ([`FIT_WORDS`] after `STATS_WORDS`). The square comes back with the statistics, in the one
//! readback of the frame (`iasm.readback`), as the thesis has it. With `delayed` the fit is
//! recorded after the shadows for the next frame and read with the statistics without a stall.

use glam::{Vec2, Vec3};
use shadowlab_core::techniques::iasm::fit::snap_divisions;
use shadowlab_core::techniques::iasm::{light_basis, Placement};
use shadowlab_core::techniques::sdsm::{step_fractions, SampleBounds, SHRINK_STEPS, SIZE_STEPS_PER_OCTAVE};

use super::plan::{FIT_WORDS, STATS_WORDS};
use crate::record::Recorder;
use crate::reduce::ORDER_KEY_WGSL;
use crate::shaders::flag;
use crate::technique::FrameInputs;
use crate::techniques::csm::{BoundsReduce, SdsmReduce, SDSM_BOUNDS_BYTES};
use crate::{binding, Gpu};

const FIT_WGSL: &str = include_str!("fit.wgsl");

/// The composed placement shader, listed as `iasm/fit.wgsl`.
pub(super) fn source() -> String {
    format!("{ORDER_KEY_WGSL}const TAIL: u32 = {STATS_WORDS}u;\n{FIT_WGSL}")
}

/// Where a frame's square came from (the `fit_source` counter).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitSource {
    /// No evaluated sample: the thesis's fixed placement.
    Fixed = 0,
    /// This frame's samples (read back with the statistics).
    ThisFrame = 1,
    /// The previous frame's samples (delayed).
    PreviousFrame = 2,
}

/// WGSL `FitParams` (fit.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FitParams {
    pub margin: f32,
    pub min_side: f32,
    /// The side fitted last; 0: none.
    pub prev: f32,
    pub div: f32,
    pub shrink: f32,
    pub steps: f32,
    pub pad0: f32,
    pub pad1: f32,
    /// sdsm's `step_fractions`.
    pub fracs: [[f32; 4]; 4],
}

pub(super) struct ViewFit {
    reduce: BoundsReduce,
    reduce_uniform: wgpu::Buffer,
    /// The reduction's [min, max] view depth input: zero (unused with one cascade).
    depth_mm: wgpu::Buffer,
    out: wgpu::Buffer,
    uniform: wgpu::Buffer,
    /// The placement's bindings: its parameters, the reduction's output, the frame's
    /// `IasmParams` and the statistics (all made once, with the technique).
    group: wgpu::BindGroup,
    pipeline: wgpu::ComputePipeline,
    light_dir: Vec3,
    params: FitParams,
    /// The side fitted last (the snapped side's hysteresis).
    prev: Option<f32>,
    pub bounds: Option<SampleBounds>,
    pub source: FitSource,
}

/// Bytes the fit keeps on the GPU beyond the shadow data (reduction output and its input, the
/// placement's parameters and the statistics' tail).
pub const FIT_BYTES: u64 = SDSM_BOUNDS_BYTES + 8 + std::mem::size_of::<FitParams>() as u64 + FIT_WORDS as u64 * 4;

impl ViewFit {
    /// `auto_k`: k of equation 3.1 is half the side (the `k` parameter 0). The square is
    /// written into `params_buf` (the frame's `IasmParams`) and the tail of `stats_buf`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &Gpu,
        light_dir: Vec3,
        margin: f32,
        min_side: f32,
        snap: bool,
        auto_k: bool,
        params_buf: &wgpu::Buffer,
        stats_buf: &wgpu::Buffer,
    ) -> ViewFit {
        let (right, up, dir) = light_basis(light_dir);
        let basis = glam::Mat4::from_cols(right.extend(0.0), up.extend(0.0), dir.extend(0.0), glam::Vec4::W).transpose();
        let reduce = SdsmReduce {
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
        let params = FitParams {
            margin,
            min_side,
            prev: 0.0,
            div: snap_divisions(),
            shrink: (2.0f32).powf(-SHRINK_STEPS / SIZE_STEPS_PER_OCTAVE),
            steps: SIZE_STEPS_PER_OCTAVE,
            pad0: 0.0,
            pad1: 0.0,
            fracs: bytemuck::cast(step_fractions()),
        };
        let layout = binding::layout(
            &gpu.device,
            "iasm.fit.place",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::storage(true), binding::storage(false), binding::storage(false)],
        );
        let constants = [("SNAP", flag(snap)), ("AUTO_K", flag(auto_k))];
        let pipeline = gpu.compute_pipeline_with("iasm.fit.place", &source(), "main", &[&layout], &constants);
        let (uniform, out) = (gpu.uniform("iasm.fit.place", &params), gpu.storage("iasm.fit", SDSM_BOUNDS_BYTES));
        let group = binding::group(
            gpu,
            "iasm.fit.place",
            &layout,
            &[uniform.as_entire_binding(), out.as_entire_binding(), params_buf.as_entire_binding(), stats_buf.as_entire_binding()],
        );
        ViewFit {
            reduce: BoundsReduce::new(gpu, "iasm.fit"),
            reduce_uniform: gpu.uniform("iasm.fit", &reduce),
            depth_mm: gpu.storage("iasm.fit.depth", 8),
            out,
            uniform,
            group,
            pipeline,
            light_dir,
            params,
            prev: None,
            bounds: None,
            source: FitSource::Fixed,
        }
    }

    /// Records the reduction of `f`'s samples and the square's placement, written into the
    /// frame's `IasmParams` and the statistics' tail, fitted against the side of the last
    /// square [`ViewFit::apply`] took.
    pub fn record(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) {
        let p = FitParams { prev: self.prev.unwrap_or(0.0), ..self.params };
        rec.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&p));
        rec.stage("iasm.fit", |enc| {
            self.reduce.record(gpu, enc, "iasm.fit", f, &self.reduce_uniform, &self.depth_mm, &self.out);
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("iasm.fit.place"), timestamp_writes: None });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &self.group, &[]);
            gpu.dispatch(&mut pass, [1, 1, 1]);
        });
    }

    /// The square in `tail` (the [`FIT_WORDS`] after the statistics), from the samples of
    /// `source`; None when no sample was evaluated (the caller places it by the fixed rule).
    pub fn apply(&mut self, tail: &[u32], source: FitSource) -> Option<Placement> {
        let word = |i: usize| f32::from_bits(tail[i]);
        if tail[0] == 0 {
            self.bounds = None;
            self.source = FitSource::Fixed;
            return None;
        }
        self.bounds = Some(SampleBounds { lo: Vec3::new(word(4), word(5), 0.0), hi: Vec3::new(word(6), word(7), 0.0), samples: tail[8] });
        self.source = source;
        let side = word(3);
        self.prev = Some(side);
        let (right, up, dir) = light_basis(self.light_dir);
        Some(Placement { right, up, dir, origin: Vec2::new(word(1), word(2)), size: side })
    }
}
