//! A lost device (a driver reset, a GPU removed, `--lose-device-at`): nothing made on it works
//! again, and egui's painter cannot go on with it (it panics). The window keeps its last view
//! here after every frame; on a loss, [`exit_on_loss`] saves it as a setup, says so in one line
//! with the command that reopens it, and exits with status 1.

use std::sync::Mutex;

use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::setup::Setup;
use shadowlab_gpu::Gpu;

use crate::session;

/// What the window showed after its last frame.
pub(crate) struct LastView {
    pub(crate) setup: Setup,
    pub(crate) camera: Camera,
    pub(crate) light: Light,
    pub(crate) time: f32,
    pub(crate) size: (u32, u32),
    pub(crate) specs: Vec<String>,
    pub(crate) out_dir: std::path::PathBuf,
    pub(crate) frames: usize,
}

static LAST_VIEW: Mutex<Option<LastView>> = Mutex::new(None);

/// The device is lost (a driver reset, a GPU removed, `--lose-device-at`): nothing made on it
/// works again, and egui's painter cannot continue on it. Saves the last view as a setup, says
/// so in one message with the command that reopens it, and exits with status 1. Called at the
/// start of each frame and, for a loss in the middle of one (egui's painter panics on a lost
/// device), from the panic hook of [`exit_on_loss_in_panics`].
pub fn exit_on_loss(why: &str) -> ! {
    let last = LAST_VIEW.lock().unwrap_or_else(|e| e.into_inner()).take();
    let msg = match last {
        Some(v) => {
            let s = session::snapshot(&v.setup, &v.camera, &v.light, v.time, v.size.0, v.size.1, &v.specs);
            let saved = session::to_toml(&s)
                .and_then(|t| session::write_fresh(&v.out_dir, "view", "toml", t.as_bytes()).map_err(|e| e.to_string()));
            match saved {
                Ok(p) => format!(
                    "the GPU device was lost ({why}) after {} frames; the view is saved: `shadowlab view --setup {}` reopens it",
                    v.frames,
                    p.display()
                ),
                Err(e) => format!("the GPU device was lost ({why}) after {} frames; the view could not be saved: {e}", v.frames),
            }
        }
        None => format!("the GPU device was lost ({why}) before the first frame"),
    };
    eprintln!("error: {msg}");
    std::process::exit(1);
}

/// Keeps `view` as the one a loss saves.
pub(crate) fn remember(view: LastView) {
    *LAST_VIEW.lock().unwrap_or_else(|e| e.into_inner()) = Some(view);
}

/// A panic once `gpu` is lost (egui's painter in the middle of a frame) ends as [`exit_on_loss`];
/// any other panic as before.
pub(crate) fn exit_on_loss_in_panics(gpu: &'static Gpu) {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if let Some(why) = gpu.lost() {
            exit_on_loss(&why);
        }
        default_hook(info)
    }));
}
