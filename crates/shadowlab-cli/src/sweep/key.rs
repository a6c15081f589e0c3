//! Cache keys of sweep points. A point's key is the SHA-256 of a short text naming everything its
//! result depends on: the binary (a hash of the running executable's bytes), the setup (the
//! setup file's content and the scene file's content, or the built-in scene's name), the
//! output size, frames, repetitions, light and start time, and the resolved spec (technique,
//! every parameter value, label). Change any of them and the point is computed again.

use std::io::Read;
use std::path::Path;

use anyhow::{Context, Result};
use sha2::{Digest, Sha256};

/// Raised when the key text's layout or what a point holds changes (old cache entries then
/// never match and are computed again). 2: points carry `flip_mean`; a point file written
/// before it (schema 1) is never looked up, let alone misread.
const KEY_VERSION: u32 = 2;

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// SHA-256 of `bytes`, as 64 hex digits.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex(&Sha256::digest(bytes))
}

/// SHA-256 of a file's bytes (read in pieces: executables and scenes can be large).
pub fn file_sha256(path: &Path) -> Result<String> {
    let mut f = std::fs::File::open(path).with_context(|| format!("reading {}", path.display()))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf).with_context(|| format!("reading {}", path.display()))?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(hex(&h.finalize()))
}

/// The binary version: a hash of the running executable's bytes (a rebuilt binary, even from
/// the same version number, may compute different results).
pub fn binary_version() -> Result<String> {
    let exe = std::env::current_exe().context("finding the running executable (its hash versions the sweep cache)")?;
    file_sha256(&exe)
}

/// What a point's result depends on.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyInput<'a> {
    /// [`binary_version`].
    pub binary: &'a str,
    /// The setup's identity (see `setup_identity` in `plan`): `builtin:NAME`, or hashes of the
    /// setup file and scene file contents.
    pub setup: &'a str,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub repeat: usize,
    pub light: usize,
    pub time: f32,
    /// The resolved spec: `technique:key=value,...` with every parameter, then `label=...`.
    pub spec: &'a str,
}

impl KeyInput<'_> {
    /// The text that is hashed (stored beside each point, so a reader can see what it covers).
    pub fn text(&self) -> String {
        format!(
            "shadowlab sweep point v{KEY_VERSION}\nbinary {}\nsetup {}\nsize {}x{}\nframes {}\nrepeat {}\nlight {}\ntime {:?}\nspec {}\n",
            self.binary, self.setup, self.width, self.height, self.frames, self.repeat, self.light, self.time, self.spec
        )
    }

    /// The point's key: SHA-256 of [`KeyInput::text`], 64 hex digits (its file name).
    pub fn key(&self) -> String {
        sha256_hex(self.text().as_bytes())
    }
}

/// A spec as the key sees it: technique name, every resolved parameter value (defaults
/// included, so `sm` and `sm:res=512` are one computation) and the label.
pub fn resolved_spec_text(r: &shadowlab_gpu::registry::Resolved) -> String {
    format!("{}:{} label={}", r.info.name, r.values.to_spec_args(), r.label)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> KeyInput<'static> {
        KeyInput {
            binary: "b1",
            setup: "builtin:planebox",
            width: 64,
            height: 64,
            frames: 1,
            repeat: 3,
            light: 0,
            time: 0.0,
            spec: "sm:res=512 label=sm",
        }
    }

    #[test]
    fn sha256_matches_the_standard_vector() {
        assert_eq!(sha256_hex(b"abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
        let dir = std::env::temp_dir().join(format!("shadowlab-key-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("abc.txt");
        std::fs::write(&f, b"abc").unwrap();
        assert_eq!(file_sha256(&f).unwrap(), sha256_hex(b"abc"));
        assert!(file_sha256(&dir.join("missing")).unwrap_err().to_string().contains("missing"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn every_input_changes_the_key_and_equal_inputs_agree() {
        let k = base().key();
        assert_eq!(k.len(), 64);
        assert_eq!(k, base().key(), "deterministic");
        let variants = [
            KeyInput { binary: "b2", ..base() },
            KeyInput { setup: "builtin:room", ..base() },
            KeyInput { width: 65, ..base() },
            KeyInput { height: 65, ..base() },
            KeyInput { frames: 2, ..base() },
            KeyInput { repeat: 1, ..base() },
            KeyInput { light: 1, ..base() },
            KeyInput { time: 0.5, ..base() },
            KeyInput { spec: "sm:res=1024 label=sm", ..base() },
        ];
        let mut seen = std::collections::HashSet::from([k]);
        for v in variants {
            assert!(seen.insert(v.key()), "{:?} collides", v);
        }
    }

    #[test]
    fn the_resolved_text_covers_defaults_and_the_label() {
        use shadowlab_core::params::TechniqueSpec;
        let r = |t: &str| shadowlab_gpu::registry::resolve(&TechniqueSpec::parse(t).unwrap(), None).unwrap();
        let a = resolved_spec_text(&r("sm"));
        assert!(a.starts_with("sm:") && a.contains("res=512") && a.contains("pcf=1") && a.ends_with("label=sm"), "{a}");
        assert_eq!(resolved_spec_text(&r("sm:res=512,label=sm")), a, "an explicit default is the same computation");
        assert_ne!(resolved_spec_text(&r("sm:res=1024")), a);
    }

    #[test]
    fn the_binary_version_is_the_running_executables_hash() {
        let v = binary_version().unwrap();
        assert_eq!(v, file_sha256(&std::env::current_exe().unwrap()).unwrap());
        assert_eq!(v.len(), 64);
    }
}
