//! `shadowlab view`: a saved view reproduces its numbers through `compare --setup`, the window
//! opens and renders under Xvfb (installed by scripts/setup.sh), and without a display the
//! command fails with one clear line.

use std::path::PathBuf;
use std::process::Command;

use shadowlab_core::builtin::builtin;
use shadowlab_core::light::Light;
use shadowlab_gpu::lab::Lab;
use shadowlab_gpu::Gpu;
use shadowlab_view::fly::{orbit, sun_angles, sun_direction};
use shadowlab_view::render::{Look, Pose, RefStatus, Renderer, Right, Show};
use shadowlab_view::session;
use shadowlab_view::widgets::resolve_text;

use crate::common::*;

fn tmp(name: &str) -> PathBuf {
    let d = crate::common::tmp(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn without_a_display_view_names_the_fix() {
    let out = bin().args(["view", "--scene", "planebox"]).env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY").output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.lines().filter(|l| l.starts_with("error:")).count(), 1, "{err}");
    assert!(err.contains("xvfb-run") && err.contains("desktop session"), "{err}");
}

#[test]
fn a_saved_view_reproduces_its_numbers_in_compare() {
    if skip_gpu() {
        return;
    }
    let gpu = Gpu::new().unwrap();
    // courtyard's banners move: a moved camera, a moved sun, time 4.5, edited parameters
    let scene = builtin("courtyard").unwrap();
    let base = shadowlab_core::setup::Setup::parse("[scene]\nbuiltin = \"courtyard\"\n").unwrap();
    let (w, h) = (80, 64);
    let a = resolve_text("sm:res=192,pcf=3,label=edited").unwrap();
    let Light::Directional { direction } = scene.lights[0] else { panic!("courtyard has a sun") };
    let (az, el) = sun_angles(direction);
    let light = Light::Directional { direction: sun_direction(az - 9.0, el + 3.0) };
    let camera = orbit(&scene.camera, -5.0);
    let pose = Pose { camera, prev_camera: camera, light, time: 4.5, prev_time: 4.5 };
    let mut r = Renderer::new(Lab::new(&gpu, &scene).unwrap(), w, h, &light, a.clone(), None).unwrap();
    let look = Look { show: Show::Error, right: Right::None, divider: 0.5 };
    let mut e = None;
    for _ in 0..100 {
        if r.frame(&pose, &look, true).unwrap().reference == RefStatus::Current {
            e = r.evaluation().cloned();
            break;
        }
    }
    let e = e.expect("the reference became current");
    let dir = tmp("roundtrip");
    let setup = session::snapshot(&base, &camera, &light, pose.time, w, h, &[a.text.clone()]);
    let file = session::write_fresh(&dir, "view", "toml", session::to_toml(&setup).unwrap().as_bytes()).unwrap();
    let report = dir.join("report");
    let out = bin().args(["compare", "--setup"]).arg(&file).arg("--out").arg(&report).args(["--quiet", "--repeat", "1"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(report.join("metrics.json")).unwrap()).unwrap();
    let t = &m["techniques"][0];
    assert_eq!(t["label"], "edited");
    assert_eq!((m["width"].as_u64(), m["height"].as_u64()), (Some(w as u64), Some(h as u64)));
    assert_eq!(t["evaluated_pixels"].as_u64(), Some(e.a.metrics.evaluated_pixels));
    for (k, v) in [
        ("wrong_pct", e.a.metrics.wrong_pct),
        ("false_lit_pct", e.a.metrics.false_lit_pct),
        ("false_shadow_pct", e.a.metrics.false_shadow_pct),
        ("mae", e.a.metrics.mae),
    ] {
        assert_eq!(t[k].as_f64(), Some(v), "{k}: compare {} vs the viewer's {v}", t[k]);
    }
    assert!(e.a.metrics.wrong_pct > 0.0, "a 192 map leaves wrong pixels to compare");
    // the same error image, pixel for pixel
    let png = image::open(report.join("edited-error-split.png")).unwrap().to_rgba8();
    assert_eq!(png.as_raw(), &e.a.error);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_window_renders_under_xvfb() {
    if skip_gpu() {
        return;
    }
    let xvfb = Command::new("xvfb-run").arg("--help").output();
    assert!(xvfb.is_ok(), "xvfb-run not found: `make setup` (scripts/setup.sh) installs xvfb for this test");
    let dir = tmp("smoke");
    let shot = dir.join("last.png");
    let out = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_shadowlab"))
        .args(["view", "--scene", "planebox", "-t", "sm", "--size", "160x120", "--exit-after", "6", "--orbit", "4", "--set-at", "3:pcf=3"])
        .arg("--screenshot")
        .arg(&shot)
        .arg("--out")
        .arg(&dir)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "stdout: {stdout}\nstderr: {stderr}");
    assert!(stdout.contains("frame 3: technique A is now sm:pcf=3"), "{stdout}");
    assert!(stdout.contains("view: 6 frames"), "{stdout}");
    let img = image::open(&shot).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (160, 120));
    // not blank: sky, lit and shadowed ground and the box are there (flat shading, few colours)
    let mut counts = std::collections::HashMap::new();
    for p in img.pixels() {
        *counts.entry(p.0).or_insert(0usize) += 1;
    }
    let most = counts.values().max().copied().unwrap_or(0);
    assert!(counts.len() >= 4, "{} colours", counts.len());
    assert!(most < img.pixels().len() * 9 / 10, "one colour covers {most} of {} pixels", img.pixels().len());
    let luma: Vec<u32> = img.pixels().map(|p| p.0[0] as u32 + p.0[1] as u32 + p.0[2] as u32).collect();
    let (lo, hi) = (luma.iter().min().unwrap(), luma.iter().max().unwrap());
    assert!(hi - lo > 150, "dark and bright pixels: luma {lo}..{hi}");
    std::fs::remove_dir_all(&dir).unwrap();
}
