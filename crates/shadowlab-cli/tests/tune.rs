//! `shadowlab tune`: the grid on the train setups, the choice against the defaults on disjoint
//! validate setups, resumed sweeps, and clear errors.

use std::path::PathBuf;

use crate::common::*;

#[test]
fn tune_chooses_on_train_and_judges_on_validate() {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        return;
    }
    let out = tmp("run");
    let args = [
        "tune",
        "-t",
        "sm:res=64|1024",
        "--train",
        "courtyard",
        "--validate",
        "city",
        "--validate",
        "planebox",
        "--size",
        "48x48",
        "--quiet",
        "--out",
    ];
    let run = bin().args(args).arg(&out).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let t = json(out.join("tune.json"));
    let ranking = t["train_ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), 2, "both grid points ranked");
    let (first, second) = (ranking[0]["mean_wrong_pct"].as_f64().unwrap(), ranking[1]["mean_wrong_pct"].as_f64().unwrap());
    assert!(first <= second, "best first");
    assert_eq!(t["chosen"], ranking[0]["label"]);
    assert_eq!(t["chosen"], "sm:res=1024", "a 64 texel map is worse than a 1024 one");
    let v = &t["chosen_validate"]["wrong_pct_by_setup"];
    assert!(v["city"].is_number() && v["planebox"].is_number(), "{v}");
    assert!(t["default_validate"]["wrong_pct_by_setup"]["city"].is_number());
    let carries = t["carries_over"].as_bool().unwrap();
    let verdict = t["verdict"].as_str().unwrap();
    assert_eq!(carries, verdict.starts_with("carries over"), "{verdict}");
    // the verdict follows the validate numbers: a better mean, and no worse on half the setups
    let (c, d) = (t["chosen_validate"]["mean_wrong_pct"].as_f64().unwrap(), t["default_validate"]["mean_wrong_pct"].as_f64().unwrap());
    let no_worse = ["city", "planebox"]
        .iter()
        .filter(|s| v[**s].as_f64().unwrap() <= t["default_validate"]["wrong_pct_by_setup"][**s].as_f64().unwrap())
        .count();
    assert_eq!(carries, c < d && 2 * no_worse >= 2, "{verdict}");
    assert!(std::fs::read_to_string(out.join("tune.md")).unwrap().contains("| sm:res=1024 |"));
    // a rerun resumes both sweeps: nothing is computed again
    let again = bin().args(args).arg(&out).output().unwrap();
    assert!(again.status.success());
    assert_eq!(json(out.join("train/sweep.json"))["points_computed"], 0);
    assert_eq!(json(out.join("validate/sweep.json"))["points_computed"], 0);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn tune_refuses_overlapping_lists_and_grids_without_lists() {
    for (extra, needle) in [
        (vec!["-t", "sm:res=64|128", "--train", "city", "--validate", "city"], "both --train and --validate"),
        (vec!["-t", "sm", "--train", "city", "--validate", "planebox"], "value lists"),
    ] {
        let out = bin().arg("tune").args(&extra).arg("--out").arg(tmp("bad")).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && err.contains("error:") && err.contains(needle), "{err}");
        assert!(!err.contains("panicked"));
    }
}

fn run_tune(out: &PathBuf, extra: &[&str]) -> serde_json::Value {
    let run = bin().arg("tune").args(extra).args(["--validate", "planebox", "--quiet", "--out"]).arg(out).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    json(out.join("tune.json"))
}

#[test]
fn halving_finds_the_grid_choice_for_fewer_full_size_points() {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        return;
    }
    // one candidate is clearly best: a 2048 texel map against maps of 16..64 texels
    let spec = "sm:res=16|24|32|40|48|56|64|2048";
    let common = ["-t", spec, "--train", "courtyard", "--size", "128x128"];
    let (g_out, h_out) = (tmp("grid"), tmp("halving"));
    let grid = run_tune(&g_out, &common);
    let halv = run_tune(&h_out, &[&common[..], &["--search", "halving", "--rungs", "3"]].concat());
    assert_eq!(grid["chosen"], "sm:res=2048");
    assert_eq!(halv["chosen"], grid["chosen"], "halving keeps the clearly best candidate");
    assert_eq!((grid["search"].as_str(), halv["search"].as_str()), (Some("grid"), Some("halving")));
    // grid: 8 points + the defaults at 128x128; halving: 8 at 32x32, 4 at 64x64, 2 + defaults at 128x128
    assert_eq!(grid["points_evaluated"], 9);
    assert_eq!(grid["full_size_points"].as_f64().unwrap(), 9.0);
    let rungs = halv["rungs"].as_array().unwrap();
    assert_eq!(rungs.len(), 2, "two rungs below the full size");
    assert_eq!((rungs[0]["width"].as_u64(), rungs[0]["scores"].as_array().unwrap().len()), (Some(32), 8));
    assert_eq!((rungs[1]["width"].as_u64(), rungs[1]["scores"].as_array().unwrap().len()), (Some(64), 4));
    assert_eq!(rungs[0]["kept"].as_array().unwrap().len(), 4);
    assert_eq!(rungs[1]["kept"].as_array().unwrap().len(), 2);
    assert!(rungs[1]["kept"].as_array().unwrap().contains(&"sm:res=2048".into()));
    assert_eq!(halv["train_ranking"].as_array().unwrap().len(), 2, "only the survivors reach the full size");
    assert_eq!(halv["points_evaluated"], 8 + 4 + 3);
    let h = halv["full_size_points"].as_f64().unwrap();
    assert!((h - (8.0 / 16.0 + 4.0 / 4.0 + 3.0)).abs() < 1e-9, "{h}");
    assert!(h < grid["full_size_points"].as_f64().unwrap());
    assert!(halv["pixels_evaluated"].as_u64().unwrap() < grid["pixels_evaluated"].as_u64().unwrap());
    // the rungs are sweeps: a rerun computes nothing
    let _ = run_tune(&h_out, &[&common[..], &["--search", "halving", "--rungs", "3"]].concat());
    for d in ["train-rung0", "train-rung1", "train"] {
        assert_eq!(json(h_out.join(d).join("sweep.json"))["points_computed"], 0, "{d}");
    }
    std::fs::remove_dir_all(&g_out).unwrap();
    std::fs::remove_dir_all(&h_out).unwrap();
}

#[test]
fn metric_flip_ranks_by_mean_flip() {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        return;
    }
    let out = tmp("flip");
    let t = run_tune(&out, &["-t", "sm:res=16|64|1024,pcf=1|3", "--train", "courtyard", "--size", "48x48", "--metric", "flip"]);
    assert_eq!(t["metric"], "flip");
    let ranking = t["train_ranking"].as_array().unwrap();
    assert_eq!(ranking.len(), 6);
    let flips: Vec<f64> = ranking.iter().map(|r| r["mean_flip_mean"].as_f64().unwrap()).collect();
    assert!(flips.windows(2).all(|w| w[0] <= w[1]), "best FLIP first: {flips:?}");
    assert!(flips[0] < flips[5], "the grid's FLIP differs: {flips:?}");
    assert_eq!(t["chosen"], ranking[0]["label"]);
    let verdict = t["verdict"].as_str().unwrap();
    assert!(verdict.contains("FLIP") || verdict.contains("is the defaults"), "{verdict}");
    std::fs::remove_dir_all(&out).unwrap();
}
