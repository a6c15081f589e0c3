//! Uniform structs shared by Rust and WGSL (`common.wgsl`). Their layouts are checked against
//! naga's reflection in `tests/shaders.rs`.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;

/// WGSL `Frame`: the camera of this view.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniform {
    pub view_proj: [[f32; 4]; 4],
    pub prev_view_proj: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    pub size: [u32; 2],
    pub _pad: [u32; 2],
}

impl FrameUniform {
    pub fn new(camera: &Camera, prev: &Camera, width: u32, height: u32) -> Self {
        FrameUniform {
            view_proj: camera.view_proj(width, height).to_cols_array_2d(),
            prev_view_proj: prev.view_proj(width, height).to_cols_array_2d(),
            camera_pos: camera.position.extend(1.0).into(),
            size: [width, height],
            _pad: [0; 2],
        }
    }
}

pub const LIGHT_DIRECTIONAL: u32 = 0;
pub const LIGHT_SPOT: u32 = 1;
pub const LIGHT_POINT: u32 = 2;

/// WGSL `LightU`: one light plus the reference's ray epsilon.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightUniform {
    /// xyz: position (spot, point).
    pub position: [f32; 4],
    /// xyz: unit direction the light travels (directional, spot).
    pub direction: [f32; 4],
    pub kind: u32,
    /// cos of the spot half-angle (-2 for other lights: every sample is inside).
    pub cos_cone: f32,
    /// Ray origin offset along the normal (scene-relative).
    pub eps: f32,
    pub _pad: u32,
}

impl LightUniform {
    pub fn new(light: &Light, eps: f32) -> Self {
        let (kind, p, d, cos_cone) = match *light {
            Light::Directional { direction } => (LIGHT_DIRECTIONAL, Vec3::ZERO, direction.normalize(), -2.0),
            Light::Spot { position, direction, cone_deg } => (LIGHT_SPOT, position, direction.normalize(), cone_deg.to_radians().cos()),
            Light::Point { position } => (LIGHT_POINT, position, Vec3::NEG_Y, -2.0),
        };
        LightUniform { position: p.extend(1.0).into(), direction: d.extend(0.0).into(), kind, cos_cone, eps, _pad: 0 }
    }
}
