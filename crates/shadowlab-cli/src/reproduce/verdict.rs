//! Verdicts: each claim against the rows of its runs. Pure: the rows in, one of reproduced,
//! not reproduced or not comparable (with why) out.

use std::collections::BTreeMap;

use serde::Serialize;

use super::data::{is_time, Claim, Direction, Kind};
use crate::sweep::record::Row;

/// What a run of the reproduction gave.
#[derive(Clone, Debug)]
pub enum Outcome {
    /// Not run (e.g. its scene files are missing), and why.
    Skipped(String),
    Done {
        software_adapter: bool,
        timer: String,
        rows: Vec<Row>,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    Reproduced,
    NotReproduced,
    NotComparable,
}

impl Status {
    pub fn text(self) -> &'static str {
        match self {
            Status::Reproduced => "reproduced",
            Status::NotReproduced => "not reproduced",
            Status::NotComparable => "not comparable",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Verdict {
    pub claim: String,
    pub status: Status,
    /// Our figure, formatted.
    pub ours: String,
    pub why: String,
}

/// A row's figure of `metric` (see claims.toml); None where the row has none.
pub fn metric(row: &Row, metric: &str) -> Option<f64> {
    Some(match metric {
        "wrong_pct" => row.quality.wrong_pct,
        "false_lit_pct" => row.quality.false_lit_pct,
        "false_shadow_pct" => row.quality.false_shadow_pct,
        "mae" => row.quality.mae,
        "flip_mean" => row.flip_mean,
        "total_ms" => row.total_ms,
        "shadow_data_bytes" => row.shadow_data_bytes as f64,
        "stalls" => row.stalls.len() as f64,
        "rays_per_pixel" => *row.counters.get("rays_traced")? / (row.quality.evaluated_pixels.max(1) as f64),
        m => {
            if let Some(c) = m.strip_prefix("counter:") {
                *row.counters.get(c)?
            } else if let Some(alts) = m.strip_prefix("stage:") {
                let alts: Vec<&str> = alts.split('|').collect();
                let stage = |name: &str| name.split_once('.').map_or(name, |(_, rest)| rest).to_string();
                let hits: Vec<f64> =
                    row.stages_ms.iter().filter(|(k, _)| alts.iter().any(|a| stage(k).starts_with(a))).map(|(_, v)| *v).collect();
                if hits.is_empty() {
                    return None;
                }
                hits.iter().sum()
            } else {
                return None;
            }
        }
    })
}

fn fmt(v: f64) -> String {
    if v.abs() >= 1e5 && v.fract() == 0.0 {
        format!("{v:.0}")
    } else if v.abs() >= 100.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.4}").trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn within(v: f64, [lo, hi]: [f64; 2]) -> bool {
    let eps = 1e-9 * v.abs().max(1.0);
    v >= lo - eps && v <= hi + eps
}

fn not_comparable(c: &Claim, ours: String, why: String) -> Verdict {
    Verdict { claim: c.id.clone(), status: Status::NotComparable, ours, why }
}

/// The verdict of `c` on `runs` (by run id).
pub fn judge(c: &Claim, runs: &BTreeMap<String, Outcome>) -> Verdict {
    // every run the claim reads must have run
    let mut software = false;
    let mut timers = Vec::new();
    for id in c.run_ids() {
        match runs.get(id) {
            None => return not_comparable(c, "-".into(), format!("run '{id}' was not part of this reproduction")),
            Some(Outcome::Skipped(why)) => return not_comparable(c, "-".into(), format!("run '{id}' did not run: {why}")),
            Some(Outcome::Done { software_adapter, timer, .. }) => {
                software |= *software_adapter;
                timers.push(timer.clone());
            }
        }
    }
    let value = |run: &str, label: &str| -> Result<f64, String> {
        let Some(Outcome::Done { rows, .. }) = runs.get(run) else { unreachable!("checked above") };
        let row = rows.iter().find(|r| r.label == label).ok_or_else(|| format!("run '{run}' has no row '{label}'"))?;
        metric(row, &c.metric).filter(|v| v.is_finite()).ok_or_else(|| format!("'{label}' in run '{run}' has no {}", c.metric))
    };
    let ratio = |run: &str| -> Result<(f64, String), String> {
        let (n, d) = (c.num.as_deref().unwrap_or_default(), c.den.as_deref().unwrap_or_default());
        let (a, b) = (value(run, n)?, value(run, d)?);
        if b == 0.0 {
            return Err(format!("'{d}' has {} = 0: no ratio", c.metric));
        }
        Ok((a / b, format!("{}x ({n} {} / {d} {})", fmt(a / b), fmt(a), fmt(b))))
    };
    let result: Result<(bool, String), String> = (|| match c.kind {
        Kind::Order => {
            let run = c.run.as_deref().unwrap_or_default();
            let v: Vec<f64> = c.labels.iter().map(|l| value(run, l)).collect::<Result<_, _>>()?;
            let ok = v.windows(2).all(|w| w[0] < w[1]);
            let parts: Vec<String> = c.labels.iter().zip(&v).map(|(l, x)| format!("{l} {}", fmt(*x))).collect();
            let sep = |i: usize| {
                if v[i] < v[i + 1] {
                    " < "
                } else if v[i] == v[i + 1] {
                    " = "
                } else {
                    " > "
                }
            };
            let mut s = parts[0].clone();
            for i in 0..v.len() - 1 {
                s += sep(i);
                s += &parts[i + 1];
            }
            Ok((ok, s))
        }
        Kind::Ratio => {
            let (r, s) = ratio(c.run.as_deref().unwrap_or_default())?;
            Ok((within(r, c.range.unwrap_or([f64::NAN; 2])), s))
        }
        Kind::Value => {
            let v = value(c.run.as_deref().unwrap_or_default(), c.label.as_deref().unwrap_or_default())?;
            Ok((within(v, c.range.unwrap_or([f64::NAN; 2])), fmt(v)))
        }
        Kind::Trend => {
            let v: Vec<f64> = c
                .runs
                .iter()
                .map(|r| match c.label.as_deref() {
                    Some(l) => value(r, l),
                    None => ratio(r).map(|x| x.0),
                })
                .collect::<Result<_, _>>()?;
            let up = c.direction == Some(Direction::Increasing);
            let ok = v.windows(2).all(|w| if up { w[0] < w[1] } else { w[0] > w[1] });
            let s: Vec<String> = c.runs.iter().zip(&v).map(|(r, x)| format!("{r} {}", fmt(*x))).collect();
            Ok((ok, s.join(" -> ")))
        }
    })();
    let (ok, ours) = match result {
        Ok(x) => x,
        Err(why) => return not_comparable(c, "-".into(), why),
    };
    let range =
        c.range.map(|[lo, hi]| format!(" (expected {}..{})", fmt(lo), if hi >= 1e9 { "inf".into() } else { fmt(hi) })).unwrap_or_default();
    if is_time(&c.metric) && software {
        let within_run = if ok { "would hold" } else { "would not hold" };
        return not_comparable(
            c,
            ours,
            format!(
                "times on a software adapter ({}) are not the paper's GPU; within this run the claim {within_run}{range}",
                timers.join("; ")
            ),
        );
    }
    let status = if ok { Status::Reproduced } else { Status::NotReproduced };
    let hw = if is_time(&c.metric) { format!("timer: {}", timers.join("; ")) } else { "hardware-independent".into() };
    Verdict { claim: c.id.clone(), status, ours, why: format!("{hw}{range}") }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reproduce::data::parse;
    use crate::sweep::record::tests::row;

    fn data() -> Vec<Claim> {
        let text = r#"
[[seed]]
id = "000"
title = "t"
file = "f"
[[run]]
id = "000-a"
seed = "000"
scene = "planebox"
closest = "c"
techniques = ["sm", "rtw", "notw"]
[[run]]
id = "000-b"
seed = "000"
scene = "planebox"
closest = "c"
techniques = ["sm", "rtw", "notw"]
[[claim]]
id = "000-order"
run = "000-a"
kind = "order"
metric = "wrong_pct"
labels = ["notw", "rtw", "sm"]
source = "s"
paper = "p"
[[claim]]
id = "000-ratio"
run = "000-a"
kind = "ratio"
metric = "total_ms"
num = "notw"
den = "rtw"
range = [1.0, 1.25]
source = "s"
paper = "p"
[[claim]]
id = "000-bytes"
run = "000-a"
kind = "value"
metric = "shadow_data_bytes"
label = "sm"
range = [1048576, 1048576]
source = "s"
paper = "p"
[[claim]]
id = "000-trend"
kind = "trend"
runs = ["000-a", "000-b"]
metric = "wrong_pct"
label = "sm"
direction = "decreasing"
source = "s"
paper = "p"
"#;
        parse(text).unwrap().claim
    }

    fn done(rows: Vec<Row>, software: bool) -> Outcome {
        Outcome::Done { software_adapter: software, timer: "t".into(), rows }
    }

    fn runs(a: Vec<Row>, b: Vec<Row>, software: bool) -> BTreeMap<String, Outcome> {
        BTreeMap::from([("000-a".to_string(), done(a, software)), ("000-b".to_string(), done(b, software))])
    }

    #[test]
    fn orders_ratios_values_and_trends_are_judged_from_the_rows() {
        let c = data();
        // row(setup, label, wrong, ms, bytes)
        let a = vec![row("s", "sm", 3.0, 1.0, 1 << 20), row("s", "rtw", 2.0, 10.0, 1), row("s", "notw", 1.0, 11.0, 1)];
        let b = vec![row("s", "sm", 2.5, 1.0, 1)];
        let r = runs(a.clone(), b.clone(), false);
        let v: Vec<Verdict> = c.iter().map(|c| judge(c, &r)).collect();
        assert_eq!(v.iter().map(|v| v.status).collect::<Vec<_>>(), vec![Status::Reproduced; 4], "{v:#?}");
        assert_eq!(v[0].ours, "notw 1 < rtw 2 < sm 3");
        assert!(v[1].ours.starts_with("1.1x"), "{}", v[1].ours);
        assert_eq!(v[2].ours, "1048576");
        // a tie breaks an order; a ratio outside its range; a value off by one byte; a rising trend
        let mut a2 = a.clone();
        a2[2].quality.wrong_pct = 2.0;
        a2[2].total_ms = 14.0;
        a2[0].shadow_data_bytes += 1;
        let b2 = vec![row("s", "sm", 3.5, 1.0, 1)];
        let r2 = runs(a2, b2, false);
        let v: Vec<Verdict> = c.iter().map(|c| judge(c, &r2)).collect();
        assert_eq!(v.iter().map(|v| v.status).collect::<Vec<_>>(), vec![Status::NotReproduced; 4], "{v:#?}");
        assert_eq!(v[0].ours, "notw 2 = rtw 2 < sm 3");
    }

    #[test]
    fn software_times_skipped_runs_and_missing_rows_are_not_comparable() {
        let c = data();
        let a = vec![row("s", "sm", 3.0, 1.0, 1 << 20), row("s", "rtw", 2.0, 10.0, 1), row("s", "notw", 1.0, 11.0, 1)];
        let r = runs(a.clone(), vec![], true);
        let t = judge(&c[1], &r);
        assert_eq!(t.status, Status::NotComparable);
        assert!(t.why.contains("software adapter") && t.why.contains("would hold"), "{}", t.why);
        assert_eq!(judge(&c[0], &r).status, Status::Reproduced, "wrong % does not depend on the adapter");
        let trend = judge(&c[3], &r);
        assert!(trend.status == Status::NotComparable && trend.why.contains("no row 'sm'"), "{}", trend.why);
        let mut skipped = runs(a, vec![], false);
        skipped.insert("000-a".into(), Outcome::Skipped("scene file missing".into()));
        let s = judge(&c[0], &skipped);
        assert!(s.status == Status::NotComparable && s.why.contains("scene file missing"), "{}", s.why);
        assert!(judge(&c[0], &BTreeMap::new()).why.contains("not part of"));
    }

    #[test]
    fn metrics_read_counters_stages_and_rays() {
        let mut r = row("s", "iasm", 1.0, 5.0, 1);
        r.stages_ms = BTreeMap::from([("iasm.shadows.t01".into(), 1.5), ("iasm.shadows.t02".into(), 2.0), ("iasm.readback".into(), 0.5)]);
        r.counters.insert("rays_traced".into(), 50.0);
        r.quality.evaluated_pixels = 200;
        assert_eq!(metric(&r, "stage:shadows|render"), Some(3.5));
        assert_eq!(metric(&r, "stage:readback"), Some(0.5));
        assert_eq!(metric(&r, "stage:render"), None);
        assert_eq!(metric(&r, "rays_per_pixel"), Some(0.25));
        assert_eq!(metric(&r, "counter:missing"), None);
        assert_eq!(metric(&r, "stalls"), Some(0.0));
    }
}
