//! Choosing: aggregates of a spec over the setups (mean and worst case), the Pareto front of
//! quality against cost (both minimised), and the recommendation for a budget. Pure functions.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use super::record::Row;

/// One spec (label) over the setups it ran on.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Aggregate {
    pub label: String,
    pub technique: String,
    /// Setups with a row of this label.
    pub setups: usize,
    pub mean_wrong_pct: f64,
    pub worst_wrong_pct: f64,
    /// Mean and worst (largest) over the setups of the rows' `flip_mean`.
    pub mean_flip_mean: f64,
    pub worst_flip_mean: f64,
    pub mean_total_ms: f64,
    pub worst_total_ms: f64,
    /// The largest shadow data over the setups.
    pub max_shadow_data_bytes: u64,
    /// Counters present in every row of the label: mean and worst (largest) over the setups.
    pub mean_counters: BTreeMap<String, f64>,
    pub worst_counters: BTreeMap<String, f64>,
    /// Some setup's row is degraded (a capacity limit reached).
    pub degraded: bool,
}

/// Aggregates per label, in the order labels first appear in `rows`.
pub fn aggregate(rows: &[Row]) -> Vec<Aggregate> {
    let mut order: Vec<&str> = Vec::new();
    for r in rows {
        if !order.contains(&r.label.as_str()) {
            order.push(&r.label);
        }
    }
    order
        .into_iter()
        .map(|label| {
            let g: Vec<&Row> = rows.iter().filter(|r| r.label == label).collect();
            let n = g.len() as f64;
            let mean = |f: &dyn Fn(&Row) -> f64| g.iter().map(|r| f(r)).sum::<f64>() / n;
            let worst = |f: &dyn Fn(&Row) -> f64| g.iter().map(|r| f(r)).fold(f64::NEG_INFINITY, f64::max);
            let common: Vec<&String> = g[0].counters.keys().filter(|k| g.iter().all(|r| r.counters.contains_key(*k))).collect();
            Aggregate {
                label: label.to_string(),
                technique: g[0].technique.clone(),
                setups: g.len(),
                mean_wrong_pct: mean(&|r| r.quality.wrong_pct),
                worst_wrong_pct: worst(&|r| r.quality.wrong_pct),
                mean_flip_mean: mean(&|r| r.flip_mean),
                worst_flip_mean: worst(&|r| r.flip_mean),
                mean_total_ms: mean(&|r| r.total_ms),
                worst_total_ms: worst(&|r| r.total_ms),
                max_shadow_data_bytes: g.iter().map(|r| r.shadow_data_bytes).max().unwrap_or(0),
                mean_counters: common.iter().map(|k| ((*k).clone(), mean(&|r| r.counters[*k]))).collect(),
                worst_counters: common.iter().map(|k| ((*k).clone(), worst(&|r| r.counters[*k]))).collect(),
                degraded: g.iter().any(|r| !r.degraded.is_empty()),
            }
        })
        .collect()
}

/// `--budget-ms`, `--budget-mb`, `--budget-bytes`: limits on the worst case over the setups.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Budget {
    /// Worst-case total_ms over the setups (timer dependent: wall clock on software adapters).
    pub ms: Option<f64>,
    /// Largest shadow data in MiB (2^20 bytes).
    pub mib: Option<f64>,
    /// Largest shadow data in bytes (hardware-independent, exact).
    pub bytes: Option<u64>,
}

impl Budget {
    pub fn is_set(&self) -> bool {
        self.ms.is_some() || self.mib.is_some() || self.bytes.is_some()
    }

    /// Whether an aggregate is within every limit that is set.
    pub fn admits(&self, a: &Aggregate) -> bool {
        self.ms.is_none_or(|ms| a.worst_total_ms <= ms)
            && self.mib.is_none_or(|mib| a.max_shadow_data_bytes as f64 <= mib * 1048576.0)
            && self.bytes.is_none_or(|b| a.max_shadow_data_bytes <= b)
    }

    /// `≤ 16 ms worst case, ≤ 64 MiB`: the limits set, for the terminal and the page.
    pub fn describe(&self) -> String {
        let mut v = Vec::new();
        if let Some(ms) = self.ms {
            v.push(format!("worst-case total <= {ms} ms"));
        }
        if let Some(mib) = self.mib {
            v.push(format!("shadow data <= {mib} MiB"));
        }
        if let Some(b) = self.bytes {
            v.push(format!("shadow data <= {b} bytes"));
        }
        v.join(", ")
    }
}

/// A candidate of a recommendation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Choice {
    pub label: String,
    pub mean_wrong_pct: f64,
    pub worst_wrong_pct: f64,
    pub worst_total_ms: f64,
    pub max_shadow_data_bytes: u64,
    /// Mean wrong % above the best's (percentage points; 0 for the best).
    pub margin_pct: f64,
}

/// The best spec within a budget and its runners-up.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recommendation {
    pub budget: Budget,
    /// Specs that ran on every setup (the only ones compared).
    pub considered: usize,
    /// Of those, the ones within the budget.
    pub within_budget: usize,
    /// Lowest mean wrong % within the budget (ties: lower worst wrong %, then cheaper); null
    /// when nothing fits.
    pub best: Option<Choice>,
    /// The next ones, best first (at most [`RUNNERS_UP`]).
    pub runners_up: Vec<Choice>,
}

/// How many runners-up a recommendation lists.
pub const RUNNERS_UP: usize = 3;

/// The aggregates that ran on all `setups` and fit `budget` (every one when it sets no limit),
/// best first: lowest mean wrong %, then lower worst wrong %, then cheaper, then by label.
pub fn rank<'a>(aggregates: &'a [Aggregate], setups: usize, budget: &Budget) -> Vec<&'a Aggregate> {
    let mut within: Vec<&Aggregate> = aggregates.iter().filter(|a| a.setups == setups && budget.admits(a)).collect();
    within.sort_by(|a, b| {
        a.mean_wrong_pct
            .total_cmp(&b.mean_wrong_pct)
            .then(a.worst_wrong_pct.total_cmp(&b.worst_wrong_pct))
            .then(a.worst_total_ms.total_cmp(&b.worst_total_ms))
            .then(a.max_shadow_data_bytes.cmp(&b.max_shadow_data_bytes))
            .then(a.label.cmp(&b.label))
    });
    within
}

/// The recommendation for `budget` among the aggregates that ran on all `setups`; None
/// without a budget.
pub fn recommend(aggregates: &[Aggregate], setups: usize, budget: &Budget) -> Option<Recommendation> {
    if !budget.is_set() {
        return None;
    }
    let considered = aggregates.iter().filter(|a| a.setups == setups).count();
    let within = rank(aggregates, setups, budget);
    let best_wrong = within.first().map(|a| a.mean_wrong_pct).unwrap_or(0.0);
    let choice = |a: &Aggregate| Choice {
        label: a.label.clone(),
        mean_wrong_pct: a.mean_wrong_pct,
        worst_wrong_pct: a.worst_wrong_pct,
        worst_total_ms: a.worst_total_ms,
        max_shadow_data_bytes: a.max_shadow_data_bytes,
        margin_pct: a.mean_wrong_pct - best_wrong,
    };
    Some(Recommendation {
        budget: *budget,
        considered,
        within_budget: within.len(),
        best: within.first().map(|a| choice(a)),
        runners_up: within.iter().skip(1).take(RUNNERS_UP).map(|a| choice(a)).collect(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::record::tests::row;

    #[test]
    fn aggregates_are_means_and_worst_cases_over_setups() {
        let mut rows = vec![row("a", "sm", 2.0, 10.0, 100), row("a", "lt", 1.0, 30.0, 500), row("b", "sm", 4.0, 20.0, 300)];
        rows[0].counters.insert("fetches_per_pixel".into(), 1.0);
        rows[2].counters.insert("fetches_per_pixel".into(), 3.0);
        rows[2].counters.insert("only_here".into(), 3.0);
        rows[2].degraded.push("capacity".into());
        let a = aggregate(&rows);
        assert_eq!(a.len(), 2);
        assert_eq!((a[0].label.as_str(), a[0].setups), ("sm", 2));
        assert_eq!((a[0].mean_wrong_pct, a[0].worst_wrong_pct), (3.0, 4.0));
        assert!((a[0].mean_flip_mean - 0.15).abs() < 1e-12 && (a[0].worst_flip_mean - 0.2).abs() < 1e-12, "FLIP: mean and worst");
        assert_eq!((a[0].mean_total_ms, a[0].worst_total_ms, a[0].max_shadow_data_bytes), (15.0, 20.0, 300));
        assert_eq!(a[0].mean_counters, BTreeMap::from([("fetches_per_pixel".to_string(), 2.0)]), "only counters every row has");
        assert_eq!(a[0].worst_counters["fetches_per_pixel"], 3.0);
        assert!(a[0].degraded && !a[1].degraded);
        assert_eq!((a[1].label.as_str(), a[1].setups, a[1].mean_wrong_pct), ("lt", 1, 1.0));
    }

    fn aggs() -> Vec<Aggregate> {
        let rows = vec![
            row("a", "cheap", 5.0, 2.0, 1 << 20),
            row("b", "cheap", 7.0, 3.0, 1 << 20),
            row("a", "mid", 2.0, 8.0, 4 << 20),
            row("b", "mid", 3.0, 12.0, 4 << 20),
            row("a", "good", 1.0, 20.0, 16 << 20),
            row("b", "good", 1.5, 25.0, 16 << 20),
            row("a", "partial", 0.0, 1.0, 1),
        ];
        aggregate(&rows)
    }

    #[test]
    fn the_recommendation_is_the_best_mean_within_the_worst_case_budget() {
        let a = aggs();
        assert!(recommend(&a, 2, &Budget::default()).is_none(), "no budget, no recommendation");
        let r = recommend(&a, 2, &Budget { ms: Some(15.0), ..Budget::default() }).unwrap();
        assert_eq!((r.considered, r.within_budget), (3, 2), "'partial' ran on one setup only");
        let best = r.best.unwrap();
        assert_eq!((best.label.as_str(), best.mean_wrong_pct, best.margin_pct), ("mid", 2.5, 0.0));
        assert_eq!(r.runners_up.len(), 1);
        assert_eq!((r.runners_up[0].label.as_str(), r.runners_up[0].margin_pct), ("cheap", 3.5));
        // the worst case decides: 'mid' takes 12 ms on setup b
        let r = recommend(&a, 2, &Budget { ms: Some(11.0), ..Budget::default() }).unwrap();
        assert_eq!(r.best.unwrap().label, "cheap");
        // memory budgets, in MiB or bytes
        let r = recommend(&a, 2, &Budget { mib: Some(4.0), ..Budget::default() }).unwrap();
        assert_eq!(r.best.unwrap().label, "mid");
        let r = recommend(&a, 2, &Budget { bytes: Some((4 << 20) - 1), ..Budget::default() }).unwrap();
        assert_eq!(r.best.unwrap().label, "cheap");
        let r = recommend(&a, 2, &Budget { ms: Some(100.0), mib: Some(64.0), bytes: None }).unwrap();
        let labels: Vec<_> = std::iter::once(r.best.clone().unwrap()).chain(r.runners_up.clone()).map(|c| c.label).collect();
        assert_eq!(labels, ["good", "mid", "cheap"]);
        assert_eq!(r.runners_up[0].margin_pct, 1.25);
        // nothing fits
        let r = recommend(&a, 2, &Budget { ms: Some(1.0), ..Budget::default() }).unwrap();
        assert!(r.best.is_none() && r.runners_up.is_empty() && r.within_budget == 0);
    }

    #[test]
    fn ties_go_to_the_better_worst_case_then_the_cheaper() {
        let rows = vec![row("a", "x", 1.0, 5.0, 10), row("b", "x", 3.0, 5.0, 10), row("a", "y", 2.0, 9.0, 10), row("b", "y", 2.0, 9.0, 10)];
        let r = recommend(&aggregate(&rows), 2, &Budget { ms: Some(10.0), ..Budget::default() }).unwrap();
        assert_eq!(r.best.unwrap().label, "y", "equal means: the lower worst case wins");
        assert_eq!(Budget { ms: Some(16.0), mib: Some(64.0), bytes: None }.describe(), "worst-case total <= 16 ms, shadow data <= 64 MiB");
    }
}
