//! Summaries of a path run's per-frame records ([`super::path`]): quality figures are means over
//! all frames, flicker the mean over consecutive pairs, times medians over frames 1.. (frame 0
//! is the warm-up; with one frame, its own median over the repetitions).

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use shadowlab_core::metrics::ErrorMetrics;

use super::path::{FrameRecord, ReferenceFrame};
use crate::timing::median;

/// Top-level figures of a technique over its frames.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Means over the frames (evaluated pixels rounded).
    #[serde(flatten)]
    pub quality: ErrorMetrics,
    /// Mean FLIP, the mean over the frames of each frame's image mean.
    pub flip_mean: f64,
    pub rays_traced: Option<f64>,
    /// Mean over consecutive pairs; None with one frame.
    pub flicker_pct: Option<f64>,
    pub total_ms: f64,
    pub stages_ms: BTreeMap<String, f64>,
}

fn mean(v: impl Iterator<Item = f64>) -> Option<f64> {
    let (mut s, mut n) = (0.0, 0usize);
    for x in v {
        s += x;
        n += 1;
    }
    (n > 0).then(|| s / n as f64)
}

/// The frames that are timed: 1.. (frame 0 is the warm-up), or the single frame.
fn timed<T>(frames: &[T]) -> &[T] {
    if frames.len() > 1 {
        &frames[1..]
    } else {
        frames
    }
}

/// Means of the quality figures over all frames; times: medians over frames 1.. (frame 0 is
/// the warm-up; with one frame, its own median over the repetitions).
pub fn summarize(frames: &[FrameRecord]) -> Summary {
    let q = |f: fn(&FrameRecord) -> f64| mean(frames.iter().map(f)).unwrap_or(0.0);
    let timed = timed(frames);
    let mut stages: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in timed {
        for (k, v) in &r.stages_ms {
            stages.entry(k.clone()).or_default().push(*v);
        }
    }
    Summary {
        quality: ErrorMetrics {
            wrong_pct: q(|r| r.quality.wrong_pct),
            false_lit_pct: q(|r| r.quality.false_lit_pct),
            false_shadow_pct: q(|r| r.quality.false_shadow_pct),
            mae: q(|r| r.quality.mae),
            evaluated_pixels: q(|r| r.quality.evaluated_pixels as f64).round() as u64,
        },
        flip_mean: q(|r| r.flip_mean),
        rays_traced: if frames.iter().all(|r| r.rays_traced.is_some()) { mean(frames.iter().filter_map(|r| r.rays_traced)) } else { None },
        flicker_pct: mean(frames.iter().filter_map(|r| r.flicker_pct)),
        total_ms: median(&timed.iter().map(|r| r.total_ms).collect::<Vec<_>>()),
        stages_ms: stages.into_iter().map(|(k, v)| (k, median(&v))).collect(),
    }
}

/// The reference's time: its median over frames 1.. (or its single frame's median).
pub fn reference_total_ms(frames: &[ReferenceFrame]) -> f64 {
    median(&timed(frames).iter().map(|r| r.total_ms).collect::<Vec<_>>())
}

#[cfg(test)]
mod tests {
    use super::*;
    fn rec(frame: usize, wrong: f64, ms: f64, flicker: Option<f64>) -> FrameRecord {
        FrameRecord {
            frame,
            quality: ErrorMetrics {
                wrong_pct: wrong,
                false_lit_pct: wrong,
                false_shadow_pct: 0.0,
                mae: wrong / 100.0,
                evaluated_pixels: 100,
            },
            flip_mean: wrong / 10.0,
            rays_traced: None,
            edge_pixels: 3,
            flicker_pct: flicker,
            total_ms: ms,
            stages_ms: BTreeMap::from([("a".to_string(), ms)]),
        }
    }
    #[test]
    fn summary_means_quality_and_medians_times_after_the_warm_up() {
        let s =
            summarize(&[rec(0, 1.0, 100.0, None), rec(1, 2.0, 5.0, Some(1.0)), rec(2, 3.0, 7.0, Some(3.0)), rec(3, 6.0, 6.0, Some(2.0))]);
        assert_eq!(s.quality.wrong_pct, 3.0);
        assert!((s.flip_mean - 0.3).abs() < 1e-12, "FLIP is a mean over all frames");
        assert_eq!(s.flicker_pct, Some(2.0));
        assert_eq!(s.total_ms, 6.0, "frame 0 (100 ms warm-up) is not timed");
        assert_eq!(s.stages_ms["a"], 6.0);
        assert_eq!(s.rays_traced, None);
        // the flattened figures sit at the record's top level, and an unknown field is refused
        let json = serde_json::to_value(&s).unwrap();
        assert_eq!(json["wrong_pct"], 3.0);
        assert_eq!(serde_json::from_value::<Summary>(json.clone()).unwrap(), s);
        let r = rec(0, 1.0, 2.0, None);
        let mut v = serde_json::to_value(&r).unwrap();
        assert_eq!(serde_json::from_value::<FrameRecord>(v.clone()).unwrap(), r);
        v["wrong_pcnt"] = 1.0.into();
        assert!(serde_json::from_value::<FrameRecord>(v).is_err(), "deny_unknown_fields still holds with the flattened figures");
        let one = summarize(&[rec(0, 4.0, 9.0, None)]);
        assert_eq!((one.quality.wrong_pct, one.total_ms, one.flicker_pct), (4.0, 9.0, None));
    }
    #[test]
    fn reference_time_skips_the_warm_up_frame() {
        let r = |frame, total_ms| ReferenceFrame {
            frame,
            time: frame as f32,
            evaluated_pixels: 1,
            edge_pixels: 0,
            rays_traced: None,
            total_ms,
        };
        assert_eq!(reference_total_ms(&[r(0, 50.0), r(1, 2.0), r(2, 4.0)]), 3.0);
        assert_eq!(reference_total_ms(&[r(0, 50.0)]), 50.0);
    }
}
