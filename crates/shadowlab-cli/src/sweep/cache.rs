//! The sweep directory: resumed, not replaced. Each finished point is `points/<key>.json`,
//! written under a temporary name and renamed, so an interrupted sweep loses no finished point
//! and leaves no half-written one; a rerun reads them back. The directory is marked by
//! [`SWEEP_MARKER`]; one that is not empty and not marked (a directory of the user's, or a
//! `compare` report) is refused before any work, and nothing in it is touched.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::record::{PointFile, SCHEMA_VERSION};
use crate::output::{write_atomic, MARKER};

/// The file that marks a directory as a shadowlab sweep (safe to resume and to rewrite).
pub const SWEEP_MARKER: &str = ".shadowlab-sweep";

pub struct SweepDir {
    pub root: PathBuf,
}

/// Whether `dir` may hold a sweep: absent, empty, or marked as one.
pub fn check(dir: &Path) -> Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(dir) else { return Ok(()) };
    let shown = dir.display();
    if !meta.is_dir() {
        bail!("--out {shown} exists and is not a directory; choose another path or remove it");
    }
    if dir.join(SWEEP_MARKER).is_file() {
        return Ok(());
    }
    if dir.join(MARKER).is_file() {
        bail!("--out {shown} is a `compare` report, not a sweep directory (no {SWEEP_MARKER}); choose a new or empty directory");
    }
    if std::fs::read_dir(dir).with_context(|| format!("reading {shown}"))?.next().is_some() {
        bail!("--out {shown} is a directory that shadowlab did not write (no {SWEEP_MARKER} in it); choose a new or empty directory, or remove it yourself");
    }
    Ok(())
}

/// Removes `*.partial-PID` files left by runs that were killed (their PID is gone).
fn remove_stale(dir: &Path) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().to_string();
        let Some(pid) = name.rsplit_once(".partial-").and_then(|(_, p)| p.parse::<u32>().ok()) else { continue };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

impl SweepDir {
    /// Checks `dir` ([`check`]), creates it with its marker and `points/`, and removes what
    /// killed runs left half-written.
    pub fn open(dir: &Path) -> Result<SweepDir> {
        check(dir)?;
        let points = dir.join("points");
        std::fs::create_dir_all(&points).with_context(|| format!("creating {}", points.display()))?;
        let marker = dir.join(SWEEP_MARKER);
        if !marker.is_file() {
            let text = format!("written by shadowlab {} (sweep)\nschema_version {SCHEMA_VERSION}\n", env!("CARGO_PKG_VERSION"));
            write_atomic(&marker, text.as_bytes())?;
        }
        remove_stale(dir);
        remove_stale(&points);
        Ok(SweepDir { root: dir.to_path_buf() })
    }

    pub fn point_path(&self, key: &str) -> PathBuf {
        self.root.join("points").join(format!("{key}.json"))
    }

    /// The finished point `key`, if there is one. A file that does not parse, is of another
    /// schema or names another key is not a finished point: it is computed again (warned).
    pub fn read_point(&self, key: &str) -> Option<PointFile> {
        let path = self.point_path(key);
        let text = std::fs::read_to_string(&path).ok()?;
        match serde_json::from_str::<PointFile>(&text) {
            Ok(p) if p.key == key && p.schema_version == SCHEMA_VERSION && p.row.key == key => Some(p),
            Ok(_) => {
                eprintln!("warning: {} is of another key or schema; computing the point again", path.display());
                None
            }
            Err(e) => {
                eprintln!("warning: {} does not parse ({e}); computing the point again", path.display());
                None
            }
        }
    }

    pub fn write_point(&self, p: &PointFile) -> Result<()> {
        write_atomic(&self.point_path(&p.key), serde_json::to_string_pretty(p)?.as_bytes())
    }

    /// Writes `name` in the directory through a temporary file and a rename.
    pub fn write(&self, name: &str, bytes: &[u8]) -> Result<()> {
        write_atomic(&self.root.join(name), bytes)
    }

    /// Every finished point in `points/` (for `sweep merge`), by key.
    pub fn all_points(dir: &Path) -> Result<std::collections::BTreeMap<String, PointFile>> {
        let points = dir.join("points");
        let mut out = std::collections::BTreeMap::new();
        let entries = std::fs::read_dir(&points)
            .with_context(|| format!("reading {} (is {} a sweep directory?)", points.display(), dir.display()))?;
        for e in entries {
            let path = e?.path();
            if path.extension().is_none_or(|x| x != "json") {
                continue;
            }
            let text = std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
            // the version first: an older layout (e.g. without flip_mean) is named as such
            let v: serde_json::Value = serde_json::from_str(&text).with_context(|| format!("{} is not a sweep point", path.display()))?;
            if let Some(other) = v.get("schema_version").and_then(|x| x.as_u64()).filter(|&x| x != SCHEMA_VERSION as u64) {
                bail!("{}: schema_version {other} (this shadowlab reads {SCHEMA_VERSION}; rerun that shard)", path.display());
            }
            let p: PointFile = serde_json::from_value(v).with_context(|| format!("{} is not a sweep point", path.display()))?;
            out.insert(p.key.clone(), p);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::record::tests::row;

    fn root(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("shadowlab-sweepdir-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        d
    }

    #[test]
    fn points_round_trip_and_bad_ones_are_recomputed() {
        let d = root("points");
        let dir = SweepDir::open(&d).unwrap();
        assert!(d.join(SWEEP_MARKER).is_file() && d.join("points").is_dir());
        assert!(dir.read_point("abc").is_none());
        let mut r = row("planebox", "sm", 1.0, 2.0, 3);
        r.key = "abc".into();
        // figures whose shortest decimal form serde_json reads back a bit off without float_roundtrip
        r.quality.wrong_pct = 1.4845709619086507;
        r.quality.mae = 1.3390861128498615;
        r.total_ms = 0.1 + 0.2;
        let p = PointFile { schema_version: SCHEMA_VERSION, key: "abc".into(), key_text: "t".into(), row: r };
        dir.write_point(&p).unwrap();
        assert_eq!(dir.read_point("abc"), Some(p.clone()), "read back bit-equal");
        assert_eq!(SweepDir::all_points(&d).unwrap().len(), 1);
        // a file under another key's name is not that key's result
        std::fs::copy(dir.point_path("abc"), dir.point_path("def")).unwrap();
        assert!(dir.read_point("def").is_none());
        std::fs::write(dir.point_path("ghi"), "{ half").unwrap();
        assert!(dir.read_point("ghi").is_none());
        // a dead run's temporary file goes; the directory is resumed, its points kept
        let stale = d.join("points").join("xyz.partial-4000000000");
        std::fs::write(&stale, "half").unwrap();
        let again = SweepDir::open(&d).unwrap();
        assert!(!stale.exists());
        assert_eq!(again.read_point("abc"), Some(p));
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn a_point_written_before_flip_is_computed_again_and_not_merged() {
        let d = root("preflip");
        let dir = SweepDir::open(&d).unwrap();
        let mut r = row("planebox", "sm", 1.0, 2.0, 3);
        r.key = "old".into();
        let mut v = serde_json::to_value(PointFile { schema_version: 1, key: "old".into(), key_text: "t".into(), row: r }).unwrap();
        v["row"].as_object_mut().unwrap().remove("flip_mean");
        std::fs::write(dir.point_path("old"), serde_json::to_string(&v).unwrap()).unwrap();
        assert!(dir.read_point("old").is_none(), "no flip_mean: computed again");
        let e = SweepDir::all_points(&d).unwrap_err().to_string();
        assert!(e.contains("schema_version 1 (this shadowlab reads 2"), "{e}");
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn directories_not_marked_as_sweeps_are_refused_untouched() {
        let d = root("refuse");
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("thesis.tex"), "years").unwrap();
        let e = SweepDir::open(&d).err().unwrap().to_string();
        assert!(e.contains("did not write") && e.contains(SWEEP_MARKER), "{e}");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1, "nothing created");
        let report = root("report");
        std::fs::create_dir_all(&report).unwrap();
        std::fs::write(report.join(MARKER), "written by shadowlab").unwrap();
        let e = SweepDir::open(&report).err().unwrap().to_string();
        assert!(e.contains("compare"), "{e}");
        let file = root("file");
        std::fs::write(&file, "x").unwrap();
        assert!(SweepDir::open(&file).err().unwrap().to_string().contains("not a directory"));
        let empty = root("empty");
        std::fs::create_dir_all(&empty).unwrap();
        assert!(SweepDir::open(&empty).is_ok());
        for p in [d, report, empty] {
            std::fs::remove_dir_all(p).unwrap();
        }
        std::fs::remove_file(file).unwrap();
    }
}
