//! TOML setup files: everything a run needs, so runs are reproducible. Unknown keys are errors.
//! Paths inside a setup are relative to the setup file.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::anim::AnimationSpec;
use crate::camera::{default_far, default_fov, default_near, Camera, CameraKey};
use crate::light::Light;
use crate::loaders::{SceneTransform, UpAxis};

#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// Animation time of frame 0, in frames (moving objects); `--time` overrides it.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub time: f32,
    pub scene: SceneSection,
    #[serde(default)]
    pub camera: Option<CameraSection>,
    #[serde(default)]
    pub lights: Vec<Light>,
    #[serde(default)]
    pub output: OutputSection,
    #[serde(default)]
    pub techniques: Vec<TechniqueEntry>,
    /// `[[animations]]`: moving objects (see `anim.rs`), added to a built-in scene's own.
    #[serde(default)]
    pub animations: Vec<AnimationSpec>,
}

/// `[camera]`: the lens and pose of frame 0, and an optional `[[camera.path]]` of keyframes
/// (position, target) that `--frames N` follows.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSection {
    pub position: Vec3,
    pub target: Vec3,
    #[serde(default = "default_fov")]
    pub fov_y_deg: f32,
    #[serde(default = "default_near")]
    pub near: f32,
    #[serde(default = "default_far")]
    pub far: f32,
    #[serde(default)]
    pub path: Vec<CameraKey>,
}

impl CameraSection {
    pub fn camera(&self) -> Camera {
        Camera::new(self.position, self.target, self.fov_y_deg, self.near, self.far)
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneSection {
    /// A scene file (.gltf, .glb, .obj), relative to the setup file.
    pub path: Option<PathBuf>,
    /// Or a built-in scene name.
    pub builtin: Option<String>,
    #[serde(default)]
    pub up: UpAxis,
    #[serde(default = "one")]
    pub scale: f32,
    #[serde(default)]
    pub offset: [f32; 3],
}

fn is_zero(t: &f32) -> bool {
    *t == 0.0
}

fn one() -> f32 {
    1.0
}

impl Default for SceneSection {
    fn default() -> Self {
        SceneSection { path: None, builtin: None, up: UpAxis::Y, scale: 1.0, offset: [0.0; 3] }
    }
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    #[serde(default = "default_size")]
    pub width: u32,
    #[serde(default = "default_size")]
    pub height: u32,
}

fn default_size() -> u32 {
    1024
}

impl Default for OutputSection {
    fn default() -> Self {
        OutputSection { width: 1024, height: 1024 }
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct TechniqueEntry {
    pub spec: String,
}

/// Where the scene comes from, resolved against the setup's directory.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    Builtin(String),
    File(PathBuf),
}

/// Environment variable naming the directory that holds the real scenes; a setup's scene path
/// that does not exist as written and has a `scenes` component is looked up under it.
pub const SCENES_ENV: &str = "SHADOWLAB_SCENES";

/// `base/p` when that exists (or when no scenes directory is given); else, when `p` has a
/// `scenes` component, the part after it under `scenes_dir` (setups written for the repository's
/// `../../shared/scenes` layout then work from any checkout with `SHADOWLAB_SCENES=/path/to/scenes`).
pub fn resolve_scene_path(base: &Path, p: &Path, scenes_dir: Option<&Path>) -> PathBuf {
    let direct = base.join(p);
    let Some(dir) = scenes_dir else { return direct };
    if direct.exists() {
        return direct;
    }
    let comps: Vec<_> = p.components().collect();
    match comps.iter().rposition(|c| c.as_os_str() == "scenes") {
        Some(i) => {
            let alt: PathBuf = dir.join(comps[i + 1..].iter().collect::<PathBuf>());
            if alt.exists() {
                alt
            } else {
                direct
            }
        }
        None => direct,
    }
}

impl Setup {
    pub fn parse(text: &str) -> Result<Setup, String> {
        toml::from_str(text).map_err(|e| e.to_string())
    }

    /// Reads a setup file; errors name the file.
    pub fn load(path: &Path) -> Result<Setup, String> {
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        let mut s = Setup::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if let Some(p) = &s.scene.path {
            let base = path.parent().unwrap_or(Path::new("."));
            let scenes_dir = std::env::var_os(SCENES_ENV).map(PathBuf::from);
            s.scene.path = Some(resolve_scene_path(base, p, scenes_dir.as_deref()));
        }
        s.validate().map_err(|e| format!("{}: {e}", path.display()))?;
        Ok(s)
    }

    pub fn validate(&self) -> Result<(), String> {
        self.scene_source()?;
        if let Some(c) = &self.camera {
            c.camera().validate()?;
            for (i, k) in c.path.iter().enumerate() {
                Camera { position: k.position, target: k.target, ..c.camera() }.validate().map_err(|e| format!("camera.path[{i}]: {e}"))?;
            }
        }
        for l in &self.lights {
            l.validate()?;
        }
        if !self.time.is_finite() {
            return Err(format!("time = {}: must be a finite number of frames", self.time));
        }
        for (i, a) in self.animations.iter().enumerate() {
            a.validate().map_err(|e| format!("animations[{i}]: {e}"))?;
        }
        Ok(())
    }

    pub fn scene_source(&self) -> Result<SceneSource, String> {
        match (&self.scene.path, &self.scene.builtin) {
            (Some(p), None) => Ok(SceneSource::File(p.clone())),
            (None, Some(b)) => Ok(SceneSource::Builtin(b.clone())),
            (None, None) => Err("[scene] needs `path` or `builtin`".into()),
            (Some(_), Some(_)) => Err("[scene] takes `path` or `builtin`, not both".into()),
        }
    }

    pub fn transform(&self) -> SceneTransform {
        SceneTransform { up: self.scene.up, scale: self.scene.scale, offset: Vec3::from(self.scene.offset) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    const EXAMPLE: &str = r#"
[scene]
path = "../../shared/scenes/sponza-dabrovic/sponza.obj"
up = "y"
scale = 1.0

[camera]
position = [-9.0, 2.0, 0.0]
target = [9.0, 5.0, 0.0]
fov_y_deg = 65.0
near = 0.1
far = 100.0

[[lights]]
type = "directional"
direction = [0.35, -1.0, 0.25]

[[lights]]
type = "spot"
position = [0.0, 5.0, 0.0]
direction = [0.0, -1.0, 0.0]
cone_deg = 35.0

[output]
width = 1024
height = 768

[[techniques]]
spec = "sm:res=512,pcf=3"
"#;
    #[test]
    fn parses_the_documented_form() {
        let s = Setup::parse(EXAMPLE).unwrap();
        s.validate().unwrap();
        assert_eq!(s.output.height, 768);
        assert_eq!(s.lights.len(), 2);
        assert!(matches!(s.lights[1], Light::Spot { cone_deg, .. } if cone_deg == 35.0));
        assert_eq!(s.techniques[0].spec, "sm:res=512,pcf=3");
        assert_eq!(s.camera.as_ref().unwrap().fov_y_deg, 65.0);
        assert!(s.camera.unwrap().path.is_empty());
    }
    #[test]
    fn camera_path_keys_parse_and_are_checked() {
        let text = "[scene]\nbuiltin = 'room'\n[camera]\nposition = [0, 1, 0]\ntarget = [0, 1, -1]\n\
                    [[camera.path]]\nposition = [0, 1, 0]\ntarget = [0, 1, -1]\n[[camera.path]]\nposition = [1, 1, 0]\ntarget = [1, 1, -1]\n";
        let s = Setup::parse(text).unwrap();
        s.validate().unwrap();
        assert_eq!(s.camera.as_ref().unwrap().path[1].position, Vec3::new(1.0, 1.0, 0.0));
        let bad = text.replace("target = [1, 1, -1]", "target = [1, 1, 0]");
        assert!(Setup::parse(&bad).unwrap().validate().unwrap_err().contains("camera.path[1]"));
        assert!(Setup::parse(&text.replace("[[camera.path]]\nposition = [0", "[[camera.path]]\nfov = 3\nposition = [0")).is_err());
    }
    #[test]
    fn animations_parse_and_are_checked() {
        let text = "[scene]\nbuiltin = 'planebox'\n\
                    [[animations]]\nname = 'box'\nmaterials = ['box']\ninside = [[-1, 0, -1], [1, 2, 1]]\n\
                    motion = { type = 'translate', offset = [2, 0, 0], period = 32 }\n\
                    [[animations]]\nname = 'fan'\ninside = [[-9, 0, -9], [9, 9, 9]]\n\
                    [animations.motion]\ntype = 'sway'\npivot = [0, 3, 0]\naxis = [0, 0, 1]\namplitude_deg = 10\nperiod = 40\n";
        let s = Setup::parse(text).unwrap();
        s.validate().unwrap();
        assert_eq!(s.animations.len(), 2);
        assert_eq!(s.animations[0].motion, crate::anim::Motion::Translate { offset: Vec3::new(2.0, 0.0, 0.0), period: 32.0 });
        assert_eq!(s.animations[1].inside.unwrap()[1], Vec3::splat(9.0));
        let e = Setup::parse(&text.replace("period = 40", "period = 0")).unwrap().validate().unwrap_err();
        assert!(e.contains("animations[1]") && e.contains("period"), "{e}");
        assert!(Setup::parse(&text.replace("amplitude_deg", "amplitude")).is_err(), "unknown motion keys are errors");
        assert!(Setup::parse(&text.replace("type = 'sway'", "type = 'wobble'")).is_err());
        assert!(Setup::parse(&text.replace("materials = ['box']", "material = 'box'")).is_err());
        let none = text.replace("materials = ['box']\ninside = [[-1, 0, -1], [1, 2, 1]]\n", "");
        assert!(Setup::parse(&none).unwrap().validate().unwrap_err().contains("select triangles"));
    }
    #[test]
    fn scene_paths_fall_back_to_the_scenes_directory() {
        let tmp = std::env::temp_dir().join(format!("shadowlab-scenes-{}", std::process::id()));
        std::fs::create_dir_all(tmp.join("sponza")).unwrap();
        std::fs::write(tmp.join("sponza/sponza.obj"), "").unwrap();
        let p = Path::new("../../shared/scenes/sponza/sponza.obj");
        let base = Path::new("/nonexistent/setups");
        assert_eq!(resolve_scene_path(base, p, Some(&tmp)), tmp.join("sponza/sponza.obj"));
        assert_eq!(resolve_scene_path(base, p, None), base.join(p), "no directory: as written");
        let missing = Path::new("../scenes/other/x.obj");
        assert_eq!(resolve_scene_path(base, missing, Some(&tmp)), base.join(missing), "not under the directory: as written");
        assert_eq!(resolve_scene_path(&tmp, Path::new("sponza/sponza.obj"), Some(Path::new("/x"))), tmp.join("sponza/sponza.obj"));
        std::fs::remove_dir_all(&tmp).unwrap();
    }
    #[test]
    fn defaults_are_the_identity_transform() {
        let d = Setup::default();
        assert_eq!(d.transform().matrix(), glam::Mat4::IDENTITY);
        let p = Setup::parse("[scene]\nbuiltin = 'room'").unwrap();
        assert_eq!(p.transform().matrix(), glam::Mat4::IDENTITY);
        assert_eq!((p.output.width, p.output.height), (1024, 1024));
    }

    #[test]
    fn unknown_keys_are_errors() {
        let e = Setup::parse(&EXAMPLE.replace("fov_y_deg", "fovy")).unwrap_err();
        assert!(e.contains("fovy"), "{e}");
        assert!(Setup::parse("[scene]\nbuiltin='room'\nscael=2").is_err());
        assert!(Setup::parse("[scene]\nbuiltin='room'\n[[lights]]\ntype='area'").is_err());
        let both = Setup::parse("[scene]\nbuiltin='room'\npath='x.obj'").unwrap();
        assert!(both.validate().is_err());
    }
}
