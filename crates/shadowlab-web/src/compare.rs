//! One view compared, as the page asks for it: a built-in scene and light, an output size and
//! technique specs (as on the CLI), each run once beside the ray-traced reference. Plain Rust
//! over shadowlab-gpu's lab, the same on native and in the browser (tests/compare.rs runs it
//! natively against the CLI's numbers).

use serde::{Deserialize, Serialize};
use shadowlab_core::builtin::{builtin, BUILTIN_SCENES};
use shadowlab_core::metrics::{compare, error_image};
use shadowlab_core::params::TechniqueSpec;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;

/// Largest output side the page accepts (a browser tab's memory; the device's own texture
/// limit is checked too).
pub const MAX_SIDE: u32 = 2048;

/// What the page asks for (docs/web.md: the automation contract).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Request {
    pub scene: String,
    #[serde(default)]
    pub light: usize,
    pub width: u32,
    pub height: u32,
    /// Technique specs, `name` or `name:key=value,...`.
    pub techniques: Vec<String>,
}

/// One technique's figures against `rt` on the view.
#[derive(Clone, Debug, Serialize)]
pub struct TechniqueResult {
    pub label: String,
    pub wrong_pct: f64,
    pub false_lit_pct: f64,
    pub false_shadow_pct: f64,
    pub mae: f64,
    /// The timed frame (see `Outcome::timer`).
    pub total_ms: f64,
    pub shadow_bytes: u64,
}

/// The JSON the page writes into `#shadowlab-result`.
#[derive(Clone, Debug, Serialize)]
pub struct Outcome {
    pub adapter: String,
    pub width: u32,
    pub height: u32,
    pub timer: String,
    pub evaluated_pixels: u64,
    pub techniques: Vec<TechniqueResult>,
}

/// A technique's pictures: its shaded image and its error image against `rt` (RGBA8).
pub struct Pictures {
    pub shaded: Vec<u8>,
    pub error: Vec<u8>,
}

/// Runs `req` on `gpu`: the reference, then each technique once (a warm-up frame, then one
/// timed frame). A bad request (unknown scene, light out of range, size, a spec that does not
/// parse or resolve) or a failed technique is an error naming it.
pub fn run(gpu: &Gpu, req: &Request) -> Result<(Outcome, Vec<Pictures>), String> {
    let scene = builtin(&req.scene).ok_or_else(|| {
        let names: Vec<&str> = BUILTIN_SCENES.iter().map(|s| s.name).collect();
        format!("unknown scene '{}' (built-in: {})", req.scene, names.join(", "))
    })?;
    let light = scene
        .lights
        .get(req.light)
        .copied()
        .ok_or_else(|| format!("scene '{}' has {} light(s); light {} does not exist", req.scene, scene.lights.len(), req.light))?;
    if req.width == 0 || req.height == 0 || req.width > MAX_SIDE || req.height > MAX_SIDE {
        return Err(format!("size {}x{} must be between 1x1 and {MAX_SIDE}x{MAX_SIDE}", req.width, req.height));
    }
    if req.techniques.is_empty() {
        return Err("no technique given (t=SPEC)".into());
    }
    let specs = req
        .techniques
        .iter()
        .map(|s| TechniqueSpec::parse(s).map_err(|e| format!("technique spec '{s}': {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    let lab = Lab::new(gpu, &scene).map_err(|e| e.to_string())?;
    let view = lab.view(&scene.camera, &scene.camera, &light, req.width, req.height).map_err(|e| e.to_string())?;
    let rt = lab.reference(&view, 1).map_err(|e| format!("rt: {e}"))?;
    let mut techniques = Vec::new();
    let mut pictures = Vec::new();
    let mut evaluated = 0;
    for (spec, text) in specs.iter().zip(&req.techniques) {
        let r = lab.run(&view, spec, 1).map_err(|e| {
            // the lab's own message may name the technique already ("'sv' is unavailable ...")
            let e = e.to_string();
            if e.starts_with(&format!("'{}'", spec.name)) {
                format!("{e} (spec '{text}')")
            } else {
                format!("technique '{text}': {e}")
            }
        })?;
        let m = compare(&r.visibility, &rt.visibility, &view.mask);
        evaluated = m.evaluated_pixels;
        techniques.push(TechniqueResult {
            label: r.label.clone(),
            wrong_pct: m.wrong_pct,
            false_lit_pct: m.false_lit_pct,
            false_shadow_pct: m.false_shadow_pct,
            mae: m.mae,
            total_ms: r.total_ms,
            shadow_bytes: r.report.shadow_data_bytes,
        });
        let error = error_image(&r.shaded, &r.visibility, &rt.visibility, &view.mask, false);
        pictures.push(Pictures { shaded: r.shaded, error });
    }
    let outcome = Outcome {
        adapter: gpu.adapter_summary(),
        width: req.width,
        height: req.height,
        timer: gpu.timer_name().to_string(),
        evaluated_pixels: evaluated,
        techniques,
    };
    Ok((outcome, pictures))
}
