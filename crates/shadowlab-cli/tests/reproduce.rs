//! `shadowlab reproduce`: the claims file names real techniques, parameters and setups; a tiny
//! end-to-end run gives a verdict per claim and resumes from its cache; missing setups make
//! claims not comparable, with why. (The verdict logic is unit-tested in reproduce/verdict.rs.)

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use crate::common::*;

const CLAIMS: &str = include_str!("../src/reproduce/claims.toml");

fn stdout(args: &[&str]) -> String {
    let o = bin().args(args).output().unwrap();
    assert!(o.status.success());
    String::from_utf8(o.stdout).unwrap()
}

/// Technique name -> its parameter names, from `shadowlab techniques`.
fn techniques() -> BTreeMap<String, BTreeSet<String>> {
    let mut m: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut current = String::new();
    for line in stdout(&["techniques"]).lines() {
        if !line.starts_with(' ') && line.contains("  —  ") {
            current = line.split_whitespace().next().unwrap().to_string();
            m.entry(current.clone()).or_default();
        } else if line.starts_with("  ") && line.contains(" default ") {
            m.get_mut(&current).unwrap().insert(line.split_whitespace().next().unwrap().to_string());
        }
    }
    m
}

#[test]
fn every_claim_names_known_techniques_parameters_and_setups() {
    let data: toml::Table = toml::from_str(CLAIMS).unwrap();
    let techs = techniques();
    assert!(techs.contains_key("notw") && techs["mdsm"].contains("k"), "listing parsed: {techs:?}");
    let scenes = stdout(&["scenes"]);
    let setups = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../setups");
    let runs = data["run"].as_array().unwrap();
    let mut run_specs: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for r in runs {
        let id = r["id"].as_str().unwrap();
        match (r.get("setup").and_then(|v| v.as_str()), r.get("scene").and_then(|v| v.as_str())) {
            (Some(s), None) => assert!(setups.join(s).is_file(), "run {id}: setups/{s} is not shipped"),
            (None, Some(s)) => assert!(scenes.contains(&format!("  {s} ")), "run {id}: '{s}' is not a built-in scene"),
            _ => panic!("run {id}: one of setup and scene"),
        }
        let specs: Vec<String> = r["techniques"].as_array().unwrap().iter().map(|t| t.as_str().unwrap().to_string()).collect();
        for spec in &specs {
            let (name, params) = spec.split_once(':').unwrap_or((spec, ""));
            let known = techs.get(name).unwrap_or_else(|| panic!("run {id}: unknown technique '{name}'"));
            for kv in params.split(',').filter(|s| !s.is_empty()) {
                let key = kv.split('=').next().unwrap();
                assert!(known.contains(key), "run {id}: '{name}' has no parameter '{key}'");
            }
        }
        run_specs.insert(id.to_string(), specs);
    }
    let claims = data["claim"].as_array().unwrap();
    assert!(claims.len() >= 30, "{} claims", claims.len());
    for c in claims {
        let id = c["id"].as_str().unwrap();
        let seed = id.split('-').next().unwrap();
        assert!(["000", "001", "002", "003", "004"].contains(&seed), "{id}");
        assert!(c["source"].as_str().unwrap().starts_with(seed), "{id}: the source names its seed's section");
        let run_ids: Vec<&str> = match c.get("run") {
            Some(r) => vec![r.as_str().unwrap()],
            None => c["runs"].as_array().unwrap().iter().map(|r| r.as_str().unwrap()).collect(),
        };
        let mut labels: Vec<&str> =
            c.get("labels").and_then(|l| l.as_array()).map(|l| l.iter().map(|x| x.as_str().unwrap()).collect()).unwrap_or_default();
        labels.extend(["label", "num", "den"].iter().filter_map(|k| c.get(*k).and_then(|v| v.as_str())));
        assert!(!labels.is_empty(), "{id}");
        for r in run_ids {
            let specs = run_specs.get(r).unwrap_or_else(|| panic!("{id}: unknown run {r}"));
            for l in &labels {
                assert!(specs.iter().any(|s| s == l), "{id}: run {r} has no '{l}'");
            }
        }
    }
}

#[test]
fn a_tiny_reproduction_judges_every_claim_and_resumes() {
    if std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1") {
        return;
    }
    let out = tmp("003");
    let args = ["reproduce", "003", "--size", "64x64", "--repeat", "1", "--quiet", "--out"];
    let run = bin().args(args).arg(&out).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let r = json(out.join("reproduce.json"));
    let data: toml::Table = toml::from_str(CLAIMS).unwrap();
    let expected: Vec<&str> =
        data["claim"].as_array().unwrap().iter().map(|c| c["id"].as_str().unwrap()).filter(|id| id.starts_with("003-")).collect();
    let verdicts = r["verdicts"].as_array().unwrap();
    let got: Vec<&str> = verdicts.iter().map(|v| v["claim"].as_str().unwrap()).collect();
    assert_eq!(got, expected, "one verdict per claim of seed 003");
    for v in verdicts {
        assert!(["reproduced", "not_reproduced", "not_comparable"].contains(&v["status"].as_str().unwrap()), "{v}");
    }
    // Table 1 and the fetch ratio are exact counters: reproduced whatever the adapter
    for id in ["003-table1-pcf16-1", "003-table1-pcf9-2", "003-table1-pcf4-3", "003-fetches"] {
        let v = verdicts.iter().find(|v| v["claim"] == id).unwrap();
        assert_eq!(v["status"], "reproduced", "{v}");
    }
    assert_eq!(r["runs"][0]["width"], 32, "003 runs at half the base size (the paper's 512 of 1024)");
    assert_eq!(r["points_computed"], 10);
    let md = std::fs::read_to_string(out.join("reproduce.md")).unwrap();
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    for id in &expected {
        assert!(md.contains(id) && html.contains(id), "{id} in the report");
    }
    assert!(md.contains("PCF(9,2): 19 outcomes") && md.contains("timer:"), "the paper's figure and the timer");
    assert!(out.join("003-planebox/index.html").is_file(), "each run is a sweep with its page");
    // the rerun resumes: every point from the cache, the same verdicts
    let again = bin().args(args).arg(&out).output().unwrap();
    assert!(again.status.success());
    let r2 = json(out.join("reproduce.json"));
    assert_eq!((r2["points_computed"].as_u64(), r2["points_cached"].as_u64()), (Some(0), Some(10)));
    assert_eq!(r2["verdicts"], r["verdicts"]);
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn missing_setups_are_not_comparable_and_bad_arguments_are_errors() {
    let out = tmp("missing");
    let empty = tmp("no-setups");
    std::fs::create_dir_all(&empty).unwrap();
    // seed 000's runs are all setup files: none is there
    let run =
        bin().args(["reproduce", "000", "--size", "32x32", "--quiet", "--out"]).arg(&out).arg("--setups").arg(&empty).output().unwrap();
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let r = json(out.join("reproduce.json"));
    let verdicts = r["verdicts"].as_array().unwrap();
    assert_eq!(verdicts.len(), 6);
    for v in verdicts {
        assert_eq!(v["status"], "not_comparable");
        assert!(v["why"].as_str().unwrap().contains("not found"), "{v}");
    }
    assert_eq!(r["points_computed"], 0);
    for (extra, needle) in [(vec!["005"], "unknown seed '005'"), (vec!["003", "--size", "big"], "size")] {
        let o = bin().arg("reproduce").args(&extra).arg("--out").arg(tmp("bad")).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("error:") && err.contains(needle), "{err}");
    }
    let not_ours = tmp("not-ours");
    std::fs::create_dir_all(&not_ours).unwrap();
    std::fs::write(not_ours.join("x"), b"x").unwrap();
    let o = bin().args(["reproduce", "003", "--out"]).arg(&not_ours).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("not written by"));
    for d in [out, empty, not_ours] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
