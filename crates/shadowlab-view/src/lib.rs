//! shadowlab-view: the interactive viewer (`shadowlab view`).
//!
//! Fly to where a technique fails, move the light, turn a parameter and watch its error against
//! the exact reference. The window is winit plus egui through egui-wgpu (eframe), on the same
//! wgpu device as the techniques, which it drives as a host of the library seam:
//! - [`render`]: the frame function, without a window (G-buffer, technique, shading, the
//!   composed picture; the reference refined while the camera is still; the lab's error image
//!   and metrics). Tests drive it headless.
//! - [`widgets`]: one widget per declared parameter.
//! - [`fly`]: camera and light motion, pure.
//! - [`session`]: the saved setup and screenshots.
//! - [`script`]: scripted runs (`--exit-after`, `--orbit`, `--set-at`).
//! - `app`: the window (its state, its panels).

mod app;
pub mod fly;
pub mod render;
pub mod script;
pub mod session;
pub mod widgets;

use std::path::PathBuf;

use shadowlab_core::camera::{Camera, CameraKey};
use shadowlab_core::light::Light;
use shadowlab_core::scene::Scene;
use shadowlab_core::setup::Setup;
use shadowlab_gpu::registry::Resolved;

/// Everything `shadowlab view` starts from (resolved by the CLI, like `compare`).
pub struct Options {
    pub scene: Scene,
    /// The setup the run came from (or one naming the built-in scene): saved setups keep its
    /// scene section, moving objects and camera path.
    pub setup: Setup,
    pub camera: Camera,
    pub camera_path: Vec<CameraKey>,
    pub light: Light,
    /// Technique A, and B for the split screen.
    pub a: Resolved,
    pub b: Option<Resolved>,
    /// Fixed render size; `None` follows the window.
    pub size: Option<(u32, u32)>,
    pub time: f32,
    /// What the picture shows first.
    pub show: render::Show,
    /// Where saved setups and screenshots go.
    pub out_dir: PathBuf,
    pub script: script::Script,
}

/// Why no window can open, with the fix; `None` when a display is there to try.
pub fn display_problem() -> Option<String> {
    if cfg!(target_os = "linux") {
        let set = |v: &str| std::env::var_os(v).is_some_and(|x| !x.is_empty());
        if !set("DISPLAY") && !set("WAYLAND_DISPLAY") {
            return Some(
                "no display: `shadowlab view` opens a window (DISPLAY and WAYLAND_DISPLAY are unset); run it in a desktop session, or headless under Xvfb: xvfb-run -a shadowlab view ...".into(),
            );
        }
    }
    None
}

/// Opens the window and runs until it is closed (or the script ends).
pub fn run(opts: Options) -> anyhow::Result<()> {
    if let Some(p) = display_problem() {
        anyhow::bail!(p);
    }
    app::run(opts)
}
