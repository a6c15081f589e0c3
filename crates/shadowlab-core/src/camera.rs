//! Look-at perspective camera (world up +Y, pixel centres at +0.5, wgpu depth range 0..1).

use glam::{Mat4, Vec3, Vec4Swizzles};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: Vec3,
    pub target: Vec3,
    #[serde(default = "default_fov")]
    pub fov_y_deg: f32,
    #[serde(default = "default_near")]
    pub near: f32,
    #[serde(default = "default_far")]
    pub far: f32,
}

pub(crate) fn default_fov() -> f32 {
    60.0
}
pub(crate) fn default_near() -> f32 {
    0.1
}
pub(crate) fn default_far() -> f32 {
    100.0
}

/// Right-handed view matrix (wgpu/D3D conventions below: NDC z in [0, 1], y up).
pub fn look_at(eye: Vec3, center: Vec3, up: Vec3) -> Mat4 {
    glam::camera::rh::view::look_at_mat4(eye, center, up)
}
pub fn perspective(fov_y_rad: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::perspective(fov_y_rad, aspect, near, far)
}
pub fn orthographic(left: f32, right: f32, bottom: f32, top: f32, near: f32, far: f32) -> Mat4 {
    glam::camera::rh::proj::directx::orthographic(left, right, bottom, top, near, far)
}

/// One keyframe of a camera path.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    pub position: Vec3,
    pub target: Vec3,
}

/// `frames` cameras along a path: `base`'s lens at positions and targets interpolated linearly
/// between the keys, evenly in key parameter (the first frame at the first key, the last at the
/// last). No keys, or a single key: the camera holds still (at `base`, or at that key).
pub fn path_cameras(base: &Camera, keys: &[CameraKey], frames: usize) -> Vec<Camera> {
    (0..frames)
        .map(|f| {
            let mut c = *base;
            match keys {
                [] => {}
                [k] => (c.position, c.target) = (k.position, k.target),
                _ => {
                    let t = if frames < 2 { 0.0 } else { f as f32 / (frames - 1) as f32 } * (keys.len() - 1) as f32;
                    let i = (t.floor() as usize).min(keys.len() - 2);
                    let u = t - i as f32;
                    c.position = keys[i].position.lerp(keys[i + 1].position, u);
                    c.target = keys[i].target.lerp(keys[i + 1].target, u);
                }
            }
            c
        })
        .collect()
}

impl Camera {
    pub fn new(position: Vec3, target: Vec3, fov_y_deg: f32, near: f32, far: f32) -> Self {
        Camera { position, target, fov_y_deg, near, far }
    }
    /// Up vector: +Y unless the view is (nearly) vertical, then +Z.
    fn up(&self) -> Vec3 {
        let f = (self.target - self.position).normalize_or_zero();
        if f.cross(Vec3::Y).length_squared() < 1e-6 {
            Vec3::Z
        } else {
            Vec3::Y
        }
    }
    pub fn view(&self) -> Mat4 {
        look_at(self.position, self.target, self.up())
    }
    pub fn proj(&self, aspect: f32) -> Mat4 {
        perspective(self.fov_y_deg.to_radians(), aspect, self.near, self.far)
    }
    pub fn view_proj(&self, width: u32, height: u32) -> Mat4 {
        self.proj(width as f32 / height as f32) * self.view()
    }
    /// Checks the fields a user can get wrong.
    pub fn validate(&self) -> Result<(), String> {
        if !(self.position.is_finite() && self.target.is_finite()) {
            return Err("camera position/target must be finite".into());
        }
        if (self.target - self.position).length() < 1e-6 {
            return Err("camera target equals its position".into());
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(format!("camera fov_y_deg {} must be in (0, 180)", self.fov_y_deg));
        }
        if !(self.near > 0.0 && self.far > self.near) {
            return Err(format!("camera needs 0 < near < far (near {}, far {})", self.near, self.far));
        }
        Ok(())
    }
    /// Projects a world point to pixel coordinates (x right, y down), or None behind the camera.
    pub fn project_to_pixel(&self, p: Vec3, width: u32, height: u32) -> Option<glam::Vec2> {
        let c = self.view_proj(width, height) * p.extend(1.0);
        if c.w <= 0.0 {
            return None;
        }
        let ndc = c.xyz() / c.w;
        Some(glam::Vec2::new((ndc.x * 0.5 + 0.5) * width as f32, (0.5 - ndc.y * 0.5) * height as f32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn path_interpolates_keys_and_holds_without_them() {
        let base = Camera::new(Vec3::ZERO, Vec3::Z, 60.0, 0.1, 100.0);
        let keys = [
            CameraKey { position: Vec3::ZERO, target: Vec3::X },
            CameraKey { position: Vec3::new(2.0, 0.0, 0.0), target: Vec3::X * 3.0 },
            CameraKey { position: Vec3::new(2.0, 4.0, 0.0), target: Vec3::X * 3.0 },
        ];
        let c = path_cameras(&base, &keys, 5);
        let xs: Vec<Vec3> = c.iter().map(|c| c.position).collect();
        assert_eq!(xs, vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::new(2.0, 2.0, 0.0), Vec3::new(2.0, 4.0, 0.0)]);
        assert_eq!(c[1].target, Vec3::X * 2.0);
        assert!(path_cameras(&base, &[], 3).iter().all(|c| *c == base));
        assert_eq!(path_cameras(&base, &keys[1..2], 2)[1].position, Vec3::X * 2.0);
        assert_eq!(path_cameras(&base, &keys, 1)[0].position, Vec3::ZERO);
    }
    #[test]
    fn target_projects_to_centre() {
        let c = Camera::new(Vec3::new(1.0, 2.0, 3.0), Vec3::new(4.0, 1.0, -2.0), 60.0, 0.1, 100.0);
        let p = c.project_to_pixel(c.target, 200, 100).unwrap();
        assert!((p - glam::Vec2::new(100.0, 50.0)).length() < 1e-3, "{p}");
        assert!(c.validate().is_ok());
        assert!(Camera { near: 0.0, ..c }.validate().is_err());
    }
}
