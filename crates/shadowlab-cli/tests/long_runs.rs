//! What a long or odd run must not do: grow memory with the frame count, or report 0 % over a
//! view where nothing was compared.

use crate::common::*;

/// `shadowlab compare ARGS --size 32x32 --out OUT`, run to completion.
fn compare_32(args: &[&str], out: &std::path::Path) -> std::process::Output {
    let mut all = vec!["compare"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--size", "32x32", "--out", out.to_str().unwrap()]);
    run(&all)
}

/// Peak resident memory (MiB) of `compare --frames frames` with `spec` on planebox at 32x32.
fn peak_mib(spec: &str, frames: usize) -> f64 {
    let out = tmp(&format!("mem-{}-{frames}", spec.replace([':', ',', '='], "_")));
    let o = compare_32(&["--scene", "planebox", "-t", spec, "--frames", &frames.to_string(), "--quiet"], &out);
    assert!(o.status.success(), "{spec}: {}", String::from_utf8_lossy(&o.stderr));
    let m = json(out.join("metrics.json"));
    let _ = std::fs::remove_dir_all(&out);
    m["peak_rss_mib"].as_f64().expect("peak_rss_mib on Linux")
}

#[test]
fn memory_does_not_grow_with_the_frame_count() {
    // per-frame records hold figures only, and no frame leaves anything behind: 4x the frames
    // peak within 10 % (lavapipe's uniform inlining left 0.2-1.2 MB a frame behind for these,
    // 40 MB for the warped maps: shadowlab_gpu::quirks)
    if skip_gpu() {
        return;
    }
    for spec in ["sm", "vsm", "lt", "rtw"] {
        let (short, long) = (peak_mib(spec, 20), peak_mib(spec, 80));
        assert!(long <= short * 1.10, "{spec}: peak {long:.1} MiB over 80 frames against {short:.1} MiB over 20");
    }
}

/// A fresh scratch directory `name` holding `file` with `text`: (the directory, the file).
fn scratch_with(name: &str, file: &str, text: &str) -> (std::path::PathBuf, std::path::PathBuf) {
    let dir = tmp(name);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(file);
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

#[test]
fn a_view_with_nothing_evaluated_says_so() {
    if skip_gpu() {
        return;
    }
    // planebox's camera turned to look away from everything
    let camera = "[camera]\nposition = [0.0, 5.0, 20.0]\ntarget = [0.0, 5.0, 40.0]\nfov_y_deg = 40.0\nnear = 0.1\nfar = 50.0\n";
    let (dir, setup) = scratch_with("empty-view", "away.toml", &format!("[scene]\nbuiltin = \"planebox\"\n{camera}"));
    let out = dir.join("report");
    let o = compare_32(&["--setup", setup.to_str().unwrap(), "-t", "sm", "--repeat", "1"], &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("warning:") && err.contains("no evaluated pixels"), "no warning on stderr: {err}");
    let m = json(out.join("metrics.json"));
    assert_eq!(m["reference"]["evaluated_pixels"], 0);
    let w = m["warnings"].as_array().unwrap();
    assert!(w.len() == 1 && w[0].as_str().unwrap().contains("no evaluated pixels"), "{w:?}");
    // a view that sees the scene has no such warning
    let seen = dir.join("seen");
    let o = compare_32(&["--scene", "planebox", "-t", "sm", "--repeat", "1", "--quiet"], &seen);
    assert!(o.status.success());
    assert_eq!(json(seen.join("metrics.json"))["warnings"], serde_json::json!([]));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn coincident_triangles_run_through_every_default_technique() {
    // a floor and 40 copies of one triangle above it (duplicated faces, as CAD and scan exports
    // have them; more than a BVH leaf holds): the BVH stays shallow and every technique of the
    // default set runs. Few copies: notw's subdivision splits every copy on its own (100 copies
    // took it 11 s a frame in the debug build; docs/bench/robustness.md)
    if skip_gpu() {
        return;
    }
    let floor = "v -4 0 -4\nv 4 0 -4\nv 4 0 4\nv -4 0 4\nv 0 1 0\nv 1 1 0\nv 0 1 1\nf 1 3 2\nf 1 4 3\n";
    let (dir, obj) = scratch_with("coincident", "copies.obj", &format!("{floor}{}", "f 5 7 6\n".repeat(40)));
    let out = dir.join("report");
    let o = compare_32(&["--scene", obj.to_str().unwrap(), "--repeat", "1", "--quiet"], &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && !err.contains("panicked"), "{err}");
    let m = json(out.join("metrics.json"));
    assert_eq!(m["triangles"], 42);
    let depth = m["bvh"]["depth"].as_u64().unwrap();
    assert!(depth <= 6, "BVH depth {depth} over 40 copies");
    assert!(m["techniques"].as_array().unwrap().len() >= 10);
    assert!(m["reference"]["evaluated_pixels"].as_u64().unwrap() > 0);
    let _ = std::fs::remove_dir_all(&dir);
}

/// A frame count of 0 or above the path limit is refused before anything is made, naming the
/// limit (each frame keeps its figures, so a run's memory and metrics.json are bounded).
#[test]
fn a_frame_count_over_the_limit_is_refused_first() {
    for (cmd, n) in [("compare", "100001"), ("compare", "0"), ("sweep", "100001")] {
        let out = tmp(&format!("frames-{cmd}-{n}"));
        let t0 = std::time::Instant::now();
        let o = run(&[cmd, "--scene", "planebox", "-t", "sm", "--frames", n, "--out", out.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(&format!("--frames {n}")) && err.contains("100000"), "{cmd} --frames {n}: {err}");
        assert!(!out.exists(), "{cmd} wrote {} before refusing", out.display());
        assert!(t0.elapsed().as_secs_f64() < 10.0, "refused late");
    }
}
