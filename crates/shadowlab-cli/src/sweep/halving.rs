//! Successive halving for `shadowlab tune --search halving`: every candidate is judged on a
//! cheap rung (a smaller output size on the same train setups), the best 1/eta go on to the
//! next rung at twice the width and height, until the last rung at the full size. Pure
//! functions: the schedule and the selection; `tune` runs the rungs as sweeps.

use anyhow::{bail, Result};
use clap::ValueEnum;
use serde::Serialize;

/// Keep the best 1/eta of the candidates per rung (the side doubles per rung, so a rung has
/// 1/eta of the candidates at 4x the pixels of the one before). Source: Jamieson and Talwalkar
/// 2016 (successive halving, eta = 2); higher: fewer points but more risk of dropping the best
/// candidate on a small, noisy rung.
pub const DEFAULT_ETA: usize = 2;
/// The smallest side a rung is given when the rung count is automatic: below it the shadow
/// edges are a few pixels and the ranking is mostly noise (shadowlab choice).
pub const MIN_RUNG_SIDE: u32 = 32;
/// The full size of halving's last rung when `--size` is not given (the seeds' evaluation size).
pub const DEFAULT_FULL_SIZE: (u32, u32) = (1024, 1024);

/// What a candidate is ranked by (lower is better).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// mean wrong % (thresholded visibility against `rt`)
    #[default]
    Wrong,
    /// mean FLIP (perceptual difference of the shaded images)
    Flip,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Search {
    /// every grid point at the full size
    #[default]
    Grid,
    /// successive halving over output-size rungs
    Halving,
}

/// The output size of each rung, smallest first; the last is `full`. `rungs == 0`: automatic,
/// 1 + ceil(log_eta(candidates)) rungs, fewer where a rung's side would drop below
/// [`MIN_RUNG_SIDE`]. An explicit count is refused where a side would drop below 8.
pub fn schedule(full: (u32, u32), candidates: usize, eta: usize, rungs: usize) -> Result<Vec<(u32, u32)>> {
    if eta < 2 {
        bail!("--eta {eta}: must be at least 2");
    }
    let count = if rungs > 0 {
        rungs
    } else {
        let mut needed = 1;
        let mut left = candidates.max(1);
        while left > 1 {
            left = left.div_ceil(eta);
            needed += 1;
        }
        let mut fit = 1;
        while fit < needed && full.0.min(full.1) >> fit >= MIN_RUNG_SIDE {
            fit += 1;
        }
        fit
    };
    let sizes: Vec<(u32, u32)> = (0..count).rev().map(|k| (full.0 >> k.min(31), full.1 >> k.min(31))).collect();
    if sizes[0].0.min(sizes[0].1) < 8 {
        bail!(
            "--rungs {count}: the first rung would be {}x{} (the side halves per rung from {}x{})",
            sizes[0].0,
            sizes[0].1,
            full.0,
            full.1
        );
    }
    Ok(sizes)
}

/// The candidates a rung keeps: the best ceil(n/eta) by score (lower first), ties by the
/// candidates' order (spec order); non-finite scores rank last. Returns indices into `scores`,
/// in that order of rank.
pub fn keep(scores: &[f64], eta: usize) -> Vec<usize> {
    let mut order: Vec<usize> = (0..scores.len()).collect();
    let key = |i: usize| if scores[i].is_finite() { scores[i] } else { f64::INFINITY };
    order.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    order.truncate(scores.len().div_ceil(eta.max(1)));
    order
}

/// One rung of a halving run, as tune.json records it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rung {
    pub width: u32,
    pub height: u32,
    /// (label, mean score over the train setups), in the rung's candidate order.
    pub scores: Vec<(String, f64)>,
    /// The labels kept for the next rung, best first.
    pub kept: Vec<String>,
    pub points: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_doubles_the_side_up_to_the_full_size() {
        assert_eq!(schedule((256, 256), 8, 2, 0).unwrap(), vec![(32, 32), (64, 64), (128, 128), (256, 256)]);
        // 9 candidates at eta 3: 9 -> 3 -> 1 = 3 rungs
        assert_eq!(schedule((512, 256), 9, 3, 0).unwrap(), vec![(128, 64), (256, 128), (512, 256)]);
        // the automatic count stops at the smallest side
        assert_eq!(schedule((64, 64), 100, 2, 0).unwrap(), vec![(32, 32), (64, 64)]);
        assert_eq!(schedule((64, 64), 1, 2, 0).unwrap(), vec![(64, 64)]);
        assert_eq!(schedule((64, 64), 4, 2, 3).unwrap(), vec![(16, 16), (32, 32), (64, 64)], "explicit count");
        assert!(schedule((64, 64), 4, 2, 5).unwrap_err().to_string().contains("4x4"));
        assert!(schedule((64, 64), 4, 1, 0).is_err());
    }

    #[test]
    fn a_rung_keeps_the_best_share_with_ties_in_spec_order() {
        assert_eq!(keep(&[3.0, 1.0, 2.0, 0.5], 2), vec![3, 1]);
        assert_eq!(keep(&[1.0, 1.0, 1.0], 2), vec![0, 1], "ties: spec order; ceil(3/2) = 2");
        assert_eq!(keep(&[f64::NAN, 2.0, 5.0], 3), vec![1]);
        assert_eq!(keep(&[4.0], 2), vec![0]);
        assert_eq!(keep(&[], 2), Vec::<usize>::new());
    }
}
