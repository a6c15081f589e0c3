//! Fuzz targets for the text inputs shadowlab-core parses (issue 41): technique spec strings and
//! setup files. The invariant: no panic, whatever the bytes; every other outcome is a value or
//! a clear error. Under `cargo test` bolero runs each target on random inputs for a moment;
//! `cargo bolero test TARGET --package shadowlab-fuzz --sanitizer NONE` runs libFuzzer
//! (docs/fuzz.md). The loaders (OBJ, MTL, glTF) read files and are not targets yet.

use bolero::check;
use shadowlab_core::params::TechniqueSpec;
use shadowlab_core::setup::Setup;

#[test]
fn technique_specs() {
    check!().for_each(|bytes: &[u8]| {
        if let Ok(text) = std::str::from_utf8(bytes) {
            if let Ok(spec) = TechniqueSpec::parse(text) {
                // what parses names a technique and keeps its text
                assert!(!spec.name.is_empty());
            }
        }
    });
}

fn setup(text: &str) {
    if let Ok(setup) = Setup::parse(text) {
        let _ = setup.validate();
    }
}

#[test]
fn setup_files() {
    check!().for_each(|bytes: &[u8]| {
        if let Ok(text) = std::str::from_utf8(bytes) {
            setup(text);
        }
    });
}

/// The shipped setups cut after every line, and with every line left out once: half-written
/// and hand-edited files, the inputs random bytes rarely reach (valid TOML, wrong content).
#[test]
fn shipped_setups_cut_and_thinned() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../setups");
    let mut files = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        for i in 0..=lines.len() {
            setup(&lines[..i].join("\n"));
            let thinned: Vec<&str> = lines.iter().enumerate().filter(|(j, _)| *j != i).map(|(_, l)| *l).collect();
            setup(&thinned.join("\n"));
        }
        files += 1;
    }
    assert!(files >= 10, "only {files} setups under {}", dir.display());
}
