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
use super::choose::{aggregate, rank, Aggregate, Budget};
use super::record::{Row, Sweep};

pub const TUNE_ABOUT: &str = "Tune a technique's parameters on train setups; validate the choice on held-out setups";

pub const TUNE_LONG: &str = "\
Runs the grid of value lists on the --train setups, picks the point with the lowest mean wrong %
over them (within an optional budget), then runs that point and the technique's defaults on the
--validate setups, which must be disjoint from the train ones. The choice carries over when it
beats the defaults' mean wrong % on the validate setups and is no worse on at least half of them:
  shadowlab tune -t 'notw:window=8|16|32,blur=0|1' --train courtyard --train setups/sponza.toml \\
                 --validate city --validate setups/conference.toml --size 512x512
Each entry of --train/--validate is a setup file (.toml) or a built-in scene name. Writes
DIR/train and DIR/validate (sweep directories, resumed on a rerun), DIR/tune.json and DIR/tune.md.";

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
    pub worst_total_ms: f64,
    pub wrong_pct_by_setup: BTreeMap<String, f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Tune {
    pub schema_version: u32,
    pub technique: String,
    pub grid: Vec<String>,
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
        worst_total_ms: a.worst_total_ms,
        wrong_pct_by_setup: rows.iter().filter(|r| r.label == label).map(|r| (r.setup.clone(), r.wrong_pct)).collect(),
    })
}

/// Whether `chosen` carries over against `default` on the validate setups, and why.
pub fn verdict(chosen: Option<&Side>, default: &Side, same_values: bool) -> (bool, String) {
    let Some(c) = chosen else {
        return (false, "nothing in the grid fits the budget on the train setups: keep the defaults".into());
    };
    if same_values {
        return (false, format!("the best train point '{}' is the defaults: nothing to change", c.label));
    }
    let n = default.wrong_pct_by_setup.len();
    let no_worse = default.wrong_pct_by_setup.iter().filter(|(s, d)| c.wrong_pct_by_setup.get(*s).is_some_and(|w| w <= *d)).count();
    let better_mean = c.mean_wrong_pct < default.mean_wrong_pct;
    let carries = better_mean && 2 * no_worse >= n;
    let how = format!(
        "'{}' on the validate setups: mean wrong {:.3} % against the defaults' {:.3} %, no worse on {no_worse} of {n}",
        c.label, c.mean_wrong_pct, default.mean_wrong_pct
    );
    if carries {
        (true, format!("carries over: {how}"))
    } else {
        (false, format!("does not carry over (keep the defaults): {how}"))
    }
}

fn sweep_args(a: &TuneArgs, setups: &[String], techniques: Vec<String>, out: PathBuf) -> SweepArgs {
    SweepArgs {
        setups: setups.iter().filter(|s| is_setup_file(s)).map(PathBuf::from).collect(),
        scenes: setups.iter().filter(|s| !is_setup_file(s)).cloned().collect(),
        techniques,
        size: a.size.clone(),
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
    prepare_dir(&a.out)?;
    // the defaults run beside the grid on both lists
    let train =
        super::sweep(&sweep_args(a, &a.train, vec![a.technique.clone(), name.clone()], a.out.join("train"))).context("the train sweep")?;
    let aggs = aggregate(&train.rows);
    let grid_aggs: Vec<Aggregate> = aggs.iter().filter(|g| g.label != name).cloned().collect();
    let ranking: Vec<Side> =
        rank(&grid_aggs, train.setups.len(), &budget).into_iter().map(|g| side(&g.label, &train.rows, &aggs)).collect::<Result<_>>()?;
    let default_train = side(&name, &train.rows, &aggs)?;
    let chosen = ranking.first().map(|s| s.label.clone());
    let mut specs = vec![name.clone()];
    specs.extend(chosen.iter().cloned());
    let validate = super::sweep(&sweep_args(a, &a.validate, specs, a.out.join("validate"))).context("the validate sweep")?;
    let vaggs = aggregate(&validate.rows);
    let default_validate = side(&name, &validate.rows, &vaggs)?;
    let chosen_validate = chosen.as_deref().map(|c| side(c, &validate.rows, &vaggs)).transpose()?;
    let params = |s: &Sweep, label: &str| s.rows.iter().find(|r| r.label == label).map(|r| r.params.clone());
    let same = chosen.as_deref().is_some_and(|c| params(&train, c) == params(&train, &name));
    let (carries_over, verdict) = verdict(chosen_validate.as_ref(), &default_validate, same);
    let t = Tune {
        schema_version: 1,
        technique: name,
        grid,
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
    s += &format!("timer: {}\n\n| train ranking | mean wrong % | worst wrong % | worst ms |\n|---|---|---|---|\n", t.timer);
    for r in t.train_ranking.iter().chain(std::iter::once(&t.default_train)) {
        s += &format!("| {} | {:.3} | {:.3} | {:.1} |\n", r.label, r.mean_wrong_pct, r.worst_wrong_pct, r.worst_total_ms);
    }
    s += "\n| validate | mean wrong % | per setup |\n|---|---|---|\n";
    for r in t.chosen_validate.iter().chain(std::iter::once(&t.default_validate)) {
        let per: Vec<String> = r.wrong_pct_by_setup.iter().map(|(k, v)| format!("{k} {v:.3}")).collect();
        s += &format!("| {} | {:.3} | {} |\n", r.label, r.mean_wrong_pct, per.join(", "));
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
            worst_total_ms: 1.0,
            wrong_pct_by_setup: per.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
        }
    }

    #[test]
    fn a_choice_carries_over_only_where_the_held_out_setups_agree() {
        let d = side("notw", &[("a", 1.0), ("b", 2.0)]);
        let better = side("notw:window=8", &[("a", 0.8), ("b", 1.9)]);
        assert!(verdict(Some(&better), &d, false).0);
        // a better mean from one setup while the other gets worse: 1 of 2 no worse still carries
        let mixed = side("x", &[("a", 0.2), ("b", 2.5)]);
        assert!(verdict(Some(&mixed), &d, false).0);
        // better on one of three, worse mean: does not
        let d3 = side("notw", &[("a", 1.0), ("b", 1.0), ("c", 1.0)]);
        let one = side("y", &[("a", 0.1), ("b", 1.5), ("c", 1.6)]);
        let (ok, why) = verdict(Some(&one), &d3, false);
        assert!(!ok && why.contains("does not carry over"), "{why}");
        let lucky = side("z", &[("a", 0.1), ("b", 1.1), ("c", 1.1)]);
        assert!(!verdict(Some(&lucky), &d3, false).0, "better mean but worse on 2 of 3");
        assert!(verdict(Some(&better), &d, true).1.contains("is the defaults"));
        assert!(!verdict(None, &d, false).0);
    }

    #[test]
    fn entries_are_setup_files_or_scenes() {
        assert!(is_setup_file("setups/sponza.toml"));
        assert!(!is_setup_file("courtyard"));
    }
}
