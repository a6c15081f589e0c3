//! `csm`'s parameters and their defaults, with the rows `sdsm` shares declared once (the cascade
//! maps, the lookup in the chosen cascade; `sdsm`'s own settings are in techniques/sdsm).

use shadowlab_core::params::family;
use shadowlab_core::params::{Block, ParamDef};
use shadowlab_core::techniques::csm::Fit;

/// Cascades. The parameter line and the memory target take the IASM thesis's
/// comparison setting, 3 x 1024 (seed 001 section 4.1: 12 MB at 32 bits), so `csm` with no
/// parameters is the thesis's CSM; leak tracing's 4 cascades are `cascades=4`. Fewer: the far
/// slices get coarse texels; more: one more scene pass each.
pub const DEFAULT_CASCADES: f64 = 3.0;
/// Texels per cascade side (seed 001: 1024).
pub const DEFAULT_RES: f64 = 1024.0;
/// Split blend: `shadowlab_core::techniques::csm::DEFAULT_LAMBDA` (0.85, seed 004's code), written as
/// an f64 literal so that listings show 0.85 rather than the f32's 0.8500000238.
pub const DEFAULT_LAMBDA: f64 = 0.85;
/// Blend band, as a fraction of each slice's depth range at its far end. Off: with hard
/// thresholded visibility a band only moves the switch; with PCF it hides the seam.
pub const DEFAULT_BLEND: f64 = 0.0;
/// Sphere: stable under camera rotation (see docs/bench/csm.md for the quality it costs).
pub const DEFAULT_FIT: f64 = 0.0;
/// Constant bias and normal offset in texels of the chosen cascade: `sm`'s sweep values (the
/// same texel-relative trade-off: low = acne, high = peter-panning / shifted shadows).
pub const DEFAULT_BIAS: f64 = family::DEFAULT_BIAS;
pub const DEFAULT_NORMAL_OFFSET: f64 = family::DEFAULT_NORMAL_OFFSET;

/// The entries `csm` and `sdsm` share (same meaning, same default).
pub const CASCADES: ParamDef = ParamDef::integer(
    "cascades",
    DEFAULT_CASCADES,
    1.0,
    shadowlab_core::techniques::csm::MAX_CASCADES as f64,
    "number of cascades (slices of the view frustum), each one res x res map",
    "seed 001 section 4.1 (3 x 1024); leak tracing uses 4",
);
pub const RES_PARAM: ParamDef = family::RES
    .with_default(DEFAULT_RES, "seed 001 section 4.1")
    .with_range(16.0, 8192.0)
    .with_doc("texels per cascade side; memory = cascades x res^2 x 4 bytes");
pub const BLEND: ParamDef = ParamDef::number(
    "blend",
    DEFAULT_BLEND,
    0.0,
    0.5,
    "blend band between cascades, fraction of a slice; costs a second lookup in the band",
    "common CSM practice; off by default (see docs/bench/csm.md)",
);
pub const BIAS_PARAM: ParamDef = family::BIAS.with_doc("constant depth bias, texels of the chosen cascade; low: acne, high: peter-panning");
pub const NORMAL_OFFSET_PARAM: ParamDef =
    family::NORMAL_OFFSET.with_doc("offset along the normal, texels of the chosen cascade; low: grazing acne, high: shifted shadows");
pub const PCF_PARAM: ParamDef = family::PCF.with_doc("PCF kernel width N (NxN comparisons in the chosen cascade); 1 = hard test");
pub const MAX_SLOPE_PARAM: ParamDef = family::MAX_SLOPE
    .with_doc("clamp on tan(angle to light) for the PCF kernel's receiver-plane bias; high: leaks under ledges at grazing light");

shadowlab_core::param_set! {
    /// The cascade maps `csm` and `sdsm` share: how many, and their side.
    pub struct CascadeMaps {
        pub cascades: u32 = CASCADES,
        pub res: u32 = RES_PARAM,
    }
}

shadowlab_core::param_set! {
    /// The lookup in the chosen cascade that `csm` and `sdsm` share (texels of that cascade).
    pub struct CascadeLookup {
        pub bias: f64 = BIAS_PARAM,
        pub normal_offset: f64 = NORMAL_OFFSET_PARAM,
        pub pcf: u32 = PCF_PARAM,
        pub max_slope: f64 = MAX_SLOPE_PARAM,
    }
    rules {
        fn ineffective(&self) -> Vec<(&'static str, String)> {
            if self.pcf == 1 {
                vec![("max_slope", "it clamps only the PCF kernel's bias, and pcf=1 has no kernel".to_string())]
            } else {
                Vec::new()
            }
        }
    }
}

/// Why `blend` does nothing with `cascades=1` (`csm` and `sdsm`).
pub(crate) const ONE_CASCADE_BLEND: &str = "cascades=1 has no next cascade to blend with";

shadowlab_core::param_choice! {
    /// `csm`'s slice enclosure (`shadowlab_core::techniques::csm::Fit`).
    pub enum CsmFit { Sphere = "sphere", Box = "box" }
}

impl From<CsmFit> for Fit {
    fn from(f: CsmFit) -> Fit {
        match f {
            CsmFit::Sphere => Fit::Sphere,
            CsmFit::Box => Fit::Box,
        }
    }
}

shadowlab_core::param_set! {
    /// `csm`'s parameters.
    pub struct CsmSettings {
        pub maps: CascadeMaps = Block::as_declared(),
        pub lambda: f64 = ParamDef::number("lambda", DEFAULT_LAMBDA, 0.0, 1.0, "practical split blend: 1 logarithmic, 0 uniform; low: coarse near cascade, high: coarse far ones", "Zhang et al. 2006 (PSSM); 0.85 from seed 004's code"),
        pub split1: f64 = ParamDef::number("split1", 0.0, 0.0, 1e6, "manual split distances split1 < split2 < split3 (view depth, scene units; 0 = practical scheme); give cascades-1 of them (manual splits: up to 4 cascades)", "manual partitioning (Engel 2006)"),
        pub split2: f64 = ParamDef::number("split2", 0.0, 0.0, 1e6, "second manual split distance (0 = unused)", "manual partitioning (Engel 2006)"),
        pub split3: f64 = ParamDef::number("split3", 0.0, 0.0, 1e6, "third manual split distance (0 = unused)", "manual partitioning (Engel 2006)"),
        pub blend: f64 = BLEND,
        pub snap: bool = ParamDef::flag("snap", true, "snap each box origin to whole texels in light space (no shimmering while the camera moves)", "Valient 2008 (stable CSM); flicker measured in docs/bench/csm.md"),
        pub fit: CsmFit = ParamDef::choice("fit", CsmFit::NAMES, DEFAULT_FIT as usize, "slice enclosure: sphere (fixed texel size, no shimmer when snapped) or box (tight light-space square: finer texels, size changes as the camera turns)", "Valient 2008 (sphere, stable CSM); box: Engel 2006; measured in docs/bench/csm.md"),
        pub tighten: bool = ParamDef::flag("tighten", true, "split only the [min, max] view depth present in the G-buffer (GPU reduction, read back: one sync)", "Lauritzen et al. 2011 (sample distribution shadow maps)"),
        pub delayed: bool = ParamDef::flag("delayed", false, "with tighten: use the previous frame's depth range (read back without a stall; the first frame splits the whole frustum) instead of this frame's (one sync)", "shadowlab (the recorded-frame seam: a host frame never stalls); measured in docs/bench/recorded_frame.md"),
        pub lookup: CascadeLookup = Block::as_declared(),
    }
    rules {
        /// Manual splits: one fewer than the cascades, increasing.
        fn validate(&self) -> Result<(), String> {
            let manual = self.manual_splits();
            let count = self.maps.cascades as usize;
            if !manual.is_empty() && manual.len() + 1 != count {
                return Err(format!("{} cascades need {} manual split distances (split1..), got {}", count, count - 1, manual.len()));
            }
            for w in manual.windows(2) {
                let ((k0, d0), (k1, d1)) = (w[0], w[1]);
                if d1 <= d0 {
                    return Err(format!("{k1} {d1} must be above {k0} {d0}"));
                }
            }
            Ok(())
        }

        fn ineffective(&self) -> Vec<(&'static str, String)> {
            let mut v = Vec::new();
            if !self.manual_splits().is_empty() {
                v.push(("lambda", "manual splits (split1..) replace the practical scheme".to_string()));
            } else if self.maps.cascades == 1 {
                v.push(("lambda", "cascades=1 has no split to place".to_string()));
            }
            if self.maps.cascades == 1 {
                v.push(("blend", ONE_CASCADE_BLEND.to_string()));
            }
            if !self.tighten {
                v.push(("delayed", "it delays tighten's depth range, and tighten=false".to_string()));
            }
            v.extend(self.lookup.ineffective());
            v
        }
    }
}

impl CsmSettings {
    /// The manual split distances given (`split1..split3` above 0, in order) with their keys.
    pub fn manual_splits(&self) -> Vec<(&'static str, f32)> {
        [("split1", self.split1), ("split2", self.split2), ("split3", self.split3)]
            .into_iter()
            .map(|(k, d)| (k, d as f32))
            .filter(|(_, d)| *d > 0.0)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use shadowlab_core::params::ParamSet;

    use super::*;
    use crate::registry::testing::{err, keys, ok};

    #[test]
    fn csm_lists_its_keys_as_before() {
        assert_eq!(
            keys(CsmSettings::defs()),
            [
                "cascades",
                "res",
                "lambda",
                "split1",
                "split2",
                "split3",
                "blend",
                "snap",
                "fit",
                "tighten",
                "delayed",
                "bias",
                "normal_offset",
                "pcf",
                "max_slope"
            ]
        );
    }

    #[test]
    fn csm_reads_typed_settings_and_checks_its_splits() {
        let s = CsmSettings::from_values(&ok("csm:split2=7,split1=3,fit=box,pcf=3").values);
        assert_eq!(s.manual_splits(), [("split1", 3.0), ("split2", 7.0)]);
        assert_eq!((Fit::from(s.fit), s.lookup.pcf, s.maps.cascades, s.maps.res), (Fit::Box, 3, 3, 1024));
        let d = CsmSettings::defaults();
        assert_eq!((Fit::from(d.fit), d.tighten, d.delayed, d.lambda), (Fit::Sphere, true, false, 0.85));

        let e = err("csm:split1=9,split2=3");
        assert!(e.contains("technique 'csm': split2 3 must be above split1 9"), "{e}");
        let e = err("csm:cascades=4,split1=3");
        assert!(e.contains("4 cascades need 3 manual split distances (split1..), got 1"), "{e}");
        assert!(err("csm:cascades=1,split1=3").contains("1 cascades need 0 manual split distances"));
    }

    #[test]
    fn csm_rejects_keys_without_effect() {
        assert!(err("csm:tighten=false,delayed=true").contains("delayed has no effect"));
        ok("csm:delayed=true");
        assert!(err("csm:split1=4,split2=12,lambda=0.5").contains("lambda has no effect"));
        assert!(err("csm:cascades=1,lambda=0.5").contains("lambda has no effect"));
        ok("csm:lambda=0.5");
        assert!(err("csm:cascades=1,blend=0.1").contains("blend has no effect"));
        ok("csm:blend=0.1");
        assert!(err("csm:max_slope=2").contains("max_slope has no effect"));
        ok("csm:pcf=3,max_slope=2");
    }
}
