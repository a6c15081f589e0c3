//! A 10 m plane and a 1 m box under a directional light: the shadow is known exactly.

use glam::{Vec2, Vec3};

use super::MeshBuilder;
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene};

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let floor = b.material(Material::solid("floor", [0.8, 0.8, 0.8]));
    let boxm = b.material(Material::solid("box", [0.8, 0.3, 0.2]));
    b.quad(Vec3::new(-5.0, 0.0, 5.0), Vec3::new(10.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -10.0), Vec2::ONE, floor);
    b.cuboid(Vec3::new(-0.5, 0.0, -0.5), Vec3::new(0.5, 1.0, 0.5), boxm);
    let cam = Camera::new(Vec3::new(4.0, 5.0, 6.0), Vec3::new(0.5, 0.0, 0.0), 50.0, 0.1, 50.0);
    let path = vec![
        CameraKey { position: cam.position, target: cam.target },
        CameraKey { position: Vec3::new(-4.0, 5.0, 6.0), target: cam.target },
    ];
    b.finish("planebox", cam, vec![Light::Directional { direction: Vec3::new(0.5, -1.0, 0.3) }], path)
}
