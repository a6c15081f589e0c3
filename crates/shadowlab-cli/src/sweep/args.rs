//! The command line of `shadowlab sweep` and `shadowlab sweep merge`.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::{Args, Subcommand};

use super::choose::Budget;

pub const SWEEP_ABOUT: &str = "Sweep technique parameters over setups: quality/cost Pareto front, a recommendation for a budget";

pub const SWEEP_LONG: &str = "\
Runs every point (setup x spec) against the reference `rt`, computed once per view (setup x frame)
and reused by every spec. Value lists expand to their product:
  shadowlab sweep --scene courtyard --scene city -t 'sm:res=512|1024|2048,pcf=1|3' -t lt --budget-ms 20

Writes DIR/sweep.json, DIR/sweep.csv, DIR/index.html and one DIR/points/<key>.json per point. The
directory is resumed: a rerun computes only the points not finished yet (the key hashes the setup
and scene file contents, size, frames, repeat, light, time, the resolved spec and this binary).
Setups run in order: the --setup files as given, then the --scene names; none: the default scene.
`--shard i/n` (1-based) runs every n-th point of the plan starting at the i-th; `shadowlab sweep
merge DIR... --out DIR` joins the shards. See docs/sweep.md.";

/// `shadowlab sweep ...` or `shadowlab sweep merge ...`.
#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SweepCli {
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    #[command(flatten)]
    pub run: SweepArgs,
}

#[derive(Subcommand, Debug)]
pub enum SweepCommand {
    /// Merge the outputs of `--shard` runs (their points/*.json) into one sweep.json/csv/report
    Merge(MergeArgs),
}

/// Budget of the recommendation (all optional; none: no recommendation).
#[derive(Args, Clone, Debug, Default)]
pub struct BudgetArgs {
    /// Recommend the best spec whose worst-case total ms over the setups is at most this
    /// (timer dependent: wall clock on software adapters such as lavapipe)
    #[arg(long)]
    pub budget_ms: Option<f64>,
    /// ... whose largest shadow data over the setups is at most this many MiB
    #[arg(long)]
    pub budget_mb: Option<f64>,
    /// ... whose largest shadow data is at most this many bytes (hardware-independent)
    #[arg(long)]
    pub budget_bytes: Option<u64>,
}

impl BudgetArgs {
    pub fn budget(&self) -> Result<Budget> {
        for (name, v) in [("--budget-ms", self.budget_ms), ("--budget-mb", self.budget_mb)] {
            if let Some(x) = v {
                if !x.is_finite() || x <= 0.0 {
                    bail!("{name} {x}: must be a positive number");
                }
            }
        }
        Ok(Budget { ms: self.budget_ms, mib: self.budget_mb, bytes: self.budget_bytes })
    }
}

#[derive(Args, Clone, Debug)]
pub struct SweepArgs {
    /// TOML setup file; repeatable (each one is a setup of the sweep)
    #[arg(long = "setup")]
    pub setups: Vec<PathBuf>,
    /// Built-in scene name or scene file, with its own camera and lights; repeatable (each one is a setup)
    #[arg(long = "scene")]
    pub scenes: Vec<String>,
    /// Technique spec with value lists, e.g. 'sm:res=512|1024,pcf=1|3'; repeatable; applies to every
    /// setup (default: each setup's own list, else the default compare set)
    #[arg(short = 't', long = "technique")]
    pub techniques: Vec<String>,
    /// Output size WxH for every setup (default: each setup's, else 1024x1024)
    #[arg(long)]
    pub size: Option<String>,
    /// Frames along each setup's camera path (1 = the single view of frame 0)
    #[arg(long, default_value_t = 1)]
    pub frames: usize,
    /// Timed repetitions per point after one warm-up (median reported)
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Index of the light to evaluate in every setup
    #[arg(long, default_value_t = 0)]
    pub light: usize,
    /// Animation time of frame 0, in frames (default: each setup's `time`, else 0)
    #[arg(long)]
    pub time: Option<f32>,
    /// Output directory (resumed when it holds a sweep; refused when it holds anything else)
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    /// Run shard i of n (1-based: 1/4 .. 4/4): the points at plan positions i-1, i-1+n, ...
    #[arg(long)]
    pub shard: Option<String>,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// No progress bar or summary
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Args, Clone, Debug)]
pub struct MergeArgs {
    /// Shard output directories (each with its sweep.json and points/)
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Output directory of the merged sweep
    #[arg(long, default_value = "sweep")]
    pub out: PathBuf,
    #[command(flatten)]
    pub budget: BudgetArgs,
    /// No summary
    #[arg(long, short)]
    pub quiet: bool,
}
