//! The parameters of the four filterable maps: the representation [`Kind`], the defaults as
//! named constants with where they come from, the rows, the shared map block
//! ([`FilteredMap`]) and each technique's typed settings.

use shadowlab_core::params::{family, Block, ParamDef};
use shadowlab_core::techniques::filtered as cpu;

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

#[cfg(test)]
mod tests {
    use super::{EsmSettings, EvsmSettings, MsmSettings, VsmSettings};
    use crate::registry::testing::{check as resolve, set_keys as keys};

    /// The tables as listed before the typed sets (`shadowlab techniques`).
    #[test]
    fn tables_keep_their_rows_in_order() {
        assert_eq!(keys::<VsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "min_variance"]);
        assert_eq!(keys::<EsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "c"]);
        assert_eq!(keys::<EvsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "min_variance", "c_pos", "c_neg"]);
        assert_eq!(keys::<MsmSettings>(), ["res", "blur", "sd", "mips", "bias", "normal_offset", "moment_bias"]);
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
