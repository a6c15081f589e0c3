//! The scene model every stage reads: de-indexed triangles with flat geometric normals,
//! materials with optional alpha cut-out, RGBA8 textures, a default camera, lights and a path.
//!
//! Triangles are stored as three consecutive [`Vertex`] records (no index buffer): triangle `i`
//! is `vertices[3i..3i+3]`. This keeps the geometric normal exact per triangle (the G-buffer and
//! the reference tracer both use it) and lets the GPU read triangles straight from the vertex buffer.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec2, Vec3};
use serde::{Deserialize, Serialize};

use crate::camera::{Camera, CameraKey};
use crate::light::Light;

/// One vertex as the GPU sees it (vertex buffer and storage buffer alike). 48 bytes.
/// WGSL: `struct Vertex { pos: vec3<f32>, material: u32, normal: vec3<f32>, _pad0: f32, uv: vec2<f32>, _pad1: vec2<f32> }`
/// (the layout is checked against naga's reflection in shadowlab-gpu's tests).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    pub pos: [f32; 3],
    pub material: u32,
    /// Geometric (face) normal of the triangle, unit length.
    pub normal: [f32; 3],
    pub _pad0: f32,
    /// Texture coordinates with the origin at the image's top-left (glTF convention; OBJ is flipped on load).
    pub uv: [f32; 2],
    pub _pad1: [f32; 2],
}

/// RGBA8 texture, row-major from the top-left.
#[derive(Clone, Debug)]
pub struct Texture {
    pub name: String,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

impl Texture {
    /// Nearest-neighbour lookup with repeat wrapping; the same rule as `texel_index` in `scene.wgsl`.
    pub fn texel_index(&self, uv: Vec2) -> usize {
        texel_index(self.width, self.height, uv)
    }
    pub fn alpha_at(&self, uv: Vec2) -> u8 {
        self.rgba[self.texel_index(uv) * 4 + 3]
    }
}

/// Nearest texel with repeat wrapping. Kept tiny and shared so that CPU and GPU cut-outs match.
pub fn texel_index(width: u32, height: u32, uv: Vec2) -> usize {
    let u = uv.x - uv.x.floor();
    let v = uv.y - uv.y.floor();
    let x = ((u * width as f32) as u32).min(width - 1);
    let y = ((v * height as f32) as u32).min(height - 1);
    (y * width + x) as usize
}

#[derive(Clone, Debug, Serialize)]
pub struct Material {
    pub name: String,
    /// Linear base colour; alpha multiplies the texture's alpha.
    pub base_color: [f32; 4],
    pub texture: Option<u32>,
    /// `Some(cutoff)`: alpha-tested (cut-out): texels with alpha < cutoff neither show nor cast shadows.
    pub alpha_cutoff: Option<f32>,
    pub double_sided: bool,
}

impl Material {
    pub fn solid(name: &str, rgb: [f32; 3]) -> Self {
        Material { name: name.into(), base_color: [rgb[0], rgb[1], rgb[2], 1.0], texture: None, alpha_cutoff: None, double_sided: true }
    }
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Bounds {
    pub min: Vec3,
    pub max: Vec3,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };
    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }
    pub fn diagonal(&self) -> f32 {
        (self.max - self.min).length()
    }
    pub fn corners(&self) -> [Vec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            Vec3::new(a.x, a.y, a.z),
            Vec3::new(b.x, a.y, a.z),
            Vec3::new(a.x, b.y, a.z),
            Vec3::new(b.x, b.y, a.z),
            Vec3::new(a.x, a.y, b.z),
            Vec3::new(b.x, a.y, b.z),
            Vec3::new(a.x, b.y, b.z),
            Vec3::new(b.x, b.y, b.z),
        ]
    }
    pub fn is_valid(&self) -> bool {
        self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z
    }
}

/// Counts of what a loader dropped or patched, reported with the scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct LoadReport {
    pub degenerate_triangles_skipped: usize,
    pub nan_triangles_skipped: usize,
    pub warnings: Vec<String>,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub vertices: Vec<Vertex>,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub camera: Camera,
    pub lights: Vec<Light>,
    /// Short camera path (keyframes) for temporal work; may be empty for loaded scenes.
    pub camera_path: Vec<CameraKey>,
    /// The user's transform applied on load (up axis, scale, offset), row-major in the outputs.
    pub transform: Mat4,
    pub report: LoadReport,
    /// Moving objects (see `anim.rs`): each owns a contiguous triangle range, together the last
    /// triangles of `vertices` (`dynamic_first()..triangle_count()`); `vertices` hold t = 0.
    pub animations: Vec<crate::motion::Animation>,
}

impl Scene {
    pub fn triangle_count(&self) -> usize {
        self.vertices.len() / 3
    }
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let v = &self.vertices[3 * i..3 * i + 3];
        [Vec3::from(v[0].pos), Vec3::from(v[1].pos), Vec3::from(v[2].pos)]
    }
    pub fn bounds(&self) -> Bounds {
        let mut b = Bounds::EMPTY;
        for v in &self.vertices {
            b.grow(Vec3::from(v.pos));
        }
        b
    }
    /// Ray-origin offset used by the reference tracer: a small fraction of the scene's size.
    pub fn ray_epsilon(&self) -> f32 {
        (self.bounds().diagonal() * 2e-5).max(1e-6)
    }
    /// Whether any material is alpha-tested (shadow techniques must honour cut-outs).
    pub fn has_cutouts(&self) -> bool {
        self.materials.iter().any(|m| m.alpha_cutoff.is_some())
    }
}

/// Builds de-indexed triangles with flat normals, dropping NaN and degenerate ones (counted).
#[derive(Default)]
pub struct TriangleSink {
    pub vertices: Vec<Vertex>,
    pub report: LoadReport,
}

impl TriangleSink {
    /// Adds one triangle; returns false (and counts it) when it is NaN/infinite or has (near) zero area.
    pub fn push(&mut self, p: [Vec3; 3], uv: [Vec2; 3], material: u32) -> bool {
        if p.iter().any(|v| !v.is_finite()) || uv.iter().any(|t| !t.is_finite()) {
            self.report.nan_triangles_skipped += 1;
            return false;
        }
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let scale = (p[1] - p[0]).length_squared().max((p[2] - p[0]).length_squared());
        let area2 = n.length_squared();
        let n = if area2 == 0.0 {
            None
        } else if area2.is_finite() && (scale * scale).is_finite() && area2 >= f32::MIN_POSITIVE {
            (area2 > scale * scale * 1e-14).then(|| n.normalize())
        } else {
            // products that leave f32's normal range (edges beyond about 1e9, or below about
            // 1e-10, where normalising a subnormal vector is inexact): the same test in f64
            // (every ordinary triangle takes the f32 path above, bit for bit)
            let q = p.map(|v| v.as_dvec3());
            let n = (q[1] - q[0]).cross(q[2] - q[0]);
            let scale = (q[1] - q[0]).length_squared().max((q[2] - q[0]).length_squared());
            let area2 = n.length_squared();
            (area2 > scale * scale * 1e-14).then(|| n.normalize().as_vec3())
        };
        let Some(n) = n.filter(|n| n.is_finite() && (n.length() - 1.0).abs() < 1e-4) else {
            self.report.degenerate_triangles_skipped += 1;
            return false;
        };
        for k in 0..3 {
            self.vertices.push(Vertex { pos: p[k].into(), material, normal: n.into(), _pad0: 0.0, uv: uv[k].into(), _pad1: [0.0; 2] });
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sink_skips_degenerate_and_nan() {
        let mut s = TriangleSink::default();
        let z = [Vec2::ZERO; 3];
        assert!(s.push([Vec3::ZERO, Vec3::X, Vec3::Y], z, 0));
        assert!(!s.push([Vec3::ZERO, Vec3::X, Vec3::X * 2.0], z, 0));
        assert!(!s.push([Vec3::ZERO, Vec3::X, Vec3::new(f32::NAN, 0.0, 0.0)], z, 0));
        assert_eq!(s.vertices.len(), 3);
        assert_eq!(s.report.degenerate_triangles_skipped, 1);
        assert_eq!(s.report.nan_triangles_skipped, 1);
        assert_eq!(Vec3::from(s.vertices[0].normal), Vec3::Z);
    }

    #[test]
    fn huge_coordinates_get_a_unit_normal_or_are_skipped() {
        // found by the glTF fuzz target: products beyond f32's range gave NaN normals
        let mut s = TriangleSink::default();
        let z = [Vec2::ZERO; 3];
        let big = 3e38;
        assert!(s.push([Vec3::new(-big, 0.0, 0.0), Vec3::new(big, 0.0, 0.0), Vec3::new(0.0, big, 0.0)], z, 0));
        assert!(s.push([Vec3::ZERO, Vec3::X * 1e20, Vec3::Y * 1e20], z, 0));
        for v in &s.vertices {
            assert!((Vec3::from(v.normal) - Vec3::Z).length() < 1e-6, "{:?}", v.normal);
        }
        assert!(!s.push([Vec3::ZERO, Vec3::X * 1e20, Vec3::X * 2e20], z, 0), "collinear");
        assert_eq!(s.report.degenerate_triangles_skipped, 1);
        // tiny: the cross product's square is subnormal in f32 (normalising gave a length of 1.15)
        assert!(s.push([Vec3::ZERO, Vec3::X * 1e-10, Vec3::new(3e-11, 3e-10, 0.0)], z, 0));
        assert!((Vec3::from(s.vertices.last().unwrap().normal) - Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn texel_index_wraps() {
        assert_eq!(texel_index(4, 2, Vec2::new(0.0, 0.0)), 0);
        assert_eq!(texel_index(4, 2, Vec2::new(0.99, 0.99)), 7);
        assert_eq!(texel_index(4, 2, Vec2::new(1.25, 0.0)), 1);
        assert_eq!(texel_index(4, 2, Vec2::new(-0.25, 0.6)), 7);
    }
}
