//! The evaluation (`final_pass`, eval.wgsl): each evaluated sample offset by the bias in world
//! units of one warped texel (its size from the warp's Jacobian, `bias_mode`), projected,
//! cropped, warped like the depth pass and compared NxN with the warped map (`close_cracks`:
//! with the nearest depth of 3x3 texels per tap); the analysis variant also counts the samples
//! per warped texel.

use super::{base_constants, WarpParams, Warped, DV_CROP_CLOSED, LOOKUP_WGSL, PARAMS_WGSL};
use crate::record::Recorder;
use crate::shaders::flag;
use crate::technique::{compose_view, view_layout, EvalPipelines, FrameInputs};
use crate::{binding, Gpu, GpuError};

/// The evaluation of one sample (`eval_sample`), for any bindings of the map.
pub(super) const EVAL_FNS_WGSL: &str = include_str!("eval.wgsl");
/// One map's bindings and entry point.
const EVAL_MAIN_WGSL: &str = include_str!("eval_main.wgsl");

pub(super) fn source() -> String {
    compose_view(&format!("{PARAMS_WGSL}{LOOKUP_WGSL}{EVAL_FNS_WGSL}{EVAL_MAIN_WGSL}"), false)
}

/// The evaluation's pipeline constants (eval.wgsl and params.wgsl): the knobs of `p` that choose
/// code paths, so that the pipeline holds only the path this map takes.
pub(super) fn constants(p: &WarpParams) -> Vec<(&'static str, f64)> {
    let mut c = base_constants(p);
    c.extend([
        ("BIAS_MODE", p.bias_mode.round() as f64),
        ("CLOSE_CRACKS", flag(p.dv_mode == DV_CROP_CLOSED)),
        ("PERSPECTIVE", flag(p.perspective > 0.5)),
    ]);
    c
}

/// The evaluation layout (the view, the lookup, the map, its comparison sampler, the counts) and
/// the evaluation with its analysis variant, specialised to `p` ([`constants`]).
pub(super) fn pipelines(gpu: &Gpu, name: &str, p: &WarpParams) -> (wgpu::BindGroupLayout, EvalPipelines) {
    let (ro, rw, tex) = (binding::storage(true), binding::storage(false), binding::texture_float());
    let layout = view_layout(
        gpu,
        &format!("{name}.final_pass"),
        &[binding::uniform(), ro, tex, tex, binding::texture_depth(), binding::comparison_sampler(), rw],
    );
    let eval = EvalPipelines::new(gpu, &format!("{name}.final_pass"), &source(), &layout, &constants(p));
    (layout, eval)
}

/// The evaluation's depth comparison, nearest texel (the PCF taps are explicit).
pub(super) fn sampler(gpu: &Gpu) -> wgpu::Sampler {
    gpu.device.create_sampler(&wgpu::SamplerDescriptor {
        label: Some("warp.cmp"),
        compare: Some(wgpu::CompareFunction::LessEqual),
        mag_filter: wgpu::FilterMode::Nearest,
        min_filter: wgpu::FilterMode::Nearest,
        address_mode_u: wgpu::AddressMode::ClampToEdge,
        address_mode_v: wgpu::AddressMode::ClampToEdge,
        ..Default::default()
    })
}

impl Warped {
    /// The evaluation; with `counting` the lab's analysis variant (view samples per texel).
    pub(super) fn eval_pass(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder, counting: bool) -> Result<(), GpuError> {
        // a layer of [`Layers`] is evaluated with the others by its owner (and the counting
        // variant below clears the whole counts buffer)
        assert!(!self.layered, "{}: a layered map is evaluated by its owner", self.name());
        let name = self.name();
        let mut extra: Vec<wgpu::BindingResource> = self.lookup_resources().to_vec();
        extra.extend([
            wgpu::BindingResource::TextureView(&self.views[2]),
            wgpu::BindingResource::Sampler(&self.sampler),
            self.counts_binding(),
        ]);
        let group = f.view_group(gpu, &self.groups.eval, &format!("{name}.final_pass"), &self.eval_layout, &extra);
        self.eval.record(gpu, rec, &format!("{name}.final_pass"), &self.counts, &group, f.gbuffer.width, f.gbuffer.height, counting);
        Ok(())
    }
}
