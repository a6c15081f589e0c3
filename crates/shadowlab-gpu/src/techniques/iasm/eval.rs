//! `iasm`'s evaluation `iasm.evaluate`: every view sample's tile and texel by equations 3.2-3.5
//! and one fetch, from the linear buffer (eval.wgsl) or the depth atlas (eval_atlas.wgsl), both
//! with eval_main.wgsl; and its lab-only twin `iasm.analysis`, counting the samples per texel.

use super::uniforms::PARAMS_WGSL;
use crate::record::Recorder;
use crate::technique::{compose_view, view_layout, FrameInputs};
use crate::{binding, Gpu};

const EVAL_WGSL: &str = include_str!("eval.wgsl");
const EVAL_ATLAS_WGSL: &str = include_str!("eval_atlas.wgsl");
const EVAL_MAIN_WGSL: &str = include_str!("eval_main.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{PARAMS_WGSL}{EVAL_WGSL}{EVAL_MAIN_WGSL}"), false)
}

pub(super) fn atlas_source() -> String {
    compose_view(&format!("{PARAMS_WGSL}{EVAL_ATLAS_WGSL}{EVAL_MAIN_WGSL}"), false)
}

/// The evaluation over one store: its layout (the frame uniform, the shadow data, the counts),
/// as shipped and counting.
pub(super) struct EvalPass {
    layout: wgpu::BindGroupLayout,
    groups: crate::binding::GroupCache,
    timed: wgpu::ComputePipeline,
    counting: wgpu::ComputePipeline,
}

impl EvalPass {
    /// store=buffer: the shadow buffer.
    pub fn buffer(gpu: &Gpu) -> EvalPass {
        EvalPass::new(gpu, "iasm.eval", binding::storage(true), &source())
    }

    /// store=atlas: the depth atlas.
    pub fn atlas(gpu: &Gpu) -> EvalPass {
        EvalPass::new(gpu, "iasm.eval_atlas", binding::texture_depth(), &atlas_source())
    }

    fn new(gpu: &Gpu, label: &str, data: wgpu::BindingType, source: &str) -> EvalPass {
        let layout = view_layout(gpu, label, &[binding::uniform(), data, binding::storage(false)]);
        let timed = gpu.compute_pipeline("iasm.evaluate", source, "main", &[&layout]);
        let counting = gpu.compute_pipeline_with("iasm.evaluate", source, "main", &[&layout], crate::context::COUNTING);
        EvalPass { layout, groups: Default::default(), timed, counting }
    }

    /// The bind group over the frame uniform, the shadow data `data` and the counts.
    pub fn group(
        &self,
        gpu: &Gpu,
        f: &FrameInputs,
        params: &wgpu::Buffer,
        data: wgpu::BindingResource,
        counts: &wgpu::Buffer,
    ) -> wgpu::BindGroup {
        f.view_group(gpu, &self.groups, "iasm.eval", &self.layout, &[params.as_entire_binding(), data, counts.as_entire_binding()])
    }

    /// Stage `iasm.evaluate`.
    pub fn evaluate(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, group: &wgpu::BindGroup) {
        rec.stage("iasm.evaluate", |enc| gpu.dispatch_2d(enc, "iasm.evaluate", &self.timed, &[group], f.gbuffer.width, f.gbuffer.height));
    }

    /// Stage `iasm.analysis`: the evaluation again, the view samples counted per texel into `counts`.
    pub fn count(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, group: &wgpu::BindGroup, counts: &wgpu::Buffer) {
        rec.stage("iasm.analysis", |enc| {
            enc.clear_buffer(counts, 0, None);
            gpu.dispatch_2d(enc, "iasm.analysis", &self.counting, &[group], f.gbuffer.width, f.gbuffer.height)
        });
    }
}
