//! A city block grid several hundred metres across under a low sun, for partitioned shadow maps
//! over a wide area (seed 001, issue 6): 9 x 9 blocks of 2 x 2 buildings (5-20 m, some 30-60 m
//! towers) on a 50 m pitch (450 m across), 20 m streets lined with thin street lamps, a ground paved per cell.
//! The camera walks down a north-south street at eye height looking along it (near lamps large
//! on screen, towers hundreds of metres away small), then turns into a cross street. The sun is
//! 25 degrees high, travelling mostly along the camera's street towards it, so long shadows of
//! lamps and buildings cross the streets and point at the viewer.

use glam::{Vec2, Vec3};

use super::{hash01, MeshBuilder};
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene};

/// Blocks per side.
pub const BLOCKS: i32 = 9;
/// Block pitch (block + street), metres.
pub const PITCH: f32 = 50.0;
/// Street width, metres.
pub const STREET: f32 = 20.0;
/// Half the city's side.
pub const HALF: f32 = BLOCKS as f32 * PITCH / 2.0;

/// Where the sunlight travels: 25 degrees above the horizon, 60 degrees off the x axis (mostly
/// along the north-south streets, towards the starting camera: shadows point at the viewer).
pub fn sun_direction() -> Vec3 {
    let (el, az) = (25f32.to_radians(), 60f32.to_radians());
    Vec3::new(el.cos() * az.cos(), -el.sin(), el.cos() * az.sin())
}

/// x (or z) of the centre of street `i` (0..=BLOCKS).
pub fn street(i: i32) -> f32 {
    -HALF + i as f32 * PITCH
}

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let ground = b.material(Material::solid("asphalt", [0.35, 0.35, 0.37]));
    let walk = b.material(Material::solid("pavement", [0.6, 0.58, 0.55]));
    let walls = [
        b.material(Material::solid("concrete", [0.7, 0.68, 0.64])),
        b.material(Material::solid("brick", [0.62, 0.4, 0.32])),
        b.material(Material::solid("glass", [0.45, 0.55, 0.62])),
    ];
    let metal = b.material(Material::solid("lamp", [0.2, 0.22, 0.2]));

    // Ground: one asphalt quad per street cell and a raised pavement per block, so no triangle
    // spans the city (culling works per region).
    for i in 0..=BLOCKS {
        for j in 0..BLOCKS {
            let (x0, z0) = (street(i) - STREET / 2.0, street(j) + STREET / 2.0);
            b.quad(Vec3::new(x0, 0.0, z0 + PITCH - STREET), Vec3::X * STREET, Vec3::NEG_Z * (PITCH - STREET), Vec2::ONE, ground);
            let (x1, z1) = (street(j) + STREET / 2.0, street(i) - STREET / 2.0);
            b.quad(Vec3::new(x1, 0.0, z1 + STREET), Vec3::X * (PITCH - STREET), Vec3::NEG_Z * STREET, Vec2::ONE, ground);
        }
    }
    for i in 0..=BLOCKS {
        for j in 0..=BLOCKS {
            let (x, z) = (street(i) - STREET / 2.0, street(j) - STREET / 2.0);
            b.quad(Vec3::new(x, 0.0, z + STREET), Vec3::X * STREET, Vec3::NEG_Z * STREET, Vec2::ONE, ground);
        }
    }
    let mut seed = 1u32;
    let mut rnd = || {
        seed += 1;
        hash01(seed)
    };
    for i in 0..BLOCKS {
        for j in 0..BLOCKS {
            let (x0, z0) = (street(i) + STREET / 2.0, street(j) + STREET / 2.0);
            let inner = PITCH - STREET;
            b.cuboid(Vec3::new(x0, 0.0, z0), Vec3::new(x0 + inner, 0.15, z0 + inner), walk);
            // 2 x 2 buildings set back 2 m, 3 m apart
            let foot = (inner - 4.0 - 3.0) / 2.0; // 11.5 m
            for (a, c) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let bx = x0 + 2.0 + a as f32 * (foot + 3.0);
                let bz = z0 + 2.0 + c as f32 * (foot + 3.0);
                // mostly 5-20 m, one in ten a 30-60 m tower
                let h = if rnd() < 0.1 { 30.0 + 30.0 * rnd() } else { 5.0 + 15.0 * rnd() * rnd() };
                let m = walls[(rnd() * 3.0) as usize % 3];
                let shrink = 2.0 * rnd();
                b.cuboid(Vec3::new(bx + shrink, 0.15, bz), Vec3::new(bx + foot, h, bz + foot - shrink), m);
                // rooftop plant room
                if rnd() > 0.4 {
                    let c0 = Vec3::new(bx + foot * 0.3, h, bz + foot * 0.3);
                    b.cuboid(c0, c0 + Vec3::new(foot * 0.3, 3.0, foot * 0.25), walls[0]);
                }
            }
        }
    }
    // Street lamps along the north-south streets, both sides, every 25 m: 6 m poles 0.16 m
    // thick with a 1.2 m arm over the road.
    for i in 0..=BLOCKS {
        for k in 0..(BLOCKS * 2) {
            let z = -HALF + 12.5 + k as f32 * 25.0;
            for side in [-1.0f32, 1.0] {
                let x = street(i) + side * (STREET / 2.0 - 0.6);
                b.cuboid(Vec3::new(x - 0.08, 0.0, z - 0.08), Vec3::new(x + 0.08, 6.0, z + 0.08), metal);
                let (xa, xb) = if side < 0.0 { (x, x + 1.2) } else { (x - 1.2, x) };
                b.cuboid(Vec3::new(xa, 5.9, z - 0.06), Vec3::new(xb, 6.02, z + 0.06), metal);
            }
        }
    }

    let sx = street(4);
    let cam = Camera::new(Vec3::new(sx + 2.0, 1.7, 180.0), Vec3::new(sx + 1.0, 6.0, -200.0), 60.0, 0.1, 600.0);
    let cross = street(6);
    let path = vec![
        CameraKey { position: cam.position, target: cam.target },
        CameraKey { position: Vec3::new(sx + 2.0, 1.7, 140.0), target: cam.target },
        CameraKey { position: Vec3::new(sx + 1.0, 1.7, cross + 3.0), target: Vec3::new(sx - 60.0, 4.0, cross - 120.0) },
        CameraKey { position: Vec3::new(sx - 20.0, 1.7, cross), target: Vec3::new(-HALF, 6.0, cross) },
    ];
    b.finish("city", cam, vec![Light::Directional { direction: sun_direction() }], path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn city_is_hundreds_of_metres_with_a_low_sun_and_a_street_camera() {
        let s = build();
        let bnd = s.bounds();
        let ext = bnd.max - bnd.min;
        assert!(ext.x > 400.0 && ext.z > 400.0 && ext.y > 20.0, "{ext}");
        let Light::Directional { direction } = s.lights[0] else { panic!() };
        let elev = (-direction.normalize().y).asin().to_degrees();
        assert!((elev - 25.0).abs() < 0.01);
        // the camera stands in a street: outside every block's pavement square
        for k in &s.camera_path {
            let p = k.position;
            let fx = (p.x + HALF).rem_euclid(PITCH);
            let fz = (p.z + HALF).rem_euclid(PITCH);
            let in_street = !(STREET / 2.0..PITCH - STREET / 2.0).contains(&fx) || !(STREET / 2.0..PITCH - STREET / 2.0).contains(&fz);
            assert!(in_street, "camera key {p} inside a block");
            assert!((p.y - 1.7).abs() < 1e-3);
        }
        assert!(s.triangle_count() > 10_000);
    }
}
