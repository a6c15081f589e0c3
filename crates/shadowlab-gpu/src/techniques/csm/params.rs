//! `csm` parameters and their defaults.

use shadowlab_core::params::family;
use shadowlab_core::params::ParamDef;

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
/// Names of `fit` (index = `shadowlab_core::techniques::csm::Fit` order).
pub const FITS: &[&str] = &["sphere", "box"];
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

pub const PARAMS: &[ParamDef] = &[
    CASCADES,
    RES_PARAM,
    ParamDef::number("lambda", DEFAULT_LAMBDA, 0.0, 1.0, "practical split blend: 1 logarithmic, 0 uniform; low: coarse near cascade, high: coarse far ones", "Zhang et al. 2006 (PSSM); 0.85 from seed 004's code"),
    ParamDef::number("split1", 0.0, 0.0, 1e6, "manual split distances split1 < split2 < split3 (view depth, scene units; 0 = practical scheme); give cascades-1 of them (manual splits: up to 4 cascades)", "manual partitioning (Engel 2006)"),
    ParamDef::number("split2", 0.0, 0.0, 1e6, "second manual split distance (0 = unused)", "manual partitioning (Engel 2006)"),
    ParamDef::number("split3", 0.0, 0.0, 1e6, "third manual split distance (0 = unused)", "manual partitioning (Engel 2006)"),
    BLEND,
    ParamDef::flag("snap", true, "snap each box origin to whole texels in light space (no shimmering while the camera moves)", "Valient 2008 (stable CSM); flicker measured in docs/bench/csm.md"),
    ParamDef::choice("fit", FITS, DEFAULT_FIT as usize, "slice enclosure: sphere (fixed texel size, no shimmer when snapped) or box (tight light-space square: finer texels, size changes as the camera turns)", "Valient 2008 (sphere, stable CSM); box: Engel 2006; measured in docs/bench/csm.md"),
    ParamDef::flag("tighten", true, "split only the [min, max] view depth present in the G-buffer (GPU reduction, read back: one sync)", "Lauritzen et al. 2011 (sample distribution shadow maps)"),
    ParamDef::flag("delayed", false, "with tighten: use the previous frame's depth range (read back without a stall; the first frame splits the whole frustum) instead of this frame's (one sync)", "shadowlab (the recorded-frame seam: a host frame never stalls); measured in docs/bench/recorded_frame.md"),
    BIAS_PARAM,
    NORMAL_OFFSET_PARAM,
    PCF_PARAM,
    MAX_SLOPE_PARAM,
];
