//! `shadowlab tune`: the grid on the train setups, the choice against the defaults on disjoint
//! validate setups, resumed sweeps, and clear errors.

use std::path::PathBuf;
use std::process::Command;

fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shadowlab"));
    c.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    c
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowlab-tune-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn json(p: PathBuf) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))).unwrap()
}

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
