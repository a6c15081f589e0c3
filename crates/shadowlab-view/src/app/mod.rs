//! The window: eframe (winit + egui-wgpu) on shadowlab's device; [`state`] holds the viewer
//! and renders the picture, [`panels`] draws the controls and the numbers.

mod loss;
mod panels;
mod state;

use std::sync::{Arc, Mutex};

use anyhow::anyhow;
use eframe::egui;
use eframe::egui_wgpu;
use shadowlab_gpu::Gpu;

use crate::Options;
use state::{App, CONTROLS_W, HUD_W};

pub(crate) fn run(opts: Options) -> anyhow::Result<()> {
    let mut setup = egui_wgpu::WgpuSetupCreateNew::without_display_handle();
    // shadowlab's own device: every adapter limit, timestamps where offered
    setup.device_descriptor = Arc::new(|adapter| Gpu::device_descriptor(adapter));
    setup.instance_descriptor.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    // the window: the fixed render size plus the panels, else 1600x900
    let (w, h) = opts.size.map_or((1600.0, 900.0), |(w, h)| (w as f32 + CONTROLS_W + HUD_W + 24.0, h as f32 + 16.0));
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default().with_title("shadowlab view").with_inner_size([w, h]),
        wgpu_options: egui_wgpu::WgpuConfiguration {
            wgpu_setup: egui_wgpu::WgpuSetup::CreateNew(setup),
            // the frame already waits for the GPU; presenting without vsync adds no second wait
            surface: egui_wgpu::SurfaceConfig { present_mode: wgpu::PresentMode::AutoNoVsync, desired_maximum_frame_latency: Some(1) },
            ..Default::default()
        },
        ..Default::default()
    };
    let fatal = Arc::new(Mutex::new(None));
    let fatal_app = fatal.clone();
    eframe::run_native(
        "shadowlab view",
        native,
        Box::new(move |cc| {
            let app = App::new(cc, opts, fatal_app).map_err(|e| -> Box<dyn std::error::Error + Send + Sync> { e.to_string().into() })?;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| anyhow!("the viewer could not run: {e} (a window needs a display: run it in a desktop session, or under Xvfb: xvfb-run -a shadowlab view ...)"))?;
    let failed = fatal.lock().expect("not poisoned").take();
    match failed {
        Some(e) => Err(anyhow!(e)),
        None => Ok(()),
    }
}

impl eframe::App for App {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        if let Some(why) = self.gpu.lost() {
            loss::exit_on_loss(&why);
        }
        if self.closing {
            return;
        }
        if ui.input(|i| i.key_pressed(egui::Key::F2)) {
            self.save_setup();
        }
        if ui.input(|i| i.key_pressed(egui::Key::F12)) {
            self.save_screenshot();
        }
        egui::Panel::left("controls").resizable(true).default_size(CONTROLS_W).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| panels::controls(self, ui));
        });
        egui::Panel::right("numbers").resizable(true).default_size(HUD_W).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| panels::numbers(self, ui));
        });
        egui::CentralPanel::default().show(ui, |ui| self.central(ui, frame));
        ui.ctx().request_repaint();
    }
}
