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

/// Debian's Chromium (installed by `make`'s set-up, scripts/setup.sh).
pub const CHROMIUM: &str = "/usr/bin/chromium";

/// The DOM of `url` after its scripts ran, from headless Chromium (a fresh profile, no network
/// chatter). Panics naming the fix when Chromium is missing: the set-up installs it.
pub fn chromium_dom(url: &str) -> String {
    assert!(std::path::Path::new(CHROMIUM).exists(), "{CHROMIUM} missing: run `make test` (scripts/setup.sh installs chromium)");
    let profile = tmp("chromium-profile");
    let o = Command::new(CHROMIUM)
        .args(["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run"])
        .args(["--disable-background-networking", "--disable-component-update", "--disable-sync"])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(["--virtual-time-budget=5000", "--dump-dom", url])
        .output()
        .expect("run chromium");
    let _ = std::fs::remove_dir_all(&profile);
    assert!(o.status.success(), "chromium failed: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8_lossy(&o.stdout).into_owned()
}
