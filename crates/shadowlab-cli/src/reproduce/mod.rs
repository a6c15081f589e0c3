//! `shadowlab reproduce`: the experiments behind the seeds' headline tables and figures, run as
//! sweeps on our closest scenes (cached and resumable: DIR/<run>/ is a sweep directory), each
//! claim of claims.toml judged on their rows, and one report with a verdict per claim.
//!
//! Flow: [`data`] (the claims, compiled in) -> one sweep per run -> [`verdict`] per claim ->
//! [`report`] (DIR/reproduce.json, DIR/reproduce.md, DIR/index.html).

pub mod data;
mod report;
pub mod verdict;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;

use crate::sweep::args::{BudgetArgs, SweepArgs};
use data::{Data, Run};
use verdict::{judge, Outcome, Verdict};

pub const ABOUT: &str = "Reproduce the seeds' headline tables and figures: a verdict per claim";

pub const LONG: &str = "\
Runs, as sweeps, the experiments behind each seed's headline tables and figures on our closest
scenes, prints the paper's figure beside ours and writes DIR/index.html, DIR/reproduce.md and
DIR/reproduce.json with a verdict per claim: reproduced, not reproduced, or not comparable (why).
  shadowlab reproduce all                 # 000 001 002 003 004 at 1024x1024
  shadowlab reproduce 003 --size 256x256  # one seed, smaller
  shadowlab reproduce all --quick         # 256x256, one timed repetition, at most 2 frames
The papers' figures are in crates/shadowlab-cli/src/reproduce/claims.toml with their sections.
Times on a software adapter (lavapipe: wall clock) are not the paper's GPU: such claims are
'not comparable' (the report says whether they would hold within the run); on a GPU with
timestamps the same command judges them. Setups needing ../shared/scenes are skipped (not
comparable) where the scene files are missing. DIR/<run>/ are sweeps: a rerun resumes.";

/// The base output size (the seeds' evaluation size, seeds 000/002/003 section 5).
pub const DEFAULT_SIZE: (u32, u32) = (1024, 1024);
/// `--quick`: base size, repetitions and the most frames per run.
pub const QUICK_SIZE: (u32, u32) = (256, 256);
pub const QUICK_REPEAT: usize = 1;
pub const QUICK_FRAMES: usize = 2;
/// No run is smaller than this per side (a scaled --size).
pub const MIN_SIDE: u32 = 16;

#[derive(Args, Clone, Debug)]
pub struct ReproduceArgs {
    /// Seeds to reproduce: 000, 001, 002, 003, 004 or all
    #[arg(default_value = "all")]
    pub seeds: Vec<String>,
    /// Output directory (resumed)
    #[arg(long, default_value = "reproduce")]
    pub out: PathBuf,
    /// Base output size WxH (runs scale it; default 1024x1024, the seeds' size)
    #[arg(long)]
    pub size: Option<String>,
    /// A quick run: 256x256 base size, one timed repetition, at most 2 frames per run
    #[arg(long)]
    pub quick: bool,
    /// Timed repetitions per point after one warm-up (median reported)
    #[arg(long)]
    pub repeat: Option<usize>,
    /// Directory of the shipped setups
    #[arg(long, default_value = "setups")]
    pub setups: PathBuf,
    /// No progress bars or tables
    #[arg(long, short)]
    pub quiet: bool,
}

/// One run as the report records it.
#[derive(Clone, Debug, Serialize)]
pub struct RunRecord {
    pub id: String,
    pub seed: String,
    pub closest: String,
    pub input: String,
    pub light: usize,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub techniques: Vec<String>,
    /// null when it ran; else why not.
    pub skipped: Option<String>,
    pub points_computed: usize,
    pub points_cached: usize,
    pub timer: String,
    pub adapter: String,
    pub seconds: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Reproduction {
    pub schema_version: u32,
    pub seeds: Vec<String>,
    pub width: u32,
    pub height: u32,
    pub repeat: usize,
    pub quick: bool,
    pub runs: Vec<RunRecord>,
    pub claims: Vec<data::Claim>,
    pub verdicts: Vec<Verdict>,
    pub points_computed: usize,
    pub points_cached: usize,
    pub seconds: f64,
}

/// The seeds `which` names, in order; `all` = every seed.
pub fn select(which: &[String], d: &Data) -> Result<Vec<String>> {
    let all: Vec<String> = d.seed.iter().map(|s| s.id.clone()).collect();
    let mut v: Vec<String> = Vec::new();
    for w in which {
        let w = w.trim();
        if w == "all" {
            v.extend(all.iter().cloned());
        } else if all.iter().any(|s| s == w) {
            v.push(w.to_string());
        } else {
            bail!("unknown seed '{w}': choose from {} or all", all.join(", "));
        }
    }
    v.retain({
        let mut seen = std::collections::BTreeSet::new();
        move |s| seen.insert(s.clone())
    });
    v.sort();
    Ok(v)
}

/// A run's output size: the base scaled, at least [`MIN_SIDE`].
pub fn run_size(base: (u32, u32), scale: f64) -> (u32, u32) {
    let s = |x: u32| ((x as f64 * scale).round() as u32).max(MIN_SIDE);
    (s(base.0), s(base.1))
}

/// Why a setup file cannot run here (missing, or its scene file missing); None: it can.
fn missing(setup: &Path) -> Option<String> {
    let text = match std::fs::read_to_string(setup) {
        Ok(t) => t,
        Err(_) => return Some(format!("setup file {} not found", setup.display())),
    };
    let v: toml::Value = toml::from_str(&text).ok()?;
    let path = v.get("scene")?.get("path")?.as_str()?;
    let scene = setup.parent().unwrap_or(Path::new(".")).join(path);
    (!scene.exists()).then(|| format!("scene file {} not found (the real scenes live in ../shared/scenes)", scene.display()))
}

fn prepare_dir(dir: &Path) -> Result<()> {
    let marker = dir.join(".shadowlab-reproduce");
    if dir.exists() && !marker.exists() && std::fs::read_dir(dir).map(|mut d| d.next().is_some()).unwrap_or(true) {
        bail!("{} exists and was not written by `shadowlab reproduce`; choose another --out", dir.display());
    }
    std::fs::create_dir_all(dir)?;
    std::fs::write(marker, b"shadowlab reproduce output\n")?;
    Ok(())
}

fn write(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension("partial");
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).with_context(|| path.display().to_string())
}

/// Runs one experiment as a sweep.
fn run_one(a: &ReproduceArgs, r: &Run, size: (u32, u32), frames: usize, repeat: usize) -> (Outcome, RunRecord) {
    let t0 = std::time::Instant::now();
    let input = r.setup.as_ref().map(|s| a.setups.join(s).display().to_string()).or(r.scene.clone()).unwrap_or_default();
    let mut rec = RunRecord {
        id: r.id.clone(),
        seed: r.seed.clone(),
        closest: r.closest.clone(),
        input: input.clone(),
        light: r.light,
        width: size.0,
        height: size.1,
        frames,
        techniques: r.techniques.clone(),
        skipped: None,
        points_computed: 0,
        points_cached: 0,
        timer: String::new(),
        adapter: String::new(),
        seconds: 0.0,
    };
    if let Some(why) = r.setup.as_ref().and_then(|_| missing(Path::new(&input))) {
        rec.skipped = Some(why.clone());
        return (Outcome::Skipped(why), rec);
    }
    let args = SweepArgs {
        setups: r.setup.iter().map(|_| PathBuf::from(&input)).collect(),
        scenes: r.scene.iter().cloned().collect(),
        techniques: r.techniques.clone(),
        size: Some(format!("{}x{}", size.0, size.1)),
        frames,
        repeat,
        light: r.light,
        time: None,
        out: a.out.join(&r.id),
        shard: None,
        budget: BudgetArgs::default(),
        quiet: true,
    };
    let out = match crate::sweep::sweep(&args) {
        Ok(s) => {
            rec.points_computed = s.points_computed;
            rec.points_cached = s.points_cached;
            rec.timer = s.timer.clone();
            rec.adapter = s.adapter.clone();
            Outcome::Done { software_adapter: s.software_adapter, timer: s.timer, rows: s.rows }
        }
        Err(e) => {
            let why = format!("the sweep failed: {e:#}");
            eprintln!("warning: run {}: {why}", r.id);
            rec.skipped = Some(why.clone());
            Outcome::Skipped(why)
        }
    };
    rec.seconds = t0.elapsed().as_secs_f64();
    (out, rec)
}

pub fn reproduce(a: &ReproduceArgs) -> Result<()> {
    let t0 = std::time::Instant::now();
    let d = data::load()?;
    let seeds = select(&a.seeds, &d)?;
    let base = match (&a.size, a.quick) {
        (Some(s), _) => crate::config::parse_size(s)?,
        (None, true) => QUICK_SIZE,
        (None, false) => DEFAULT_SIZE,
    };
    let repeat = a.repeat.unwrap_or(if a.quick { QUICK_REPEAT } else { 3 });
    if repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    prepare_dir(&a.out)?;
    let runs: Vec<&Run> = d.run.iter().filter(|r| seeds.contains(&r.seed)).collect();
    let mut outcomes = BTreeMap::new();
    let mut records = Vec::new();
    for (k, r) in runs.iter().enumerate() {
        let size = run_size(base, r.scale);
        let frames = if a.quick { r.frames.min(QUICK_FRAMES) } else { r.frames };
        if !a.quiet {
            let what = r.setup.as_deref().or(r.scene.as_deref()).unwrap_or_default();
            eprintln!(
                "[{}/{}] {} ({what}, {}x{}, {} specs x {frames} frames) ...",
                k + 1,
                runs.len(),
                r.id,
                size.0,
                size.1,
                r.techniques.len()
            );
        }
        let (o, rec) = run_one(a, r, size, frames, repeat);
        if !a.quiet {
            match &rec.skipped {
                Some(why) => eprintln!("      skipped: {why}"),
                None => eprintln!("      {} computed, {} cached, {:.1} s", rec.points_computed, rec.points_cached, rec.seconds),
            }
        }
        outcomes.insert(r.id.clone(), o);
        records.push(rec);
    }
    let claims: Vec<data::Claim> = d.claim.iter().filter(|c| seeds.iter().any(|s| s == c.seed())).cloned().collect();
    let verdicts: Vec<Verdict> = claims.iter().map(|c| judge(c, &outcomes)).collect();
    let rep = Reproduction {
        schema_version: 1,
        seeds,
        width: base.0,
        height: base.1,
        repeat,
        quick: a.quick,
        points_computed: records.iter().map(|r| r.points_computed).sum(),
        points_cached: records.iter().map(|r| r.points_cached).sum(),
        runs: records,
        claims,
        verdicts,
        seconds: t0.elapsed().as_secs_f64(),
    };
    write(&a.out.join("reproduce.json"), serde_json::to_string_pretty(&rep)?.as_bytes())?;
    let md = report::markdown(&rep, &d);
    write(&a.out.join("reproduce.md"), md.as_bytes())?;
    write(&a.out.join("index.html"), report::html(&rep, &d).as_bytes())?;
    if !a.quiet {
        print!("{}", report::terminal(&rep));
        println!("report: {} ({:.1} s)", a.out.join("index.html").display(), rep.seconds);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seeds_and_sizes() {
        let d = data::load().unwrap();
        assert_eq!(select(&["all".into()], &d).unwrap(), ["000", "001", "002", "003", "004"]);
        assert_eq!(select(&["003".into(), "000".into(), "003".into()], &d).unwrap(), ["000", "003"]);
        assert!(select(&["005".into()], &d).unwrap_err().to_string().contains("unknown seed '005'"));
        assert_eq!(run_size((1024, 1024), 0.5), (512, 512));
        assert_eq!(run_size((64, 48), 0.1), (16, 16));
    }

    #[test]
    fn setups_without_their_scene_files_are_skipped_with_why() {
        let dir = std::env::temp_dir().join(format!("shadowlab-repro-missing-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("s.toml");
        std::fs::write(&f, "[scene]\npath = \"nowhere/x.obj\"\n").unwrap();
        assert!(missing(&f).unwrap().contains("scene file"));
        std::fs::write(&f, "[scene]\nbuiltin = \"courtyard\"\n").unwrap();
        assert_eq!(missing(&f), None);
        assert!(missing(&dir.join("none.toml")).unwrap().contains("not found"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
