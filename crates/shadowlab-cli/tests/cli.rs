//! End-to-end tests of the `shadowlab` binary: outputs, determinism, and clear errors for bad
//! input (one `error:` line, non-zero exit, no panic, no report left behind).

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::*;

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shadowlab-core/tests/fixtures")
}

/// metrics.json without the timings and the peak memory (which legitimately vary).
fn metrics_without_times(dir: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("metrics.json")).unwrap()).unwrap();
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                m.retain(|k, _| !k.ends_with("_ms") && k != "peak_rss_mib");
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    strip(&mut v);
    v
}

#[test]
fn compare_writes_report_metrics_and_exports() {
    if skip_gpu() {
        return;
    }
    let out = tmp("report");
    let o = run(&[
        "compare",
        "--scene",
        "planebox",
        "--size",
        "96x64",
        "-t",
        "sm",
        "-t",
        "sm:pcf=3,label=soft",
        "--repeat",
        "1",
        "--export",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in [
        "index.html",
        "metrics.json",
        "metrics.csv",
        "rt.png",
        "sm.png",
        "sm-error.png",
        "soft.png",
        "position.npy",
        "normal.npy",
        "mask.npy",
        "visibility/rt.npy",
        "visibility/soft.npy",
    ] {
        assert!(out.join(f).exists(), "missing {f}");
    }
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["width"], 96);
    assert_eq!(m["height"], 64);
    assert_eq!(m["scene_transform"][0][0], 1.0);
    let t = &m["techniques"][1];
    assert_eq!(t["label"], "soft");
    assert_eq!(t["technique"], "sm");
    assert_eq!(t["params"]["pcf"], 3.0);
    assert_eq!(t["counters"]["fetches_per_pixel"], 9.0);
    for k in ["wrong_pct", "false_lit_pct", "false_shadow_pct", "mae", "evaluated_pixels", "shadow_data_bytes", "stages_ms", "total_ms"] {
        assert!(!t[k].is_null(), "metrics.json lacks {k}");
    }
    assert!(t["evaluated_pixels"].as_u64().unwrap() > 100);
    // npy header states the shape
    let head = std::fs::read(out.join("position.npy")).unwrap();
    let text = String::from_utf8_lossy(&head[..128.min(head.len())]);
    assert!(text.contains("(64, 96, 3"), "{text}");
    let csv = std::fs::read_to_string(out.join("metrics.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3);
    assert!(!std::fs::read_dir(out.parent().unwrap()).unwrap().any(|e| e.unwrap().file_name().to_string_lossy().contains(".partial")));
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn flip_is_zero_where_the_shading_agrees_with_rt_and_positive_where_not() {
    if skip_gpu() {
        return;
    }
    let out = tmp("flip");
    // rt against itself; sv agrees with rt on planebox; sm with a 64x64 map does not
    let o = run(&[
        "compare",
        "-q",
        "--scene",
        "planebox",
        "--size",
        "96x64",
        "-t",
        "rt",
        "-t",
        "sv",
        "-t",
        "sm:res=64",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let t = m["techniques"].as_array().unwrap();
    let flip = |i: usize| t[i]["flip_mean"].as_f64().unwrap_or_else(|| panic!("{} has no flip_mean", t[i]["label"]));
    assert_eq!(flip(0), 0.0, "rt against rt");
    assert!(flip(1) < 1e-3, "sv: {}", flip(1));
    if t[1]["mae"].as_f64().unwrap() == 0.0 {
        assert_eq!(flip(1), 0.0, "sv's visibility equals rt's: the same image");
    }
    assert!(t[2]["wrong_pct"].as_f64().unwrap() > 0.0, "sm:res=64 has wrong pixels");
    assert!(flip(2) > 1e-4 && flip(2) < 0.5, "sm:res=64: {}", flip(2));
    for (i, slug) in ["rt", "sv", "sm_res_64"].iter().enumerate() {
        let file = t[i]["images"]["flip"].as_str().unwrap();
        assert_eq!(file, format!("{slug}-flip.png"));
        let img = image::open(out.join(file)).unwrap().into_rgb8();
        assert_eq!(img.dimensions(), (96, 64));
        let black = img.pixels().all(|p| p.0 == [0, 0, 4]);
        assert_eq!(black, flip(i) == 0.0, "{file}: magma's black exactly where there is no error");
    }
    let csv = std::fs::read_to_string(out.join("metrics.csv")).unwrap();
    assert!(csv.starts_with("label,technique,wrong_pct,false_lit_pct,false_shadow_pct,mae,flip_mean,"), "{csv}");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<th>wrong %</th><th>FLIP&dagger;</th>") && html.contains("src=\"sm_res_64-flip.png\""));
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn a_scene_file_loads_without_a_setup() {
    if skip_gpu() {
        return;
    }
    let out = tmp("file");
    let scene = fixtures().join("quad.obj");
    let o = run(&[
        "compare",
        "-q",
        "--scene",
        scene.to_str().unwrap(),
        "--size",
        "32x32",
        "-t",
        "sm",
        "--repeat",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["scene"], "quad");
    assert!(m["triangles"].as_u64().unwrap() > 0);
    assert_eq!(m["scene_transform"][1][1], 1.0);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn the_same_run_twice_gives_identical_metrics() {
    if skip_gpu() {
        return;
    }
    let (a, b) = (tmp("twice-a"), tmp("twice-b"));
    for d in [&a, &b] {
        // the default list: every technique family that supports the sun
        let o = run(&["compare", "--scene", "foliage", "--size", "128x128", "--repeat", "1", "-q", "--out", d.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let m = metrics_without_times(&a);
    assert!(m["techniques"].as_array().unwrap().len() >= 12, "the default list runs every family");
    assert_eq!(m, metrics_without_times(&b));
    let _ = std::fs::remove_dir_all(&a);
    let _ = std::fs::remove_dir_all(&b);
}

#[test]
fn frames_follow_the_camera_path_with_per_frame_metrics() {
    if skip_gpu() {
        return;
    }
    let out = tmp("frames");
    let o = out.to_str().unwrap();
    let r = run(&["compare", "-q", "--scene", "room", "--size", "96x96", "--frames", "4", "-t", "sm", "-t", "sm:res=1024", "--out", o]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["frames"], 4);
    let cams = m["cameras"].as_array().unwrap();
    assert_eq!(cams.len(), 4);
    assert_ne!(cams[0]["position"], cams[3]["position"], "the room's camera walks its path");
    assert_eq!(m["reference"]["frames"].as_array().unwrap().len(), 4);
    for t in m["techniques"].as_array().unwrap() {
        let fr = t["frames"].as_array().unwrap();
        assert_eq!(fr.len(), 4);
        assert!(fr[0]["flicker_pct"].is_null() && fr[1..].iter().all(|f| f["flicker_pct"].is_number()));
        let mean = fr.iter().map(|f| f["wrong_pct"].as_f64().unwrap()).sum::<f64>() / 4.0;
        assert!((t["wrong_pct"].as_f64().unwrap() - mean).abs() < 1e-9, "top-level wrong % is the mean over frames");
        let fl = fr[1..].iter().map(|f| f["flicker_pct"].as_f64().unwrap()).sum::<f64>() / 3.0;
        assert!((t["flicker_pct"].as_f64().unwrap() - fl).abs() < 1e-9);
        let flip = fr.iter().map(|f| f["flip_mean"].as_f64().unwrap()).sum::<f64>() / 4.0;
        assert!((t["flip_mean"].as_f64().unwrap() - flip).abs() < 1e-12, "top-level FLIP is the mean over frames");
        for f in fr.iter().filter(|f| f["wrong_pct"].as_f64().unwrap() > 0.0) {
            assert!(f["flip_mean"].as_f64().unwrap() > 0.0, "wrong pixels are seen by FLIP too: {f}");
        }
        assert!(fr.iter().any(|f| f["wrong_pct"] != fr[0]["wrong_pct"]), "frames differ");
    }
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("flicker vs previous frame"), "per-frame charts in the report");
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_input_gives_one_clear_error_and_no_report() {
    let out = tmp("bad");
    let o = out.to_str().unwrap();
    let f = fixtures();
    let setup_dir = tmp("setup");
    std::fs::create_dir_all(&setup_dir).unwrap();
    let bad_setup = setup_dir.join("bad.toml");
    std::fs::write(&bad_setup, "[scene]\nbuiltin = \"room\"\nscael = 2.0\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (vec!["--scene".into(), "atlantis".into()], "unknown scene"),
        (vec!["-t".into(), "nope".into()], "unknown technique"),
        (vec!["-t".into(), "sm:rez=2".into()], "no parameter 'rez'"),
        (vec!["-t".into(), "sm:res=0".into()], "out of range"),
        (vec!["--size".into(), "0x10".into()], "at least 1"),
        (vec!["--size".into(), "big".into()], "WxH"),
        (vec!["--scene".into(), f.join("malformed/garbage.obj").display().to_string()], "garbage.obj"),
        (vec!["--scene".into(), f.join("malformed/truncated.glb").display().to_string()], "truncated.glb"),
        (vec!["--scene".into(), "/nonexistent/scene.obj".into()], "not found"),
        (vec!["--setup".into(), bad_setup.display().to_string()], "scael"),
        (vec!["--scene".into(), "room".into(), "--light".into(), "1".into(), "-t".into(), "sm".into()], "point"),
        (vec!["--light".into(), "7".into()], "light"),
        (vec!["--frames".into(), "0".into()], "--frames"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["compare".to_string(), "--quiet".into(), "--out".into(), o.into()];
        all.extend(args);
        let refs: Vec<&str> = all.iter().map(|s| s.as_str()).collect();
        assert_clean_error(&run(&refs), needle);
        assert!(!out.exists(), "a failed run left {}", out.display());
    }
    // over the device limit: needs the device
    if !skip_gpu() {
        assert_clean_error(&run(&["compare", "-q", "--scene", "planebox", "--size", "100000x8", "--out", o]), "device");
        assert!(!out.exists());
    }
}

#[test]
fn no_adapter_is_one_clear_error() {
    // Restricting wgpu to a backend this build lacks leaves no adapter at all.
    let o =
        bin().env("WGPU_BACKEND", "gl").args(["render", "--scene", "planebox", "--size", "8x8", "--out", "/dev/null"]).output().unwrap();
    assert_clean_error(&o, "no GPU adapter found");
    assert!(String::from_utf8_lossy(&o.stderr).contains("mesa-vulkan-drivers"));
}

#[test]
fn techniques_and_scenes_list_the_registries() {
    let o = run(&["techniques"]);
    assert!(o.status.success());
    let s = String::from_utf8_lossy(&o.stdout);
    for needle in ["sm ", "rt ", "res", "default 512", "pcf", "normal_offset", "source:", "compare: sm, sm:pcf=3"] {
        assert!(s.contains(needle), "techniques output lacks '{needle}'");
    }
    // the default compare set is the registry's, listed once
    let set = shadowlab_gpu::registry::default_compare().join(" ");
    assert!(s.contains(&format!("Without -t, compare runs the `compare:` specs above: {set}.")), "{s}");
    let o = run(&["scenes"]);
    let s = String::from_utf8_lossy(&o.stdout);
    for needle in ["courtyard", "room", "foliage", "[default]"] {
        assert!(s.contains(needle), "scenes output lacks '{needle}'");
    }
}

#[test]
fn moving_objects_move_with_the_frames_and_bad_animations_are_clear_errors() {
    let setup_dir = tmp("anim-setup");
    std::fs::create_dir_all(&setup_dir).unwrap();
    let bad = setup_dir.join("bad.toml");
    std::fs::write(&bad, "[scene]\nbuiltin = 'planebox'\n[[animations]]\nname = 'x'\nmaterials = ['nope']\nmotion = { type = 'orbit', center = [0, 0, 0], axis = [0, 1, 0], period = 10 }\n").unwrap();
    let out = tmp("anim");
    let o = out.to_str().unwrap();
    assert_clean_error(&run(&["compare", "-q", "--setup", bad.to_str().unwrap(), "--out", o]), "unknown material 'nope'");
    assert_clean_error(&run(&["compare", "-q", "--scene", "planebox", "--time", "NaN", "--out", o]), "--time");
    assert!(!out.exists());
    if skip_gpu() {
        return;
    }
    let good = setup_dir.join("good.toml");
    std::fs::write(&good, "[scene]\nbuiltin = 'planebox'\n[[animations]]\nname = 'box'\nmaterials = ['box']\nmotion = { type = 'translate', offset = [2, 0, 0], period = 4 }\n").unwrap();
    let r = run(&[
        "compare",
        "-q",
        "--setup",
        good.to_str().unwrap(),
        "--size",
        "96x96",
        "--frames",
        "3",
        "--time",
        "1",
        "-t",
        "sm",
        "--out",
        o,
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["animation"]["dynamic_triangles"], 12, "the box's 12 triangles move");
    assert_eq!(m["animation"]["animations"][0]["name"], "box");
    let times: Vec<f64> = m["reference"]["frames"].as_array().unwrap().iter().map(|f| f["time"].as_f64().unwrap()).collect();
    assert_eq!(times, [1.0, 2.0, 3.0]);
    let _ = std::fs::remove_dir_all(&out);
    let r = run(&["compare", "-q", "--scene", "planebox", "--size", "64x64", "-t", "sm", "--out", o]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let m: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(m["animation"]["dynamic_triangles"], 0, "planebox stands still");
    let _ = std::fs::remove_dir_all(&out);
    let _ = std::fs::remove_dir_all(&setup_dir);
}

#[test]
fn no_stray_error_lines_without_xdg_runtime_dir() {
    // Mesa complains on stderr when XDG_RUNTIME_DIR is unset; the binary sets a private one
    if skip_gpu() {
        return;
    }
    let out = tmp("xdg.png");
    let o = Command::new(env!("CARGO_BIN_EXE_shadowlab"))
        .env_remove("XDG_RUNTIME_DIR")
        .args(["render", "--scene", "planebox", "--size", "32x32", "-t", "sm", "--repeat", "1", "--quiet", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "render failed: {err}");
    assert!(!err.contains("error"), "stray error output: {err}");
    let _ = std::fs::remove_file(&out);
}

#[test]
fn out_refuses_a_directory_or_file_shadowlab_did_not_write() {
    // refused before any GPU work, so this runs without an adapter too
    let dir = tmp("users-dir");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("mine.txt"), "keep me").unwrap();
    let file = tmp("users-file");
    std::fs::write(&file, "keep me too").unwrap();
    for (out, needle) in [(&dir, "did not write"), (&file, "not a directory")] {
        let o = run(&["compare", "--scene", "planebox", "--size", "16x16", "-t", "sm", "-q", "--out", out.to_str().unwrap()]);
        assert_clean_error(&o, needle);
        assert_eq!(String::from_utf8_lossy(&o.stderr).lines().filter(|l| l.contains("error")).count(), 1, "one error line");
    }
    assert_eq!(std::fs::read_to_string(dir.join("mine.txt")).unwrap(), "keep me");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep me too");
    assert_eq!(
        std::fs::read_dir(dir.parent().unwrap())
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().contains("users-dir.partial"))
            .count(),
        0
    );
    std::fs::remove_dir_all(&dir).unwrap();
    std::fs::remove_file(&file).unwrap();
}

/// The report in a real browser: the table sorts by a column and hides columns (the view a
/// link carries in its fragment), and the quality/cost chart is there.
#[test]
fn the_report_sorts_and_hides_columns_in_chromium() {
    if skip_gpu() {
        return;
    }
    let out = tmp("report-browser");
    let specs = ["sm:pcf=3", "sm", "sv", "vsm"];
    let mut args = vec!["compare", "--scene", "planebox", "--size", "96x64", "--repeat", "1", "--quiet", "--out", out.to_str().unwrap()];
    for s in &specs {
        args.extend(["-t", s]);
    }
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let metrics: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("metrics.json")).unwrap()).unwrap();
    let mut by_wrong: Vec<(f64, String)> = metrics["techniques"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| (t["wrong_pct"].as_f64().unwrap(), t["label"].as_str().unwrap().to_string()))
        .collect();
    by_wrong.sort_by(|a, b| b.0.total_cmp(&a.0));
    let url = format!("file://{}#sort=1,desc&hide=2,3", out.join("index.html").display());
    let dom = chromium_dom(&url);
    let table = &dom[dom.find("<table id=\"metrics\">").expect("the metrics table")..];
    let table = &table[..table.find("</table>").unwrap()];
    // rows in the DOM's order, by their first cell
    let order: Vec<&str> = table.split("<tr>").skip(2).map(|r| r.split("<td>").nth(1).unwrap().split('<').next().unwrap().trim()).collect();
    let want: Vec<&str> = by_wrong.iter().map(|(_, l)| l.as_str()).collect();
    // equal wrong % may come in either order; the sorted figures must not increase
    assert_eq!(order.len(), want.len(), "{order:?}");
    let wrong_of = |l: &str| by_wrong.iter().find(|(_, x)| x == l).unwrap().0;
    assert!(order.windows(2).all(|w| wrong_of(w[0]) >= wrong_of(w[1])), "sorted by wrong % descending: {order:?} vs {want:?}");
    assert!(dom.contains("th class=\"sortable desc\""), "the sorted column is marked");
    assert_eq!(table.matches("display: none").count(), 2 * (1 + specs.len()), "FLIP and false-lit hidden in every row");
    assert!(dom.contains("Quality against cost") && dom.matches("<svg").count() >= 2, "the quality/cost charts");
    let _ = std::fs::remove_dir_all(&out);
}
