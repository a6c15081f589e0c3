//! The viewer's panels: controls on the left (camera, time, light, techniques and their
//! parameters, what the picture shows), numbers on the right (times with their timer, the
//! error once the reference is current, counters, memory, the debug pictures).

use eframe::egui;
use egui_plot::{Line, Plot, PlotPoints};
use shadowlab_core::light::Light;
use shadowlab_gpu::registry::REGISTRY;

use super::state::App;
use crate::fly::{sun_angles, sun_direction};
use crate::render::{RefStatus, Right, Show, SideEval};
use crate::widgets;

pub fn controls(app: &mut App, ui: &mut egui::Ui) {
    ui.heading("shadowlab view");
    ui.label("WASD/QE fly, drag to look, wheel: speed, R: reset camera, F2: save setup, F12: screenshot");
    ui.horizontal(|ui| {
        if ui.button("Save setup (F2)").clicked() {
            app.save_setup();
        }
        if ui.button("Screenshot (F12)").clicked() {
            app.save_screenshot();
        }
    });
    ui.separator();
    ui.collapsing("Camera and time", |ui| {
        if ui.button("Reset camera (R)").clicked() {
            app.camera = app.base_camera;
        }
        ui.add(egui::Slider::new(&mut app.speed, 1e-3..=1e3).logarithmic(true).text("fly speed /s"));
        if !app.camera_path.is_empty() {
            ui.horizontal(|ui| {
                ui.checkbox(&mut app.play_path, "play path");
                let before = app.path_u;
                ui.add(egui::Slider::new(&mut app.path_u, 0.0..=1.0).text("path"));
                if app.path_u != before {
                    let cams = shadowlab_core::camera::path_cameras(&app.base_camera, &app.camera_path, 1001);
                    app.camera = cams[(app.path_u * 1000.0).round() as usize];
                }
            });
        }
        ui.horizontal(|ui| {
            ui.checkbox(&mut app.play_time, "play");
            ui.add(egui::DragValue::new(&mut app.time).speed(0.25).prefix("time "));
            ui.label("frames");
        });
        ui.add(egui::Slider::new(&mut app.time_rate, 1.0..=120.0).text("frames/s when playing"));
    });
    ui.collapsing("Light", |ui| light(app, ui));
    ui.separator();
    technique(app, ui, false);
    ui.separator();
    ui.horizontal(|ui| {
        ui.label("right side:");
        let mut right = app.look.right;
        ui.selectable_value(&mut right, Right::None, "none");
        ui.selectable_value(&mut right, Right::Technique, "technique B");
        ui.selectable_value(&mut right, Right::Reference, "rt");
        if right != app.look.right {
            if right == Right::Technique && app.r.technique(true).is_none() {
                app.set_spec(true, Some("sm"));
            }
            app.look.right = right;
        }
    });
    if app.look.right != Right::None {
        ui.add(egui::Slider::new(&mut app.look.divider, 0.0..=1.0).text("divider (or drag it)"));
    }
    if app.look.right == Right::Technique {
        technique(app, ui, true);
    }
    ui.separator();
    ui.horizontal(|ui| {
        ui.label("show:");
        ui.selectable_value(&mut app.look.show, Show::Shaded, "shaded");
        ui.selectable_value(&mut app.look.show, Show::Visibility, "visibility");
        ui.selectable_value(&mut app.look.show, Show::Error, "error vs rt");
    });
    if app.look.show == Show::Error {
        ui.label("false lit red, false shadow blue; the shaded picture until the reference is current");
    }
}

fn light(app: &mut App, ui: &mut egui::Ui) {
    if ui.button("Reset light").clicked() {
        app.light = app.base_light;
    }
    let mut l = app.light;
    match &mut l {
        Light::Directional { direction } => angles(ui, direction, "sun"),
        Light::Spot { position, direction, cone_deg } => {
            ui.add(egui::DragValue::new(&mut position.x).speed(0.05).prefix("x "));
            ui.add(egui::DragValue::new(&mut position.y).speed(0.05).prefix("y "));
            ui.add(egui::DragValue::new(&mut position.z).speed(0.05).prefix("z "));
            let mut back = -*direction;
            angles(ui, &mut back, "aim");
            if back != -*direction {
                *direction = -back;
            }
            ui.add(egui::Slider::new(cone_deg, 1.0..=89.0).text("cone deg"));
        }
        Light::Point { position } => {
            ui.add(egui::DragValue::new(&mut position.x).speed(0.05).prefix("x "));
            ui.add(egui::DragValue::new(&mut position.y).speed(0.05).prefix("y "));
            ui.add(egui::DragValue::new(&mut position.z).speed(0.05).prefix("z "));
        }
    }
    if l != app.light && l.validate().is_ok() {
        app.light = l;
    }
    ui.label("A moved light re-creates every technique and the reference (their maps and histories are per light).");
}

/// Azimuth/elevation sliders for a direction the light travels; untouched, it stays bit-equal.
fn angles(ui: &mut egui::Ui, direction: &mut glam::Vec3, what: &str) {
    let (mut az, mut el) = sun_angles(*direction);
    let a = ui.add(egui::Slider::new(&mut az, -180.0..=180.0).text(format!("{what} azimuth")));
    let e = ui.add(egui::Slider::new(&mut el, -89.0..=89.0).text(format!("{what} elevation")));
    if a.changed() || e.changed() {
        *direction = sun_direction(az, el);
    }
}

fn technique(app: &mut App, ui: &mut egui::Ui, right: bool) {
    let which = if right { "B" } else { "A" };
    let Some(cur) = app.r.technique(right).cloned() else { return };
    let mut pick = cur.info.name.to_string();
    egui::ComboBox::from_label(format!("technique {which}")).selected_text(&pick).show_ui(ui, |ui| {
        for t in REGISTRY.iter().filter(|t| t.lights.contains(&app.light.kind())) {
            ui.selectable_value(&mut pick, t.name.to_string(), t.name).on_hover_text(t.summary);
        }
    });
    if pick != cur.info.name {
        app.set_spec(right, Some(&pick));
        return;
    }
    ui.label(format!("spec: {}", cur.text));
    let mut change = None;
    for d in cur.info.params() {
        let mut v = cur.values.0[d.key].clone();
        if widgets::edit(ui, d, &mut v).changed() {
            change = Some((d.key, v.to_string()));
        }
    }
    if let Some((k, v)) = change {
        if let Err(e) = app.set_param(right, k, &v) {
            app.error = Some(e);
        }
    }
}

pub fn numbers(app: &mut App, ui: &mut egui::Ui) {
    let gpu = app.gpu;
    ui.label(gpu.adapter_summary());
    if let Some(e) = &app.error {
        ui.colored_label(egui::Color32::from_rgb(240, 80, 80), e);
    }
    if !app.status.is_empty() {
        ui.label(&app.status);
    }
    let (w, h) = app.r.size();
    if let Some(info) = &app.info {
        let what = if info.reused { " (still: composition only)" } else { "" };
        ui.label(format!("{w}x{h}: frame {:.1} ms ({:.1} fps){what}", info.frame_ms, 1000.0 / info.frame_ms.max(1e-3)));
        ui.small(format!("timer: {} (G-buffer, techniques, shading, composition)", gpu.timer_name()));
        let pts: Vec<[f64; 2]> = app.frame_times.iter().copied().collect();
        Plot::new("frame_times").height(90.0).allow_drag(false).allow_zoom(false).allow_scroll(false).include_y(0.0).show(ui, |p| {
            p.line(Line::new("frame ms", PlotPoints::from(pts)));
        });
        let status = match info.reference {
            RefStatus::Stale => "reference: stale (recomputed when the camera stops)".to_string(),
            RefStatus::Refining { done, of } => format!("reference: refining, band {done} of {of}"),
            RefStatus::Current => "reference: current".to_string(),
        };
        ui.label(status);
        if !info.stamped_ms.is_empty() {
            stages(ui, "stages, this frame", gpu.stages_timer_name(), &info.stamped_ms);
        }
    }
    let current = app.info.as_ref().is_some_and(|i| i.reference == RefStatus::Current);
    let eval = app.r.evaluation().filter(|_| current).cloned();
    match eval {
        Some(e) => {
            ui.small(format!("rt traced in {:.0} ms over its bands (wall clock)", e.reference_ms));
            side(ui, "A", &e.a, gpu.stages_timer_name());
            if let Some(b) = &e.b {
                side(ui, "B", b, gpu.stages_timer_name());
            }
            debug_pictures(app, ui, e.id, &e.a);
        }
        None => {
            ui.label("error, counters and debug pictures: once the reference is current");
        }
    }
}

fn side(ui: &mut egui::Ui, which: &str, s: &SideEval, stages_timer: &str) {
    ui.separator();
    ui.strong(format!("{which}: {}", s.label));
    let m = &s.metrics;
    ui.label(format!("wrong {:.3} %  (false lit {:.3} %, false shadow {:.3} %)", m.wrong_pct, m.false_lit_pct, m.false_shadow_pct));
    ui.label(format!("MAE {:.4} over {} pixels", m.mae, m.evaluated_pixels));
    ui.label(format!("shadow data {:.2} MiB", s.report.shadow_data_bytes as f64 / (1024.0 * 1024.0)));
    for d in &s.report.degraded {
        ui.colored_label(egui::Color32::from_rgb(240, 160, 40), format!("degraded: {d}"));
    }
    for (k, v) in s.report.counters.iter().filter(|(k, _)| k.contains("rays")) {
        ui.label(format!("{k}: {v}"));
    }
    if !s.stages_ms.is_empty() {
        stages(ui, &format!("{which} stages"), stages_timer, &s.stages_ms);
    }
    egui::CollapsingHeader::new(format!("{which} counters")).show(ui, |ui| {
        for (k, v) in &s.report.counters {
            ui.monospace(format!("{k} = {v}"));
        }
    });
}

fn stages(ui: &mut egui::Ui, title: &str, timer: &str, ms: &std::collections::BTreeMap<String, f64>) {
    egui::CollapsingHeader::new(title).default_open(true).show(ui, |ui| {
        ui.small(format!("timer: {timer}"));
        for (k, v) in ms {
            ui.monospace(format!("{v:8.2} ms  {k}"));
        }
    });
}

fn debug_pictures(app: &mut App, ui: &mut egui::Ui, id: u64, a: &SideEval) {
    let d = &mut app.debug;
    if d.key != Some(id) {
        d.textures = a
            .report
            .images
            .iter()
            .map(|img| {
                let c = egui::ColorImage::from_rgba_unmultiplied([img.width as usize, img.height as usize], &img.rgba);
                (img.name.clone(), ui.ctx().load_texture(format!("debug:{}", img.name), c, egui::TextureOptions::NEAREST))
            })
            .collect();
        d.key = Some(id);
        d.pick = d.pick.min(d.textures.len().saturating_sub(1));
    }
    if d.textures.is_empty() {
        return;
    }
    ui.separator();
    let names: Vec<String> = d.textures.iter().map(|(n, _)| n.clone()).collect();
    egui::ComboBox::from_label("debug picture").selected_text(&names[d.pick]).show_ui(ui, |ui| {
        for (i, n) in names.iter().enumerate() {
            ui.selectable_value(&mut d.pick, i, n);
        }
    });
    let tex = &d.textures[d.pick].1;
    let size = tex.size_vec2();
    let wmax = ui.available_width();
    ui.image((tex.id(), size * (wmax / size.x).min(1.0).max(wmax.min(256.0) / size.x)));
}
