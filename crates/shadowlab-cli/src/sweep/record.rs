//! What a sweep writes, typed: one point file per (setup, spec) (`points/<key>.json`), the
//! rows and plan entries that `sweep.json` ([`super::json::Sweep`]) holds, and the flat
//! `sweep.csv`. Fields are described in docs/sweep.md.

use std::collections::{BTreeMap, BTreeSet};

use serde::{Deserialize, Serialize};
use shadowlab_core::metrics::ErrorMetrics;
use shadowlab_core::params::ParamValues;

/// Version of sweep.json's and the point files' layout; raised with any change to it.
/// 2: `flip_mean` in rows, `mean_flip_mean`/`worst_flip_mean` in aggregates.
pub const SCHEMA_VERSION: u32 = 2;

/// One (spec, setup) result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Row {
    /// The setup's name (setup file stem, or the scene's name).
    pub setup: String,
    /// The setup file's path, or `builtin:<scene>` / the scene file for `--scene`.
    pub setup_source: String,
    pub label: String,
    pub technique: String,
    pub params: ParamValues,
    /// Quality: means over the frames (see docs/metrics.md).
    #[serde(flatten)]
    pub quality: ErrorMetrics,
    /// Mean FLIP (LDR) of the shaded image against `rt`'s, over all pixels; mean over frames.
    pub flip_mean: f64,
    /// Mean over consecutive frames; null with one frame.
    pub flicker_pct: Option<f64>,
    /// The timed frame (median; see `timer` in sweep.json).
    pub total_ms: f64,
    /// Per-stage breakdown (see `stages_timer`); never summed as the total.
    pub stages_ms: BTreeMap<String, f64>,
    /// Pipeline and resource creation (not in total_ms).
    pub setup_ms: f64,
    /// GPU memory the technique keeps per light.
    pub shadow_data_bytes: u64,
    /// Hardware-independent counters of the last frame (`fetches_per_pixel`, `rays_traced`, ...).
    pub counters: BTreeMap<String, f64>,
    /// Capacity limits reached (one line each); empty when the result is complete.
    pub degraded: Vec<String>,
    pub submits_per_frame: u64,
    pub stalls: Vec<String>,
    /// The adapter that computed this point.
    pub adapter: String,
    /// A CPU adapter (lavapipe/llvmpipe): `total_ms` is not a GPU's time.
    pub software_adapter: bool,
    /// Which clock `total_ms` is (`Gpu::timer_name`).
    pub timer: String,
    /// Which clock `stages_ms` are (`Gpu::stages_timer_name`).
    pub stages_timer: String,
    /// The point's cache key (its file `points/<key>.json`).
    pub key: String,
}

/// `points/<key>.json`: one finished point.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointFile {
    pub schema_version: u32,
    pub key: String,
    /// The text whose SHA-256 is the key: what the result depends on.
    pub key_text: String,
    pub row: Row,
}

/// One setup of the sweep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetupInfo {
    pub name: String,
    pub source: String,
    /// `builtin:<name>` or the scene file's path.
    pub scene_source: String,
    pub width: u32,
    pub height: u32,
    /// Labels of its points, in order.
    pub labels: Vec<String>,
}

/// One point of the whole sweep (all shards), in the order that `--shard` counts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlanEntry {
    pub key: String,
    pub setup: String,
    pub label: String,
}

/// `--shard index/count` (1-based index).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

fn quote(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        String::new()
    }
}

/// sweep.csv: one line per row; fixed columns, then `param.<key>`, `counter.<name>` and
/// `stage_ms.<stage>` over the union of all rows (blank where a row has none).
pub fn csv(rows: &[Row]) -> String {
    let union = |f: &dyn Fn(&Row) -> Vec<String>| rows.iter().flat_map(f).collect::<BTreeSet<String>>();
    let params = union(&|r| r.params.0.keys().cloned().collect());
    let counters = union(&|r| r.counters.keys().cloned().collect());
    let stages = union(&|r| r.stages_ms.keys().cloned().collect());
    let mut head: Vec<String> = [
        "setup",
        "label",
        "technique",
        "wrong_pct",
        "false_lit_pct",
        "false_shadow_pct",
        "mae",
        "flip_mean",
        "flicker_pct",
        "evaluated_pixels",
        "total_ms",
        "setup_ms",
        "shadow_data_bytes",
        "submits_per_frame",
        "degraded",
        "adapter",
        "key",
    ]
    .map(String::from)
    .to_vec();
    head.extend(params.iter().map(|k| format!("param.{k}")));
    head.extend(counters.iter().map(|k| format!("counter.{k}")));
    head.extend(stages.iter().map(|k| format!("stage_ms.{k}")));
    let mut s = head.iter().map(|h| quote(h)).collect::<Vec<_>>().join(",") + "\n";
    for r in rows {
        let mut c = vec![
            quote(&r.setup),
            quote(&r.label),
            quote(&r.technique),
            num(r.quality.wrong_pct),
            num(r.quality.false_lit_pct),
            num(r.quality.false_shadow_pct),
            num(r.quality.mae),
            num(r.flip_mean),
            r.flicker_pct.map(num).unwrap_or_default(),
            r.quality.evaluated_pixels.to_string(),
            num(r.total_ms),
            num(r.setup_ms),
            r.shadow_data_bytes.to_string(),
            r.submits_per_frame.to_string(),
            quote(&r.degraded.join("; ")),
            quote(&r.adapter),
            r.key.clone(),
        ];
        c.extend(params.iter().map(|k| r.params.0.get(k).map(|v| quote(&v.to_string())).unwrap_or_default()));
        c.extend(counters.iter().map(|k| r.counters.get(k).map(|v| num(*v)).unwrap_or_default()));
        c.extend(stages.iter().map(|k| r.stages_ms.get(k).map(|v| num(*v)).unwrap_or_default()));
        s += &(c.join(",") + "\n");
    }
    s
}

#[cfg(test)]
pub mod tests {
    use super::*;

    /// A row for tests (pure logic of this module and of `choose`).
    pub fn row(setup: &str, label: &str, wrong: f64, ms: f64, bytes: u64) -> Row {
        Row {
            setup: setup.into(),
            setup_source: format!("builtin:{setup}"),
            label: label.into(),
            technique: label.split(':').next().unwrap().into(),
            params: ParamValues::default(),
            quality: ErrorMetrics {
                wrong_pct: wrong,
                false_lit_pct: wrong / 2.0,
                false_shadow_pct: wrong / 2.0,
                mae: wrong / 100.0,
                evaluated_pixels: 100,
            },
            flip_mean: wrong / 20.0,
            flicker_pct: None,
            total_ms: ms,
            stages_ms: BTreeMap::new(),
            setup_ms: 1.0,
            shadow_data_bytes: bytes,
            counters: BTreeMap::new(),
            degraded: Vec::new(),
            submits_per_frame: 1,
            stalls: Vec::new(),
            adapter: "llvmpipe".into(),
            software_adapter: true,
            timer: "wall".into(),
            stages_timer: "profiled".into(),
            key: "k".into(),
        }
    }

    #[test]
    fn csv_has_one_line_per_row_and_the_union_of_columns() {
        let mut a = row("room", "sm:res=512,pcf=3", 1.5, 2.0, 1024);
        a.counters.insert("fetches_per_pixel".into(), 9.0);
        a.stages_ms.insert("sm.render".into(), 0.5);
        let mut b = row("room", "lt", 0.25, 3.0, 2048);
        b.counters.insert("rays_traced".into(), 10.0);
        b.degraded = vec!["x, y".into()];
        let s = csv(&[a, b]);
        let lines: Vec<&str> = s.lines().collect();
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("setup,label,technique,wrong_pct,false_lit_pct,false_shadow_pct,mae,flip_mean,flicker_pct,"));
        assert!(lines[0].ends_with(",counter.fetches_per_pixel,counter.rays_traced,stage_ms.sm.render"), "{}", lines[0]);
        assert!(lines[1].starts_with("room,\"sm:res=512,pcf=3\",sm,1.5,0.75,0.75,0.015,0.075,,"), "{}", lines[1]);
        assert!(lines[1].ends_with(",9,,0.5"), "{}", lines[1]);
        assert!(lines[2].contains(",\"x, y\",") && lines[2].ends_with(",,10,"), "{}", lines[2]);
    }
}
