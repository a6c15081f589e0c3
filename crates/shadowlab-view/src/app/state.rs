//! The viewer's state: camera, light, time, techniques and what is shown; each egui frame
//! moves the camera from the input, renders one frame with [`Renderer::frame`] and shows its
//! picture ([`App::central`]).

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use std::time::Instant;

use anyhow::anyhow;
use eframe::egui;
use shadowlab_core::camera::{path_cameras, Camera, CameraKey};
use shadowlab_core::light::Light;
use shadowlab_core::setup::Setup;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;

use crate::fly::{fly, orbit, turn_light, FlyInput};
use crate::render::{FrameInfo, Look, Pose, Renderer, Right};
use crate::script::Script;
use crate::{session, widgets, Options};

use super::loss::{self, LastView};

/// Seconds without camera, light or time change before the reference starts refining.
const SETTLE_S: f64 = 0.15;
/// Seconds of frame times in the HUD's plot.
const PLOT_S: f64 = 10.0;
/// Mouse look, radians per point dragged.
const LOOK_PER_POINT: f32 = 0.005;

pub const CONTROLS_W: f32 = 300.0;
pub const HUD_W: f32 = 300.0;

/// The debug pictures of the current evaluation, as egui textures.
#[derive(Default)]
pub struct DebugPictures {
    /// Which evaluation they belong to ([`crate::render::Evaluation::id`]).
    pub key: Option<u64>,
    pub textures: Vec<(String, egui::TextureHandle)>,
    pub pick: usize,
}

pub(crate) struct App {
    pub r: Renderer<'static>,
    pub gpu: &'static Gpu,
    tex: Option<egui::TextureId>,
    tex_size: (u32, u32),
    pub setup: Setup,
    pub base_camera: Camera,
    pub camera_path: Vec<CameraKey>,
    pub camera: Camera,
    prev_camera: Camera,
    pub base_light: Light,
    pub light: Light,
    pub time: f32,
    prev_time: f32,
    pub play_time: bool,
    /// Animation frames per second while playing.
    pub time_rate: f32,
    pub path_u: f32,
    pub play_path: bool,
    pub look: Look,
    /// Fly speed, world units per second.
    pub speed: f32,
    fixed_size: Option<(u32, u32)>,
    last_pose: Option<Pose>,
    last_change: Instant,
    last_frame: Instant,
    started: Instant,
    pub frame_times: VecDeque<[f64; 2]>,
    pub info: Option<FrameInfo>,
    /// The last message (saved files, edits) and the last error.
    pub status: String,
    pub error: Option<String>,
    out_dir: std::path::PathBuf,
    script: Script,
    frames: usize,
    /// Every frame's time (ms), and the window's frame period (ms, frame to frame, egui and
    /// presentation included), for the scripted run's summary (kept in scripted runs only).
    all_frame_ms: Vec<f64>,
    all_period_ms: Vec<f64>,
    last_moving: bool,
    /// When the current still period began, and how long after it the reference was current.
    still_since: Option<Instant>,
    current_after: Option<(f64, usize)>,
    /// A scripted run has asked the window to close.
    pub closing: bool,
    /// When (seconds after the start) the last `memory:` line was printed.
    memory_printed: f64,
    dragging_divider: bool,
    pub debug: DebugPictures,
    /// A scripted run's failure, returned by [`run`] once the window is closed.
    fatal: Arc<Mutex<Option<String>>>,
}

impl App {
    pub fn new(cc: &eframe::CreationContext, opts: Options, fatal: Arc<Mutex<Option<String>>>) -> anyhow::Result<App> {
        let rs = cc.wgpu_render_state.as_ref().ok_or_else(|| anyhow!("eframe started without wgpu"))?;
        let gpu: &'static Gpu = Box::leak(Box::new(Gpu::from_device(rs.device.clone(), rs.queue.clone(), rs.adapter.get_info())?));
        let scene = Box::leak(Box::new(opts.scene));
        let lab = Lab::new(gpu, scene)?;
        loss::exit_on_loss_in_panics(gpu);
        let (w, h) = opts.size.unwrap_or((640, 480));
        let r = Renderer::new(lab, w, h, &opts.light, opts.a, opts.b.clone())?;
        let extent = scene.bounds().diagonal().max(1e-3);
        let now = Instant::now();
        Ok(App {
            r,
            gpu,
            tex: None,
            tex_size: (0, 0),
            setup: opts.setup,
            base_camera: opts.camera,
            camera_path: opts.camera_path,
            camera: opts.camera,
            prev_camera: opts.camera,
            base_light: opts.light,
            light: opts.light,
            time: opts.time,
            prev_time: opts.time,
            play_time: false,
            time_rate: 30.0,
            path_u: 0.0,
            play_path: false,
            look: Look { show: opts.show, right: if opts.b.is_some() { Right::Technique } else { Right::None }, divider: 0.5 },
            speed: extent * 0.15,
            fixed_size: opts.size,
            last_pose: None,
            last_change: now,
            last_frame: now,
            started: now,
            frame_times: VecDeque::new(),
            info: None,
            status: String::new(),
            error: None,
            out_dir: opts.out_dir,
            script: opts.script,
            frames: 0,
            all_frame_ms: Vec::new(),
            all_period_ms: Vec::new(),
            last_moving: false,
            still_since: None,
            current_after: None,
            closing: false,
            memory_printed: 0.0,
            dragging_divider: false,
            debug: Default::default(),
            fatal,
        })
    }

    /// Technique A (and B when shown) as spec texts: what a saved setup runs.
    pub fn specs(&self) -> Vec<String> {
        let mut v = vec![self.r.technique(false).expect("A").text.clone()];
        if self.look.right == Right::Technique {
            if let Some(b) = self.r.technique(true) {
                v.push(b.text.clone());
            }
        }
        v
    }

    pub fn save_setup(&mut self) {
        let (w, h) = self.r.size();
        let s = session::snapshot(&self.setup, &self.camera, &self.light, self.time, w, h, &self.specs());
        let res =
            session::to_toml(&s).and_then(|t| session::write_fresh(&self.out_dir, "view", "toml", t.as_bytes()).map_err(|e| e.to_string()));
        self.report(res.map(|p| format!("setup saved: {} (shadowlab compare --setup {})", p.display(), p.display())));
    }

    pub fn save_screenshot(&mut self) {
        let res = self.screenshot_png().and_then(|png| session::write_fresh(&self.out_dir, "view", "png", &png).map_err(|e| e.to_string()));
        self.report(res.map(|p| format!("screenshot: {}", p.display())));
    }

    fn screenshot_png(&self) -> Result<Vec<u8>, String> {
        let (w, h) = self.r.size();
        session::png(w, h, &self.r.read_picture())
    }

    pub fn report(&mut self, r: Result<String, String>) {
        match r {
            Ok(m) => {
                println!("{m}");
                self.status = m;
                self.error = None;
            }
            Err(e) => self.error = Some(e),
        }
    }

    /// Sets parameter `key` of technique A (or B) to `text`, as the widgets and `--set-at` do.
    pub fn set_param(&mut self, right: bool, key: &str, text: &str) -> Result<(), String> {
        let cur = self.r.technique(right).ok_or("no technique on the right")?.clone();
        let next = widgets::with_value(&cur, key, text).map_err(|e| e.to_string())?;
        let light = self.light;
        self.r.set_technique(right, Some(next), &light).map_err(|e| e.to_string())
    }

    /// Replaces technique A (or B) by the spec `text`.
    pub fn set_spec(&mut self, right: bool, text: Option<&str>) {
        let light = self.light;
        let res = text.map(widgets::resolve_text).transpose().map_err(|e| e.to_string());
        let res = res.and_then(|spec| self.r.set_technique(right, spec, &light).map_err(|e| e.to_string()));
        if let Err(e) = res {
            self.error = Some(e);
        }
    }

    fn camera_on_path(&self) -> Camera {
        let cams = path_cameras(&self.base_camera, &self.camera_path, 1001);
        cams[(self.path_u.clamp(0.0, 1.0) * 1000.0).round() as usize]
    }

    /// Fly input from the keyboard and the drag over the picture.
    fn fly_input(&mut self, ui: &egui::Ui, resp: &egui::Response, picture: egui::Rect) -> FlyInput {
        let mut f = FlyInput::default();
        if !ui.ctx().egui_wants_keyboard_input() {
            ui.input(|i| {
                let axis = |a: egui::Key, b: egui::Key| i.key_down(a) as i32 as f32 - i.key_down(b) as i32 as f32;
                f.forward = axis(egui::Key::W, egui::Key::S);
                f.right = axis(egui::Key::D, egui::Key::A);
                f.up = axis(egui::Key::E, egui::Key::Q);
            });
        }
        let divider_x = picture.left() + self.look.divider * picture.width();
        if resp.drag_started() {
            let near = resp.interact_pointer_pos().is_some_and(|p| (p.x - divider_x).abs() < 6.0);
            self.dragging_divider = self.look.right != Right::None && near;
        }
        if resp.dragged() {
            let d = resp.drag_delta();
            if self.dragging_divider {
                if let Some(p) = resp.interact_pointer_pos() {
                    self.look.divider = ((p.x - picture.left()) / picture.width()).clamp(0.0, 1.0);
                }
            } else {
                f.yaw = d.x * LOOK_PER_POINT;
                f.pitch = -d.y * LOOK_PER_POINT;
            }
        } else {
            self.dragging_divider = false;
        }
        if resp.hovered() {
            let wheel = ui.input(|i| i.smooth_scroll_delta.y);
            if wheel != 0.0 {
                self.speed *= 1.1f32.powf(wheel / 50.0);
            }
        }
        f
    }

    /// Script steps due before this frame.
    fn scripted_steps(&mut self) {
        if self.script.orbit_deg != 0.0 && self.script.orbit_frames.is_none_or(|n| self.frames < n) {
            self.camera = orbit(&self.camera, self.script.orbit_deg);
        }
        if self.script.lose_device_at == Some(self.frames) {
            println!("frame {}: destroying the GPU device (--lose-device-at)", self.frames);
            self.gpu.device.destroy();
        }
        if let Some(spec) = self.script.cycle_step(self.frames).map(str::to_string) {
            if self.script.light_turn_deg != 0.0 {
                self.light = turn_light(&self.light, self.script.light_turn_deg, self.camera.target);
            }
            self.set_spec(false, Some(&spec));
            if let Some(e) = self.error.take() {
                self.fail(format!("--cycle {spec} at frame {}: {e}", self.frames));
            }
        }
        if let Some(every) = self.script.memory_every_s {
            let t = self.started.elapsed().as_secs_f64();
            if self.frames == 0 || t >= self.memory_printed + every {
                self.memory_printed = t;
                self.print_memory("");
            }
        }
        let changes: Vec<(String, String)> = self.script.changes_at(self.frames).map(|(k, v)| (k.to_string(), v.to_string())).collect();
        for (k, v) in changes {
            match self.set_param(false, &k, &v) {
                Ok(()) => println!("frame {}: technique A is now {}", self.frames, self.r.technique(false).expect("A").text),
                Err(e) => self.fail(format!("--set-at {}:{k}={v}: {e}", self.frames)),
            }
        }
    }

    /// A `memory:` line of a scripted run (`--memory-every`).
    fn print_memory(&self, suffix: &str) {
        let rss = crate::script::resident_mib().map_or("n/a".to_string(), |m| format!("{m:.1}"));
        let t = self.started.elapsed().as_secs_f64();
        let a = &self.r.technique(false).expect("A").text;
        println!("memory: t={t:.1} s, frame {}, resident {rss} MiB, technique A {a}{suffix}", self.frames);
    }

    /// Keeps what [`loss::exit_on_loss`] saves current (after every frame).
    fn remember_view(&self) {
        let (w, h) = self.r.size();
        loss::remember(LastView {
            setup: self.setup.clone(),
            camera: self.camera,
            light: self.light,
            time: self.time,
            size: (w, h),
            specs: self.specs(),
            out_dir: self.out_dir.clone(),
            // this frame is rendered; `scripted_end` counts it after
            frames: self.frames + 1,
        });
    }

    fn fail(&mut self, e: String) {
        *self.fatal.lock().expect("not poisoned") = Some(e.clone());
        self.error = Some(e);
    }

    /// After the frame: count it, and end a scripted run once it has rendered its frames.
    fn scripted_end(&mut self, ui: &egui::Ui) {
        self.frames += 1;
        if !self.script.is_scripted() {
            return;
        }
        let due = self.script.exit_after.is_some_and(|n| self.frames >= n)
            || self.script.exit_after_s.is_some_and(|s| self.started.elapsed().as_secs_f64() >= s);
        if self.closing || (!due && self.fatal.lock().expect("not poisoned").is_none()) {
            return;
        }
        self.closing = true;
        if let Some(path) = self.script.screenshot.clone() {
            let res = self.screenshot_png().and_then(|png| {
                let tmp = path.with_extension("partial.png");
                std::fs::write(&tmp, png).and_then(|_| std::fs::rename(&tmp, &path)).map_err(|e| format!("{}: {e}", path.display()))
            });
            if let Err(e) = res {
                self.fail(format!("--screenshot: {e}"));
            }
        }
        let (w, h) = self.r.size();
        let median = |v: &[f64]| {
            let mut v = v.to_vec();
            v.sort_by(f64::total_cmp);
            v.get(v.len() / 2).copied().unwrap_or(0.0)
        };
        if self.script.memory_every_s.is_some() {
            self.print_memory(" (end)");
        }
        let (frame_ms, period_ms) = (median(&self.all_frame_ms), median(&self.all_period_ms));
        let current = match self.current_after {
            Some((t, n)) => format!("; reference current {t:.0} ms after the camera stopped ({n} frames)"),
            None => String::new(),
        };
        println!(
            "view: {} frames at {w}x{h}, median frame {frame_ms:.1} ms ({}), median window frame period while moving {period_ms:.1} ms ({:.1} fps, egui and presentation included){current}",
            self.frames,
            self.gpu.timer_name(),
            1000.0 / period_ms.max(1e-3)
        );
        ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
    }

    /// Moves, renders and shows one frame in the central panel.
    pub fn central(&mut self, ui: &mut egui::Ui, frame: &eframe::Frame) {
        let avail = ui.available_rect_before_wrap();
        let resp = ui.allocate_rect(avail, egui::Sense::click_and_drag());
        let ppp = ui.ctx().pixels_per_point();
        let size =
            self.fixed_size.unwrap_or(((avail.width() * ppp).round().max(16.0) as u32, (avail.height() * ppp).round().max(16.0) as u32));
        if let Err(e) = self.r.resize(size.0, size.1) {
            self.error = Some(e.to_string());
        }
        let (w, h) = self.r.size();
        let scale = (avail.width() / w as f32).min(avail.height() / h as f32);
        let picture = egui::Rect::from_center_size(avail.center(), egui::vec2(w as f32 * scale, h as f32 * scale));
        let now = Instant::now();
        let period = now.duration_since(self.last_frame);
        if self.frames > 0 && self.last_moving && self.script.is_scripted() {
            // frame to frame while the camera moves (still frames add reference bands)
            self.all_period_ms.push(period.as_secs_f64() * 1e3);
        }
        let dt = period.as_secs_f32().min(0.25);
        self.last_frame = now;
        let input = self.fly_input(ui, &resp, picture);
        if ui.input(|i| i.key_pressed(egui::Key::R)) && !ui.ctx().egui_wants_keyboard_input() {
            self.camera = self.base_camera;
        }
        if self.play_time {
            self.time += dt * self.time_rate;
        }
        if self.play_path && !self.camera_path.is_empty() {
            self.path_u = (self.path_u + dt * 0.05) % 1.0;
            self.camera = self.camera_on_path();
        }
        if self.script.is_scripted() {
            self.scripted_steps();
        }
        self.camera = fly(&self.camera, &input, dt, self.speed);
        let pose =
            Pose { camera: self.camera, prev_camera: self.prev_camera, light: self.light, time: self.time, prev_time: self.prev_time };
        let changed = self.last_pose.is_none_or(|p| p.camera != pose.camera || p.light != pose.light || p.time != pose.time);
        if changed {
            self.last_change = now;
        }
        let settled = pose.prev_camera == pose.camera && pose.prev_time == pose.time;
        let still = settled && if self.script.is_scripted() { !changed } else { self.last_change.elapsed().as_secs_f64() > SETTLE_S };
        self.last_moving = changed;
        match self.r.frame(&pose, &self.look, still) {
            Ok(info) => {
                let t = self.started.elapsed().as_secs_f64();
                self.frame_times.push_back([t, info.frame_ms]);
                while self.frame_times.front().is_some_and(|f| f[0] < t - PLOT_S) {
                    self.frame_times.pop_front();
                }
                if self.script.is_scripted() {
                    self.all_frame_ms.push(info.frame_ms);
                }
                self.track_stillness(still, &info, changed);
                if info.recreated {
                    self.status = "light moved: every technique and the reference were created again for it (maps, lt's history and iasm's pages are per light)".into();
                }
                self.info = Some(info);
            }
            Err(e) => {
                if let Some(why) = self.gpu.lost() {
                    loss::exit_on_loss(&why);
                }
                self.error = Some(e.to_string())
            }
        }
        self.remember_view();
        self.last_pose = Some(pose);
        self.prev_camera = self.camera;
        self.prev_time = self.time;
        self.show_picture(ui, frame, picture);
        self.scripted_end(ui);
    }

    /// Measures how long after the camera stopped the reference became current.
    fn track_stillness(&mut self, still: bool, info: &FrameInfo, changed: bool) {
        if changed {
            self.still_since = None;
            return;
        }
        let since = *self.still_since.get_or_insert_with(|| self.last_change);
        if still && info.reference == crate::render::RefStatus::Current && self.current_after.is_none() {
            self.current_after = Some((since.elapsed().as_secs_f64() * 1e3, self.frames + 1));
        }
    }

    fn show_picture(&mut self, ui: &egui::Ui, frame: &eframe::Frame, rect: egui::Rect) {
        let Some(rs) = frame.wgpu_render_state() else { return };
        let view = self.r.picture().create_view(&wgpu::TextureViewDescriptor {
            format: Some(wgpu::TextureFormat::Rgba8UnormSrgb),
            usage: Some(wgpu::TextureUsages::TEXTURE_BINDING),
            ..Default::default()
        });
        let mut egui_renderer = rs.renderer.write();
        let size = self.r.size();
        let id = match self.tex {
            Some(id) if self.tex_size == size => id,
            Some(id) => {
                egui_renderer.update_egui_texture_from_wgpu_texture(&rs.device, &view, wgpu::FilterMode::Linear, id);
                id
            }
            None => egui_renderer.register_native_texture(&rs.device, &view, wgpu::FilterMode::Linear),
        };
        drop(egui_renderer);
        self.tex = Some(id);
        self.tex_size = size;
        let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        ui.painter().image(id, rect, uv, egui::Color32::WHITE);
    }
}
