//! `shadowlab`: render, compare and benchmark shadow techniques against an exact reference.

mod bench;
mod compare;
mod config;
mod export;
mod listing;
mod metrics;
mod output;
mod report;
mod reproduce;
mod sweep;
mod view;

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

#[derive(Parser)]
#[command(name = "shadowlab", version, about = "Shadow-technique lab: every technique against an exact ray-traced reference")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// Where a run comes from: a setup file and/or a scene, with overrides.
#[derive(Args, Clone, Debug, Default)]
pub struct RunArgs {
    /// TOML setup file (scene, camera, lights, output size, techniques)
    #[arg(long)]
    pub setup: Option<PathBuf>,
    /// Built-in scene name or scene file (.gltf, .glb, .obj); overrides the setup's scene
    #[arg(long)]
    pub scene: Option<String>,
    /// Technique spec `name` or `name:key=value,...`; repeatable; overrides the setup's list
    #[arg(short = 't', long = "technique")]
    pub techniques: Vec<String>,
    /// Output size WxH (default: the setup's, else 1024x1024)
    #[arg(long)]
    pub size: Option<String>,
    /// Index of the light to evaluate (default 0)
    #[arg(long, default_value_t = 0)]
    pub light: usize,
    /// Timed repetitions per technique after one warm-up (median reported)
    #[arg(long, default_value_t = 3)]
    pub repeat: usize,
    /// Frames along the camera path (the setup's `[[camera.path]]`, else the built-in scene's;
    /// the camera holds still where there is none). 1 = the single view of frame 0
    #[arg(long, default_value_t = 1)]
    pub frames: usize,
    /// Animation time of frame 0, in frames (moving objects: frame k of `--frames` is at
    /// time + k; a single view is at this time). Default: the setup's `time`, else 0
    #[arg(long)]
    pub time: Option<f32>,
    /// No progress bar or summary
    #[arg(long, short)]
    pub quiet: bool,
}

#[derive(Subcommand)]
enum Command {
    /// List built-in scenes and shipped setups
    Scenes,
    /// List techniques with their parameters, defaults and sources
    Techniques,
    /// Render one technique (default `rt`) to a shaded PNG
    Render {
        #[command(flatten)]
        run: RunArgs,
        /// Output PNG
        #[arg(long, default_value = "render.png")]
        out: PathBuf,
    },
    /// Compare techniques against `rt`: report/index.html, metrics.json/.csv, PNGs
    Compare {
        #[command(flatten)]
        run: RunArgs,
        /// Output directory (written under a temporary name, then renamed)
        #[arg(long, default_value = "report")]
        out: PathBuf,
        /// Also write position/normal/mask/visibility .npy files for Python
        #[arg(long)]
        export: bool,
    },
    /// Interactive viewer: fly, move the light, edit parameters live, see the error against `rt`
    View(view::ViewArgs),
    #[command(about = sweep::args::SWEEP_ABOUT, long_about = sweep::args::SWEEP_LONG)]
    Sweep(sweep::args::SweepCli),
    #[command(about = sweep::tune::TUNE_ABOUT, long_about = sweep::tune::TUNE_LONG)]
    Tune(sweep::tune::TuneArgs),
    #[command(about = reproduce::ABOUT, long_about = reproduce::LONG)]
    Reproduce(reproduce::ReproduceArgs),
    /// Time every stage on the built-in scenes (and sponza/conference when present)
    Bench {
        /// Setup files to benchmark (default: the built-in scenes plus setups/sponza.toml and setups/conference.toml when their scenes exist)
        #[arg(long)]
        setup: Vec<PathBuf>,
        /// Output size WxH
        #[arg(long, default_value = "1024x1024")]
        size: String,
        /// Timed frames per stage (median reported)
        #[arg(long, default_value_t = 5)]
        frames: usize,
        /// Write the markdown table here as well as to stdout
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Mesa's window-system code prints `error: XDG_RUNTIME_DIR is invalid or not set in the
/// environment.` on every run where the variable is missing, which users read as shadowlab's
/// error. Only `view` opens a window (through X11, which needs no runtime directory): a private
/// runtime directory (0700, under the temporary directory) stands in for it, so that every
/// `error:` line is shadowlab's own.
fn ensure_runtime_dir() {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        if std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| !d.is_empty()) {
            return;
        }
        let uid = std::fs::metadata("/proc/self").map(|m| m.uid()).unwrap_or(0);
        let dir = std::env::temp_dir().join(format!("shadowlab-runtime-{uid}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        let ours = std::fs::metadata(&dir).is_ok_and(|m| m.is_dir() && m.uid() == uid && m.mode() & 0o077 == 0);
        if ours {
            // single-threaded here: nothing else reads the environment yet
            std::env::set_var("XDG_RUNTIME_DIR", &dir);
        }
    }
}

fn main() {
    ensure_runtime_dir();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Scenes => listing::scenes(),
        Command::Techniques => listing::techniques(),
        Command::Render { run, out } => compare::render(&run, &out),
        Command::Compare { run, out, export } => compare::compare(&run, &out, export),
        Command::View(args) => view::view(&args),
        Command::Sweep(cli) => sweep::main(&cli),
        Command::Tune(args) => sweep::tune::tune(&args),
        Command::Reproduce(args) => reproduce::reproduce(&args),
        Command::Bench { setup, size, frames, out } => bench::bench(&setup, &size, frames, out.as_deref()),
    };
    if let Err(e) = result {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
