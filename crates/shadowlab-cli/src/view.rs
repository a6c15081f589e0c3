//! `view`: the interactive viewer (crate `shadowlab-view`), resolved like `compare`.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;
use shadowlab_core::setup::{SceneSection, Setup};

use crate::config::resolve;
use crate::RunArgs;

#[derive(Args, Clone, Debug, Default)]
pub struct ViewArgs {
    /// TOML setup file (scene, camera, lights, techniques)
    #[arg(long)]
    pub setup: Option<PathBuf>,
    /// Built-in scene name or scene file (.gltf, .glb, .obj); overrides the setup's scene
    #[arg(long)]
    pub scene: Option<String>,
    /// Technique spec: the first is A, a second is B (split screen); default: the setup's first
    /// technique, else the first of the default compare set the light supports
    #[arg(short = 't', long = "technique")]
    pub techniques: Vec<String>,
    /// Fixed render size WxH (default: follows the window)
    #[arg(long)]
    pub size: Option<String>,
    /// Index of the light (default 0)
    #[arg(long, default_value_t = 0)]
    pub light: usize,
    /// Animation time, in frames (default: the setup's `time`, else 0)
    #[arg(long)]
    pub time: Option<f32>,
    /// What the picture shows first: shaded, visibility or error (against rt)
    #[arg(long, default_value = "shaded", value_parser = ["shaded", "visibility", "error"])]
    pub show: String,
    /// Directory for saved setups (F2) and screenshots (F12)
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// Render this many frames, then exit (scripted runs, CI)
    #[arg(long)]
    pub exit_after: Option<usize>,
    /// Write the last frame's picture to this PNG (with --exit-after)
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Turn the camera about its target by this many degrees per frame (scripted runs)
    #[arg(long, default_value_t = 0.0)]
    pub orbit: f32,
    /// Orbit only during the first N frames, then hold still (with --orbit)
    #[arg(long)]
    pub orbit_frames: Option<usize>,
    /// Set a parameter of technique A at a frame: FRAME:KEY=VALUE (repeatable; scripted runs)
    #[arg(long = "set-at")]
    pub set_at: Vec<String>,
    /// Run this many seconds, then exit (scripted runs, long sessions)
    #[arg(long)]
    pub exit_after_s: Option<f64>,
    /// Technique A becomes the next of these specs every --cycle-every frames (repeatable;
    /// scripted runs)
    #[arg(long = "cycle")]
    pub cycle: Vec<String>,
    /// Frames between --cycle steps
    #[arg(long, default_value_t = 0)]
    pub cycle_every: usize,
    /// Turn the light about the vertical axis by this many degrees at each --cycle step
    #[arg(long, default_value_t = 0.0)]
    pub light_turn: f32,
    /// Print the resident memory every this many seconds (scripted runs: `memory:` lines)
    #[arg(long)]
    pub memory_every: Option<f64>,
    /// Destroy the GPU device before frame N, as a driver reset would (tests the viewer's
    /// handling of a lost device: it saves the view and exits with a message)
    #[arg(long, hide = true)]
    pub lose_device_at: Option<usize>,
}

pub fn view(args: &ViewArgs) -> Result<()> {
    if args.screenshot.is_some() && args.exit_after.is_none() && args.exit_after_s.is_none() {
        bail!("--screenshot writes the last frame of a scripted run: give --exit-after N too (or press F12 in the window)");
    }
    if args.exit_after == Some(0) {
        bail!("--exit-after must be at least 1");
    }
    if args.exit_after_s.is_some_and(|s| !(s.is_finite() && s > 0.0)) {
        bail!("--exit-after-s must be a positive number of seconds");
    }
    if !args.cycle.is_empty() && args.cycle_every == 0 {
        bail!("--cycle changes technique A every --cycle-every N frames: give N (at least 1)");
    }
    if args.cycle.is_empty() && (args.cycle_every > 0 || args.light_turn != 0.0) {
        bail!("--cycle-every and --light-turn act at --cycle steps: give --cycle SPEC (repeatable)");
    }
    for spec in &args.cycle {
        shadowlab_view::widgets::resolve_text(spec).map_err(|e| anyhow!("--cycle {spec}: {e}"))?;
    }
    if !args.light_turn.is_finite() || args.memory_every.is_some_and(|s| !(s.is_finite() && s > 0.0)) {
        bail!("--light-turn must be a finite number of degrees and --memory-every a positive number of seconds");
    }
    if !args.orbit.is_finite() {
        bail!("--orbit {}: must be a finite number of degrees", args.orbit);
    }
    let set_at = args.set_at.iter().map(|s| shadowlab_view::script::parse_set_at(s).map_err(|e| anyhow!(e))).collect::<Result<Vec<_>>>()?;
    if args.techniques.len() > 2 {
        bail!("view shows at most two techniques (A, and B on the right of a split screen); got {}", args.techniques.len());
    }
    // before loading a scene: a window must be possible
    if let Some(p) = shadowlab_view::display_problem() {
        bail!(p);
    }
    let run = RunArgs {
        setup: args.setup.clone(),
        scene: args.scene.clone(),
        techniques: args.techniques.clone(),
        size: args.size.clone(),
        light: args.light,
        time: args.time,
        ..Default::default()
    };
    let cfg = resolve(&run, &shadowlab_gpu::registry::default_compare())?;
    let mut specs = cfg.specs.clone().into_iter();
    let a = specs.next().ok_or_else(|| anyhow!("no technique supports this {} light", cfg.light().kind()))?;
    let b = if args.techniques.len() == 2 { specs.next() } else { None };
    let setup = base_setup(args)?;
    let opts = shadowlab_view::Options {
        camera: cfg.camera,
        camera_path: cfg.camera_path.clone(),
        light: *cfg.light(),
        a,
        b,
        size: args.size.as_ref().map(|_| (cfg.width, cfg.height)),
        time: cfg.time,
        out_dir: args.out.clone(),
        show: match args.show.as_str() {
            "visibility" => shadowlab_view::render::Show::Visibility,
            "error" => shadowlab_view::render::Show::Error,
            _ => shadowlab_view::render::Show::Shaded,
        },
        script: shadowlab_view::script::Script {
            exit_after: args.exit_after,
            screenshot: args.screenshot.clone(),
            orbit_deg: args.orbit,
            orbit_frames: args.orbit_frames,
            set_at,
            lose_device_at: args.lose_device_at,
            exit_after_s: args.exit_after_s,
            cycle: args.cycle.clone(),
            cycle_every: args.cycle_every,
            light_turn_deg: args.light_turn,
            memory_every_s: args.memory_every,
        },
        setup,
        scene: cfg.scene,
    };
    shadowlab_view::run(opts)
}

/// The setup a saved view starts from: the given one (its scene replaced by `--scene`), or
/// one naming the scene.
fn base_setup(args: &ViewArgs) -> Result<Setup> {
    let mut s = match &args.setup {
        Some(p) => Setup::load(p).map_err(|e| anyhow!(e))?,
        None => Setup::default(),
    };
    match &args.scene {
        Some(name) if shadowlab_core::builtin::builtin(name).is_some() => {
            s.scene = SceneSection { builtin: Some(name.clone()), ..Default::default() };
        }
        Some(file) => s.scene = SceneSection { path: Some(PathBuf::from(file)), ..Default::default() },
        None if args.setup.is_none() => s.scene.builtin = Some(shadowlab_core::builtin::DEFAULT_SCENE.into()),
        None => {}
    }
    Ok(s)
}
