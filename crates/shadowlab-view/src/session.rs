//! What the viewer saves: the current view as a setup TOML that `shadowlab compare --setup`
//! reproduces exactly (scene, camera, light, time, size, techniques and their parameters), and
//! files written under fresh names, never half-written.

use std::path::{Path, PathBuf};

use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;
use shadowlab_core::setup::{CameraSection, OutputSection, Setup, TechniqueEntry};

/// `base` (scene section, moving objects, camera path) with the viewer's camera, one light,
/// animation time, output size and technique specs.
pub fn snapshot(base: &Setup, camera: &Camera, light: &Light, time: f32, width: u32, height: u32, specs: &[String]) -> Setup {
    let mut s = base.clone();
    if let Some(p) = &s.scene.path {
        // a saved setup may live anywhere: the scene by its absolute path
        s.scene.path = Some(std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()));
    }
    let path = base.camera.as_ref().map(|c| c.path.clone()).unwrap_or_default();
    s.camera = Some(CameraSection {
        position: camera.position,
        target: camera.target,
        fov_y_deg: camera.fov_y_deg,
        near: camera.near,
        far: camera.far,
        path,
    });
    s.lights = vec![*light];
    s.time = time;
    s.output = OutputSection { width, height };
    s.techniques = specs.iter().map(|spec| TechniqueEntry { spec: spec.clone() }).collect();
    s
}

/// The setup as TOML, with a header saying where it came from.
pub fn to_toml(setup: &Setup) -> Result<String, String> {
    let body = toml::to_string(setup).map_err(|e| format!("cannot write the setup: {e}"))?;
    Ok(format!("# Saved by `shadowlab view`; `shadowlab compare --setup THIS_FILE` reproduces the view and its numbers.\n{body}"))
}

/// Writes `bytes` as `dir/stem-NNN.ext` with the first free NNN, through a temporary file and a
/// rename (an interrupted write leaves no partial file under the final name).
pub fn write_fresh(dir: &Path, stem: &str, ext: &str, bytes: &[u8]) -> std::io::Result<PathBuf> {
    std::fs::create_dir_all(dir)?;
    for i in 1..100_000 {
        let path = dir.join(format!("{stem}-{i:03}.{ext}"));
        if path.exists() {
            continue;
        }
        let tmp = dir.join(format!(".{stem}-{i:03}.{ext}.partial"));
        std::fs::write(&tmp, bytes)?;
        std::fs::rename(&tmp, &path)?;
        return Ok(path);
    }
    Err(std::io::Error::other(format!("{}: no free name {stem}-NNN.{ext}", dir.display())))
}

/// PNG bytes of an RGBA8 picture.
pub fn png(width: u32, height: u32, rgba: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(&mut out, rgba, width, height, image::ExtendedColorType::Rgba8, image::ImageFormat::Png)
        .map_err(|e| e.to_string())?;
    Ok(out.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn a_snapshot_round_trips_through_toml_bit_for_bit() {
        let base = Setup::parse("[scene]\nbuiltin = \"planebox\"\n").unwrap();
        // values with no short decimal form: the TOML must still give the same f32 bits back
        let cam = Camera::new(Vec3::new(0.1, 1.0 / 3.0, 7.77e-3), Vec3::new(-2.0, 0.2, std::f32::consts::PI), 57.3, 0.05, 80.0);
        let light = Light::Directional { direction: Vec3::new(0.3, -0.9, 1.0 / 7.0) };
        let specs = vec!["sm:res=1024,pcf=3".to_string(), "lt:label=mine".to_string()];
        let s = snapshot(&base, &cam, &light, 12.345, 320, 200, &specs);
        let text = to_toml(&s).unwrap();
        let back = Setup::parse(&text).unwrap();
        back.validate().unwrap();
        assert_eq!(back.camera.as_ref().unwrap().camera(), cam);
        assert_eq!(back.lights, vec![light]);
        assert_eq!(back.time.to_bits(), 12.345f32.to_bits());
        assert_eq!((back.output.width, back.output.height), (320, 200));
        let got: Vec<_> = back.techniques.iter().map(|t| t.spec.clone()).collect();
        assert_eq!(got, specs);
        assert_eq!(back.scene.builtin.as_deref(), Some("planebox"));
    }

    #[test]
    fn fresh_names_never_overwrite() {
        let dir = std::env::temp_dir().join(format!("shadowlab-view-fresh-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let a = write_fresh(&dir, "view", "toml", b"a").unwrap();
        let b = write_fresh(&dir, "view", "toml", b"b").unwrap();
        assert_ne!(a, b);
        assert_eq!(std::fs::read(&a).unwrap(), b"a");
        assert_eq!(std::fs::read(&b).unwrap(), b"b");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2, "no temporary file left");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
