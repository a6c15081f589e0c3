//! The typed settings of `rtw`, `notw` and `notw-dv` ([`RtwSettings`], [`NotwSettings`],
//! [`DvSettings`]) and the blocks the warped point-light maps share ([`Subdivision`],
//! [`BiasFootprint`], [`NotwCore`]), declared from the rows of params.rs, with their rules.

use shadowlab_core::params::family::Bias;
use shadowlab_core::params::{Block, ParamDef};

use super::params::*;

/// The bias family in warped texels (warp's docs for the constant bias, the slope bias and the
/// normal offset), with `bias` as the constant bias's row.
fn warped_bias(bias: ParamDef) -> Block {
    Block::as_declared().with(bias).with(SLOPE).with(NORMAL_OFFSET)
}

/// Why a paraboloid map's `depth_clamp` does nothing (depth.wgsl: its exact depth is clamped to
/// the piece's distance range, whatever the clamp).
pub(crate) const PARABOLOID_CLAMP: &str = "a paraboloid map clamps the exact depth to the piece's distance range";

/// `(key, why)` for each of `keys`, all dead for the same reason.
fn dead_keys(keys: &[&'static str], why: &str) -> Vec<(&'static str, String)> {
    keys.iter().map(|k| (*k, why.to_string())).collect()
}

/// The NoTW smoothing window (functions averaged over [i - window/2, i + window/2]) must be
/// below the map side.
fn window_below_res(window: u32, res: u32) -> Result<(), String> {
    if window >= res {
        Err(format!("window {window} must be below res {res}"))
    } else {
        Ok(())
    }
}

shadowlab_core::param_set! {
    /// Subdivision of the triangles before the warped (or paraboloid) depth pass: the bend
    /// threshold and its bounds (levels, capacity, smallest piece).
    pub struct Subdivision {
        /// Warped texels; 0 = off (f32: the uniform's precision decides "off").
        pub subdiv: f32 = SUBDIV,
        pub subdiv_levels: u32 = SUBDIV_LEVELS,
        pub subdiv_capacity: u32 = SUBDIV_CAPACITY,
        pub min_piece: f32 = MIN_PIECE,
        pub depth_split: f32 = DEPTH_SPLIT,
        pub tessellate: u32 = TESSELLATE,
    }
}

impl Subdivision {
    /// Whether the pieces are subdivided at all.
    pub fn on(&self) -> bool {
        self.subdiv > 0.0
    }
    /// On a paraboloid map (`dpsm`, `dpsm-notw`) the bend is judged across the edge only.
    pub(crate) fn paraboloid_dead(&self) -> Vec<(&'static str, String)> {
        if self.on() {
            dead_keys(&["depth_split"], "a paraboloid map's subdivision judges the bend across the edge only")
        } else {
            vec![]
        }
    }
    /// Without subdivision its bounds do nothing.
    pub(crate) fn dead(&self) -> Vec<(&'static str, String)> {
        if self.on() {
            vec![]
        } else {
            dead_keys(&["subdiv_levels", "subdiv_capacity", "min_piece", "depth_split", "tessellate"], "subdiv=0 turns subdivision off")
        }
    }
}

shadowlab_core::param_set! {
    /// How a warped texel's world size, which scales the bias and the normal offset, is taken
    /// from the warp (eval.wgsl; see `DEFAULT_BIAS_MODE`).
    pub struct BiasFootprint {
        pub bias_mode: u32 = BIAS_MODE,
        pub footprint_cap: f32 = FOOTPRINT_CAP,
    }
}

impl BiasFootprint {
    /// On a warped map: only modes 2-4 cap the gradient footprint.
    pub(crate) fn dead(&self) -> Vec<(&'static str, String)> {
        if self.bias_mode < 2 {
            dead_keys(
                &["footprint_cap"],
                &format!("bias_mode={} does not use the capped gradient footprint (modes 2-4 do)", self.bias_mode),
            )
        } else {
            vec![]
        }
    }
    /// What a map without a warp runs with (`notw-dv`, `dpsm`; they declare no footprint):
    /// eval.wgsl sizes every texel as the cropped texel whatever the mode, so the mode is the
    /// isotropic default.
    pub(crate) fn unwarped() -> BiasFootprint {
        BiasFootprint { bias_mode: BIAS_MODE_ISOTROPIC.default as u32, footprint_cap: FOOTPRINT_CAP.default as f32 }
    }
}

shadowlab_core::param_set! {
    /// NoTW's warp on one map, shared by `notw`, `cube-notw` (per face) and `dpsm-notw` (per
    /// hemisphere; they override some defaults): smoothing, counts, subdivision, depth, lookup
    /// and bias.
    pub struct NotwCore {
        pub window: u32 = WINDOW,
        pub blur: u32 = NOTW_BLUR,
        pub mix: f32 = MIX,
        pub interp: bool = INTERP,
        pub subdivision: Subdivision = Block::as_declared().with(NOTW_SUBDIV),
        pub close_cracks: bool = CLOSE_CRACKS,
        pub exact_depth: bool = NOTW_EXACT,
        pub pcf: u32 = PCF,
        pub bias: Bias = warped_bias(NOTW_BIAS),
        pub dv_margin: f32 = DV_MARGIN,
        pub strength: f32 = STRENGTH,
        pub footprint: BiasFootprint = Block::as_declared(),
        pub depth_clamp: u32 = DEPTH_CLAMP,
        pub exact_inverse: bool = EXACT_INVERSE,
    }
}

impl NotwCore {
    /// The rules of the block on a map of side `res`.
    pub(crate) fn validate_at(&self, res: u32) -> Result<(), String> {
        window_below_res(self.window, res)
    }
    /// The keys of the block that do nothing with these values; `paraboloid`: a hemisphere of
    /// `dpsm-notw`, whose exact depth is clamped to the piece's distance range instead.
    pub(crate) fn dead(&self, paraboloid: bool) -> Vec<(&'static str, String)> {
        let mut v = self.subdivision.dead();
        v.extend(self.footprint.dead());
        if paraboloid {
            v.extend(self.subdivision.paraboloid_dead());
            v.extend(dead_keys(&["depth_clamp"], PARABOLOID_CLAMP));
        } else if !self.exact_depth {
            v.extend(dead_keys(&["depth_clamp"], "exact_depth=false"));
        }
        if !self.exact_depth {
            v.extend(dead_keys(&["exact_inverse"], "exact_depth=false"));
        }
        v
    }
}

shadowlab_core::param_set! {
    /// `rtw`'s parameters: RTW's importance and 1D blur, subdivision, depth, lookup and bias.
    pub struct RtwSettings {
        pub res: u32 = RES,
        pub w_dv: f32 = W_DV,
        pub w_eye: f32 = W_EYE,
        pub blur: u32 = BLUR,
        pub interp: bool = INTERP,
        pub subdivision: Subdivision = Block::as_declared(),
        pub close_cracks: bool = CLOSE_CRACKS,
        pub exact_depth: bool = EXACT_DEPTH,
        pub pcf: u32 = PCF,
        pub bias: Bias = warped_bias(BIAS),
        pub dv_margin: f32 = DV_MARGIN,
        pub strength: f32 = STRENGTH,
        pub footprint: BiasFootprint = Block::as_declared().with(BIAS_MODE_ISOTROPIC),
        pub depth_clamp: u32 = DEPTH_CLAMP,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = self.subdivision.dead();
            v.extend(self.footprint.dead());
            if !self.exact_depth {
                v.extend(dead_keys(&["depth_clamp"], "exact_depth=false"));
            }
            v
        }
    }
}

shadowlab_core::param_set! {
    /// `notw`'s parameters: the NoTW block, then hidden-edge culling, the smoothing's tent and
    /// the shadow-edge importance (planar maps only).
    pub struct NotwSettings {
        pub res: u32 = RES,
        pub core: NotwCore = Block::as_declared().with(NOTW_WINDOW).with(NOTW_EXACT_INVERSE).with(NOTW_STRENGTH),
        pub cull_hidden: bool = CULL_HIDDEN,
        pub window_tent: bool = WINDOW_TENT,
        pub edge_importance: u32 = EDGE_IMPORTANCE,
        pub exact_tol: f32 = EXACT_TOL,
    }
    rules {
        fn validate(&self) -> Result<(), String> {
            self.core.validate_at(self.res)
        }
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = self.core.dead(false);
            if !self.core.subdivision.on() {
                v.extend(dead_keys(&["cull_hidden"], "subdiv=0 turns subdivision off"));
            }
            if !self.core.exact_depth {
                v.extend(dead_keys(&["exact_tol"], "exact_depth=false"));
            }
            v
        }
    }
}

shadowlab_core::param_set! {
    /// `notw-dv`'s parameters: the DV crop's map, lookup and bias (no warp, so no footprint
    /// mode; no subdivision, so no exact depth to clamp).
    pub struct DvSettings {
        pub res: u32 = RES,
        pub pcf: u32 = PCF,
        pub bias: Bias = warped_bias(BIAS),
        pub dv_margin: f32 = DV_MARGIN,
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    pub(crate) use crate::registry::testing::{error, set_keys as keys};

    #[test]
    fn the_tables_keep_their_keys_in_order() {
        #[rustfmt::skip]
        let rtw = ["res", "w_dv", "w_eye", "blur", "interp", "subdiv", "subdiv_levels", "subdiv_capacity", "min_piece",
            "depth_split", "tessellate", "close_cracks", "exact_depth", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "dv_margin",
            "strength", "bias_mode", "footprint_cap", "depth_clamp"];
        #[rustfmt::skip]
        let notw = ["res", "window", "blur", "mix", "interp", "subdiv", "subdiv_levels", "subdiv_capacity", "min_piece",
            "depth_split", "tessellate", "close_cracks", "exact_depth", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "dv_margin",
            "strength", "bias_mode", "footprint_cap", "depth_clamp", "exact_inverse", "cull_hidden", "window_tent", "edge_importance",
            "exact_tol"];
        #[rustfmt::skip]
        let dv = ["res", "pcf", "bias", "slope_bias", "max_slope", "normal_offset", "dv_margin"];
        assert_eq!(keys::<RtwSettings>(), rtw);
        assert_eq!(keys::<NotwSettings>(), notw);
        assert_eq!(keys::<DvSettings>(), dv);
    }

    #[test]
    fn the_rules_reject_conflicts_and_dead_keys() {
        assert_eq!(error("notw:window=512"), "technique 'notw': window 512 must be below res 512");
        assert_eq!(error("notw:res=1024,window=512"), "");
        let e = error("notw:subdiv=0,cull_hidden=true");
        assert_eq!(e, "technique 'notw': cull_hidden has no effect: subdiv=0 turns subdivision off");
        assert!(error("notw:subdiv=0,min_piece=1,subdiv_levels=3").contains("subdiv_levels has no effect"));
        assert!(error("rtw:subdiv=0,tessellate=3").contains("tessellate has no effect: subdiv=0"));
        assert!(error("rtw:subdiv=0,subdiv_capacity=64").contains("subdiv_capacity has no effect: subdiv=0"));
        assert!(error("notw:exact_depth=false,exact_inverse=true").contains("exact_inverse has no effect: exact_depth=false"));
        assert!(error("notw:bias_mode=0,footprint_cap=4").contains("footprint_cap has no effect: bias_mode=0"));
        // rtw's exact depth is off by default
        assert!(error("rtw:depth_clamp=1").contains("depth_clamp has no effect: exact_depth=false"));
        assert!(error("notw-dv:bias_mode=2").contains("has no parameter 'bias_mode'"));
        // the same keys where they act, and dead keys left at their defaults
        for ok in [
            "notw:subdiv=0",
            "notw:cull_hidden=true,subdiv_levels=3,min_piece=1",
            "notw:exact_depth=true,exact_inverse=true,depth_clamp=1,footprint_cap=4",
            "notw:depth_split=0.7",
            "rtw:depth_split=2",
            "rtw:exact_depth=true,depth_clamp=1,bias_mode=2,footprint_cap=4",
            "notw-dv:dv_margin=4,pcf=3",
        ] {
            assert_eq!(error(ok), "", "{ok}");
        }
    }
}
