//! Built-in procedural scenes: deterministic, no files needed. Each has a default camera,
//! light(s) and a short camera path.

mod city;
mod courtyard;
mod eaves;
mod foliage;
mod planebox;
mod room;

use glam::{Mat4, Vec2, Vec3};

/// The foliage hand cart at t = 0 (body corners) and its travel (tests follow it).
pub use foliage::{CART as FOLIAGE_CART, CART_TRAVEL as FOLIAGE_CART_TRAVEL};

use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{LoadReport, Material, Scene, Texture, TriangleSink};

/// Name, one-line description and constructor of every built-in scene.
pub struct BuiltinScene {
    pub name: &'static str,
    pub summary: &'static str,
    pub build: fn() -> Scene,
}

pub const BUILTIN_SCENES: &[BuiltinScene] = &[
    BuiltinScene {
        name: "courtyard",
        summary: "Sponza-like atrium: two storeys of columns and arches, thin banners swinging on their rods, grazing sun (perspective aliasing)",
        build: courtyard::build,
    },
    BuiltinScene {
        name: "room",
        summary: "closed interior: table, 12 chairs with thin legs (one slides in and out), shelves; spot light (light 0) and point light (light 1)",
        build: room::build,
    },
    BuiltinScene {
        name: "foliage",
        summary: "alpha-tested leaf cards, a wire fence, a street lamp with swaying thin wires before a wall, a crossing hand cart (light leaks); sun",
        build: foliage::build,
    },
    BuiltinScene {
        name: "planebox",
        summary: "a 10 m plane and a 1 m box under a directional light: the exact-shadow test case",
        build: planebox::build,
    },
    BuiltinScene {
        name: "city",
        summary: "9 x 9 blocks of towers, 450 m across, street lamps, street-level camera, sun 25 degrees high (IASM/CSM wide area)",
        build: city::build,
    },
    BuiltinScene {
        name: "eaves",
        summary: "dense stress case: a porch under a 65 k-triangle tile roof on rafters, a lattice screen; point light (0) and spot (2) close under the eaves, low sun (1)",
        build: eaves::build,
    },
];

pub const DEFAULT_SCENE: &str = "courtyard";

pub fn builtin(name: &str) -> Option<Scene> {
    BUILTIN_SCENES.iter().find(|s| s.name == name).map(|s| (s.build)())
}

/// Small mesh-building kit for the procedural scenes.
pub struct MeshBuilder {
    sink: TriangleSink,
    materials: Vec<Material>,
    textures: Vec<Texture>,
    /// Transform applied to everything added (see [`MeshBuilder::with_transform`]).
    xf: Mat4,
}

impl Default for MeshBuilder {
    fn default() -> Self {
        MeshBuilder { sink: TriangleSink::default(), materials: vec![], textures: vec![], xf: Mat4::IDENTITY }
    }
}

impl MeshBuilder {
    pub fn material(&mut self, m: Material) -> u32 {
        self.materials.push(m);
        (self.materials.len() - 1) as u32
    }
    pub fn texture(&mut self, t: Texture) -> u32 {
        self.textures.push(t);
        (self.textures.len() - 1) as u32
    }
    /// Runs `f` with an extra transform applied to the geometry it adds.
    pub fn with_transform(&mut self, m: Mat4, f: impl FnOnce(&mut Self)) {
        let old = self.xf;
        self.xf = old * m;
        f(self);
        self.xf = old;
    }
    pub fn tri(&mut self, p: [Vec3; 3], uv: [Vec2; 3], mat: u32) {
        let q = p.map(|v| self.xf.transform_point3(v));
        self.sink.push(q, uv, mat);
    }
    /// Quad `o, o+u, o+u+v, o+v` (counter-clockwise seen from `u x v`), uv 0..uv_scale.
    pub fn quad(&mut self, o: Vec3, u: Vec3, v: Vec3, uv_scale: Vec2, mat: u32) {
        let (a, b, c, d) = (o, o + u, o + u + v, o + v);
        let (ta, tb, tc, td) = (Vec2::new(0.0, uv_scale.y), Vec2::new(uv_scale.x, uv_scale.y), Vec2::new(uv_scale.x, 0.0), Vec2::ZERO);
        self.tri([a, b, c], [ta, tb, tc], mat);
        self.tri([a, c, d], [ta, tc, td], mat);
    }
    /// Axis-aligned box from `min` to `max`, six outward faces.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3, mat: u32) {
        let s = max - min;
        let (x, y, z) = (Vec3::X * s.x, Vec3::Y * s.y, Vec3::Z * s.z);
        let one = Vec2::ONE;
        self.quad(min, y, x, one, mat); // -z
        self.quad(min + z, x, y, one, mat); // +z
        self.quad(min, z, y, one, mat); // -x
        self.quad(min + x, y, z, one, mat); // +x
        self.quad(min, x, z, one, mat); // -y
        self.quad(min + y, z, x, one, mat); // +y
    }
    /// Closed cylinder (prism with `segments` sides) between the centres `a` and `b`.
    pub fn cylinder(&mut self, a: Vec3, b: Vec3, radius: f32, segments: u32, mat: u32) {
        let axis = (b - a).normalize();
        let t = axis.any_orthonormal_vector();
        let s = axis.cross(t);
        let ring = |i: u32| {
            let ang = i as f32 / segments as f32 * std::f32::consts::TAU;
            (t * ang.cos() + s * ang.sin()) * radius
        };
        for i in 0..segments {
            let (r0, r1) = (ring(i), ring((i + 1) % segments));
            let (u0, u1) = (i as f32 / segments as f32, (i + 1) as f32 / segments as f32);
            self.tri([a + r0, a + r1, b + r1], [Vec2::new(u0, 1.0), Vec2::new(u1, 1.0), Vec2::new(u1, 0.0)], mat);
            self.tri([a + r0, b + r1, b + r0], [Vec2::new(u0, 1.0), Vec2::new(u1, 0.0), Vec2::new(u0, 0.0)], mat);
            self.tri([a, a + r1, a + r0], [Vec2::ZERO; 3], mat);
            self.tri([b, b + r0, b + r1], [Vec2::ZERO; 3], mat);
        }
    }
    pub fn finish(self, name: &str, camera: Camera, lights: Vec<Light>, camera_path: Vec<CameraKey>) -> Scene {
        let mut report: LoadReport = self.sink.report;
        if report.degenerate_triangles_skipped > 0 {
            report.warnings.push(format!("{} degenerate triangles skipped", report.degenerate_triangles_skipped));
        }
        Scene {
            name: name.into(),
            vertices: self.sink.vertices,
            materials: self.materials,
            textures: self.textures,
            camera,
            lights,
            camera_path,
            transform: Mat4::IDENTITY,
            animations: Vec::new(),
            report,
        }
    }
}

/// Deterministic hash-based noise in [0, 1) (no RNG crate needed for reproducible scenes).
pub fn hash01(seed: u32) -> f32 {
    let mut x = seed.wrapping_mul(0x9E37_79B9) ^ 0x85EB_CA6B;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7FEB_352D);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846C_A68B);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn every_builtin_builds_deterministically() {
        for s in BUILTIN_SCENES {
            let a = (s.build)();
            let b = (s.build)();
            assert!(a.triangle_count() > 10, "{} too small", s.name);
            assert_eq!(a.vertices, b.vertices, "{} not deterministic", s.name);
            assert!(!a.lights.is_empty() && a.camera.validate().is_ok(), "{}", s.name);
            assert!(a.camera_path.len() >= 2, "{} needs a camera path", s.name);
            assert!(a.vertices.iter().all(|v| (v.material as usize) < a.materials.len()));
            for l in &a.lights {
                l.validate().unwrap();
            }
            assert_eq!(a.report.degenerate_triangles_skipped, 0, "{}", s.name);
        }
    }
    #[test]
    fn cuboid_normals_point_outwards() {
        let mut b = MeshBuilder::default();
        let m = b.material(Material::solid("m", [1.0; 3]));
        b.cuboid(Vec3::ZERO, Vec3::ONE, m);
        let s = b.finish("t", Camera::new(Vec3::ONE * 3.0, Vec3::ZERO, 60.0, 0.1, 10.0), vec![], vec![]);
        assert_eq!(s.triangle_count(), 12);
        for i in 0..12 {
            let t = s.triangle(i);
            let c = (t[0] + t[1] + t[2]) / 3.0;
            assert!(Vec3::from(s.vertices[3 * i].normal).dot(c - Vec3::splat(0.5)) > 0.0);
        }
    }
}
