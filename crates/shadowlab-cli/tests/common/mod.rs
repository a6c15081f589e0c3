//! What every CLI test binary shares: the built `shadowlab`, the GPU-skip switch, scratch
//! directories, and the check that a failure is one clear error line.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::{Command, Output};

/// The `shadowlab` binary under test, with a runtime directory (Mesa's WSI wants one).
pub fn bin() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_shadowlab"));
    c.env("XDG_RUNTIME_DIR", std::env::temp_dir());
    c
}

/// `SHADOWLAB_SKIP_GPU_TESTS=1` skips the tests that need an adapter.
pub fn skip_gpu() -> bool {
    std::env::var("SHADOWLAB_SKIP_GPU_TESTS").as_deref() == Ok("1")
}

/// A scratch path for `name`, removed if a previous run left it (not created).
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("shadowlab-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// Runs `shadowlab args...` to completion.
pub fn run(args: &[&str]) -> Output {
    bin().args(args).output().expect("run shadowlab")
}

/// The run failed with an `error:` line mentioning `needle`, and did not panic.
pub fn assert_clean_error(out: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "expected failure, stderr: {err}");
    assert!(!err.contains("panicked"), "panic instead of an error: {err}");
    assert!(err.contains("error:") && err.contains(needle), "expected an error mentioning '{needle}', got: {err}");
}

/// A JSON file, parsed.
pub fn json(p: PathBuf) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))).unwrap()
}
