//! `sm`: baseline shadow mapping (Williams 1978) for directional (orthographic, fitted to the
//! scene bounds) and spot (perspective) lights, with constant, slope-scaled and normal-offset
//! bias in units of one shadow texel, and NxN PCF through hardware comparison sampling.
//! Stored depth: post-projective, 0 = near the light (orthographic: linear).

use bytemuck::{Pod, Zeroable};
use shadowlab_core::light::Light;
use shadowlab_core::lightspace;
use shadowlab_core::params::family::{Bias, PCF, RES};
use shadowlab_core::params::{Block, ParamSet, ParamTable};

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

shadowlab_core::param_set! {
    /// `sm`'s parameters (and the map of `min-sm`): the shared map size, PCF and bias family, at
    /// their shared defaults (measured for `sm`; see `shadowlab_core::params::family`).
    pub struct MapSettings {
        pub res: u32 = RES,
        pub pcf: u32 = PCF,
        pub bias: Bias = Block::as_declared(),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.bias.ineffective(self.pcf)
        }
    }
}

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "sm",
    summary: "shadow mapping: one depth map from the light (orthographic or perspective), biased hard test or NxN PCF",
    cost: "one depth pass over the scene + N^2 comparison fetches per pixel",
    quality: "aliasing where texels project large on screen (perspective aliasing); acne vs peter-panning trade-off",
    source: "Williams 1978; seed 002 chapter 2; PCF: Reeves, Salesin, Cook 1987",
    lights: &["directional", "spot"],
    params: ParamTable::of::<MapSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &["", "pcf=3"],
    shaders,
    create: |gpu, scene, p, light| Ok(Box::new(ShadowMap::new(gpu, scene, &MapSettings::from_values(p), light)?)),
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
    pub fn new(gpu: &Gpu, scene: &GpuScene, p: &MapSettings, light: &Light) -> Result<ShadowMap, GpuError> {
        let res = p.res;
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
