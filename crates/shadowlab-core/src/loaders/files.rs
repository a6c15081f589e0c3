//! Where the loaders read bytes from: the disk, or a set of files held in memory (files dropped
//! on the web page, fuzz inputs, tests). A scene file names others (OBJ -> MTL -> textures,
//! glTF -> buffers and images) by relative paths; both sources resolve them the same way.

use std::collections::BTreeMap;
use std::io;
use std::path::{Component, Path, PathBuf};

/// Read access to a tree of files.
pub trait Files {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;
    fn is_file(&self, path: &Path) -> bool;
    /// A file or a directory.
    fn exists(&self, path: &Path) -> bool;
    /// The paths of a directory's entries (files and directories).
    fn list(&self, dir: &Path) -> io::Result<Vec<PathBuf>>;
}

/// The file system.
pub struct Disk;

impl Files for Disk {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        std::fs::read(path)
    }
    fn is_file(&self, path: &Path) -> bool {
        path.is_file()
    }
    fn exists(&self, path: &Path) -> bool {
        path.exists()
    }
    fn list(&self, dir: &Path) -> io::Result<Vec<PathBuf>> {
        std::fs::read_dir(dir)?.map(|e| e.map(|e| e.path())).collect()
    }
}

/// Files held in memory under relative paths (`scene.obj`, `tex/a.png`). Paths are compared
/// after lexical normalisation: `.` dropped, `..` applied, a root or prefix ignored, so that
/// `./a/../b.mtl` and `/b.mtl` both name `b.mtl`. Directories are the paths' prefixes.
#[derive(Clone, Debug, Default)]
pub struct InMemory {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl InMemory {
    pub fn new() -> Self {
        InMemory::default()
    }
    pub fn insert(&mut self, path: impl AsRef<Path>, bytes: Vec<u8>) {
        self.files.insert(normalise(path.as_ref()), bytes);
    }
    pub fn len(&self) -> usize {
        self.files.len()
    }
    pub fn is_empty(&self) -> bool {
        self.files.is_empty()
    }
}

fn normalise(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::Normal(s) => out.push(s),
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir | Component::RootDir | Component::Prefix(_) => {}
        }
    }
    out
}

impl Files for InMemory {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files
            .get(&normalise(path))
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, format!("{}: no such file among those given", path.display())))
    }
    fn is_file(&self, path: &Path) -> bool {
        self.files.contains_key(&normalise(path))
    }
    fn exists(&self, path: &Path) -> bool {
        let p = normalise(path);
        p.as_os_str().is_empty() || self.files.keys().any(|k| k.starts_with(&p))
    }
    fn list(&self, dir: &Path) -> io::Result<Vec<PathBuf>> {
        let d = normalise(dir);
        let mut out: Vec<PathBuf> = Vec::new();
        for k in self.files.keys() {
            if let Ok(rest) = k.strip_prefix(&d) {
                if let Some(first) = rest.components().next() {
                    let entry = d.join(first);
                    if out.last() != Some(&entry) {
                        out.push(entry);
                    }
                }
            }
        }
        if out.is_empty() && !self.exists(dir) {
            return Err(io::Error::new(io::ErrorKind::NotFound, format!("{}: no such directory", dir.display())));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn in_memory_paths_resolve_like_a_tree() {
        let mut f = InMemory::new();
        f.insert("scene.obj", b"o".to_vec());
        f.insert("tex/A.png", b"p".to_vec());
        f.insert("tex/sub/b.png", b"q".to_vec());
        assert_eq!(f.read(Path::new("./tex/../scene.obj")).unwrap(), b"o");
        assert_eq!(f.read(Path::new("/scene.obj")).unwrap(), b"o");
        assert!(f.read(Path::new("tex/a.png")).is_err(), "case matters, as on Linux");
        assert!(f.is_file(Path::new("tex/A.png")) && !f.is_file(Path::new("tex")));
        assert!(f.exists(Path::new("tex")) && f.exists(Path::new("")) && !f.exists(Path::new("nope")));
        let listed = f.list(Path::new("tex")).unwrap();
        assert_eq!(listed, vec![PathBuf::from("tex/A.png"), PathBuf::from("tex/sub")]);
        assert_eq!(f.list(Path::new("")).unwrap(), vec![PathBuf::from("scene.obj"), PathBuf::from("tex")]);
        assert!(f.list(Path::new("nope")).is_err());
    }
}
