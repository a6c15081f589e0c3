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

mod mips;
mod technique;

use bytemuck::{Pod, Zeroable};
use shadowlab_core::params::{family, Block, ParamDef, ParamSet, ParamTable};
use shadowlab_core::techniques::filtered as cpu;

use crate::shaders::compose;
use crate::technique::{compose_view, TechniqueInfo};
pub use technique::{Filtered, Representation};

/// The representation library (encoders, bounds, `*_visibility_gather`): self-contained WGSL
/// with no bindings, for other passes (leak tracing) to prepend.
pub const MOMENTS_WGSL: &str = include_str!("moments.wgsl");
const PARAMS_WGSL: &str = include_str!("params.wgsl");
const RENDER_WGSL: &str = include_str!("render.wgsl");
const EVAL_WGSL: &str = include_str!("eval.wgsl");

pub fn shaders() -> Vec<(&'static str, String)> {
    vec![
        ("filtered/render.wgsl", render_source()),
        ("filtered/eval.wgsl", eval_source()),
        ("filtered/mips.wgsl (rgba32float)", mips::source("rgba32float")),
    ]
}
/// The composed moments raster (`FilteredParams` at group 0; leak tracing renders its sd maps with it).
pub fn render_source() -> String {
    compose(&format!("{MOMENTS_WGSL}{PARAMS_WGSL}{RENDER_WGSL}"), true)
}
fn eval_source() -> String {
    compose_view(&format!("{MOMENTS_WGSL}{PARAMS_WGSL}{EVAL_WGSL}"), false)
}

shadowlab_core::param_choice! {
    /// The four representations; the index is `mode.x` in the WGSL (and leak tracing's `base`).
    pub enum Kind { Vsm = "vsm", Esm = "esm", Evsm = "evsm", Msm = "msm" }
}

impl Kind {
    /// Channels of the (non-sd) map.
    pub fn channels(self) -> u32 {
        [2, 1, 4, 4][self as usize]
    }
}

/// Blur kernel width default. Measured (docs/bench/filtered.md): 1 gives the fewest wrong
/// pixels against `rt` on foliage, courtyard and sponza (any blur widens every leak and every
/// edge); larger widths soften the edges (the point of pre-filtering) at that cost.
pub const DEFAULT_BLUR: f64 = 1.0;
/// Constant bias (texels along the light) and normal offset (texels along the normal). The upper
/// bounds need no bias (seed 004 section 2.1): a sweep (normal offset 0/0.5/1 x bias 0/0.5,
/// 512x512 output, foliage and courtyard, 2026-11-22, docs/bench/filtered.md) found 0/0 best or
/// within 0.1 point of best for all four; every normal offset widens the leaks (courtyard VSM
/// 1.19 % wrong at 0, 1.56 % at 0.5, 1.99 % at 1). Kept as parameters for curved receivers.
pub const DEFAULT_BIAS: f64 = 0.0;
pub const DEFAULT_NORMAL_OFFSET: f64 = 0.0;

const RES: ParamDef = family::RES.with_doc("shadow map side (texels)");
const BLUR: ParamDef = ParamDef::integer(
    "blur",
    DEFAULT_BLUR,
    1.0,
    15.0,
    "Gaussian pre-filter kernel width (odd; 1 = none; sigma = (width-1)/4); ignored with sd=true; high: wider leaks and softer edges",
    "seed 004 section 2.1 eq. 2; default: shadowlab measurement (docs/bench/filtered.md)",
);
const SD: ParamDef = ParamDef::flag(
    "sd",
    false,
    "single depth: store linear depth only (R32Float), gather 2x2 and convert in the shader",
    "seed 004 section 3.2",
);
const MIPS: ParamDef = ParamDef::flag("mips", false, "box-filtered mip chain (+1/3 memory) read trilinearly at the pixel's footprint; ignored with sd=true; softer, wider leaks where texels are small on screen", "Donnelly and Lauritzen 2006 (filtering with mipmaps); issue 5");
const BIAS: ParamDef = family::BIAS
    .with_default(DEFAULT_BIAS, "shadowlab measurement (docs/bench/filtered.md)")
    .with_doc("constant depth bias, texels; high: peter-panning");
const NORMAL_OFFSET: ParamDef = family::NORMAL_OFFSET
    .with_default(DEFAULT_NORMAL_OFFSET, "Holbert 2011; value: shadowlab measurement (docs/bench/filtered.md)")
    .with_doc("offset along the normal, texels; low: self-shadowing on curved/grazing receivers, high: shifted shadows");
const MIN_VARIANCE: ParamDef = ParamDef::number(
    "min_variance",
    cpu::DEFAULT_MIN_VARIANCE,
    0.0,
    1.0,
    "minimum variance (depth units^2; EVSM: scaled by each warp's slope); low: acne, high: leaks",
    "seed 004 section 4 (1e-10)",
);
const ESM_C: ParamDef = ParamDef::number(
    "c",
    cpu::DEFAULT_ESM_C,
    0.0,
    88.0,
    "ESM exponent; low: leaks near contact, > 88: f32 overflow",
    "seed 004 section 4 (80)",
);
const C_POS: ParamDef = ParamDef::number(
    "c_pos",
    cpu::DEFAULT_EVSM_C_POS,
    0.0,
    42.0,
    "EVSM positive exponent (depth in [-1,1]); high: f32 overflow of e^{2c}",
    "seed 004 section 4 (20)",
);
const C_NEG: ParamDef =
    ParamDef::number("c_neg", cpu::DEFAULT_EVSM_C_NEG, 0.0, 42.0, "EVSM negative exponent (depth in [-1,1])", "seed 004 section 4 (5)");
const MOMENT_BIAS: ParamDef = ParamDef::number(
    "moment_bias",
    cpu::DEFAULT_MOMENT_BIAS,
    0.0,
    1.0,
    "MSM blend of the moments towards 0.5; low: unstable (singular Hankel matrix), high: leaks",
    "seed 004 section 4 (3e-6 with 32-bit floats)",
);

shadowlab_core::param_set! {
    /// The map settings the four filterable maps share: size, pre-filter, single depth, mip
    /// chain, bias (texels).
    pub struct FilteredMap {
        pub res: u32 = RES,
        pub blur: u32 = BLUR,
        pub sd: bool = SD,
        pub mips: bool = MIPS,
        pub bias: f64 = BIAS,
        pub normal_offset: f64 = NORMAL_OFFSET,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            if self.sd {
                vec![
                    ("blur", "sd=true stores the depth unblurred".into()),
                    ("mips", "sd=true builds no mip chain".into()),
                ]
            } else {
                Vec::new()
            }
        }
    }
}

shadowlab_core::param_set! {
    /// `vsm`'s parameters.
    pub struct VsmSettings {
        pub map: FilteredMap = Block::as_declared(),
        pub min_variance: f64 = MIN_VARIANCE,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.map.ineffective()
        }
    }
}

shadowlab_core::param_set! {
    /// `esm`'s parameters.
    pub struct EsmSettings {
        pub map: FilteredMap = Block::as_declared(),
        pub c: f64 = ESM_C,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.map.ineffective()
        }
    }
}

shadowlab_core::param_set! {
    /// `evsm`'s parameters.
    pub struct EvsmSettings {
        pub map: FilteredMap = Block::as_declared(),
        pub min_variance: f64 = MIN_VARIANCE,
        pub c_pos: f64 = C_POS,
        pub c_neg: f64 = C_NEG,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.map.ineffective()
        }
    }
}

shadowlab_core::param_set! {
    /// `msm`'s parameters.
    pub struct MsmSettings {
        pub map: FilteredMap = Block::as_declared(),
        pub moment_bias: f64 = MOMENT_BIAS,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.map.ineffective()
        }
    }
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

#[cfg(test)]
mod tests {
    use shadowlab_core::params::{ParamSet, TechniqueSpec};

    use super::{EsmSettings, EvsmSettings, MsmSettings, VsmSettings};
    use crate::GpuError;

    fn keys<P: ParamSet>() -> Vec<&'static str> {
        P::defs().iter().map(|d| d.key).collect()
    }

    /// The tables as listed before the typed sets (`shadowlab techniques`).
    #[test]
    fn tables_keep_their_rows_in_order() {
        assert_eq!(keys::<VsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "min_variance"]);
        assert_eq!(keys::<EsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "c"]);
        assert_eq!(keys::<EvsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "min_variance", "c_pos", "c_neg"]);
        assert_eq!(keys::<MsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "moment_bias"]);
    }

    fn resolve(spec: &str) -> Result<(), String> {
        match crate::registry::resolve(&TechniqueSpec::parse(spec).unwrap(), None) {
            Ok(_) => Ok(()),
            Err(GpuError::Invalid(msg)) => Err(msg),
            Err(e) => panic!("{spec}: {e:?}"),
        }
    }

    #[test]
    fn keys_without_effect_are_reported() {
        for name in ["vsm", "esm", "evsm", "msm"] {
            let e = resolve(&format!("{name}:sd=true,mips=true")).unwrap_err();
            assert!(e.contains(&format!("technique '{name}': mips has no effect: sd=true")), "{e}");
            let e = resolve(&format!("{name}:blur=5,sd=true")).unwrap_err();
            assert!(e.contains("blur has no effect: sd=true"), "{e}");
            for ok in ["sd=true", "sd=true,bias=0.5,normal_offset=0.5,res=1024", "mips=true,blur=5", "sd=false,mips=true"] {
                resolve(&format!("{name}:{ok}")).unwrap_or_else(|e| panic!("{name}:{ok}: {e}"));
            }
        }
    }
}
