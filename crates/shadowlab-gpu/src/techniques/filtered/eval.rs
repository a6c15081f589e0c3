//! The evaluation (`<name>.evaluate`, eval.wgsl): each sample biased, projected and its depth
//! compared with the map through the representation's upper bound (2x2 bilinear, sd: one
//! gather; with mips trilinear at the pixel's footprint); the analysis variant counts the view
//! samples per texel.

use super::{Filtered, FilteredParams, MOMENTS_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::shaders::flag;
use crate::technique::{compose_view, view_layout, EvalPipelines, FrameInputs};
use crate::{binding, Gpu, GpuError};

const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{MOMENTS_WGSL}{PARAMS_WGSL}{EVAL_WGSL}"), false)
}

/// The evaluation's pipeline constants (eval.wgsl): the knobs of `p` that choose code paths.
fn constants(p: &FilteredParams) -> [(&'static str, f64); 4] {
    [
        ("KIND", p.kind as f64),
        ("SINGLE_DEPTH", flag(p.single_depth != 0)),
        ("MIPPED", flag(p.mip_levels > 1)),
        ("PERSPECTIVE", flag(p.perspective > 0.5)),
    ]
}

/// The evaluation layout (the view, the uniform, the map, its sampler, the counts), the
/// evaluation with its analysis variant specialised to `p` ([`constants`]), and the map's
/// clamped sampler.
pub(super) fn pipelines(gpu: &Gpu, name: &str, p: &FilteredParams) -> (wgpu::BindGroupLayout, EvalPipelines, wgpu::Sampler) {
    let sampler_type = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::NonFiltering);
    let layout =
        view_layout(gpu, &format!("{name}.eval"), &[binding::uniform(), binding::texture_float(), sampler_type, binding::storage(false)]);
    let eval = EvalPipelines::new(gpu, &format!("{name}.evaluate"), &source(), &layout, &constants(p));
    let sampler = gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("filtered.gather"),
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        ..Default::default()
    });
    (layout, eval, sampler)
}

impl Filtered {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    pub(super) fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        let name = self.kind.name();
        let map_view = &self.map_view;
        let group = f.view_group(
            gpu,
            &self.groups,
            &format!("{name}.eval"),
            &self.eval_layout,
            &[
                self.uniform.as_entire_binding(),
                wgpu::BindingResource::TextureView(&map_view),
                wgpu::BindingResource::Sampler(&self.sampler),
                self.counts.as_entire_binding(),
            ],
        );
        let label = format!("{name}.evaluate");
        self.eval.record(gpu, rec, &label, &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}
