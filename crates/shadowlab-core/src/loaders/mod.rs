//! Scene files: glTF 2.0 (`.gltf`, `.glb`) and Wavefront OBJ + MTL, through the `gltf`, `tobj`
//! and `image` crates. Scenes load in the file's own coordinates; the only transform is the
//! user's [`SceneTransform`] (up axis, uniform scale, offset), recorded in the outputs.

mod files;
mod gltf_loader;
mod obj_loader;

pub use files::{Disk, Files, InMemory};

use std::path::Path;

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::Camera;
use crate::light::Light;
use crate::scene::{Scene, Texture};

#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    #[error("{path}: {msg}")]
    Invalid { path: String, msg: String },
    #[error("{path}: unsupported scene format (expected .gltf, .glb or .obj)")]
    UnsupportedFormat { path: String },
}

impl LoadError {
    pub fn invalid(path: &Path, msg: impl std::fmt::Display) -> Self {
        LoadError::Invalid { path: path.display().to_string(), msg: msg.to_string() }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum UpAxis {
    #[default]
    Y,
    /// Z-up files: (x, y, z) -> (x, z, -y).
    Z,
}

/// The user's transform: up-axis rotation, then uniform scale, then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneTransform {
    pub up: UpAxis,
    pub scale: f32,
    pub offset: Vec3,
}

impl Default for SceneTransform {
    fn default() -> Self {
        SceneTransform { up: UpAxis::Y, scale: 1.0, offset: Vec3::ZERO }
    }
}

impl SceneTransform {
    pub fn matrix(&self) -> Mat4 {
        let rot = match self.up {
            UpAxis::Y => Mat4::IDENTITY,
            // columns are the images of x, y, z: x->x, y->-z, z->y
            UpAxis::Z => Mat4::from_cols(glam::Vec4::X, -glam::Vec4::Z, glam::Vec4::Y, glam::Vec4::W),
        };
        Mat4::from_translation(self.offset) * Mat4::from_scale(Vec3::splat(self.scale)) * rot
    }
}

/// Loads a scene file by extension, applies `xf`, and gives it a default camera and light
/// fitted to its bounds (setups normally override both).
pub fn load(path: &Path, xf: &SceneTransform) -> Result<Scene, LoadError> {
    load_from(&Disk, path, xf)
}

/// [`load`], reading `path` and the files it names (MTL, textures, buffers) from `files`.
pub fn load_from(files: &dyn Files, path: &Path, xf: &SceneTransform) -> Result<Scene, LoadError> {
    if !(xf.scale.is_finite() && xf.scale > 0.0 && xf.offset.is_finite()) {
        return Err(LoadError::invalid(path, "scale must be a positive finite number and offset finite"));
    }
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let m = xf.matrix();
    let mut scene = match ext.as_str() {
        "gltf" | "glb" => gltf_loader::load(files, path, m)?,
        "obj" => obj_loader::load(files, path, m)?,
        _ => return Err(LoadError::UnsupportedFormat { path: path.display().to_string() }),
    };
    if scene.vertices.is_empty() {
        return Err(LoadError::invalid(path, "no valid triangles"));
    }
    scene.transform = m;
    let b = scene.bounds();
    let c = b.center();
    let d = b.diagonal();
    if !(d.is_finite() && c.is_finite()) {
        return Err(LoadError::invalid(path, format!("the scene spans more than f32 can hold (bounds {:?} to {:?})", b.min, b.max)));
    }
    scene.camera = Camera::new(c + Vec3::new(0.6, 0.35, 0.6) * d, c, 55.0, d * 1e-3, d * 3.0);
    scene.lights = vec![Light::Directional { direction: Vec3::new(0.35, -1.0, 0.25) }];
    scene.name = path.file_stem().and_then(|s| s.to_str()).unwrap_or("scene").to_string();
    Ok(scene)
}

/// Largest texture side kept on the GPU; bigger images are downsampled on load (cut-outs stay
/// consistent because G-buffer, shadow maps and the reference all read the same texels).
pub const MAX_TEXTURE_SIZE: u32 = 1024;

/// Decodes an image file into an RGBA8 [`Texture`], downsampled to [`MAX_TEXTURE_SIZE`].
pub fn load_texture(path: &Path) -> Result<Texture, String> {
    let img = image::ImageReader::open(path)
        .map_err(|e| e.to_string())?
        .with_guessed_format()
        .map_err(|e| e.to_string())?
        .decode()
        .map_err(|e| e.to_string())?;
    Ok(texture_from_image(path.display().to_string(), img))
}

pub fn texture_from_image(name: String, img: image::DynamicImage) -> Texture {
    let img = if img.width().max(img.height()) > MAX_TEXTURE_SIZE {
        img.resize(MAX_TEXTURE_SIZE, MAX_TEXTURE_SIZE, image::imageops::FilterType::Triangle)
    } else {
        img
    };
    let rgba = img.to_rgba8();
    Texture { name, width: rgba.width(), height: rgba.height(), rgba: rgba.into_raw() }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn z_up_maps_as_documented() {
        let xf = SceneTransform { up: UpAxis::Z, scale: 2.0, offset: Vec3::new(1.0, 0.0, 0.0) };
        let p = xf.matrix().transform_point3(Vec3::new(1.0, 2.0, 3.0));
        // (x, y, z) -> (x, z, -y), then *2, then +offset
        assert!((p - Vec3::new(3.0, 6.0, -4.0)).length() < 1e-6, "{p}");
    }
}
