//! metrics.json of a real `shadowlab compare` (small built-in scene, two frames, a few
//! techniques): valid against docs/metrics.schema.json, strictly (a missing or mistyped field
//! fails), and read back into the typed record unchanged.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::*;

#[path = "../src/metrics/mod.rs"]
#[allow(dead_code, unused_imports)]
mod metrics;

fn schema() -> serde_json::Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/metrics.schema.json");
    serde_json::from_str(&std::fs::read_to_string(&path).expect("docs/metrics.schema.json")).expect("the schema is JSON")
}

/// The metrics.json text of one small compare run (written once per test process).
fn written() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| {
        let out: PathBuf = std::env::temp_dir().join(format!("shadowlab-schema-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&out);
        let o = Command::new(env!("CARGO_BIN_EXE_shadowlab"))
            .env("XDG_RUNTIME_DIR", std::env::temp_dir())
            .args(["compare", "--scene", "planebox", "--size", "48x32", "--frames", "2", "--repeat", "1", "--quiet", "--export"])
            .args(["-t", "sm", "-t", "sm:pcf=3,label=soft", "-t", "csm", "--out", out.to_str().unwrap()])
            .output()
            .expect("run shadowlab");
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = std::fs::read_to_string(out.join("metrics.json")).unwrap();
        let marker = std::fs::read_to_string(out.join(".shadowlab-output")).unwrap();
        assert!(marker.contains(&format!("schema_version {}", metrics::SCHEMA_VERSION)), "marker: {marker}");
        std::fs::remove_dir_all(&out).unwrap();
        text
    })
}

fn errors(validator: &jsonschema::Validator, v: &serde_json::Value) -> Vec<String> {
    validator.iter_errors(v).map(|e| format!("{} at {}", e, e.instance_path())).collect()
}

#[test]
fn written_metrics_match_the_schema_and_the_schema_is_strict() {
    if skip_gpu() {
        return;
    }
    let validator = jsonschema::validator_for(&schema()).expect("a valid JSON Schema");
    let m: serde_json::Value = serde_json::from_str(written()).unwrap();
    let e = errors(&validator, &m);
    assert!(e.is_empty(), "metrics.json against docs/metrics.schema.json:\n{}", e.join("\n"));
    assert_eq!(m["schema_version"], metrics::SCHEMA_VERSION);

    // strict: a missing field, a mistyped one and an unknown one each fail
    let mut missing = m.clone();
    missing["techniques"][0].as_object_mut().unwrap().remove("wrong_pct");
    assert!(!validator.is_valid(&missing), "a missing technique field must fail");
    let mut mistyped = m.clone();
    mistyped["reference"]["frames"][1]["edge_pixels"] = "12".into();
    assert!(!validator.is_valid(&mistyped), "a string for a count must fail");
    let mut no_flip = m.clone();
    no_flip["techniques"][0].as_object_mut().unwrap().remove("flip_mean");
    assert!(!validator.is_valid(&no_flip), "flip_mean is required");
    let mut bad_flip = m.clone();
    bad_flip["techniques"][0]["frames"][0]["flip_mean"] = 1.5.into();
    assert!(!validator.is_valid(&bad_flip), "FLIP is in [0, 1]");
    let mut unknown = m.clone();
    unknown["bvh"]["leaves"] = 3.into();
    assert!(!validator.is_valid(&unknown), "an unknown field must fail");
    let mut top = m.clone();
    top.as_object_mut().unwrap().remove("schema_version");
    assert!(!validator.is_valid(&top), "schema_version is required");
    // parameter values: numbers, integers, booleans or choice names
    let mut params = m.clone();
    params["techniques"][0]["params"] = serde_json::json!({"res": 512, "bias": 0.5, "snap": true, "fit": "sphere"});
    assert!(validator.is_valid(&params), "{:?}", errors(&validator, &params));
    params["techniques"][0]["params"]["res"] = serde_json::json!([512]);
    assert!(!validator.is_valid(&params), "a parameter is a scalar");
}

#[test]
fn written_metrics_read_back_into_the_typed_record_unchanged() {
    if skip_gpu() {
        return;
    }
    let text = written();
    let typed: metrics::Metrics = serde_json::from_str(text).expect("metrics.json reads into metrics::Metrics");
    assert_eq!(typed.frames, 2);
    assert_eq!(typed.techniques.len(), 3);
    assert_eq!(typed.techniques[1].label, "soft");
    assert!(typed.techniques.iter().all(|t| t.frames.len() == 2 && t.visibility_npy.is_some()));
    for t in &typed.techniques {
        assert!((0.0..=1.0).contains(&t.flip_mean) && t.images.flip == format!("{}-flip.png", t.label.replace([':', '=', ','], "_")));
        assert!(t.frames.iter().all(|f| (0.0..=1.0).contains(&f.flip_mean)));
    }
    assert_eq!(typed.to_json().unwrap(), text, "writing the record read back gives the same text");
}
