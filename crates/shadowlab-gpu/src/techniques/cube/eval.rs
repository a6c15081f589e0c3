//! `cube`'s evaluation (`cube.evaluate`, eval.wgsl): sm's bias in face texels at the sample, an
//! NxN kernel of nearest-texel taps, each read on the face its direction falls on (seamless);
//! the analysis variant counts the view samples per texel of the six faces.

use super::{CubeMap, FACES_WGSL};
use crate::record::Recorder;
use crate::shaders::flag;
use crate::technique::{compose_view, view_layout, EvalPipelines, FrameInputs};
use crate::techniques::sm::BIAS_WGSL;
use crate::{binding, Gpu, GpuError};

const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{FACES_WGSL}{BIAS_WGSL}{EVAL_WGSL}"), false)
}

/// The evaluation layout (the view, `CubeParams`, the face array, the counts) and the
/// evaluation with its analysis variant; `hardware`: the faces hold reversed depth; `pcf`: the
/// kernel width (a pipeline constant).
pub(super) fn pipelines(gpu: &Gpu, hardware: bool, pcf: u32) -> (wgpu::BindGroupLayout, EvalPipelines) {
    let array = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Depth,
        view_dimension: wgpu::TextureViewDimension::D2Array,
        multisampled: false,
    };
    let layout = view_layout(gpu, "cube.evaluate", &[binding::uniform(), array, binding::storage(false)]);
    let eval = EvalPipelines::new(gpu, "cube.evaluate", &source(), &layout, &[("HW_DEPTH", flag(hardware)), ("PCF", pcf as f64)]);
    (layout, eval)
}

impl CubeMap {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    pub(super) fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let view = &self.array_view;
        let group = f.view_group(
            gpu,
            &self.groups,
            "cube.evaluate",
            &self.eval_layout,
            &[self.params.as_entire_binding(), wgpu::BindingResource::TextureView(&view), self.counts.as_entire_binding()],
        );
        self.eval.record(gpu, rec, "cube.evaluate", &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}
