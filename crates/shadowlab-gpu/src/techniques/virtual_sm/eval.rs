//! `virtual`'s evaluation `virtual.evaluate` (eval.wgsl): every PCF tap looked up through the
//! page table in the atlas (the finest mapped level); and the lab's `virtual.analysis`, the
//! same counting samples per level.

use super::resources::Resources;
use super::uniforms::PAGES_WGSL;
use crate::record::Recorder;
use crate::technique::{compose_view, view_layout, EvalPipelines, FrameInputs};
use crate::techniques::cube::FACES_WGSL;
use crate::{binding, Gpu};

const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{FACES_WGSL}{PAGES_WGSL}{}{EVAL_WGSL}", crate::techniques::sm::BIAS_WGSL), false)
}

pub(super) struct EvalPass {
    pub(crate) groups: crate::binding::GroupCache,
    layout: wgpu::BindGroupLayout,
    pipelines: EvalPipelines,
}

impl EvalPass {
    pub fn new(gpu: &Gpu) -> EvalPass {
        let layout = view_layout(
            gpu,
            "virtual.eval",
            &[binding::uniform(), binding::storage(true), binding::texture_depth(), binding::storage(false)],
        );
        let pipelines = EvalPipelines::new(gpu, "virtual.eval", &source(), &layout, &[]);
        EvalPass { groups: Default::default(), layout, pipelines }
    }

    /// Stage `virtual.evaluate`, or with `counting` `virtual.analysis`.
    pub fn record(&self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, r: &Resources, counting: bool) {
        let group = f.view_group(
            gpu,
            &self.groups,
            "virtual.eval",
            &self.layout,
            &[
                r.uniform.as_entire_binding(),
                r.page_table.as_entire_binding(),
                wgpu::BindingResource::TextureView(&r.atlas_view),
                r.counts.as_entire_binding(),
            ],
        );
        let stage = if counting { "virtual.analysis" } else { "virtual.evaluate" };
        self.pipelines.record(gpu, rec, stage, &r.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
    }
}
