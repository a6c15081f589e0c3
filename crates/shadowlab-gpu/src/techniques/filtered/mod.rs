//! Filterable shadow maps (seed 004 section 2.1): `vsm` (z, z^2; Chebyshev), `esm` (e^{cz};
//! Markov), `evsm` (positive and negative exponential warps, two Chebyshev bounds, the minimum),
//! `msm` (four moments, Hamburger 4-moment bound). Four registry entries, one implementation.
//!
//! Passes: `<name>.render` rasterises the scene from the light (directional: orthographic,
//! spot: perspective, via `lightspace::fit`) writing b(z) per texel; `<name>.blur` pre-filters it
//! with the separable Gaussian of [`crate::blur`] (`blur` = kernel width, 1 = none);
//! `<name>.evaluate` interpolates the 2x2 texels around each sample bilinearly and takes the
//! representation's upper bound on the lit fraction. With `sd=true` (seed 004 section 3.2) only
//! the depth is stored (R32Float, never blurred) and the evaluation gathers 2x2 depths, converts
//! each and interpolates (`*_visibility_gather` in `moments.wgsl`, for leak tracing). With
//! `mips=true` a box-filtered mip chain is built (`<name>.mips`) and read trilinearly at the
//! level matching the pixel's footprint in the map (from the neighbouring view samples).
//!
//! Stored depth: linear light-space depth in [0, 1], 0 = near the light (orthographic: the
//! post-projective depth; spot: view depth / far, far = the farthest scene-bounds corner).
//! Map formats: VSM RG32Float (8 B/texel), ESM R32Float (4), EVSM and MSM RGBA32Float (16),
//! sd R32Float (4). The CPU math is `shadowlab_core::techniques::filtered`.
//!
//! The parameters are params.rs; a map is made in map.rs, rendered in render.rs (with mips.rs),
//! evaluated in eval.rs and reported in report.rs.

mod eval;
mod map;
mod mips;
mod params;
mod render;
mod report;

pub use params::*;
pub use render::render_source;

use bytemuck::{Pod, Zeroable};
use shadowlab_core::params::{ParamSet, ParamTable};

use crate::blur::Blur;
use crate::record::Recorder;
use crate::technique::{counted_evaluation, FrameInputs, Technique, TechniqueInfo, TechniqueReport};
use crate::{Gpu, GpuError};
use mips::MipChain;

/// The representation library (encoders, bounds, `*_visibility_gather`): self-contained WGSL
/// with no bindings, for other passes (leak tracing) to prepend.
pub const MOMENTS_WGSL: &str = include_str!("moments.wgsl");
/// `FilteredParams`, shared by render.wgsl and eval.wgsl.
const PARAMS_WGSL: &str = include_str!("params.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("filtered/render.wgsl", render_source()),
        ("filtered/eval.wgsl", eval::source()),
        ("filtered/mips.wgsl (rgba32float)", mips::source("rgba32float")),
    ]
}

const LIGHTS: &[&str] = &["directional", "spot"];
const COST: &str = "one pass over the scene into a float map + optional separable blur (2 x width taps per texel) + one 2x2 read per pixel";

pub const VSM_INFO: TechniqueInfo = TechniqueInfo {
    name: "vsm",
    summary: "variance shadow map: (z, z^2), pre-filterable, Chebyshev upper bound",
    cost: COST,
    quality: "soft, bias-free edges; light leaks where an occluder lies in front of another (high variance)",
    source: "Donnelly and Lauritzen 2006; seed 004 section 2.1",
    lights: LIGHTS,
    params: ParamTable::of::<VsmSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| {
        let s = VsmSettings::from_values(p);
        Ok(Box::new(Filtered::new(gpu, scene, &s.map, Representation::Vsm { min_variance: s.min_variance }, light)?))
    },
};
pub const ESM_INFO: TechniqueInfo = TechniqueInfo {
    name: "esm",
    summary: "exponential shadow map: e^{cz}, pre-filterable, Markov upper bound",
    cost: COST,
    quality: "leaks wherever receiver and occluder are close in depth (contact), worse for large depth ranges",
    source: "Annen et al. 2008, Salvi 2008; seed 004 section 2.1",
    lights: LIGHTS,
    params: ParamTable::of::<EsmSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[],
    shaders,
    create: |gpu, scene, p, light| {
        let s = EsmSettings::from_values(p);
        Ok(Box::new(Filtered::new(gpu, scene, &s.map, Representation::Esm { c: s.c }, light)?))
    },
};
pub const EVSM_INFO: TechniqueInfo = TechniqueInfo {
    name: "evsm",
    summary: "exponential variance shadow map: moments of e^{c+ z} and -e^{-c- z}, min of two Chebyshev bounds",
    cost: COST,
    quality: "fewer leaks than VSM and ESM; 16 bytes per texel",
    source: "Lauritzen and McCool 2008; seed 004 section 2.1 (leak tracing's default)",
    lights: LIGHTS,
    params: ParamTable::of::<EvsmSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &["", "sd=true"],
    shaders,
    create: |gpu, scene, p, light| {
        let s = EvsmSettings::from_values(p);
        let rep = Representation::Evsm { min_variance: s.min_variance, c_pos: s.c_pos, c_neg: s.c_neg };
        Ok(Box::new(Filtered::new(gpu, scene, &s.map, rep, light)?))
    },
};
pub const MSM_INFO: TechniqueInfo = TechniqueInfo {
    name: "msm",
    summary: "moment shadow map: (z, z^2, z^3, z^4), Hamburger 4-moment bound with moment bias",
    cost: COST,
    quality: "sharper bound than VSM for two occluder layers; leaks near steep edges with values near 1",
    source: "Peters and Klein 2015 (algorithm 2); seed 004 section 2.1",
    lights: LIGHTS,
    params: ParamTable::of::<MsmSettings>(),
    stalls: "",
    needs: "",
    storage_buffers: 8,
    compare: &[""],
    shaders,
    create: |gpu, scene, p, light| {
        let s = MsmSettings::from_values(p);
        Ok(Box::new(Filtered::new(gpu, scene, &s.map, Representation::Msm { moment_bias: s.moment_bias }, light)?))
    },
};

/// WGSL `FilteredParams` (render.wgsl and eval.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FilteredParams {
    pub light_view_proj: [[f32; 4]; 4],
    /// World size of one texel (orthographic) or per unit of light-view depth (perspective).
    pub texel_world: f32,
    /// 1 if perspective.
    pub perspective: f32,
    pub res: f32,
    /// 1 / far (perspective linear depth).
    pub inv_far: f32,
    /// [`Kind`] as its index.
    pub kind: u32,
    /// 1: single depth (z only, the moments rebuilt from a 2x2 gather).
    pub single_depth: u32,
    /// Mip levels (0 or 1 = none).
    pub mip_levels: u32,
    pub pad0: u32,
    pub min_variance: f32,
    pub esm_c: f32,
    pub evsm_c_pos: f32,
    pub evsm_c_neg: f32,
    pub moment_bias: f32,
    /// Texels.
    pub depth_bias: f32,
    /// Texels.
    pub normal_offset: f32,
    pub pad1: f32,
}

/// The representation with the shape parameters its technique declares (params.rs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Representation {
    Vsm { min_variance: f64 },
    Esm { c: f64 },
    Evsm { min_variance: f64, c_pos: f64, c_neg: f64 },
    Msm { moment_bias: f64 },
}

impl Representation {
    pub fn kind(self) -> Kind {
        match self {
            Representation::Vsm { .. } => Kind::Vsm,
            Representation::Esm { .. } => Kind::Esm,
            Representation::Evsm { .. } => Kind::Evsm,
            Representation::Msm { .. } => Kind::Msm,
        }
    }
}

/// One light's filterable map (made in map.rs).
pub struct Filtered {
    pub(crate) groups: crate::binding::GroupCache,
    kind: Kind,
    sd: bool,
    res: u32,
    params: FilteredParams,
    map: wgpu::Texture,
    /// The moments' view the evaluation binds (made once: its bind group is kept).
    map_view: wgpu::TextureView,
    depth: wgpu::Texture,
    clear: wgpu::Color,
    blur: Option<Blur>,
    /// Effective kernel width (1 with sd).
    blur_width: u32,
    mips: Option<MipChain>,
    counts: wgpu::Buffer,
    uniform: wgpu::Buffer,
    render_pipeline: wgpu::RenderPipeline,
    render_group: wgpu::BindGroup,
    /// The evaluation and its analysis variant.
    eval: crate::technique::EvalPipelines,
    eval_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

/// A frame of a filterable map: the moments rendered, pre-filtered and mip-mapped (render.rs),
/// then the upper bound evaluated per sample (eval.rs).
impl Technique for Filtered {
    fn render(&mut self, gpu: &Gpu, f: &FrameInputs, rec: &mut Recorder) -> Result<(), GpuError> {
        self.render_map(gpu, f, rec);
        Ok(())
    }

    counted_evaluation!();

    fn report(&mut self, gpu: &Gpu) -> TechniqueReport {
        report::report(self, gpu)
    }
}
