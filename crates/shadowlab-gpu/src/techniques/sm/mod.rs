//! `sm`: baseline shadow mapping (Williams 1978) for directional (orthographic, fitted to the
//! scene bounds) and spot (perspective) lights, with constant, slope-scaled and normal-offset
//! bias in units of one shadow texel, and NxN PCF through hardware comparison sampling.
//! Stored depth: post-projective, 0 = near the light (orthographic: linear).

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::params::{ParamDef, ParamValues};

use crate::record::Recorder;
use crate::scene_gpu::GpuScene;
use crate::shaders::compose_depth;
use crate::technique::{compose_view, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};

mod pass;
pub use pass::{DepthPass, MapPass};

const DEPTH_WGSL: &str = include_str!("depth.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");
/// The bias model and sample counting of eval.wgsl, also composed into mdsm's evaluation.
pub const BIAS_WGSL: &str = include_str!("bias.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![("sm/depth.wgsl", depth_source()), ("sm/eval.wgsl", eval_source())]
}

/// The composed depth pass (uniform `SmParams` at group 0; mdsm and min-sm render with it too).
pub fn depth_source() -> String {
    compose_depth(DEPTH_WGSL)
}

/// The composed evaluation (view bindings, then `SmParams`, depth map, comparison sampler, counts).
pub fn eval_source() -> String {
    compose_view(&format!("{BIAS_WGSL}{EVAL_WGSL}"), false)
}

/// Shadow-map side in texels. The seeds evaluate 512 against 1024x1024 output.
pub const DEFAULT_RES: f64 = 512.0;
// Bias defaults come from a sweep (bias 0/0.25/0.5 x slope 0/0.5/1 x normal offset 0/0.5/1,
// res 512, 512x512 output) on courtyard, room, foliage and sponza, 2026-11-22: (0.5, 0, 0.5) was
// within 0.1 point of the best wrong-pixel rate on every scene; any slope bias added light leaks
// under ledges (sponza 1.62 % -> 2.58 % with slope 1) because the normal offset already grows
// with the slope. See BENCHMARKS.md.
/// Constant bias (texels along the light). Too low: acne on lit surfaces; too high: peter-panning.
pub const DEFAULT_BIAS: f64 = 0.5;
/// Slope-scaled bias (texels x tan of the light angle, clamped at `max_slope`). Off by default:
/// with the normal offset it only detaches contact shadows (light leaks under ledges).
pub const DEFAULT_SLOPE_BIAS: f64 = 0.0;
/// Normal offset (texels along the surface normal). Without it grazing surfaces show acne
/// (room: 22 % wrong at 0); too high shifts shadows sideways and makes thin occluders miss.
pub const DEFAULT_NORMAL_OFFSET: f64 = 0.5;

/// `sm`'s parameters, one constant each so that techniques with the same definition (same
/// default, range, doc and source) list them without copying.
pub const RES: ParamDef = ParamDef {
    key: "res",
    default: DEFAULT_RES,
    min: 16.0,
    max: 16384.0,
    integer: true,
    doc: "shadow map side (texels)",
    source: "seeds 000/002 evaluation: 512 with 1024x1024 output",
    choices: &[],
};
pub const PCF: ParamDef = ParamDef {
    key: "pcf",
    default: 1.0,
    min: 1.0,
    max: 7.0,
    integer: true,
    doc: "PCF kernel width N (NxN single-texel comparisons; (N-1)/2 x tan texels of bias added for the kernel); 1 = hard test",
    source: "Reeves et al. 1987; kernel bias: Isidoro 2006",
    choices: &[],
};
pub const BIAS: ParamDef = ParamDef {
    key: "bias",
    default: DEFAULT_BIAS,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "constant depth bias, texels; low: acne, high: peter-panning",
    source: "shadowlab sweep 2026-11-22 (BENCHMARKS.md)",
    choices: &[],
};
pub const SLOPE_BIAS: ParamDef = ParamDef {
    key: "slope_bias",
    default: DEFAULT_SLOPE_BIAS,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "slope-scaled bias, texels x tan(angle to light), tan clamped at max_slope",
    source: "shadowlab sweep 2026-11-22: 0 (normal offset covers slopes)",
    choices: &[],
};
pub const MAX_SLOPE: ParamDef = ParamDef {
    key: "max_slope",
    default: 4.0,
    min: 0.0,
    max: 1000.0,
    integer: false,
    doc: "clamp on tan(angle to light) for the slope bias and the PCF kernel bias; high: leaks under ledges at grazing light",
    source: "shadowlab sweep 2026-11-22 (2, 4, 10 with pcf=3)",
    choices: &[],
};
pub const NORMAL_OFFSET: ParamDef = ParamDef {
    key: "normal_offset",
    default: DEFAULT_NORMAL_OFFSET,
    min: 0.0,
    max: 100.0,
    integer: false,
    doc: "offset along the normal, texels; low: grazing acne, high: shifted shadows",
    source: "Holbert 2011 (normal offset shadows); value from the shadowlab sweep",
    choices: &[],
};

pub const PARAMS: &[ParamDef] = &[RES, PCF, BIAS, SLOPE_BIAS, MAX_SLOPE, NORMAL_OFFSET];

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "sm",
    summary: "shadow mapping: one depth map from the light (orthographic or perspective), biased hard test or NxN PCF",
    cost: "one depth pass over the scene + N^2 comparison fetches per pixel",
    quality: "aliasing where texels project large on screen (perspective aliasing); acne vs peter-panning trade-off",
    source: "Williams 1978; seed 002 chapter 2; PCF: Reeves, Salesin, Cook 1987",
    lights: &["directional", "spot"],
    params: PARAMS,
    stalls: "",
    needs: "",
    compare: &["", "pcf=3"],
    create: |gpu, scene, p, light| Ok(Box::new(ShadowMap::new(gpu, scene, p, light)?)),
};

/// WGSL `SmParams` (in depth.wgsl and eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SmParams {
    pub light_view_proj: [[f32; 4]; 4],
    pub texel: [f32; 4],
    pub bias: [f32; 4],
}

pub struct ShadowMap {
    pass: MapPass,
}

impl ShadowMap {
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &ParamValues, light: &Light) -> Result<ShadowMap, GpuError> {
        let res = p.get_u32("res");
        gpu.check_size(res, res, "shadow map")?;
        let lp = lightspace::fit(light, &scene.bounds, res).ok_or_else(|| GpuError::Invalid("sm does not support point lights".into()))?;
        Ok(ShadowMap { pass: MapPass::new(gpu, scene, "sm", p, &lp) })
    }
}

impl Technique for ShadowMap {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.render(gpu, f, rec);
        Ok(())
    }

    fn evaluate(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.evaluate(gpu, f, rec);
        Ok(())
    }

    fn analyze(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.pass.analyze(gpu, f, rec);
        Ok(())
    }

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        self.pass.report(gpu).0
    }
}
