//! The GPU integration tests (lavapipe where there is no GPU).
//! One test binary: every file beside this one is a module of it, so the suite links once and
//! the harness runs all tests on its threads together. A file left out of the list below would
//! not run: `every_test_file_is_a_module` fails then.

mod common;

mod anim;
mod csm;
mod cube;
mod determinism;
mod dpsm;
mod filtered;
mod gpu;
mod host;
mod hygiene;
mod iasm;
mod iasm_fit;
mod limits;
mod lt;
mod mdsm;
mod min_sm;
mod new_technique;
mod params;
mod record;
mod sdsm;
mod shaders;
mod sv;
mod r#virtual;
mod virtual_local;
mod warp;
mod warp_bias;
mod warp_hidden;
mod warp_kinks;

#[test]
fn every_test_file_is_a_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let this = include_str!("main.rs");
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        let Some(stem) = p.file_stem().and_then(|s| s.to_str()) else { continue };
        if p.extension().is_some_and(|x| x == "rs") && stem != "main" {
            let declared = this.contains(&format!("\nmod {stem};")) || this.contains(&format!("\nmod r#{stem};"));
            assert!(declared, "tests/{stem}.rs is not declared in tests/main.rs: its tests would not run");
        }
    }
}
