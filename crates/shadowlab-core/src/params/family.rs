//! The parameters many techniques share, defined once: the shadow map's size, PCF and the bias
//! family (constant, slope-scaled, its clamp, normal offset). A technique lists these as they
//! are, or with its own default (`BIAS.with_default(1.5, "...")`) where its measurements differ.
//! Biases are in texels of the technique's map (warped texels for the warped maps, a face's
//! texels for cube maps).

use super::ParamDef;

/// Shadow-map side in texels. The seeds evaluate 512 against 1024x1024 output.
pub const DEFAULT_RES: f64 = 512.0;
// Bias defaults come from a sweep (bias 0/0.25/0.5 x slope 0/0.5/1 x normal offset 0/0.5/1,
// res 512, 512x512 output) on courtyard, room, foliage and sponza, 2026-11-22: (0.5, 0, 0.5) was
// within 0.1 point of the best wrong-pixel rate on every scene; any slope bias added light leaks
// under ledges (sponza 1.62 % -> 2.58 % with slope 1) because the normal offset already grows
// with the slope. See docs/bench/sm.md ("Bias defaults").
/// Constant bias (texels along the light). Too low: acne on lit surfaces; too high: peter-panning.
pub const DEFAULT_BIAS: f64 = 0.5;
/// Slope-scaled bias (texels x tan of the light angle, clamped at `max_slope`). Off by default:
/// with the normal offset it only detaches contact shadows (light leaks under ledges).
pub const DEFAULT_SLOPE_BIAS: f64 = 0.0;
/// Clamp on tan(angle to light) for the slope bias and the PCF kernel bias.
pub const DEFAULT_MAX_SLOPE: f64 = 4.0;
/// Normal offset (texels along the surface normal). Without it grazing surfaces show acne
/// (room: 22 % wrong at 0); too high shifts shadows sideways and makes thin occluders miss.
pub const DEFAULT_NORMAL_OFFSET: f64 = 0.5;

pub const RES: ParamDef =
    ParamDef::integer("res", DEFAULT_RES, 16.0, 16384.0, "shadow map side (texels)", "seeds 000/002 evaluation: 512 with 1024x1024 output");
pub const PCF: ParamDef = ParamDef::integer(
    "pcf",
    1.0,
    1.0,
    7.0,
    "PCF kernel width N (NxN single-texel comparisons; (N-1)/2 x tan texels of bias added for the kernel); 1 = hard test",
    "Reeves et al. 1987; kernel bias: Isidoro 2006",
);
pub const BIAS: ParamDef = ParamDef::number(
    "bias",
    DEFAULT_BIAS,
    0.0,
    100.0,
    "constant depth bias, texels; low: acne, high: peter-panning",
    "shadowlab sweep 2026-11-22 (docs/bench/sm.md)",
);
pub const SLOPE_BIAS: ParamDef = ParamDef::number(
    "slope_bias",
    DEFAULT_SLOPE_BIAS,
    0.0,
    100.0,
    "slope-scaled bias, texels x tan(angle to light), tan clamped at max_slope",
    "shadowlab sweep 2026-11-22: 0 (normal offset covers slopes)",
);
pub const MAX_SLOPE: ParamDef = ParamDef::number(
    "max_slope",
    DEFAULT_MAX_SLOPE,
    0.0,
    1000.0,
    "clamp on tan(angle to light) for the slope bias and the PCF kernel bias; high: leaks under ledges at grazing light",
    "shadowlab sweep 2026-11-22 (2, 4, 10 with pcf=3)",
);
pub const NORMAL_OFFSET: ParamDef = ParamDef::number(
    "normal_offset",
    DEFAULT_NORMAL_OFFSET,
    0.0,
    100.0,
    "offset along the normal, texels; low: grazing acne, high: shifted shadows",
    "Holbert 2011 (normal offset shadows); value from the shadowlab sweep",
);

crate::param_set! {
    /// The bias family as one block: constant, slope-scaled (with its clamp) and normal offset,
    /// in texels of the technique's map.
    pub struct Bias {
        pub bias: f64 = BIAS,
        pub slope_bias: f64 = SLOPE_BIAS,
        pub max_slope: f64 = MAX_SLOPE,
        pub normal_offset: f64 = NORMAL_OFFSET,
    }
}

impl Bias {
    /// `max_slope` clamps only the slope bias and the PCF kernel's bias: with neither
    /// (`slope_bias=0`, `pcf=1`) it does nothing.
    pub fn ineffective(&self, pcf: u32) -> Vec<(&'static str, String)> {
        if self.slope_bias == 0.0 && pcf == 1 {
            vec![("max_slope", "it clamps the slope bias and the PCF kernel's bias, and slope_bias=0, pcf=1".into())]
        } else {
            vec![]
        }
    }

    /// `[bias, slope_bias, normal_offset, max_slope]`, the order of the WGSL `bias` vectors.
    pub fn packed(&self) -> [f32; 4] {
        [self.bias as f32, self.slope_bias as f32, self.normal_offset as f32, self.max_slope as f32]
    }
}
