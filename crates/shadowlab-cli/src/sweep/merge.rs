//! `shadowlab sweep merge DIR... --out DIR`: the shards of one sweep (same plan) joined into one
//! sweep.json, sweep.csv and report. Every point of the plan must be in some shard's `points/`;
//! the merged directory gets them all, so it is itself a complete, resumable sweep.

use anyhow::{bail, Context, Result};

use super::args::MergeArgs;
use super::cache::SweepDir;
use super::json::Sweep;
use super::record::Row;
use super::{assemble, finish, summary, Header};

fn read_sweep(dir: &std::path::Path) -> Result<Sweep> {
    let path = dir.join("sweep.json");
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("reading {} (a shard writes it when it finishes: rerun that shard, it resumes)", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not a sweep.json of this shadowlab", path.display()))
}

pub fn merge(a: &MergeArgs) -> Result<()> {
    let budget = a.budget.budget()?;
    super::cache::check(&a.out)?;
    let sweeps: Vec<Sweep> = a.dirs.iter().map(|d| read_sweep(d)).collect::<Result<_>>()?;
    let first = &sweeps[0];
    for (s, d) in sweeps.iter().zip(&a.dirs).skip(1) {
        if s.plan != first.plan {
            bail!(
                "{} is a shard of another sweep than {} (their plans of points differ: other setups, specs, options or binary); merge only the shards of one sweep",
                d.display(),
                a.dirs[0].display()
            );
        }
    }
    let mut points = std::collections::BTreeMap::new();
    for d in &a.dirs {
        points.append(&mut SweepDir::all_points(d)?);
    }
    let missing: Vec<String> =
        first.plan.iter().filter(|e| !points.contains_key(&e.key)).map(|e| format!("{} / {}", e.setup, e.label)).collect();
    if !missing.is_empty() {
        let shown: Vec<&str> = missing.iter().take(5).map(String::as_str).collect();
        bail!(
            "{} of {} points are in none of the shards ({}{}); run the missing shards (or rerun an interrupted one: it resumes), then merge again",
            missing.len(),
            first.plan.len(),
            shown.join(", "),
            if missing.len() > 5 { ", ..." } else { "" }
        );
    }
    let out = SweepDir::open(&a.out)?;
    let mut rows: Vec<Row> = Vec::new();
    for e in &first.plan {
        let p = &points[&e.key];
        if out.read_point(&e.key).is_none() {
            out.write_point(p)?;
        }
        rows.push(p.row.clone());
    }
    let header = Header {
        frames: first.frames,
        repeat: first.repeat,
        light: first.light,
        time: first.time,
        setups: first.setups.clone(),
        plan: first.plan.clone(),
    };
    let from = a.dirs.iter().map(|d| d.display().to_string()).collect();
    let n = rows.len();
    let sweep = assemble(header, None, rows, budget, (0, n, 0), from);
    finish(&out, &sweep)?;
    super::warnings(&sweep);
    if !a.quiet {
        summary(&sweep);
        println!("report: {}", out.root.join("index.html").display());
    }
    Ok(())
}
