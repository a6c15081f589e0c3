//! metrics.json, typed: what `compare` writes and what the CSV, the terminal summary and the
//! HTML report read. Every field is documented in docs/metrics.md and checked against
//! docs/metrics.schema.json by the CLI tests; [`SCHEMA_VERSION`] changes with any change to it.

mod csv;
mod text;

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};
use shadowlab_core::anim::Motion;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::metrics::{ErrorMetrics, SamplingStats};
use shadowlab_core::params::ParamValues;
use shadowlab_core::scene::LoadReport;
use shadowlab_gpu::lab::{FrameRecord, ReferenceFrame};

pub use csv::csv;
pub use text::{summary, warnings};

/// Version of metrics.json's layout (also in the output marker, [`crate::output::MARKER`]):
/// raised when a field is renamed, removed or changes meaning; added fields raise it too, since
/// the schema is strict.
/// 2: `flip_mean` per technique and frame, `images.flip`.
/// 3: `warnings` (a view with no evaluated pixels says so).
pub const SCHEMA_VERSION: u32 = 3;

/// Milliseconds per named stage (`<technique>.<stage>`).
pub type StagesMs = BTreeMap<String, f64>;

/// The whole metrics.json of one `compare` run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Metrics {
    pub schema_version: u32,
    pub scene: String,
    /// `builtin:<name>` or the scene file's path.
    pub scene_source: String,
    /// The user's transform applied on load (up axis, scale, offset), row-major.
    pub scene_transform: [[f32; 4]; 4],
    pub triangles: usize,
    pub has_cutouts: bool,
    pub load_report: LoadReport,
    /// Frame 0's camera (the configured one).
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub light_index: usize,
    pub width: u32,
    pub height: u32,
    pub adapter: String,
    /// Which clock `total_ms` is (see `Gpu::timer_name`).
    pub timer: String,
    /// Which clock the `stages_ms` are.
    pub stages_timer: String,
    pub repeat: usize,
    pub animation: Animation,
    pub bvh: Bvh,
    /// The G-buffer + mask frame of the last view (one submit, one wait).
    pub gbuffer_ms: f64,
    pub gbuffer_stages_ms: StagesMs,
    pub frames: usize,
    /// One camera per frame.
    pub cameras: Vec<Camera>,
    pub reference: Reference,
    pub techniques: Vec<Technique>,
    /// Peak resident memory of the process (MiB; null where /proc is unavailable).
    pub peak_rss_mib: Option<f64>,
    /// What makes the figures mean less than they seem (frames with no evaluated pixels);
    /// printed as `warning:` lines too.
    pub warnings: Vec<String>,
}

/// The run's warnings: frames whose view has no evaluated pixels (nothing lit and in view, so
/// every quality figure of that frame compares nothing).
pub fn run_warnings(reference: &[ReferenceFrame]) -> Vec<String> {
    let empty: Vec<usize> = reference.iter().filter(|f| f.evaluated_pixels == 0).map(|f| f.frame).collect();
    let what = "no evaluated pixels (no geometry in view faces the light, or it is outside the spot cone)";
    match empty.len() {
        0 => vec![],
        n if n == reference.len() && n == 1 => vec![format!("the view has {what}: every quality figure compares nothing")],
        n if n == reference.len() => vec![format!("all {n} frames have {what}: every quality figure compares nothing")],
        n => {
            let shown: Vec<String> = empty.iter().take(8).map(|f| f.to_string()).collect();
            let more = if n > 8 { ", ..." } else { "" };
            vec![format!("{n} of {} frames have {what} (frames {}{more}); the means count them as 0 %", reference.len(), shown.join(", "))]
        }
    }
}

/// Moving objects: how many triangles move (0 = a still scene), which, how, and the times.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Animation {
    pub dynamic_triangles: usize,
    /// First moving triangle on the GPU.
    pub dynamic_first: u32,
    /// Always `frames`.
    pub time_unit: String,
    pub start_time: f32,
    pub animations: Vec<AnimatedObject>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnimatedObject {
    pub name: String,
    pub triangles: usize,
    pub motion: Motion,
}

/// The reference's BVH.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bvh {
    /// GPU buffers of the BVH (nodes and triangle order).
    pub gpu_bytes: usize,
    pub nodes: usize,
    /// CPU-side size of the BVH.
    pub bytes: usize,
    pub bytes_per_triangle: f64,
    pub depth: usize,
    pub build_ms: f64,
}

/// The reference `rt`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Always `rt`.
    pub label: String,
    /// Of the last frame.
    pub evaluated_pixels: usize,
    /// Of the last frame.
    pub edge_pixels: u64,
    pub stages_ms: StagesMs,
    /// Median over frames 1.. (one frame: over its repetitions).
    pub total_ms: f64,
    /// The last frame's counters (`rays_traced`, ...).
    pub counters: BTreeMap<String, f64>,
    pub frames: Vec<ReferenceFrame>,
}

/// One technique spec over the frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Technique {
    pub label: String,
    pub technique: String,
    pub params: ParamValues,
    /// Means over the frames (docs/metrics.md).
    #[serde(flatten)]
    pub quality: ErrorMetrics,
    /// Mean FLIP (LDR) of the shaded image against `rt`'s, over all pixels; mean over frames.
    pub flip_mean: f64,
    pub flicker_pct: Option<f64>,
    pub shadow_data_bytes: u64,
    pub stages_ms: StagesMs,
    pub total_ms: f64,
    pub submits_per_frame: u64,
    pub stalls: Vec<String>,
    pub setup_ms: f64,
    pub counters: BTreeMap<String, f64>,
    pub sampling: Option<SamplingStats>,
    /// Where the technique reached a capacity limit and gave a coarser, deterministic result
    /// (one line each, with its counters); empty when complete.
    pub degraded: Vec<String>,
    pub images: Images,
    pub visibility_npy: Option<String>,
    pub frames: Vec<FrameRecord>,
}

/// A technique's pictures (paths relative to the output directory).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Images {
    pub shaded: String,
    pub error: String,
    pub error_split: String,
    /// The last frame's FLIP error map against `rt` (magma colour map).
    pub flip: String,
    pub extra: Vec<ExtraImage>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExtraImage {
    pub name: String,
    pub file: String,
}

impl Metrics {
    /// The JSON text of metrics.json: keys in alphabetical order at every level (as the
    /// untyped writer had them), two-space indentation.
    pub fn to_json(&self) -> serde_json::Result<String> {
        serde_json::to_string_pretty(&serde_json::to_value(self)?)
    }

    pub fn light(&self) -> Option<&Light> {
        self.lights.get(self.light_index)
    }
}

#[cfg(test)]
pub mod sample;
