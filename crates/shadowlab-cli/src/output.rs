//! Outputs are written under a temporary name and renamed into place, so an interrupted run
//! never leaves a half-written report. An existing `--out` is replaced only if shadowlab wrote
//! it (its [`MARKER`] file is there) or it is an empty directory; anything else is refused
//! before any work, and nothing is touched.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// The file every output directory of shadowlab holds: the proof that replacing it loses
/// nothing of the user's.
pub const MARKER: &str = ".shadowlab-output";

/// What the marker file says: who wrote the directory, and the layout of its metrics.json
/// ([`crate::metrics::SCHEMA_VERSION`]).
pub fn marker_text() -> String {
    format!("written by shadowlab {}\nschema_version {}\n", env!("CARGO_PKG_VERSION"), crate::metrics::SCHEMA_VERSION)
}

/// Whether `target` may be (re)written as an output directory: absent, an empty directory, or
/// one shadowlab wrote. Otherwise one line naming the path and what to do.
pub fn check_target(target: &Path) -> Result<()> {
    let Ok(meta) = std::fs::symlink_metadata(target) else { return Ok(()) };
    let shown = target.display();
    if !meta.is_dir() {
        anyhow::bail!("--out {shown} exists and is not a directory; choose another path or remove it");
    }
    if target.join(MARKER).is_file() {
        return Ok(());
    }
    let empty = std::fs::read_dir(target).with_context(|| format!("reading {shown}"))?.next().is_none();
    if !empty {
        anyhow::bail!("--out {shown} is a directory that shadowlab did not write (no {MARKER} in it); choose a new or empty directory, or remove it yourself");
    }
    Ok(())
}

/// A directory being written; [`StagedDir::commit`] moves it to its final name.
pub struct StagedDir {
    pub tmp: PathBuf,
    target: PathBuf,
    done: bool,
}

impl StagedDir {
    pub fn new(target: &Path) -> Result<StagedDir> {
        check_target(target)?;
        let name = target.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_else(|| "report".into());
        let parent = target.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
        remove_stale(parent, &name);
        let tmp = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
        std::fs::write(tmp.join(MARKER), marker_text()).with_context(|| format!("writing {}", tmp.display()))?;
        Ok(StagedDir { tmp, target: target.to_path_buf(), done: false })
    }

    pub fn path(&self, rel: &str) -> PathBuf {
        self.tmp.join(rel)
    }

    /// Replaces the target with the staged directory.
    pub fn commit(mut self) -> Result<PathBuf> {
        // checked again: something may have appeared there during the run
        check_target(&self.target)?;
        if self.target.exists() {
            let old = self.tmp.with_extension("old");
            std::fs::rename(&self.target, &old).with_context(|| format!("moving the old {} aside", self.target.display()))?;
            std::fs::rename(&self.tmp, &self.target)?;
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(&self.tmp, &self.target)?;
        }
        self.done = true;
        Ok(self.target.clone())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.done {
            let _ = std::fs::remove_dir_all(&self.tmp);
        }
    }
}

/// Removes `.NAME.partial-PID` directories left by runs that were killed (their PID is gone).
fn remove_stale(parent: &Path, name: &str) {
    let prefix = format!(".{name}.partial-");
    let Ok(entries) = std::fs::read_dir(parent) else { return };
    for e in entries.flatten() {
        let file = e.file_name().to_string_lossy().to_string();
        let Some(pid) = file.strip_prefix(&prefix).and_then(|p| p.split('.').next()).and_then(|p| p.parse::<u32>().ok()) else { continue };
        if pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists() {
            let _ = std::fs::remove_dir_all(e.path());
        }
    }
}

/// Writes a file through a temporary sibling and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension(format!("partial-{}", std::process::id()));
    std::fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))?;
    Ok(())
}

/// A file-name-safe form of a label.
pub fn slug(label: &str) -> String {
    let s: String = label.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '.' { c } else { '_' }).collect();
    s.trim_matches('.').to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn staged_dir_replaces_the_target_and_cleans_stale_partials() {
        let root = std::env::temp_dir().join(format!("shadowlab-staged-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        let target = root.join("report");
        std::fs::create_dir_all(&target).unwrap();
        std::fs::write(target.join("old.txt"), "old").unwrap();
        std::fs::write(target.join(MARKER), "written by shadowlab").unwrap();
        let stale = root.join(".report.partial-4000000000");
        std::fs::create_dir_all(&stale).unwrap();
        let staged = StagedDir::new(&target).unwrap();
        assert!(!stale.exists(), "a partial directory of a dead process survived");
        std::fs::write(staged.path("new.txt"), "new").unwrap();
        assert!(target.join("old.txt").exists(), "the old report must stay until commit");
        staged.commit().unwrap();
        assert!(target.join("new.txt").exists() && !target.join("old.txt").exists());
        // dropped without commit: nothing changes, nothing is left behind
        let staged = StagedDir::new(&target).unwrap();
        std::fs::write(staged.path("half.txt"), "x").unwrap();
        drop(staged);
        assert!(!target.join("half.txt").exists());
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1);
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn outputs_never_replace_what_shadowlab_did_not_write() {
        let root = std::env::temp_dir().join(format!("shadowlab-safety-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).unwrap();
        // a directory of the user's: refused, untouched
        let mine = root.join("mine");
        std::fs::create_dir_all(&mine).unwrap();
        std::fs::write(mine.join("thesis.tex"), "years of work").unwrap();
        let e = StagedDir::new(&mine).err().expect("refused").to_string();
        assert!(e.contains("did not write") && e.contains("mine"), "{e}");
        assert_eq!(std::fs::read_to_string(mine.join("thesis.tex")).unwrap(), "years of work");
        assert_eq!(std::fs::read_dir(&root).unwrap().count(), 1, "nothing staged beside it");
        // a file: refused, untouched
        let file = root.join("notes.txt");
        std::fs::write(&file, "keep").unwrap();
        let e = StagedDir::new(&file).err().expect("refused").to_string();
        assert!(e.contains("not a directory"), "{e}");
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "keep");
        // an empty directory: used, and marked
        let empty = root.join("empty");
        std::fs::create_dir_all(&empty).unwrap();
        let staged = StagedDir::new(&empty).unwrap();
        std::fs::write(staged.path("index.html"), "r").unwrap();
        staged.commit().unwrap();
        assert!(empty.join(MARKER).is_file() && empty.join("index.html").is_file());
        let marker = std::fs::read_to_string(empty.join(MARKER)).unwrap();
        assert!(marker.ends_with(&format!("\nschema_version {}\n", crate::metrics::SCHEMA_VERSION)), "{marker}");
        // shadowlab's own output: replaced
        let staged = StagedDir::new(&empty).unwrap();
        staged.commit().unwrap();
        assert!(!empty.join("index.html").exists() && empty.join(MARKER).is_file());
        // something of the user's that appeared during the run: the commit refuses
        let late = root.join("late");
        let staged = StagedDir::new(&late).unwrap();
        std::fs::create_dir_all(&late).unwrap();
        std::fs::write(late.join("x"), "user").unwrap();
        assert!(staged.commit().is_err());
        assert_eq!(std::fs::read_to_string(late.join("x")).unwrap(), "user");
        std::fs::remove_dir_all(&root).unwrap();
    }

    #[test]
    fn slugs_are_file_names() {
        assert_eq!(slug("sm:res=2048,pcf=3"), "sm_res_2048_pcf_3");
        assert_eq!(slug("../x"), "_x");
    }
}
