//! `eaves`: the dense stress case (issue 18). A temple porch whose roof is fine geometry: a
//! corrugated tile roof of ~65 k triangles over rafters, a lattice screen of thin bars between
//! two rows of fluted columns, over one large flat floor. Lights hang close under the dense
//! geometry, where warped and paraboloid maps must resolve many small occluders near the light:
//!
//! - `lights[0]`: a point light under the eaves, 0.5 m below the rafters (cube, dpsm and their
//!   warped forms: the faces towards the roof see thousands of triangles each);
//! - `lights[1]`: a low sun (directional, 15 degrees high) into the porch, across the floor and
//!   through the lattice;
//! - `lights[2]`: a spot light under the roof aimed down through the lattice.
//!
//! The camera stands on the floor outside the porch looking in under the roof, the point light
//! inside the view.

use glam::{Vec2, Vec3};

use super::{hash01, MeshBuilder};
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene};

/// The porch: x in [-HALF_X, HALF_X], z in [-DEPTH, 0] under the roof; the eaves overhang to
/// z = EAVES.
const HALF_X: f32 = 8.0;
const DEPTH: f32 = 6.0;
const EAVES: f32 = 1.5;
/// Height of the rafters' underside at the front (z = EAVES) and at the back (z = -DEPTH).
const EAVE_H: f32 = 3.6;
const RIDGE_H: f32 = 5.2;
/// Corrugated tiles: quads along x and along the slope.
const TILES_X: u32 = 256;
const TILES_Z: u32 = 128;

pub const POINT_POSITION: Vec3 = Vec3::new(0.6, 3.35, 0.4);
pub const SPOT_POSITION: Vec3 = Vec3::new(-2.0, 3.4, -2.0);

/// Height of the rafters' underside at depth z (a straight slope from the eaves to the back).
fn roof_h(z: f32) -> f32 {
    let t = (EAVES - z) / (EAVES + DEPTH);
    EAVE_H + (RIDGE_H - EAVE_H) * t
}

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let floor = b.material(Material::solid("stone floor", [0.62, 0.60, 0.55]));
    let column = b.material(Material::solid("column", [0.80, 0.77, 0.70]));
    let wood = b.material(Material::solid("rafters", [0.40, 0.26, 0.16]));
    let tiles = b.material(Material::solid("roof tiles", [0.55, 0.22, 0.16]));
    let lattice = b.material(Material::solid("lattice", [0.30, 0.22, 0.14]));
    let wall = b.material(Material::solid("back wall", [0.84, 0.80, 0.72]));

    // One large flat receiver (two triangles) and the back wall.
    b.quad(Vec3::new(-20.0, 0.0, 20.0), Vec3::new(40.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -40.0), Vec2::splat(8.0), floor);
    b.cuboid(Vec3::new(-HALF_X, 0.0, -DEPTH - 0.3), Vec3::new(HALF_X, RIDGE_H, -DEPTH), wall);

    // Two rows of fluted columns (24-sided prisms with a square plinth).
    for row in [-0.5f32, -4.0] {
        for i in 0..6 {
            let x = -HALF_X + 1.0 + i as f32 * (2.0 * HALF_X - 2.0) / 5.0;
            b.cuboid(Vec3::new(x - 0.4, 0.0, row - 0.4), Vec3::new(x + 0.4, 0.3, row + 0.4), column);
            b.cylinder(Vec3::new(x, 0.3, row), Vec3::new(x, roof_h(row), row), 0.28, 24, column);
        }
    }

    // Lattice screen between the front columns: thin vertical and horizontal bars.
    let (lz, l_lo, l_hi) = (-0.5f32, 0.9f32, 2.6f32);
    for i in 0..96 {
        let x = -HALF_X + 0.5 + i as f32 * (2.0 * HALF_X - 1.0) / 95.0;
        b.cuboid(Vec3::new(x - 0.02, l_lo, lz - 0.02), Vec3::new(x + 0.02, l_hi, lz + 0.02), lattice);
    }
    for j in 0..12 {
        let y = l_lo + j as f32 * (l_hi - l_lo) / 11.0;
        b.cuboid(Vec3::new(-HALF_X + 0.5, y - 0.015, lz - 0.03), Vec3::new(HALF_X - 0.5, y + 0.015, lz + 0.03), lattice);
    }

    // Rafters along the slope, every 0.16 m, each a thin box following the roof line.
    let n_rafters = 100;
    for i in 0..n_rafters {
        let x = -HALF_X + (i as f32 + 0.5) * 2.0 * HALF_X / n_rafters as f32;
        let (z0, z1) = (EAVES, -DEPTH);
        let (a, c) = (Vec3::new(x - 0.03, roof_h(z0), z0), Vec3::new(x - 0.03, roof_h(z1), z1));
        let up = Vec3::new(0.0, 0.12, 0.0);
        let side = Vec3::new(0.06, 0.0, 0.0);
        b.quad(a, side, c - a, Vec2::ONE, wood); // underside
        b.quad(a, c - a, up, Vec2::ONE, wood); // -x side
        b.quad(a + side, up, c - a, Vec2::ONE, wood); // +x side
        b.quad(a, up, side, Vec2::ONE, wood); // eave end
    }

    // Corrugated tiles just above the rafters: a height field rippled across x, with a small
    // hashed jitter so that no two tiles are alike (no accidental regularity for the warp).
    let height = |i: u32, j: u32| {
        let x = -HALF_X - 0.2 + i as f32 * (2.0 * HALF_X + 0.4) / TILES_X as f32;
        let z = EAVES + 0.1 - j as f32 * (EAVES + DEPTH + 0.1) / TILES_Z as f32;
        let ripple = 0.05 * (x * std::f32::consts::TAU / 0.25).sin().abs();
        let jitter = 0.01 * hash01(i * 7919 + j * 104_729);
        Vec3::new(x, roof_h(z) + 0.14 + ripple + jitter, z)
    };
    for j in 0..TILES_Z {
        for i in 0..TILES_X {
            let (p00, p10, p11, p01) = (height(i, j), height(i + 1, j), height(i + 1, j + 1), height(i, j + 1));
            let uv = [Vec2::ZERO, Vec2::X, Vec2::ONE];
            // counter-clockwise seen from below (the lit, seen side of the underside)
            b.tri([p00, p11, p10], uv, tiles);
            b.tri([p00, p01, p11], uv, tiles);
        }
    }

    let cam = Camera::new(Vec3::new(5.5, 1.6, 9.0), Vec3::new(-0.5, 2.4, -2.0), 60.0, 0.1, 80.0);
    let path = vec![
        CameraKey { position: cam.position, target: cam.target },
        CameraKey { position: Vec3::new(-5.5, 1.6, 9.0), target: Vec3::new(0.5, 2.4, -2.0) },
    ];
    let horizontal = Vec2::new(-0.55, -0.45);
    let sun = Vec3::new(horizontal.x, -horizontal.length() * 15f32.to_radians().tan(), horizontal.y).normalize();
    let lights = vec![
        Light::Point { position: POINT_POSITION },
        Light::Directional { direction: sun },
        Light::Spot { position: SPOT_POSITION, direction: Vec3::new(0.15, -1.0, 0.6).normalize(), cone_deg: 50.0 },
    ];
    b.finish("eaves", cam, lights, path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_roof_over_the_lights() {
        let s = build();
        assert!(s.triangle_count() > 65_000, "{} triangles", s.triangle_count());
        // both lights under the eaves sit below the rafters and above the floor
        for p in [POINT_POSITION, SPOT_POSITION] {
            assert!(p.y > 0.0 && p.y < roof_h(p.z), "{p}");
        }
        // the point light is within half a metre of the rafters above it
        assert!(roof_h(POINT_POSITION.z) - POINT_POSITION.y <= 0.6);
    }
}
