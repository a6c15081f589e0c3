//! `shadowlab sweep`: technique specs with value lists over several setups, each point judged
//! against the reference computed once per view; a resumable per-point cache, shards and their
//! merge, a quality/cost report with the Pareto front, and a recommendation for a budget.
//!
//! Flow: [`expand`] the `-t` lists (checked against the registry) -> [`plan`] the setups and
//! point keys (checked like `compare`) -> skip what [`cache`] holds -> [`run`] the rest per
//! setup -> [`record`] rows, [`choose`] aggregates and recommendation -> [`report`].

pub mod args;
mod cache;
mod choose;
mod expand;
mod halving;
mod json;
mod key;
mod merge;
mod plan;
pub(crate) mod record;
mod report;
mod run;
pub mod tune;

use std::collections::BTreeSet;

use anyhow::{bail, Result};
use indicatif::{ProgressBar, ProgressStyle};
use shadowlab_gpu::Gpu;

use args::{SweepArgs, SweepCli, SweepCommand};
use cache::SweepDir;
use choose::{aggregate, recommend, Budget};
use json::Sweep;
use plan::{Common, SetupInput};
use record::{PlanEntry, PointFile, Row, SetupInfo, Shard, SCHEMA_VERSION};

/// `shadowlab sweep` and `shadowlab sweep merge`.
pub fn main(cli: &SweepCli) -> Result<()> {
    match &cli.command {
        Some(SweepCommand::Merge(m)) => merge::merge(m),
        None => sweep(&cli.run).map(|_| ()),
    }
}

fn progress(quiet: bool, len: u64) -> ProgressBar {
    if quiet || len == 0 {
        return ProgressBar::hidden();
    }
    let pb = ProgressBar::new(len);
    pb.set_style(ProgressStyle::with_template("{bar:30} {pos}/{len} {elapsed} (ETA {eta}) {msg}").unwrap());
    pb
}

/// Runs a sweep and writes its directory; returns what sweep.json holds.
pub fn sweep(a: &SweepArgs) -> Result<Sweep> {
    let t0 = std::time::Instant::now();
    shadowlab_gpu::lab::path::check_frames(a.frames)?;
    if a.repeat == 0 {
        bail!("--repeat must be at least 1");
    }
    if let Some(t) = a.time.filter(|t| !t.is_finite()) {
        bail!("--time {t}: must be a finite number of frames");
    }
    let shard = a.shard.as_deref().map(plan::parse_shard).transpose()?;
    let budget = a.budget.budget()?;
    // before any scene is loaded: the lists and their values, and the output directory
    let specs = expand::expand(&a.techniques)?;
    cache::check(&a.out)?;
    let binary = key::binary_version()?;
    let inputs: Vec<SetupInput> =
        a.setups.iter().map(|p| SetupInput::File(p.clone())).chain(a.scenes.iter().map(|s| SetupInput::Scene(s.clone()))).collect();
    let common =
        Common { specs: &specs, size: a.size.clone(), frames: a.frames, repeat: a.repeat, light: a.light, time: a.time, binary: &binary };
    let setups = plan::plan(&inputs, &common)?;
    let entries = plan::entries(&setups);
    let selected: BTreeSet<usize> = plan::selected(entries.len(), shard).into_iter().collect();
    let dir = SweepDir::open(&a.out)?;

    // per setup: the selected points and which of them are finished already
    let mut results: Vec<Option<Row>> = vec![None; entries.len()];
    let mut pending: Vec<Vec<usize>> = Vec::new();
    let mut position = 0;
    for s in &setups {
        let mut todo = Vec::new();
        for (k, (key, _)) in s.keys.iter().enumerate() {
            if selected.contains(&position) {
                match dir.read_point(key) {
                    Some(p) => results[position] = Some(p.row),
                    None => todo.push(k),
                }
            }
            position += 1;
        }
        pending.push(todo);
    }
    let cached = results.iter().filter(|r| r.is_some()).count();
    let total_steps: u64 = pending.iter().map(|p| run::steps(a.frames, p.len())).sum();
    let (mut computed, mut views) = (0, 0);
    if total_steps > 0 {
        let gpu = Gpu::new()?;
        let pb = progress(a.quiet, total_steps);
        let mut first = 0;
        for (s, todo) in setups.iter().zip(&pending) {
            let mut done = |k: usize, row: Row| -> Result<()> {
                let (key, key_text) = s.keys[k].clone();
                dir.write_point(&PointFile { schema_version: SCHEMA_VERSION, key, key_text, row: row.clone() })?;
                results[first + k] = Some(row);
                computed += 1;
                Ok(())
            };
            views += run::run_setup(&gpu, s, todo, a.frames, a.repeat, &pb, &mut done)?;
            first += s.keys.len();
        }
        pb.finish_and_clear();
    }
    let rows: Vec<Row> = results.into_iter().flatten().collect();
    let infos: Vec<SetupInfo> = setups.iter().map(|s| s.info.clone()).collect();
    let header = Header { frames: a.frames, repeat: a.repeat, light: a.light, time: a.time, setups: infos, plan: entries };
    let sweep = assemble(header, shard, rows, budget, (computed, cached, views), Vec::new());
    finish(&dir, &sweep)?;
    warnings(&sweep);
    if !a.quiet {
        summary(&sweep);
        println!("report: {} ({:.1} s)", dir.root.join("index.html").display(), t0.elapsed().as_secs_f64());
    }
    Ok(sweep)
}

/// What a sweep.json says about the plan, shared by a run and a merge.
pub struct Header {
    pub frames: usize,
    pub repeat: usize,
    pub light: usize,
    /// `--time`, or null: each setup's own `time`
    pub time: Option<f32>,
    pub setups: Vec<SetupInfo>,
    pub plan: Vec<PlanEntry>,
}

/// The rows' distinct values of `f`, joined (`; `).
fn distinct(rows: &[Row], f: impl Fn(&Row) -> &str) -> String {
    let mut v: Vec<&str> = Vec::new();
    for r in rows {
        if !v.contains(&f(r)) {
            v.push(f(r));
        }
    }
    v.join("; ")
}

/// sweep.json from its rows: the aggregates over the setups and the recommendation.
pub fn assemble(
    h: Header,
    shard: Option<Shard>,
    rows: Vec<Row>,
    budget: Budget,
    counts: (usize, usize, usize),
    merged_from: Vec<String>,
) -> Sweep {
    let aggregates = aggregate(&rows);
    let recommendation = recommend(&aggregates, h.setups.len(), &budget);
    Sweep {
        schema_version: SCHEMA_VERSION,
        adapter: distinct(&rows, |r| &r.adapter),
        software_adapter: rows.iter().any(|r| r.software_adapter),
        timer: distinct(&rows, |r| &r.timer),
        stages_timer: distinct(&rows, |r| &r.stages_timer),
        frames: h.frames,
        repeat: h.repeat,
        light: h.light,
        time: h.time,
        setups: h.setups,
        shard,
        plan: h.plan,
        points_computed: counts.0,
        points_cached: counts.1,
        views_computed: counts.2,
        merged_from,
        rows,
        aggregates,
        budget,
        recommendation,
    }
}

/// Writes sweep.json, sweep.csv and index.html (each through a temporary file and a rename).
pub fn finish(dir: &SweepDir, sweep: &Sweep) -> Result<()> {
    dir.write("sweep.json", sweep.to_json()?.as_bytes())?;
    dir.write("sweep.csv", record::csv(&sweep.rows).as_bytes())?;
    dir.write("index.html", report::html(sweep)?.as_bytes())?;
    Ok(())
}

/// One warning line per degraded point (a capacity limit reached), as `compare` prints them.
pub fn warnings(s: &Sweep) {
    for r in &s.rows {
        for d in &r.degraded {
            eprintln!("warning: {} / {} is degraded: {d}", r.setup, r.label);
        }
    }
}

/// The terminal summary: counts, the timer, the recommendation.
pub fn summary(s: &Sweep) {
    let shard = s.shard.map(|sh| format!(" (shard {}/{} of {} points)", sh.index, sh.count, s.plan.len())).unwrap_or_default();
    println!(
        "sweep: {} points{shard}: {} computed, {} cached; {} views (G-buffer + rt) computed",
        s.rows.len(),
        s.points_computed,
        s.points_cached,
        s.views_computed
    );
    if !s.timer.is_empty() {
        println!("timer: {} ({})", s.timer, s.adapter);
    }
    for line in report::recommendation_lines(s) {
        println!("{line}");
    }
}
