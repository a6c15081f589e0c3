//! Resolves a run from a setup file, a scene name/path and CLI overrides; everything is checked
//! before any GPU work or output starts.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context, Result};
use shadowlab_core::builtin::{builtin, BUILTIN_SCENES, DEFAULT_SCENE};
use shadowlab_core::camera::{Camera, CameraKey};
use shadowlab_core::light::Light;
use shadowlab_core::loaders::{self, SceneTransform};
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::scene::Scene;
use shadowlab_core::setup::{SceneSource, Setup};
use shadowlab_gpu::registry::{self, Resolved};

use crate::RunArgs;

pub struct RunConfig {
    pub scene: Scene,
    pub source: String,
    pub camera: Camera,
    /// Keyframes `--frames` follows: the setup's `[[camera.path]]` when the setup has a camera,
    /// else the built-in scene's path (empty: the camera holds still).
    pub camera_path: Vec<CameraKey>,
    pub lights: Vec<Light>,
    pub light_index: usize,
    pub width: u32,
    pub height: u32,
    /// Each spec resolved once against the registry (and checked against the light).
    pub specs: Vec<Resolved>,
    /// Animation time of frame 0 (`--time`, frames).
    pub time: f32,
}

impl RunConfig {
    pub fn light(&self) -> &Light {
        &self.lights[self.light_index]
    }
}

pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| anyhow!("--size '{s}': expected WxH, e.g. 1024x1024"))?;
    let w: u32 = w.trim().parse().map_err(|_| anyhow!("--size '{s}': width is not a whole number"))?;
    let h: u32 = h.trim().parse().map_err(|_| anyhow!("--size '{s}': height is not a whole number"))?;
    if w == 0 || h == 0 {
        bail!("--size '{s}': width and height must be at least 1");
    }
    Ok((w, h))
}

/// Loads a built-in scene by name or a scene file by path.
pub fn load_scene(source: &SceneSource, xf: &SceneTransform) -> Result<Scene> {
    match source {
        SceneSource::Builtin(name) => builtin(name).ok_or_else(|| {
            let names: Vec<_> = BUILTIN_SCENES.iter().map(|s| s.name).collect();
            anyhow!("unknown scene '{name}' (built-in: {}; or give a .gltf/.glb/.obj path)", names.join(", "))
        }),
        SceneSource::File(p) => {
            if !p.exists() {
                bail!(
                    "scene file {} not found (a setup's scene path is relative to the setup file; set {}=/path/to/scenes to find the real scenes elsewhere)",
                    p.display(),
                    shadowlab_core::setup::SCENES_ENV
                );
            }
            Ok(loaders::load(p, xf)?)
        }
    }
}

fn scene_arg(s: &str) -> SceneSource {
    let looks_like_file = s.contains('/') || s.contains('.') || Path::new(s).exists();
    if looks_like_file && builtin(s).is_none() {
        SceneSource::File(PathBuf::from(s))
    } else {
        SceneSource::Builtin(s.to_string())
    }
}

/// Resolves a run; without techniques from `-t` or the setup it runs `default_specs`
/// (the registry's default compare set leaves out what the light cannot use).
pub fn resolve(args: &RunArgs, default_specs: &[String]) -> Result<RunConfig> {
    let setup = match &args.setup {
        Some(p) => Setup::load(p).map_err(|e| anyhow!(e))?,
        None => Setup::default(),
    };
    let source = match (&args.scene, &args.setup) {
        (Some(s), _) => scene_arg(s),
        (None, Some(_)) => setup.scene_source().map_err(|e| anyhow!(e))?,
        (None, None) => SceneSource::Builtin(DEFAULT_SCENE.into()),
    };
    let defaults = args.techniques.is_empty() && setup.techniques.is_empty();
    let specs_text: Vec<String> = if !args.techniques.is_empty() {
        args.techniques.clone()
    } else if !setup.techniques.is_empty() {
        setup.techniques.iter().map(|t| t.spec.clone()).collect()
    } else {
        default_specs.to_vec()
    };
    let mut specs = Vec::new();
    let mut labels = std::collections::HashSet::new();
    for text in &specs_text {
        // names and parameters are checked before a (possibly large) scene is loaded
        let spec = TechniqueSpec::parse(text).map_err(|e| anyhow!(e))?;
        let r = registry::resolve(&spec, None)?;
        if !labels.insert(r.label.clone()) {
            bail!("two techniques share the label '{}'; give one `label=...`", r.label);
        }
        specs.push(r);
    }
    let (width, height) = match &args.size {
        Some(s) => parse_size(s)?,
        None => (setup.output.width, setup.output.height),
    };
    if width == 0 || height == 0 {
        bail!("output size {width}x{height}: width and height must be at least 1");
    }
    let time = args.time.unwrap_or(setup.time);
    if !time.is_finite() {
        bail!("--time {time}: must be a finite number of frames");
    }
    let mut scene = load_scene(&source, &setup.transform()).with_context(|| "loading the scene")?;
    shadowlab_core::anim::apply(&mut scene, &setup.animations).map_err(|e| anyhow!("[[animations]]: {e}"))?;
    for w in &scene.report.warnings {
        eprintln!("warning: {w}");
    }
    let (camera, camera_path) = match &setup.camera {
        Some(c) => (c.camera(), c.path.clone()),
        None => (scene.camera, scene.camera_path.clone()),
    };
    let lights = if setup.lights.is_empty() { scene.lights.clone() } else { setup.lights.clone() };
    if args.light >= lights.len() {
        bail!("--light {}: the run has {} light(s)", args.light, lights.len());
    }
    let light = &lights[args.light];
    if defaults {
        // the default list skips what the light cannot use; named techniques must support it
        specs.retain(|s| s.check_light(light).is_ok());
    }
    for s in &specs {
        s.check_light(light)?;
    }
    let cfg = RunConfig {
        source: match &source {
            SceneSource::Builtin(n) => format!("builtin:{n}"),
            SceneSource::File(p) => p.display().to_string(),
        },
        scene,
        camera,
        camera_path,
        lights,
        light_index: args.light,
        width,
        height,
        specs,
        time,
    };
    Ok(cfg)
}
