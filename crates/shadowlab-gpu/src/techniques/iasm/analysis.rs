//! `iasm`'s importance pass `iasm.importance` (analysis.wgsl): per tile of the square, the view
//! samples' importance (equation 3.1), count and light-depth range, and the samples outside the
//! square; read back for the plan with the fit's square (`iasm.readback`, the sync).

use shadowlab_core::techniques::iasm::TILE_COUNT;

use super::plan::READ_WORDS;
use super::uniforms::{IasmParams, PARAMS_WGSL};
use crate::record::Recorder;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::{binding, Gpu};

const ANALYSIS_WGSL: &str = include_str!("analysis.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{PARAMS_WGSL}{ANALYSIS_WGSL}"), false)
}

pub(super) struct AnalysisPass {
    layout: wgpu::BindGroupLayout,
    groups: crate::binding::GroupCache,
    pipeline: wgpu::ComputePipeline,
}

impl AnalysisPass {
    pub fn new(gpu: &Gpu) -> AnalysisPass {
        let layout = view_layout(gpu, "iasm.analysis", &[binding::uniform(), binding::storage(false)]);
        let pipeline = gpu.compute_pipeline("iasm.analysis", &source(), "main", &[&layout]);
        AnalysisPass { layout, groups: Default::default(), pipeline }
    }

    /// Writes `params` into `params_buf` and clears the statistics in `stats_buf` (not the
    /// fit's tail), before [`AnalysisPass::dispatch`]; `fit=view` places the square between
    /// the two.
    pub fn clear(&self, rec: &mut Recorder, params: &IasmParams, params_buf: &wgpu::Buffer, stats_buf: &wgpu::Buffer) {
        rec.write_buffer(params_buf, 0, bytemuck::bytes_of(params));
        let mut init: Vec<u32> = (0..TILE_COUNT).flat_map(|_| [0, 0, 0, u32::MAX, 0, 0, 0, 0]).collect();
        init.push(0);
        rec.write_buffer(stats_buf, 0, bytemuck::cast_slice(&init));
    }

    /// Dispatches the analysis of `f` over the square in `params_buf` into `stats_buf`.
    pub fn dispatch(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, params_buf: &wgpu::Buffer, stats_buf: &wgpu::Buffer) {
        let group = f.view_group(
            gpu,
            &self.groups,
            "iasm.analysis",
            &self.layout,
            &[params_buf.as_entire_binding(), stats_buf.as_entire_binding()],
        );
        rec.stage("iasm.importance", |enc| {
            gpu.dispatch_2d(enc, "iasm.importance", &self.pipeline, &[&group], f.gbuffer.width, f.gbuffer.height)
        });
    }
}

/// The statistics in `stats_buf` and the fit's tail ([`READ_WORDS`]), read back now (the
/// sync `iasm.readback`, the frame's only one).
pub(super) fn read_stats(rec: &mut Recorder, stats_buf: &wgpu::Buffer) -> Vec<u32> {
    let t0 = web_time::Instant::now();
    let words: Vec<u32> = rec.read_buffer_as(stats_buf, READ_WORDS, "iasm.readback");
    rec.cpu("iasm.readback", t0.elapsed().as_secs_f64() * 1e3);
    words
}
