//! `shadowlab tune`: a grid search of one technique's parameters on `--train` setups, judged on
//! disjoint `--validate` setups against the technique's defaults, so that a chosen value is only
//! called better where views it was not chosen on agree.
//!
//! Both halves are sweeps (`DIR/train`, `DIR/validate`: cached and resumable like any sweep);
//! the outcome is `DIR/tune.json` and `DIR/tune.md`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use clap::Args;
use serde::Serialize;

use super::args::{BudgetArgs, SweepArgs};
use super::choose::{aggregate, Aggregate, Budget};
use super::halving::{self, Metric, Rung, Search};
use super::json::Sweep;
use super::record::Row;

pub const TUNE_ABOUT: &str = "Tune a technique's parameters on train setups; validate the choice on held-out setups";

pub const TUNE_LONG: &str = "\
Runs the grid of value lists on the --train setups, picks the point with the lowest mean wrong %
(--metric flip: mean FLIP) over them (within an optional budget; ties: the earlier spec), then
runs that point and the technique's defaults on the --validate setups, which must be disjoint
from the train ones. The choice carries over when it beats the defaults' mean on the validate
setups and is no worse on at least half of them:
  shadowlab tune -t 'notw:window=8|16|32,blur=0|1' --train courtyard --train setups/sponza.toml \\
                 --validate city --validate setups/conference.toml --size 512x512
Each entry of --train/--validate is a setup file (.toml) or a built-in scene name. Writes
DIR/train and DIR/validate (sweep directories, resumed on a rerun), DIR/tune.json and DIR/tune.md.
--search halving (successive halving): every grid point runs on the train setups at a small
size (rung 0), the best 1/eta (--eta, default 2) go on at twice the width and height, until the
last rung at the full size (--size, else 1024x1024). --rungs N sets the count (default: enough
to leave one candidate, the smallest side at least 32). Rung k is DIR/train-rung<k>.";

#[derive(Args, Clone, Debug)]
pub struct TuneArgs {
    /// Technique spec with value lists (`name:key=a|b,key2=c|d`): the grid to search
    #[arg(short = 't', long = "technique")]
    pub technique: String,
    /// A setup file (.toml) or built-in scene to tune on (repeatable)
    #[arg(long = "train", required = true)]
    pub train: Vec<String>,
    /// A setup file (.toml) or built-in scene to validate on, disjoint from --train (repeatable)
    #[arg(long = "validate", required = true)]
    pub validate: Vec<String>,
    /// Output size WxH for every setup (default: each setup's)
    #[arg(long)]
    pub size: Option<String>,
    /// Timed repetitions per point
    #[arg(long, default_value_t = 1)]
    pub repeat: usize,
    /// Index of the light in every setup
    #[arg(long, default_value_t = 0)]
    pub light: usize,
    /// Output directory (resumed)
    #[arg(long, default_value = "tune")]
    pub out: PathBuf,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// What the choice minimises: mean wrong % or mean FLIP over the train setups
    #[arg(long, value_enum, default_value_t = Metric::Wrong)]
    pub metric: Metric,
    /// grid: every point at the full size; halving: successive halving over size rungs
    #[arg(long, value_enum, default_value_t = Search::Grid)]
    pub search: Search,
    /// halving: keep the best 1/eta of the candidates per rung
    #[arg(long, default_value_t = halving::DEFAULT_ETA)]
    pub eta: usize,
    /// halving: number of rungs (0 = automatic)
    #[arg(long, default_value_t = 0)]
    pub rungs: usize,
    /// No progress bars
    #[arg(long, short)]
    pub quiet: bool,
}

/// One spec's figures over a list of setups.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Side {
    pub label: String,
    pub mean_wrong_pct: f64,
    pub worst_wrong_pct: f64,
    pub mean_flip_mean: f64,
    pub worst_total_ms: f64,
    pub wrong_pct_by_setup: BTreeMap<String, f64>,
    pub flip_mean_by_setup: BTreeMap<String, f64>,
}

impl Side {
    /// The mean and the per-setup figures of `metric`.
    fn by(&self, metric: Metric) -> (f64, &BTreeMap<String, f64>) {
        match metric {
            Metric::Wrong => (self.mean_wrong_pct, &self.wrong_pct_by_setup),
            Metric::Flip => (self.mean_flip_mean, &self.flip_mean_by_setup),
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Tune {
    pub schema_version: u32,
    pub technique: String,
    pub metric: Metric,
    pub search: Search,
    pub grid: Vec<String>,
    /// halving's rungs before the last (empty for a grid search).
    pub rungs: Vec<Rung>,
    /// Train points evaluated (every rung, the defaults included), and their pixels.
    pub points_evaluated: usize,
    pub pixels_evaluated: u64,
    /// Train points weighted by their output pixels over the full size's: the search's cost
    /// in full-size points (a grid search: its point count).
    pub full_size_points: f64,
    pub train: Vec<String>,
    pub validate: Vec<String>,
    pub budget: Budget,
    pub timer: String,
    /// Every grid point on the train setups, best first (within the budget).
    pub train_ranking: Vec<Side>,
    pub default_train: Side,
    /// The best grid point on the train setups; null when nothing fits the budget.
    pub chosen: Option<String>,
    pub chosen_validate: Option<Side>,
    pub default_validate: Side,
    pub carries_over: bool,
    pub verdict: String,
}

/// A `--train`/`--validate` entry: a setup file or a built-in scene.
fn is_setup_file(entry: &str) -> bool {
    entry.ends_with(".toml") || Path::new(entry).is_file()
}

fn side(label: &str, rows: &[Row], aggs: &[Aggregate]) -> Result<Side> {
    let a = aggs.iter().find(|a| a.label == label).ok_or_else(|| anyhow!("no result for '{label}'"))?;
    Ok(Side {
        label: label.to_string(),
        mean_wrong_pct: a.mean_wrong_pct,
        worst_wrong_pct: a.worst_wrong_pct,
        mean_flip_mean: a.mean_flip_mean,
        worst_total_ms: a.worst_total_ms,
        wrong_pct_by_setup: rows.iter().filter(|r| r.label == label).map(|r| (r.setup.clone(), r.quality.wrong_pct)).collect(),
        flip_mean_by_setup: rows.iter().filter(|r| r.label == label).map(|r| (r.setup.clone(), r.flip_mean)).collect(),
    })
}

/// The mean of `metric` over the setups.
fn score(a: &Aggregate, metric: Metric) -> f64 {
    match metric {
        Metric::Wrong => a.mean_wrong_pct,
        Metric::Flip => a.mean_flip_mean,
    }
}

/// The grid points that ran on all `setups` and fit `budget`, best first by the mean of
/// `metric`; ties keep the order of `order` (spec order).
pub fn rank_by<'a>(aggs: &'a [Aggregate], order: &[String], setups: usize, budget: &Budget, metric: Metric) -> Vec<&'a Aggregate> {
    let pos = |a: &Aggregate| order.iter().position(|l| *l == a.label).unwrap_or(usize::MAX);
    let mut v: Vec<&Aggregate> = aggs.iter().filter(|a| a.setups == setups && budget.admits(a) && pos(a) != usize::MAX).collect();
    v.sort_by(|a, b| score(a, metric).total_cmp(&score(b, metric)).then(pos(a).cmp(&pos(b))));
    v
}

/// Whether `chosen` carries over against `default` on the validate setups, and why.
pub fn verdict(chosen: Option<&Side>, default: &Side, same_values: bool, metric: Metric) -> (bool, String) {
    let Some(c) = chosen else {
        return (false, "nothing in the grid fits the budget on the train setups: keep the defaults".into());
    };
    if same_values {
        return (false, format!("the best train point '{}' is the defaults: nothing to change", c.label));
    }
    let ((cm, cs), (dm, ds)) = (c.by(metric), default.by(metric));
    let n = ds.len();
    let no_worse = ds.iter().filter(|(s, d)| cs.get(*s).is_some_and(|w| w <= *d)).count();
    let carries = cm < dm && 2 * no_worse >= n;
    let how = match metric {
        Metric::Wrong => format!("mean wrong {cm:.3} % against the defaults' {dm:.3} %"),
        Metric::Flip => format!("mean FLIP {cm:.4} against the defaults' {dm:.4}"),
    };
    let how = format!("'{}' on the validate setups: {how}, no worse on {no_worse} of {n}", c.label);
    if carries {
        (true, format!("carries over: {how}"))
    } else {
        (false, format!("does not carry over (keep the defaults): {how}"))
    }
}

fn sweep_args(a: &TuneArgs, setups: &[String], techniques: Vec<String>, out: PathBuf, size: Option<String>) -> SweepArgs {
    SweepArgs {
        setups: setups.iter().filter(|s| is_setup_file(s)).map(PathBuf::from).collect(),
        scenes: setups.iter().filter(|s| !is_setup_file(s)).cloned().collect(),
        techniques,
        size,
        frames: 1,
        repeat: a.repeat,
        light: a.light,
        time: None,
        out,
        shard: None,
        budget: BudgetArgs::default(),
        quiet: a.quiet,
    }
}

pub fn tune(a: &TuneArgs) -> Result<()> {
    let budget = a.budget.budget()?;
    for t in &a.train {
        if a.validate.contains(t) {
            bail!("'{t}' is in both --train and --validate: validation must use setups the choice was not made on");
        }
    }
    let grid = super::expand::expand(std::slice::from_ref(&a.technique))?;
    let name = a.technique.split(':').next().unwrap_or_default().trim().to_string();
    if grid.len() < 2 {
        bail!("-t '{}': give value lists to search (e.g. {name}:key=a|b)", a.technique);
    }
    // halving: the rung sizes, checked before any work
    let (full_size, schedule) = match a.search {
        Search::Grid => (a.size.clone(), Vec::new()),
        Search::Halving => {
            let full = match &a.size {
                Some(s) => crate::config::parse_size(s)?,
                None => halving::DEFAULT_FULL_SIZE,
            };
            (Some(format!("{}x{}", full.0, full.1)), halving::schedule(full, grid.len(), a.eta, a.rungs)?)
        }
    };
    prepare_dir(&a.out)?;
    let (mut points, mut pixels) = (0usize, 0u64);
    let mut count = |s: &Sweep| {
        points += s.rows.len();
        pixels += s.rows.iter().map(|r| r.quality.evaluated_pixels).sum::<u64>();
    };
    // halving: every rung but the last narrows the candidates
    let mut candidates = grid.clone();
    let mut rungs = Vec::new();
    let mut full_size_points = 0.0;
    for (k, (w, h)) in schedule.iter().take(schedule.len().saturating_sub(1)).enumerate() {
        let dir = a.out.join(format!("train-rung{k}"));
        let s = super::sweep(&sweep_args(a, &a.train, candidates.clone(), dir, Some(format!("{w}x{h}"))))
            .with_context(|| format!("halving rung {k} ({w}x{h})"))?;
        count(&s);
        let (fw, fh) = schedule[schedule.len() - 1];
        full_size_points += s.rows.len() as f64 * (*w as f64 * *h as f64) / (fw as f64 * fh as f64);
        let aggs = aggregate(&s.rows);
        let scores: Vec<f64> =
            candidates.iter().map(|c| aggs.iter().find(|g| g.label == *c).map_or(f64::NAN, |g| score(g, a.metric))).collect();
        let kept: Vec<String> = halving::keep(&scores, a.eta).into_iter().map(|i| candidates[i].clone()).collect();
        rungs.push(Rung {
            width: *w,
            height: *h,
            scores: candidates.iter().cloned().zip(scores.iter().copied()).collect(),
            kept: kept.clone(),
            points: s.rows.len(),
        });
        // the survivors in spec order, so that the last rung breaks ties as a grid would
        candidates.retain(|c| kept.contains(c));
    }
    // the last rung (the whole grid for a grid search) at the full size, the defaults beside it
    let mut specs = candidates.clone();
    specs.push(name.clone());
    let train = super::sweep(&sweep_args(a, &a.train, specs, a.out.join("train"), full_size.clone())).context("the train sweep")?;
    count(&train);
    full_size_points += train.rows.len() as f64;
    let aggs = aggregate(&train.rows);
    let ranking: Vec<Side> = rank_by(&aggs, &candidates, train.setups.len(), &budget, a.metric)
        .into_iter()
        .map(|g| side(&g.label, &train.rows, &aggs))
        .collect::<Result<_>>()?;
    let default_train = side(&name, &train.rows, &aggs)?;
    let chosen = ranking.first().map(|s| s.label.clone());
    let mut specs = vec![name.clone()];
    specs.extend(chosen.iter().cloned());
    let validate = super::sweep(&sweep_args(a, &a.validate, specs, a.out.join("validate"), full_size)).context("the validate sweep")?;
    let vaggs = aggregate(&validate.rows);
    let default_validate = side(&name, &validate.rows, &vaggs)?;
    let chosen_validate = chosen.as_deref().map(|c| side(c, &validate.rows, &vaggs)).transpose()?;
    let params = |s: &Sweep, label: &str| s.rows.iter().find(|r| r.label == label).map(|r| r.params.clone());
    let same = chosen.as_deref().is_some_and(|c| params(&train, c) == params(&train, &name));
    let (carries_over, verdict) = verdict(chosen_validate.as_ref(), &default_validate, same, a.metric);
    let t = Tune {
        schema_version: 2,
        technique: name,
        metric: a.metric,
        search: a.search,
        grid,
        rungs,
        points_evaluated: points,
        pixels_evaluated: pixels,
        full_size_points,
        train: a.train.clone(),
        validate: a.validate.clone(),
        budget,
        timer: train.timer.clone(),
        train_ranking: ranking,
        default_train,
        chosen,
        chosen_validate,
        default_validate,
        carries_over,
        verdict,
    };
    write(&a.out.join("tune.json"), serde_json::to_string_pretty(&t)?.as_bytes())?;
    write(&a.out.join("tune.md"), markdown(&t).as_bytes())?;
    if !a.quiet {
        print!("{}", markdown(&t));
        println!("tune: {}", a.out.join("tune.md").display());
    }
    Ok(())
}

/// The output directory: new, or one `tune` made before (its sweeps are resumed).
fn prepare_dir(dir: &Path) -> Result<()> {
    let marker = dir.join(".shadowlab-tune");
    if dir.exists() && !marker.exists() && std::fs::read_dir(dir).map(|mut d| d.next().is_some()).unwrap_or(true) {
        bail!("{} exists and was not written by `shadowlab tune`; choose another --out", dir.display());
    }
    std::fs::create_dir_all(dir)?;
    std::fs::write(marker, b"shadowlab tune output\n")?;
    Ok(())
}

fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).with_context(|| path.display().to_string())
}

pub fn markdown(t: &Tune) -> String {
    let mut s = format!("# tune {}: {}\n\ntrain: {}; validate: {}\n", t.technique, t.verdict, t.train.join(", "), t.validate.join(", "));
    if t.budget.is_set() {
        s += &format!("budget: {}\n", t.budget.describe());
    }
    let metric = match t.metric {
        Metric::Wrong => "mean wrong %",
        Metric::Flip => "mean FLIP",
    };
    let search = match t.search {
        Search::Grid => "grid",
        Search::Halving => "successive halving",
    };
    s += &format!(
        "ranked by: {metric}; search: {search} ({} train points, {:.2} full-size points, {} evaluated pixels)\n",
        t.points_evaluated, t.full_size_points, t.pixels_evaluated
    );
    for (k, r) in t.rungs.iter().enumerate() {
        s += &format!("rung {k} at {}x{}: {} candidates, kept {}\n", r.width, r.height, r.scores.len(), r.kept.join(", "));
    }
    s += &format!("timer: {}\n\n| train ranking | mean wrong % | worst wrong % | mean FLIP | worst ms |\n|---|---|---|---|---|\n", t.timer);
    for r in t.train_ranking.iter().chain(std::iter::once(&t.default_train)) {
        s += &format!(
            "| {} | {:.3} | {:.3} | {:.4} | {:.1} |\n",
            r.label, r.mean_wrong_pct, r.worst_wrong_pct, r.mean_flip_mean, r.worst_total_ms
        );
    }
    s += "\n| validate | mean wrong % | mean FLIP | per setup (wrong %) |\n|---|---|---|---|\n";
    for r in t.chosen_validate.iter().chain(std::iter::once(&t.default_validate)) {
        let per: Vec<String> = r.wrong_pct_by_setup.iter().map(|(k, v)| format!("{k} {v:.3}")).collect();
        s += &format!("| {} | {:.3} | {:.4} | {} |\n", r.label, r.mean_wrong_pct, r.mean_flip_mean, per.join(", "));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn side(label: &str, per: &[(&str, f64)]) -> Side {
        let m = per.iter().map(|p| p.1).sum::<f64>() / per.len() as f64;
        Side {
            label: label.into(),
            mean_wrong_pct: m,
            worst_wrong_pct: per.iter().map(|p| p.1).fold(0.0, f64::max),
            mean_flip_mean: m / 10.0,
            worst_total_ms: 1.0,
            wrong_pct_by_setup: per.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            flip_mean_by_setup: per.iter().map(|(k, v)| (k.to_string(), *v / 10.0)).collect(),
        }
    }

    #[test]
    fn a_choice_carries_over_only_where_the_held_out_setups_agree() {
        let d = side("notw", &[("a", 1.0), ("b", 2.0)]);
        let better = side("notw:window=8", &[("a", 0.8), ("b", 1.9)]);
        assert!(verdict(Some(&better), &d, false, Metric::Wrong).0);
        // a better mean from one setup while the other gets worse: 1 of 2 no worse still carries
        let mixed = side("x", &[("a", 0.2), ("b", 2.5)]);
        assert!(verdict(Some(&mixed), &d, false, Metric::Wrong).0);
        // better on one of three, worse mean: does not
        let d3 = side("notw", &[("a", 1.0), ("b", 1.0), ("c", 1.0)]);
        let one = side("y", &[("a", 0.1), ("b", 1.5), ("c", 1.6)]);
        let (ok, why) = verdict(Some(&one), &d3, false, Metric::Wrong);
        assert!(!ok && why.contains("does not carry over"), "{why}");
        let lucky = side("z", &[("a", 0.1), ("b", 1.1), ("c", 1.1)]);
        assert!(!verdict(Some(&lucky), &d3, false, Metric::Wrong).0, "better mean but worse on 2 of 3");
        assert!(verdict(Some(&better), &d, true, Metric::Wrong).1.contains("is the defaults"));
        assert!(!verdict(None, &d, false, Metric::Wrong).0);
    }

    fn agg(label: &str, wrong: f64, flip: f64) -> Aggregate {
        let rows = vec![crate::sweep::record::tests::row("a", label, wrong, 1.0, 1)];
        let mut a = aggregate(&rows).remove(0);
        a.mean_flip_mean = flip;
        a
    }

    #[test]
    fn the_ranking_follows_the_metric_and_breaks_ties_by_spec_order() {
        let aggs = vec![agg("p", 1.0, 0.3), agg("q", 2.0, 0.1), agg("r", 1.0, 0.2), agg("other", 0.0, 0.0)];
        let order: Vec<String> = ["p", "q", "r"].map(String::from).to_vec();
        let labels = |m| rank_by(&aggs, &order, 1, &Budget::default(), m).iter().map(|a| a.label.clone()).collect::<Vec<_>>();
        assert_eq!(labels(Metric::Wrong), ["p", "r", "q"], "equal wrong %: p before r (spec order); 'other' is not a candidate");
        assert_eq!(labels(Metric::Flip), ["q", "r", "p"]);
        let d = side("notw", &[("a", 1.0), ("b", 1.0)]);
        let mut c = side("x", &[("a", 2.0), ("b", 2.0)]);
        c.mean_flip_mean = 0.01;
        c.flip_mean_by_setup = [("a".to_string(), 0.01), ("b".to_string(), 0.01)].into();
        assert!(!verdict(Some(&c), &d, false, Metric::Wrong).0);
        let (ok, why) = verdict(Some(&c), &d, false, Metric::Flip);
        assert!(ok && why.contains("FLIP"), "{why}");
    }

    #[test]
    fn entries_are_setup_files_or_scenes() {
        assert!(is_setup_file("setups/sponza.toml"));
        assert!(!is_setup_file("courtyard"));
    }
}
