//! `csm` parameters and their defaults.

use shadowlab_core::params::{ParamDef, BOOL};

use crate::techniques::sm;

/// Cascades. The parameter line and the memory target take the IASM thesis's
/// comparison setting, 3 x 1024 (seed 001 section 4.1: 12 MB at 32 bits), so `csm` with no
/// parameters is the thesis's CSM; leak tracing's 4 cascades are `cascades=4`. Fewer: the far
/// slices get coarse texels; more: one more scene pass each.
pub const DEFAULT_CASCADES: f64 = 3.0;
/// Texels per cascade side (seed 001: 1024).
pub const DEFAULT_RES: f64 = 1024.0;
/// Split blend: `shadowlab_core::cascades::DEFAULT_LAMBDA` (0.85, seed 004's code), written as
/// an f64 literal so that listings show 0.85 rather than the f32's 0.8500000238.
pub const DEFAULT_LAMBDA: f64 = 0.85;
/// Blend band, as a fraction of each slice's depth range at its far end. Off: with hard
/// thresholded visibility a band only moves the switch; with PCF it hides the seam.
pub const DEFAULT_BLEND: f64 = 0.0;
/// Names of `fit` (index = `shadowlab_core::cascades::Fit` order).
pub const FITS: &[&str] = &["sphere", "box"];
/// Sphere: stable under camera rotation (see docs/bench/csm.md for the quality it costs).
pub const DEFAULT_FIT: f64 = 0.0;
/// Constant bias and normal offset in texels of the chosen cascade: `sm`'s sweep values (the
/// same texel-relative trade-off: low = acne, high = peter-panning / shifted shadows).
pub const DEFAULT_BIAS: f64 = sm::DEFAULT_BIAS;
pub const DEFAULT_NORMAL_OFFSET: f64 = sm::DEFAULT_NORMAL_OFFSET;
/// Clamp on tan(angle to light) for the PCF kernel's receiver-plane bias (as `sm`'s max_slope).
pub const MAX_SLOPE: f32 = sm::MAX_SLOPE.default as f32;

pub const PARAMS: &[ParamDef] = &[
    ParamDef {
        key: "cascades",
        default: DEFAULT_CASCADES,
        min: 1.0,
        max: shadowlab_core::cascades::MAX_CASCADES as f64,
        integer: true,
        doc: "number of cascades (slices of the view frustum), each one res x res map",
        source: "seed 001 section 4.1 (3 x 1024); leak tracing uses 4",
        choices: &[],
    },
    ParamDef {
        key: "res",
        default: DEFAULT_RES,
        min: 16.0,
        max: 8192.0,
        integer: true,
        doc: "texels per cascade side; memory = cascades x res^2 x 4 bytes",
        source: "seed 001 section 4.1",
        choices: &[],
    },
    ParamDef {
        key: "lambda",
        default: DEFAULT_LAMBDA,
        min: 0.0,
        max: 1.0,
        integer: false,
        doc: "practical split blend: 1 logarithmic, 0 uniform; low: coarse near cascade, high: coarse far ones",
        source: "Zhang et al. 2006 (PSSM); 0.85 from seed 004's code",
        choices: &[],
    },
    ParamDef {
        key: "split1",
        default: 0.0,
        min: 0.0,
        max: 1e6,
        integer: false,
        doc: "manual split distances split1 < split2 < split3 (view depth, scene units; 0 = practical scheme); give cascades-1 of them (manual splits: up to 4 cascades)",
        source: "manual partitioning (Engel 2006)",
        choices: &[],
    },
    ParamDef {
        key: "split2",
        default: 0.0,
        min: 0.0,
        max: 1e6,
        integer: false,
        doc: "second manual split distance (0 = unused)",
        source: "manual partitioning (Engel 2006)",
        choices: &[],
    },
    ParamDef {
        key: "split3",
        default: 0.0,
        min: 0.0,
        max: 1e6,
        integer: false,
        doc: "third manual split distance (0 = unused)",
        source: "manual partitioning (Engel 2006)",
        choices: &[],
    },
    ParamDef {
        key: "blend",
        default: DEFAULT_BLEND,
        min: 0.0,
        max: 0.5,
        integer: false,
        doc: "blend band between cascades, fraction of a slice; costs a second lookup in the band",
        source: "common CSM practice; off by default (see docs/bench/csm.md)",
        choices: &[],
    },
    ParamDef {
        key: "snap",
        default: 1.0,
        min: 0.0,
        max: 1.0,
        integer: true,
        doc: "snap each box origin to whole texels in light space (no shimmering while the camera moves)",
        source: "Valient 2008 (stable CSM); flicker measured in docs/bench/csm.md",
        choices: BOOL,
    },
    ParamDef {
        key: "fit",
        default: DEFAULT_FIT,
        min: 0.0,
        max: 1.0,
        integer: true,
        doc: "slice enclosure: sphere (fixed texel size, no shimmer when snapped) or box (tight light-space square: finer texels, size changes as the camera turns)",
        source: "Valient 2008 (sphere, stable CSM); box: Engel 2006; measured in docs/bench/csm.md",
        choices: FITS,
    },
    ParamDef {
        key: "tighten",
        default: 1.0,
        min: 0.0,
        max: 1.0,
        integer: true,
        doc: "split only the [min, max] view depth present in the G-buffer (GPU reduction, read back: one sync)",
        source: "Lauritzen et al. 2011 (sample distribution shadow maps)",
        choices: BOOL,
    },
    ParamDef {
        key: "delayed",
        default: 0.0,
        min: 0.0,
        max: 1.0,
        integer: true,
        doc: "with tighten: use the previous frame's depth range (read back without a stall; the first frame splits the whole frustum) instead of this frame's (one sync)",
        source: "shadowlab (the recorded-frame seam: a host frame never stalls); measured in docs/bench/recorded_frame.md",
        choices: BOOL,
    },
    ParamDef {
        key: "bias",
        default: DEFAULT_BIAS,
        min: 0.0,
        max: 100.0,
        integer: false,
        doc: "constant depth bias, texels of the chosen cascade; low: acne, high: peter-panning",
        source: "sm's sweep (BENCHMARKS.md)",
        choices: &[],
    },
    ParamDef {
        key: "normal_offset",
        default: DEFAULT_NORMAL_OFFSET,
        min: 0.0,
        max: 100.0,
        integer: false,
        doc: "offset along the normal, texels of the chosen cascade; low: grazing acne, high: shifted shadows",
        source: "Holbert 2011; value from sm's sweep",
        choices: &[],
    },
    ParamDef {
        key: "pcf",
        default: 1.0,
        min: 1.0,
        max: 7.0,
        integer: true,
        doc: "PCF kernel width N (NxN comparisons in the chosen cascade); 1 = hard test",
        source: "Reeves et al. 1987; kernel bias: Isidoro 2006",
        choices: &[],
    },
];
