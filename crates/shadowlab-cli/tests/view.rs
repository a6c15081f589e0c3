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

/// `shadowlab view ARGS --out DIR` under Xvfb, killed after `timeout_s` seconds.
fn view_under_xvfb(args: &[&str], dir: &std::path::Path, timeout_s: u32) -> std::process::Output {
    Command::new("timeout")
        .arg(timeout_s.to_string())
        .args(["xvfb-run", "-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_shadowlab"))
        .arg("view")
        .args(args)
        .arg("--out")
        .arg(dir)
        .env("XDG_RUNTIME_DIR", std::env::temp_dir())
        .output()
        .unwrap()
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
    let shot_arg = shot.to_str().unwrap();
    let args = ["--scene", "planebox", "-t", "sm", "--size", "160x120", "--exit-after", "6", "--orbit", "4", "--set-at", "3:pcf=3"];
    let out = view_under_xvfb(&[&args[..], &["--screenshot", shot_arg]].concat(), &dir, 300);
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

/// A lost device (forced: `--lose-device-at` destroys it, as a driver reset would) ends the
/// viewer with one message naming the loss and how to reopen the view, saved as a setup; no
/// panic, no frozen window.
#[test]
fn a_lost_device_saves_the_view_and_says_so() {
    if skip_gpu() {
        return;
    }
    let dir = tmp("lost");
    let args =
        ["--scene", "planebox", "-t", "sm:pcf=3", "--size", "160x120", "--exit-after", "40", "--orbit", "2", "--lose-device-at", "4"];
    let out = view_under_xvfb(&args, &dir, 120);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "stdout: {stdout}\nstderr: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stdout.contains("frame 4: destroying the GPU device"), "{stdout}");
    assert!(stderr.contains("the GPU device was lost (destroyed)") && stderr.contains("shadowlab view --setup"), "{stderr}");
    let saved: Vec<_> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|x| x == "toml")).collect();
    assert_eq!(saved.len(), 1, "{saved:?}");
    assert!(stderr.contains(&saved[0].display().to_string()), "{stderr}");
    let setup = shadowlab_core::setup::Setup::load(&saved[0]).unwrap();
    setup.validate().unwrap();
    let specs: Vec<_> = setup.techniques.iter().map(|t| t.spec.as_str()).collect();
    assert_eq!(specs, ["sm:pcf=3"]);
    // the camera orbited before the loss: the saved view is where the window was, not the start
    let start = shadowlab_core::builtin::builtin("planebox").unwrap().camera;
    assert_ne!(setup.camera.unwrap().position, start.position);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A scripted session that switches techniques and turns the light (every technique and the
/// reference are made again for each light) keeps its resident memory: after two rounds of the
/// cycle, the end is within 10 % (the 10-minute run: BENCHMARKS.md, scripts/long-session.sh).
#[test]
fn a_long_session_keeps_its_memory() {
    if skip_gpu() {
        return;
    }
    let dir = tmp("long");
    let args = [
        ["--scene", "planebox", "-t", "sm", "--size", "160x120", "--exit-after", "160", "--orbit", "1.5"].as_slice(),
        &["--cycle", "sm", "--cycle", "vsm:res=512", "--cycle", "lt:res=512", "--cycle", "sm:pcf=3", "--cycle-every", "4"],
        &["--light-turn", "9", "--memory-every", "0.25"],
    ]
    .concat();
    let out = view_under_xvfb(&args, &dir, 300);
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "stdout: {stdout}\nstderr: {stderr}");
    // "memory: t=1.2 s, frame 40, resident 210.3 MiB, technique A ..."
    let samples: Vec<(usize, f64)> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("memory: "))
        .map(|l| {
            let frame = l.split("frame ").nth(1).unwrap().split(',').next().unwrap().parse().unwrap();
            let mib = l.split("resident ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
            (frame, mib)
        })
        .collect();
    assert!(samples.len() >= 4, "{stdout}");
    assert!(stdout.contains("technique A lt:res=512"), "the cycle ran: {stdout}");
    let warm = samples.iter().find(|(f, _)| *f >= 32).expect("a sample after two rounds").1;
    let end = samples.last().unwrap();
    assert_eq!(end.0, 160, "{stdout}");
    assert!(end.1 <= warm * 1.10, "resident {:.1} MiB at the end against {warm:.1} MiB after two rounds: {samples:?}", end.1);
    let _ = std::fs::remove_dir_all(&dir);
}
