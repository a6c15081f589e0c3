//! CPU-only: the parameter tables are well formed, and every parameter a technique's code reads
//! is declared, with the accessor of its kind, in the table of a technique that runs that code.
//! Reads are found in the sources (`p.get("key")`, `get_u32`, `get_bool`, `choice`,
//! `choice_index`), so a read on a branch no test takes is checked too.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use shadowlab_core::params::{Kind, TechniqueSpec};
use shadowlab_gpu::registry::{self, REGISTRY};

#[test]
fn tables_are_well_formed_and_resolve_at_their_defaults() {
    for t in REGISTRY {
        let mut keys = BTreeSet::new();
        for p in t.params {
            assert!(keys.insert(p.key), "{}: '{}' declared twice", t.name, p.key);
            assert!(p.min <= p.default && p.default <= p.max, "{}: {} default {} outside [{}, {}]", t.name, p.key, p.default, p.min, p.max);
            assert!(!p.doc.is_empty() && !p.source.is_empty(), "{}: {} needs a doc and a source", t.name, p.key);
            if let Kind::Choice(names) = p.kind {
                assert!((p.default as usize) < names.len(), "{}: {}", t.name, p.key);
            }
        }
        let spec = TechniqueSpec::parse(t.name).unwrap();
        let r = registry::resolve(&spec, None).unwrap();
        assert_eq!(r.values.0.len(), t.params.len(), "{}", t.name);
        // the defaults written out as a spec resolve to the same values (names, not indices)
        let args = r.values.to_spec_args();
        let again = if args.is_empty() { t.name.to_string() } else { format!("{}:{args}", t.name) };
        assert_eq!(registry::resolve(&TechniqueSpec::parse(&again).unwrap(), None).unwrap().values, r.values, "{again}");
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

/// (accessor, key) of every `.accessor("key"` in `src`.
fn reads(src: &str) -> Vec<(&'static str, String)> {
    let mut out = Vec::new();
    for acc in ["get", "get_u32", "get_bool", "choice", "choice_index"] {
        let pat = format!(".{acc}(\"");
        let mut rest = src;
        while let Some(i) = rest.find(&pat) {
            rest = &rest[i + pat.len()..];
            let key: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if rest[key.len()..].starts_with('"') {
                out.push((acc, key));
            }
        }
    }
    out
}

fn accessor_fits(acc: &str, kind: Kind) -> bool {
    match acc {
        "get" => matches!(kind, Kind::Number | Kind::Integer),
        "get_u32" => kind == Kind::Integer,
        "get_bool" => kind == Kind::Flag,
        _ => matches!(kind, Kind::Choice(_)),
    }
}

#[test]
fn every_parameter_read_is_declared_with_its_kind() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    // a technique folder: techniques/<name>/, or reference/ (rt)
    let mut folders: BTreeMap<String, String> = BTreeMap::new();
    for e in std::fs::read_dir(root.join("techniques")).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let text: String = sources(&p).iter().map(|f| std::fs::read_to_string(f).unwrap()).collect();
            folders.insert(name, text);
        }
    }
    folders.insert("reference".into(), sources(&root.join("reference")).iter().map(|f| std::fs::read_to_string(f).unwrap()).collect());
    // which registry entries each folder defines, and which folders' code each folder runs
    let defined = |text: &str| -> Vec<&'static str> {
        REGISTRY.iter().filter(|t| text.contains(&format!("TechniqueInfo {{\n    name: \"{}\",", t.name))).map(|t| t.name).collect()
    };
    let mut runners: BTreeMap<&str, BTreeSet<&'static str>> = BTreeMap::new();
    for (folder, text) in &folders {
        for name in defined(text) {
            runners.entry(folder.as_str()).or_default().insert(name);
            for (other, _) in folders.iter().filter(|(o, _)| *o != folder) {
                if text.contains(&format!("techniques::{other}")) {
                    runners.entry(other.as_str()).or_default().insert(name);
                }
            }
        }
    }
    assert_eq!(runners.values().flatten().collect::<BTreeSet<_>>().len(), REGISTRY.len(), "every entry found: {runners:?}");
    let mut checked = 0;
    for (folder, text) in &folders {
        assert!(!text.contains(".0.get(") && !text.contains(".0.contains_key("), "{folder}: a parameter read around the table");
        let techs = &runners[folder.as_str()];
        for (acc, key) in reads(text) {
            let decls: Vec<(&str, Kind)> = REGISTRY
                .iter()
                .filter(|t| techs.contains(t.name))
                .flat_map(|t| t.params.iter().filter(|p| p.key == key).map(move |p| (t.name, p.kind)))
                .collect();
            assert!(!decls.is_empty(), "{folder}/: reads '{key}', which none of {techs:?} declares");
            for (t, kind) in decls {
                assert!(accessor_fits(acc, kind), "{folder}/: {acc}(\"{key}\") but {t} declares it {kind:?}");
            }
            checked += 1;
        }
    }
    assert!(checked > 80, "only {checked} reads found: is the scan still right?");
}

/// Tests, examples and the CLI read results' parameters too: a key some technique declares must
/// be declared of the accessor's kind by at least one (keys such as `k` mean different things
/// to different techniques).
#[test]
fn parameter_reads_outside_the_techniques_fit_the_tables() {
    let crates = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["shadowlab-gpu/tests", "shadowlab-gpu/examples", "shadowlab-cli/src"] {
        files.extend(sources(&crates.join(dir)));
    }
    for f in files.iter().filter(|f| !f.ends_with("params.rs")) {
        let text = std::fs::read_to_string(f).unwrap();
        for (acc, key) in reads(&text) {
            let decls: Vec<(&str, Kind)> =
                REGISTRY.iter().flat_map(|t| t.params.iter().filter(|p| p.key == key).map(move |p| (t.name, p.kind))).collect();
            if decls.is_empty() {
                continue; // not a parameter read (`get` of a map, a counter)
            }
            assert!(decls.iter().any(|(_, kind)| accessor_fits(acc, *kind)), "{}: {acc}(\"{key}\") but {decls:?}", f.display());
        }
    }
}
