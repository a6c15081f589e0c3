//! CPU-only: the parameter tables are well formed, every row of every table is read by its
//! technique's typed settings (a value set away from its default resolves and passes the
//! rules, or is rejected by them with a reason), and no technique reads values by key.
//! Techniques read their fields from `param_set!` structs; `ParamValues` has no keyed getters,
//! so a read of an undeclared parameter does not compile.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use shadowlab_core::params::{Kind, TechniqueSpec};
use shadowlab_gpu::registry::{self, REGISTRY};

#[test]
fn tables_are_well_formed_and_resolve_at_their_defaults() {
    for t in REGISTRY {
        let mut keys = BTreeSet::new();
        for p in t.params() {
            assert!(keys.insert(p.key), "{}: '{}' declared twice", t.name, p.key);
            let auto = p.kind == Kind::AutoNumber && p.default.is_nan();
            assert!(
                auto || (p.min <= p.default && p.default <= p.max),
                "{}: {} default {} outside [{}, {}]",
                t.name,
                p.key,
                p.default,
                p.min,
                p.max
            );
            assert!(!p.doc.is_empty() && !p.source.is_empty(), "{}: {} needs a doc and a source", t.name, p.key);
            if let Kind::Choice(names) = p.kind {
                assert!((p.default as usize) < names.len(), "{}: {}", t.name, p.key);
            }
        }
        let spec = TechniqueSpec::parse(t.name).unwrap();
        let r = registry::resolve(&spec, None).unwrap();
        assert_eq!(r.values.0.len(), t.params().len(), "{}", t.name);
        // the defaults written out as a spec resolve to the same values (names, not indices);
        // against the table alone: written out, every key counts as given, and the rules would
        // rightly reject the keys that do nothing at the defaults
        let args = r.values.to_spec_args();
        let again = if args.is_empty() { t.name.to_string() } else { format!("{}:{args}", t.name) };
        assert_eq!(TechniqueSpec::parse(&again).unwrap().resolve(t.params()).unwrap(), r.values, "{again}");
    }
}

#[test]
fn the_default_compare_set_resolves() {
    let specs = registry::default_compare();
    assert!(specs.len() >= 15, "{specs:?}");
    assert!(specs.contains(&"sm:pcf=3".to_string()) && !specs.iter().any(|s| s == "rt"));
    for s in specs {
        registry::resolve(&TechniqueSpec::parse(&s).unwrap(), None).unwrap();
    }
}

/// `.rs` files under `dir`.
fn sources(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(sources(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// A value of `p` other than its default, as a spec writes it.
fn other_value(p: &shadowlab_core::params::ParamDef) -> String {
    match p.kind {
        Kind::Flag => (p.default == 0.0).to_string(),
        Kind::Choice(names) => names[(p.default as usize + 1) % names.len()].to_string(),
        Kind::Integer => (if p.default < p.max { p.default + 1.0 } else { p.default - 1.0 }).to_string(),
        Kind::AutoNumber if p.default.is_nan() => p.min.max(0.0).min(p.max).to_string(),
        Kind::AutoNumber | Kind::Number => {
            let x = if p.default < p.max { (p.default + (p.max - p.default).min(1.0) * 0.5).min(p.max) } else { p.min };
            x.to_string()
        }
    }
}

/// Every row is read by the technique's settings: resolving a spec with that one value changed
/// builds the typed struct (which panics on a row it does not read the right way) and applies
/// the rules, which either accept the value or give a reason.
#[test]
fn every_row_is_read_through_the_typed_settings() {
    let mut accepted = 0;
    for t in REGISTRY {
        for p in t.params() {
            let spec = format!("{}:{}={}", t.name, p.key, other_value(p));
            match registry::resolve(&TechniqueSpec::parse(&spec).unwrap(), None) {
                Ok(r) => {
                    assert_ne!(r.values.value(p.key), Some(&p.default_value()), "{spec}");
                    accepted += 1;
                }
                Err(e) => {
                    let e = e.to_string();
                    assert!(e.starts_with(&format!("technique '{}': ", t.name)), "{spec}: {e}");
                }
            }
        }
    }
    assert!(accepted > 100, "only {accepted} single changes accepted");
}

/// Techniques read typed fields: no technique folder goes around its settings to the values.
#[test]
fn no_technique_reads_values_by_key() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut scanned = BTreeSet::new();
    for dir in ["techniques", "reference"] {
        for f in sources(&root.join(dir)) {
            let text = std::fs::read_to_string(&f).unwrap();
            for pat in [".value(\"", ".0.get(\"", ".0[\"", "values.0"] {
                assert!(!text.contains(pat), "{}: reads a parameter around its settings ({pat})", f.display());
            }
            scanned.insert(f);
        }
    }
    assert!(scanned.len() > 40, "{} files scanned", scanned.len());
}

/// The registry is the one list: every `TechniqueInfo` defined in a technique folder (or the
/// reference's) is in `REGISTRY`, and every registry entry is defined in exactly one folder, so
/// a technique cannot be added without its registry line, nor listed twice.
#[test]
fn every_technique_folder_is_in_the_registry() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut defined: Vec<(String, String)> = Vec::new();
    let mut dirs: Vec<PathBuf> =
        std::fs::read_dir(root.join("techniques")).unwrap().map(|e| e.unwrap().path()).filter(|p| p.is_dir()).collect();
    dirs.push(root.join("reference"));
    for dir in dirs {
        for f in sources(&dir) {
            let text = std::fs::read_to_string(&f).unwrap();
            for (i, _) in text.match_indices("TechniqueInfo {\n    name: \"") {
                let rest = &text[i + "TechniqueInfo {\n    name: \"".len()..];
                let name = &rest[..rest.find('"').unwrap()];
                defined.push((name.to_string(), dir.file_name().unwrap().to_string_lossy().into_owned()));
            }
        }
    }
    for (name, folder) in &defined {
        assert!(REGISTRY.iter().any(|t| t.name == name), "techniques/{folder}/ defines '{name}', which REGISTRY does not list");
    }
    for t in REGISTRY {
        let n = defined.iter().filter(|(name, _)| name == t.name).count();
        assert_eq!(n, 1, "'{}' is defined in {n} folders", t.name);
    }
}
