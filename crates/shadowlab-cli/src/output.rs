//! Outputs are written under a temporary name and renamed into place, so an interrupted run
//! never leaves a half-written report.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// A directory being written; [`StagedDir::commit`] moves it to its final name.
pub struct StagedDir {
    pub tmp: PathBuf,
    target: PathBuf,
    done: bool,
}

impl StagedDir {
    pub fn new(target: &Path) -> Result<StagedDir> {
        let name = target.file_name().map(|n| n.to_string_lossy().to_string()).unwrap_or_else(|| "report".into());
        let parent = target.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
        remove_stale(parent, &name);
        let tmp = parent.join(format!(".{name}.partial-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&tmp);
        std::fs::create_dir_all(&tmp).with_context(|| format!("creating {}", tmp.display()))?;
        Ok(StagedDir { tmp, target: target.to_path_buf(), done: false })
    }

    pub fn path(&self, rel: &str) -> PathBuf {
        self.tmp.join(rel)
    }

    /// Replaces the target with the staged directory.
    pub fn commit(mut self) -> Result<PathBuf> {
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
    fn slugs_are_file_names() {
        assert_eq!(slug("sm:res=2048,pcf=3"), "sm_res_2048_pcf_3");
        assert_eq!(slug("../x"), "_x");
    }
}
