//! A city-scale scene for `csm` (shared by tests/csm.rs and examples/csm_path.rs): a 17 x 17
//! grid of blocks, 24 m apart (about 400 m across), buildings 6-46 m tall, and a row of street
//! lamps (thin poles) along the street the camera looks down, at street level with a 400 m far
//! plane. The view spans a small part of the scene near the camera and a long way beyond: the
//! case cascades exist for.

use glam::Vec3;
use shadowlab_core::builtin::{hash01, MeshBuilder};
use shadowlab_core::camera::{Camera, CameraKey};
use shadowlab_core::light::Light;
use shadowlab_core::scene::{Material, Scene};

pub fn city() -> Scene {
    let mut b = MeshBuilder::default();
    let ground = b.material(Material::solid("ground", [0.55; 3]));
    let wall = b.material(Material::solid("wall", [0.8, 0.75, 0.7]));
    let pole = b.material(Material::solid("pole", [0.3; 3]));
    let (n, pitch, block) = (17i32, 24.0f32, 14.0f32);
    let half = n as f32 * pitch * 0.5;
    b.quad(Vec3::new(-half, 0.0, half), Vec3::new(2.0 * half, 0.0, 0.0), Vec3::new(0.0, 0.0, -2.0 * half), glam::Vec2::ONE, ground);
    for i in 0..n {
        for j in 0..n {
            let c = Vec3::new((i - n / 2) as f32 * pitch, 0.0, (j - n / 2) as f32 * pitch);
            let h = 6.0 + 40.0 * hash01((i * 131 + j * 17) as u32);
            b.cuboid(c - Vec3::new(block * 0.5, 0.0, block * 0.5), c + Vec3::new(block * 0.5, h, block * 0.5), wall);
        }
    }
    // street lamps along the street x = 12 (between block columns), every 6 m
    for k in 0..30 {
        let p = Vec3::new(12.0 + 3.5, 0.0, 40.0 - 6.0 * k as f32);
        b.cylinder(p, p + Vec3::Y * 5.0, 0.12, 8, pole);
        b.cuboid(p + Vec3::new(-1.2, 5.0, -0.1), p + Vec3::new(0.1, 5.2, 0.1), pole);
    }
    let cam = Camera::new(Vec3::new(12.0, 1.7, 44.0), Vec3::new(12.0, 4.0, -200.0), 60.0, 0.1, 400.0);
    let path = (0..4).map(|i| CameraKey { position: cam.position - Vec3::Z * (3.0 * i as f32), target: cam.target }).collect();
    b.finish("city", cam, vec![Light::Directional { direction: Vec3::new(0.45, -0.8, 0.3) }], path)
}
