//! Leak tracing's parameter tables (`lt`, `ltt`, `hybrid-pcf`), the three modes and the
//! [`Variant`] a `LeakTracing` is made from.

use shadowlab_core::params::{family, Block, ParamDef};
use shadowlab_core::techniques::filtered as cpu;
use shadowlab_core::techniques::lt as leak;

use super::uniforms::MAX_LEVELS;
use crate::techniques::filtered::Kind;

/// Which of the three techniques (`mode.x` in classify.wgsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Lt = 0,
    Ltt = 1,
    HybridPcf = 2,
}

impl Mode {
    pub fn name(self) -> &'static str {
        ["lt", "ltt", "hybrid-pcf"][self as usize]
    }
}

/// Reprojection depth tolerance, relative to the view depth. Too low: sloped surfaces seen at
/// grazing angles fail (the reprojected pixel centre lies elsewhere on the slope) and trace
/// rays every frame; too high: disocclusions reuse the occluder's mask.
pub const DEFAULT_DEPTH_TOL: f64 = 0.05;
/// Reprojection normal test: minimum cosine between this and last frame's normal. Too high:
/// curved surfaces fail; too low: creases reuse the other face's mask.
pub const DEFAULT_NORMAL_COS: f64 = 0.9;
/// `hybrid-pcf` bias: `sm`'s defaults (constant 0.5 texel, normal offset 0.5 texel, the
/// shadowlab sweep). Too low: acne becomes rays (not wrong, but slow); too high: the unanimous
/// 2x2 test misses thin lit gaps (wrong pixels).
pub const DEFAULT_PCF_BIAS: f64 = 0.5;
pub const DEFAULT_PCF_NORMAL_OFFSET: f64 = 0.5;

/// Map side per cascade: the authors' 2048 (seed 004 section 4). Measured (docs/bench/lt.md,
/// 1024x1024, foliage / sponza paths): 512 -> 2048 lowers the wrong pixels 0.078 -> 0.022 % /
/// 0.013 -> 0.007 % and the rays by 26 % / 34 % at about the same time (the cascades are
/// re-rendered rarely), for 48 MiB of maps instead of 3. Too low: wide uncertain bands (rays)
/// and sub-texel casters missing from the map (wrong pixels the mask cannot find).
pub const DEFAULT_RES: f64 = 2048.0;
const RES: ParamDef = family::RES.with_default(DEFAULT_RES, "seed 004 section 4 (2048 per cascade); shadowlab measurement (docs/bench/lt.md)").with_doc("shadow map side (texels, per cascade / spot map / cube face); low: more rays (wider uncertain bands) and missed thin occluders/gaps");
/// `base`'s names are filtered's [`Kind`], in the order of the shaders' mode numbers.
const BASE: ParamDef = ParamDef::choice(
    "base",
    Kind::NAMES,
    2,
    "filterable representation rebuilt from the gathered depths: vsm, esm, evsm, msm",
    "seed 004 section 4.1 (EVSM fastest, VSM close; ESM/MSM need more rays)",
);
const EPS: ParamDef = ParamDef::number(
    "eps",
    leak::DEFAULT_EPS,
    0.0,
    0.5,
    "LTT epsilon: a ray where eps < s < 1-eps; low: bound noise becomes rays, high: misses leaks (0.5: no LTT rays)",
    "seed 004 eq. 3 (0.01)",
);
/// Remove rays off by default: measured on camera paths (courtyard and foliage, 256x256, 12
/// frames, docs/bench/lt.md) RR removed 10-20 % of the rays but raised the wrong pixels after
/// frame 8 from 0.003 % to 0.11 % (courtyard) and 0.18 % to 0.30 % (foliage), at no measurable
/// time gain. The paper uses it (1.05x speed-up, seed 004 table 3).
pub const DEFAULT_RR: bool = false;
const RR: ParamDef = ParamDef::flag(
    "rr",
    DEFAULT_RR,
    "remove rays (eq. 8) where all reprojected neighbours confirmed the shadow test (removed rays snap to the test); on: fewer rays, edges that move under the camera can be lost",
    "seed 004 section 3.1.2 (on); default off: shadowlab measurement (docs/bench/lt.md)",
);
const REUSE: ParamDef = ParamDef::flag(
    "reuse",
    true,
    "reuse the static maps: a cascade's enlarged map until its slice leaves it, the whole-scene/spot map forever (fixed light); off: every map refitted and re-rendered each frame",
    "seed 004 sections 3.3-3.4",
);
const FULL: ParamDef = ParamDef::flag(
    "full",
    false,
    "full 3x3 neighbourhood every frame instead of the jittered 2x2 that covers 3x3 over 4 frames",
    "seed 004 section 3.1.1 (2x2 jitter as good, cheaper)",
);
const HISTORY_TEST: ParamDef = ParamDef::flag(
    "history_test",
    true,
    "reprojection also fails (forcing a ray) where last frame's depth or normal differs (disocclusion); includes section 3.1.2's temporal depth test; off: only off-screen fails",
    "seed 004 sections 3.1 and 3.1.2 (temporal depth test)",
);
const DEPTH_TOL: ParamDef = ParamDef::number(
    "depth_tol",
    DEFAULT_DEPTH_TOL,
    0.0,
    1.0,
    "relative view-depth tolerance of the reprojection test; low: rays on grazing surfaces, high: disocclusions reuse stale bits",
    "shadowlab choice (not in the paper)",
);
const NORMAL_COS: ParamDef = ParamDef::number(
    "normal_cos",
    DEFAULT_NORMAL_COS,
    -1.0,
    1.0,
    "minimum cosine between current and last frame's normal in the reprojection test",
    "shadowlab choice (not in the paper)",
);
/// `shadowlab_core::techniques::csm::DEFAULT_LAMBDA` (an f32) as written: the authors' 0.85.
pub const DEFAULT_LAMBDA: f64 = 0.85;
const CASCADES: ParamDef = ParamDef::integer(
    "cascades",
    4.0,
    1.0,
    (MAX_LEVELS + 1) as f64,
    "directional lights: cascades, the last one ray traced (1 = one map over the whole scene, no ray-traced level)",
    "seed 004 section 4 (4 cascades, levels 0-2 hybrid, the last ray traced)",
);
const LAMBDA: ParamDef = ParamDef::number(
    "lambda",
    DEFAULT_LAMBDA,
    0.0,
    1.0,
    "practical split blend (1 = logarithmic); low: coarse near cascade, high: far cascades coarse and the ray-traced one large",
    "seed 004's code (0.85 log + 0.15 uniform)",
);
const ENLARGE: ParamDef = ParamDef::number(
    "enlarge",
    leak::DEFAULT_ENLARGE,
    0.0,
    1.0,
    "cascade box enlargement for reuse; low: re-rendered on small moves, high: coarser texels",
    "seed 004 section 3.3 (15 %)",
);
const FORCE_ALL: ParamDef =
    ParamDef::flag("force_all", false, "trace a ray for every evaluated pixel (equals rt; for tests)", "shadowlab test switch");
const MIN_VARIANCE: ParamDef = ParamDef::number(
    "min_variance",
    cpu::DEFAULT_MIN_VARIANCE,
    0.0,
    1.0,
    "VSM/EVSM minimum variance (depth units^2)",
    "seed 004 section 4 (1e-10)",
);
const ESM_C: ParamDef = ParamDef::number("c", cpu::DEFAULT_ESM_C, 0.0, 88.0, "ESM exponent", "seed 004 section 4 (80)");
const C_POS: ParamDef =
    ParamDef::number("c_pos", cpu::DEFAULT_EVSM_C_POS, 0.0, 42.0, "EVSM positive exponent (depth in [-1,1])", "seed 004 section 4 (20)");
const C_NEG: ParamDef =
    ParamDef::number("c_neg", cpu::DEFAULT_EVSM_C_NEG, 0.0, 42.0, "EVSM negative exponent (depth in [-1,1])", "seed 004 section 4 (5)");
const MOMENT_BIAS: ParamDef =
    ParamDef::number("moment_bias", cpu::DEFAULT_MOMENT_BIAS, 0.0, 1.0, "MSM moment bias", "seed 004 section 4 (3e-6)");
const PCF_BIAS: ParamDef = family::BIAS
    .with_default(DEFAULT_PCF_BIAS, "sm's default (shadowlab sweep); seed 004 section 4.2: HySM needs a tuned bias")
    .with_doc("constant depth bias (texels); low: acne turns into rays, high: lit gaps missed");
const PCF_NORMAL_OFFSET: ParamDef =
    family::NORMAL_OFFSET.with_default(DEFAULT_PCF_NORMAL_OFFSET, "sm's default (shadowlab sweep)").with_doc("normal offset (texels)");

shadowlab_core::param_set! {
    /// The map levels all three techniques share: the map side and, for directional lights,
    /// the cascades.
    pub struct MapLevels {
        pub res: u32 = RES,
        pub cascades: u32 = CASCADES,
        pub lambda: f64 = LAMBDA,
        pub enlarge: f64 = ENLARGE,
    }
}

impl MapLevels {
    /// `lambda` and `enlarge` where they do nothing: one map (no cascades), or (`enlarge`)
    /// cascades refitted every frame (no reuse).
    fn ineffective_with(&self, reuse: bool) -> Vec<(&'static str, String)> {
        if self.cascades == 1 {
            let why = "cascades=1 is one map over the whole scene (no cascades)";
            vec![("lambda", why.into()), ("enlarge", why.into())]
        } else if !reuse {
            vec![("enlarge", "reuse=false refits the cascade boxes every frame (nothing kept to enlarge)".into())]
        } else {
            Vec::new()
        }
    }
}

shadowlab_core::param_set! {
    /// The shape of the filterable base (`lt`, `ltt`): each base reads some of them.
    pub struct Moments {
        pub min_variance: f64 = MIN_VARIANCE,
        pub c: f64 = ESM_C,
        pub c_pos: f64 = C_POS,
        pub c_neg: f64 = C_NEG,
        pub moment_bias: f64 = MOMENT_BIAS,
    }
}

impl Moments {
    /// The keys `base` does not read (classify.wgsl's `visibility_gather_of`).
    fn unread_by(base: Kind) -> Vec<(&'static str, String)> {
        let readers: [(&'static str, &[Kind], &str); 5] = [
            ("min_variance", &[Kind::Vsm, Kind::Evsm], "vsm and evsm"),
            ("c", &[Kind::Esm], "esm"),
            ("c_pos", &[Kind::Evsm], "evsm"),
            ("c_neg", &[Kind::Evsm], "evsm"),
            ("moment_bias", &[Kind::Msm], "msm"),
        ];
        readers
            .into_iter()
            .filter(|(_, by, _)| !by.contains(&base))
            .map(|(key, _, names)| (key, format!("base={} does not read it (only {names})", base.name())))
            .collect()
    }
}

shadowlab_core::param_set! {
    /// `lt`'s parameters: the filterable base, LTT and the temporal mask.
    pub struct LtSettings {
        pub map: MapLevels = Block::as_declared(),
        pub base: Kind = BASE,
        pub eps: f64 = EPS,
        pub rr: bool = RR,
        pub reuse: bool = REUSE,
        pub full: bool = FULL,
        pub history_test: bool = HISTORY_TEST,
        pub depth_tol: f64 = DEPTH_TOL,
        pub normal_cos: f64 = NORMAL_COS,
        pub force_all: bool = FORCE_ALL,
        pub moments: Moments = Block::as_declared(),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = self.map.ineffective_with(self.reuse);
            if !self.history_test {
                let why = "history_test=false does no depth or normal test";
                v.extend([("depth_tol", why.into()), ("normal_cos", why.into())]);
            }
            v.extend(Moments::unread_by(self.base));
            v
        }
    }
}

shadowlab_core::param_set! {
    /// `ltt`'s parameters: `lt`'s without the temporal mask.
    pub struct LttSettings {
        pub map: MapLevels = Block::as_declared(),
        pub base: Kind = BASE,
        pub eps: f64 = EPS,
        pub reuse: bool = REUSE,
        pub force_all: bool = FORCE_ALL,
        pub moments: Moments = Block::as_declared(),
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = self.map.ineffective_with(self.reuse);
            v.extend(Moments::unread_by(self.base));
            v
        }
    }
}

shadowlab_core::param_set! {
    /// `hybrid-pcf`'s parameters: no filterable base, the plain map's bias instead.
    pub struct HybridSettings {
        pub map: MapLevels = Block::as_declared(),
        pub reuse: bool = REUSE,
        pub force_all: bool = FORCE_ALL,
        pub bias: f64 = PCF_BIAS,
        pub normal_offset: f64 = PCF_NORMAL_OFFSET,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            self.map.ineffective_with(self.reuse)
        }
    }
}

/// One of the three techniques with its settings, as `LeakTracing::new` takes it.
#[derive(Clone, Debug, PartialEq)]
pub enum Variant {
    Lt(LtSettings),
    Ltt(LttSettings),
    HybridPcf(HybridSettings),
}

impl Variant {
    pub fn mode(&self) -> Mode {
        match self {
            Variant::Lt(_) => Mode::Lt,
            Variant::Ltt(_) => Mode::Ltt,
            Variant::HybridPcf(_) => Mode::HybridPcf,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{HybridSettings, LtSettings, LttSettings};
    use crate::registry::testing::{check as resolve, set_keys as keys};

    /// The tables as listed before the typed sets (`shadowlab techniques`).
    #[test]
    fn tables_keep_their_rows_in_order() {
        let lt = [
            "res",
            "cascades",
            "lambda",
            "enlarge",
            "base",
            "eps",
            "rr",
            "reuse",
            "full",
            "history_test",
            "depth_tol",
            "normal_cos",
            "force_all",
            "min_variance",
            "c",
            "c_pos",
            "c_neg",
            "moment_bias",
        ];
        assert_eq!(keys::<LtSettings>(), lt);
        let ltt = [
            "res",
            "cascades",
            "lambda",
            "enlarge",
            "base",
            "eps",
            "reuse",
            "force_all",
            "min_variance",
            "c",
            "c_pos",
            "c_neg",
            "moment_bias",
        ];
        assert_eq!(keys::<LttSettings>(), ltt);
        assert_eq!(keys::<HybridSettings>(), ["res", "cascades", "lambda", "enlarge", "reuse", "force_all", "bias", "normal_offset"]);
    }

    #[test]
    fn keys_without_effect_are_reported() {
        for (spec, key) in [
            ("lt:base=vsm,c_pos=30", "c_pos"),
            ("lt:base=vsm,c=30", "c"),
            ("lt:base=vsm,moment_bias=0.001", "moment_bias"),
            ("lt:base=esm,min_variance=0.001", "min_variance"),
            ("lt:c_neg=3,base=msm", "c_neg"),
            ("lt:c=30", "c"),
            ("lt:moment_bias=0.001", "moment_bias"),
            ("ltt:base=msm,min_variance=0.001", "min_variance"),
            ("ltt:base=evsm,c=70", "c"),
            ("lt:history_test=false,depth_tol=0.1", "depth_tol"),
            ("lt:history_test=false,normal_cos=0.5", "normal_cos"),
            ("lt:cascades=1,lambda=0.5", "lambda"),
            ("ltt:cascades=1,enlarge=0.2", "enlarge"),
            ("hybrid-pcf:reuse=false,enlarge=0.2", "enlarge"),
            ("hybrid-pcf:cascades=1,lambda=0.5", "lambda"),
        ] {
            let e = resolve(spec).expect_err(spec);
            assert!(e.starts_with(&format!("technique '{}': ", &spec[..spec.find(':').unwrap()])), "{spec}: {e}");
            assert!(e.contains(&format!("{key} has no effect")), "{spec}: {e}");
        }
        let e = resolve("lt:base=vsm,c_pos=30").unwrap_err();
        assert!(e.contains("c_pos has no effect: base=vsm"), "{e}");
        // one reason per key, however many make it dead
        let e = resolve("lt:cascades=1,reuse=false,enlarge=0.2").unwrap_err();
        assert_eq!(e.matches("enlarge has no effect").count(), 1, "{e}");
        for spec in [
            "lt",
            "lt:base=vsm,min_variance=0.001",
            "lt:base=esm,c=70",
            "lt:c_pos=30,c_neg=3,min_variance=1e-9",
            "lt:base=msm,moment_bias=0.001",
            "ltt:base=esm,c=70,eps=0.02",
            "lt:history_test=true,depth_tol=0.1,normal_cos=0.5",
            // dead keys not given are not reported
            "lt:base=vsm,history_test=false,cascades=1,reuse=false",
            "lt:cascades=2,lambda=0.5,enlarge=0.2",
            "lt:reuse=false,lambda=0.5",
            "hybrid-pcf:bias=1,normal_offset=1,cascades=3",
        ] {
            resolve(spec).unwrap_or_else(|e| panic!("{spec}: {e}"));
        }
    }
}
