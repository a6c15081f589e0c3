//! End-to-end tests of `shadowlab sweep`: outputs, the per-point cache across an interruption,
//! shards merged into the unsharded rows, and clear errors before any work.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

use crate::common::*;

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "stdout: {}\nstderr: {}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).to_string()
}

/// The small sweep of these tests: one scene, 3 points.
fn sweep(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["sweep", "--scene", "planebox", "--size", "64x64", "-t", "sm:res=256|512", "-t", "lt", "--repeat", "1", "--quiet"];
    args.extend_from_slice(&["--out", out.to_str().unwrap()]);
    args.extend_from_slice(extra);
    run(&args)
}

fn sweep_json(dir: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("sweep.json")).unwrap()).unwrap()
}

/// The rows without their times (which legitimately vary between runs).
fn rows_without_times(v: &Value) -> Vec<Value> {
    let mut rows = v["rows"].as_array().unwrap().clone();
    for r in &mut rows {
        r.as_object_mut().unwrap().retain(|k, _| !k.ends_with("_ms"));
    }
    rows
}

fn point_files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir.join("points")).unwrap().map(|e| e.unwrap().path()).collect();
    v.sort();
    v
}

fn no_partials(dir: &Path) {
    for d in [dir.to_path_buf(), dir.join("points")] {
        for e in std::fs::read_dir(&d).unwrap() {
            let n = e.unwrap().file_name().to_string_lossy().to_string();
            assert!(!n.contains(".partial"), "half-written {n} left in {}", d.display());
        }
    }
}

#[test]
fn a_sweep_writes_its_outputs_and_a_rerun_computes_only_the_missing_point() {
    if skip_gpu() {
        return;
    }
    let out = tmp("resume");
    ok(&sweep(&out, &["--budget-bytes", "1048576"]));
    let v = sweep_json(&out);
    assert_eq!(v["schema_version"], 2);
    assert_eq!((v["points_computed"].as_u64(), v["points_cached"].as_u64()), (Some(3), Some(0)));
    assert_eq!(v["views_computed"], 1, "one G-buffer + reference for the three points");
    let rows = v["rows"].as_array().unwrap();
    let labels: Vec<&str> = rows.iter().map(|r| r["label"].as_str().unwrap()).collect();
    assert_eq!(labels, ["sm:res=256", "sm:res=512", "lt"]);
    assert_eq!(rows[1]["params"]["res"], 512);
    assert_eq!(rows[1]["shadow_data_bytes"], 512 * 512 * 4);
    for r in rows {
        assert_eq!(r["setup"], "planebox");
        assert!(r["evaluated_pixels"].as_u64().unwrap() > 1000 && r["total_ms"].as_f64().unwrap() > 0.0);
        assert!(r["wrong_pct"].as_f64().unwrap() < 5.0, "planebox has an exact shadow: {r}");
        let flip = r["flip_mean"].as_f64().expect("every row has flip_mean");
        assert!((0.0..0.2).contains(&flip), "{r}");
        if r["wrong_pct"].as_f64().unwrap() > 0.0 {
            assert!(flip > 0.0, "wrong pixels are seen by FLIP: {r}");
        }
        if r["mae"].as_f64().unwrap() == 0.0 {
            assert_eq!(flip, 0.0, "the same visibility, the same image: {r}");
        }
    }
    assert!(v["timer"].as_str().unwrap().len() > 5 && v["stages_timer"].is_string() && v["adapter"].is_string());
    // --budget-bytes 1 MiB: lt's maps do not fit; the better sm does
    assert_eq!(v["recommendation"]["best"]["label"], "sm:res=512");
    assert_eq!(v["recommendation"]["runners_up"][0]["label"], "sm:res=256");
    assert!(v["recommendation"]["runners_up"][0]["margin_pct"].as_f64().unwrap() >= 0.0);
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 4);
    assert!(csv.lines().nth(2).unwrap().starts_with("planebox,sm:res=512,sm,"));
    assert!(csv.starts_with("setup,label,technique,wrong_pct,false_lit_pct,false_shadow_pct,mae,flip_mean,"), "{csv}");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("Pareto front") && html.contains("recommended for shadow data"));
    assert!(html.contains("id=\"quality\"") && html.contains("id=\"plot-setup-0-flip-ms\""), "FLIP is offered as the quality");
    assert_eq!(point_files(&out).len(), 3);
    no_partials(&out);

    // a rerun: everything cached, no view computed
    let stdout = ok(&sweep(&out, &[]));
    assert!(stdout.is_empty(), "--quiet: {stdout}");
    let again = sweep_json(&out);
    assert_eq!(
        (again["points_computed"].as_u64(), again["points_cached"].as_u64(), again["views_computed"].as_u64()),
        (Some(0), Some(3), Some(0))
    );
    assert_eq!(again["rows"], v["rows"], "cached rows are the stored ones, times included");

    // an interruption: one finished point and the final files lost
    let lost = point_files(&out)[1].clone();
    std::fs::remove_file(&lost).unwrap();
    std::fs::remove_file(out.join("sweep.json")).unwrap();
    let o = run(&[
        "sweep",
        "--scene",
        "planebox",
        "--size",
        "64x64",
        "-t",
        "sm:res=256|512",
        "-t",
        "lt",
        "--repeat",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    let stdout = ok(&o);
    assert!(stdout.contains("1 computed, 2 cached"), "{stdout}");
    let resumed = sweep_json(&out);
    assert_eq!(
        (resumed["points_computed"].as_u64(), resumed["points_cached"].as_u64(), resumed["views_computed"].as_u64()),
        (Some(1), Some(2), Some(1))
    );
    assert!(lost.is_file(), "the lost point is stored again");
    assert_eq!(rows_without_times(&resumed), rows_without_times(&v), "the recomputed point equals the lost one");
    no_partials(&out);

    // another size is another sweep: nothing is reused
    ok(&run(&[
        "sweep",
        "--scene",
        "planebox",
        "--size",
        "48x48",
        "-t",
        "sm:res=256",
        "--repeat",
        "1",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert_eq!(sweep_json(&out)["points_computed"], 1);
    assert_eq!(point_files(&out).len(), 4);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn shards_merge_into_the_rows_of_the_whole_sweep() {
    if skip_gpu() {
        return;
    }
    let (whole, s1, s2, merged) = (tmp("whole"), tmp("shard1"), tmp("shard2"), tmp("merged"));
    ok(&sweep(&whole, &[]));
    ok(&sweep(&s1, &["--shard", "1/2"]));
    let a = sweep_json(&s1);
    assert_eq!(a["shard"]["index"], 1);
    assert_eq!(a["plan"].as_array().unwrap().len(), 3);
    let labels: Vec<&str> = a["rows"].as_array().unwrap().iter().map(|r| r["label"].as_str().unwrap()).collect();
    assert_eq!(labels, ["sm:res=256", "lt"], "shard 1/2: plan positions 0 and 2");
    // merging before every shard is done: the missing point is named
    let o = run(&["sweep", "merge", s1.to_str().unwrap(), "--out", merged.to_str().unwrap()]);
    assert_clean_error(&o, "1 of 3 points are in none of the shards (planebox / sm:res=512)");
    ok(&sweep(&s2, &["--shard", "2/2"]));
    assert_eq!(sweep_json(&s2)["rows"].as_array().unwrap().len(), 1);
    let stdout = ok(&run(&["sweep", "merge", s1.to_str().unwrap(), s2.to_str().unwrap(), "--out", merged.to_str().unwrap()]));
    assert!(stdout.contains("3 points"), "{stdout}");
    let m = sweep_json(&merged);
    assert_eq!(rows_without_times(&m), rows_without_times(&sweep_json(&whole)));
    assert!(m["shard"].is_null() && m["merged_from"].as_array().unwrap().len() == 2);
    assert_eq!(point_files(&merged).len(), 3, "the merged directory holds every point");
    assert_eq!(std::fs::read_to_string(merged.join("sweep.csv")).unwrap().lines().count(), 4);
    // the merged directory is a complete sweep: resuming it computes nothing
    ok(&sweep(&merged, &[]));
    assert_eq!(sweep_json(&merged)["points_computed"], 0);
    for d in [whole, s1, s2, merged] {
        std::fs::remove_dir_all(d).unwrap();
    }
}

#[test]
fn bad_sweep_input_is_one_clear_error_before_any_work() {
    let out = tmp("bad");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (&["sweep", "--scene", "planebox", "-t", "sm:res=7|512", "--out", o], "res=7"),
        (&["sweep", "--scene", "planebox", "-t", "sm:res=512|", "--out", o], "key 'res'"),
        (&["sweep", "--scene", "planebox", "-t", "sm:bais=1|2", "--out", o], "'bais'"),
        (&["sweep", "--scene", "planebox", "-t", "sm", "--shard", "3/2", "--out", o], "--shard"),
        (&["sweep", "--scene", "nowhere", "-t", "sm", "--out", o], "unknown scene 'nowhere'"),
        (&["sweep", "--scene", "planebox", "-t", "cube", "--out", o], "setup 'planebox'"),
        (&["sweep", "--scene", "planebox", "-t", "sm", "--budget-ms", "0", "--out", o], "--budget-ms"),
        (&["sweep", "--scene", "planebox", "--scene", "planebox", "-t", "sm", "--out", o], "two setups"),
        (&["sweep", "merge", "/nonexistent-shard", "--out", o], "sweep.json"),
    ];
    for (args, needle) in cases {
        assert_clean_error(&run(args), needle);
        assert!(!out.exists(), "{args:?} left {}", out.display());
    }
    // a directory of the user's is refused and left as it was
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    assert_clean_error(&run(&["sweep", "--scene", "planebox", "-t", "sm", "--out", o]), "did not write");
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 1);
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn help_lists_sweep_and_merge() {
    let top = String::from_utf8_lossy(&run(&["--help"]).stdout).to_string();
    assert!(top.contains("sweep"), "{top}");
    let h = String::from_utf8_lossy(&run(&["sweep", "--help"]).stdout).to_string();
    for flag in ["--setup", "--scene", "--shard", "--budget-ms", "--budget-mb", "--budget-bytes", "--frames", "--repeat", "merge"] {
        assert!(h.contains(flag), "sweep --help lacks {flag}: {h}");
    }
    let m = String::from_utf8_lossy(&run(&["sweep", "merge", "--help"]).stdout).to_string();
    assert!(m.contains("--out") && m.contains("DIRS"), "{m}");
}

#[test]
fn a_sweep_killed_mid_way_keeps_its_finished_points_and_computes_only_the_rest() {
    if skip_gpu() {
        return;
    }
    let out = tmp("kill");
    let o = out.to_str().unwrap().to_string();
    let args = [
        "sweep",
        "--scene",
        "foliage",
        "--size",
        "160x160",
        "-t",
        "sm:res=256|512|1024|2048,pcf=1|3",
        "--repeat",
        "1",
        "-q",
        "--out",
        o.as_str(),
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_shadowlab")).env("XDG_RUNTIME_DIR", std::env::temp_dir()).args(args).spawn().unwrap();
    // killed (SIGKILL: no clean-up) as soon as its first point is stored
    let t0 = std::time::Instant::now();
    while !out.join("points").is_dir() || point_files(&out).is_empty() {
        assert!(t0.elapsed().as_secs() < 120, "no point finished in 2 minutes");
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let _ = child.kill();
    child.wait().unwrap();
    let finished = point_files(&out).iter().filter(|p| p.extension().is_some_and(|x| x == "json")).count();
    assert!(finished >= 1);
    let stdout = ok(&run(&args));
    assert!(stdout.is_empty());
    let v = sweep_json(&out);
    assert_eq!(v["points_cached"].as_u64().unwrap() as usize, finished, "every point stored before the kill is reused");
    assert_eq!(v["points_computed"].as_u64().unwrap() as usize, 8 - finished, "only the missing points are computed");
    assert_eq!(v["rows"].as_array().unwrap().len(), 8);
    no_partials(&out);
    std::fs::remove_dir_all(&out).unwrap();
}
