//! Cube shadow maps for point lights (seed 002 section 3.3.1), the CPU half: the six faces, which
//! face a direction from the light falls on, where on that face, and the seamless texel lookup
//! of a PCF tap that leaves its face (the tap's direction is re-projected onto the neighbour
//! face). `techniques/cube/eval.wgsl` implements the same rules; the tests here are the hand
//! cases both must satisfy.
//!
//! Face `f` looks along `FACES[f].n` with a 90 degree square frustum; a direction `d` with
//! `dot(d, n) > 0` hits its plane at `n + s u + t v` (s, t in [-1, 1] on the face). Map
//! coordinates are `x = (s + 1) / 2` (left to right) and `y = (1 - t) / 2` (top row first), as
//! `sm` stores its maps. The view matrix of a face has rows `u`, `v`, `-n`, so the depth pass's
//! clip space and these coordinates agree.

use glam::{Mat4, Vec3};

use crate::camera::perspective;
use crate::scene::Vertex;

/// One cube face: the axis it looks along and its right / up vectors (right-handed: u x v = -n
/// as in a right-handed camera looking along -z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    pub n: Vec3,
    pub u: Vec3,
    pub v: Vec3,
    pub name: &'static str,
}

/// +X, -X, +Y, -Y, +Z, -Z.
pub const FACES: [Face; 6] = [
    Face { n: Vec3::X, u: Vec3::Z, v: Vec3::Y, name: "+x" },
    Face { n: Vec3::NEG_X, u: Vec3::NEG_Z, v: Vec3::Y, name: "-x" },
    Face { n: Vec3::Y, u: Vec3::X, v: Vec3::Z, name: "+y" },
    Face { n: Vec3::NEG_Y, u: Vec3::X, v: Vec3::NEG_Z, name: "-y" },
    Face { n: Vec3::Z, u: Vec3::NEG_X, v: Vec3::Y, name: "+z" },
    Face { n: Vec3::NEG_Z, u: Vec3::X, v: Vec3::Y, name: "-z" },
];

/// The face a direction from the light falls on: the axis of largest |component|; ties go to
/// x before y before z (so every direction has exactly one face, also on edges and corners).
pub fn face_of(d: Vec3) -> usize {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        if d.x >= 0.0 {
            0
        } else {
            1
        }
    } else if a.y >= a.z {
        if d.y >= 0.0 {
            2
        } else {
            3
        }
    } else if d.z >= 0.0 {
        4
    } else {
        5
    }
}

/// Map coordinates (x, y) of direction `d` on face `f` (in [0, 1] when `f == face_of(d)`;
/// outside [0, 1] for directions beyond the face's edges). `d` must have `dot(d, n) > 0`.
pub fn project(f: usize, d: Vec3) -> [f32; 2] {
    let fc = &FACES[f];
    let z = d.dot(fc.n);
    let (s, t) = (d.dot(fc.u) / z, d.dot(fc.v) / z);
    [(s + 1.0) * 0.5, (1.0 - t) * 0.5]
}

/// The direction through map position (x, y) of face `f` (inverse of [`project`], unnormalised;
/// positions outside [0, 1] give directions beyond the edges, into the neighbour faces).
pub fn direction(f: usize, x: f32, y: f32) -> Vec3 {
    let fc = &FACES[f];
    fc.n + fc.u * (2.0 * x - 1.0) + fc.v * (1.0 - 2.0 * y)
}

/// The texel (face, column, row) a PCF tap reads: the tap at map position (x, y) of face `f`
/// (possibly outside the face) is turned back into a direction and looked up on the face that
/// direction falls on, so a kernel crossing an edge samples the neighbour face (seamless).
pub fn tap_texel(f: usize, x: f32, y: f32, res: u32) -> (usize, u32, u32) {
    let d = direction(f, x, y);
    let g = face_of(d);
    let [gx, gy] = project(g, d);
    let texel = |c: f32| ((c * res as f32).floor().max(0.0) as u32).min(res - 1);
    (g, texel(gx), texel(gy))
}

/// The view of face `f` from `light`: rows u, v, -n (a right-handed camera looking along n).
pub fn face_view(light: Vec3, f: usize) -> Mat4 {
    let fc = &FACES[f];
    let r = Mat4::from_cols(fc.u.extend(0.0), fc.v.extend(0.0), (-fc.n).extend(0.0), glam::Vec4::W).transpose();
    r * Mat4::from_translation(-light)
}

/// View-projection of face `f`: the face view and a 90 degree square perspective (0..1 depth),
/// whose clip space gives the map coordinates of [`project`].
pub fn face_view_proj(light: Vec3, f: usize, near: f32, far: f32) -> Mat4 {
    perspective(std::f32::consts::FRAC_PI_2, 1.0, near, far) * face_view(light, f)
}

/// World size of one texel of a `res` face at a point `d` from the light on face `f` (the
/// face's plane at depth dot(d, n) is 2 dot(d, n) wide): the unit of the bias on every face.
pub fn texel_size(f: usize, d: Vec3, res: u32) -> f32 {
    2.0 * d.dot(FACES[f].n) / res as f32
}

/// Whether the triangle `tri` lies wholly outside one side plane of face `f`'s 90-degree
/// frustum from `light` (all three corners beyond it): it draws nothing into that face. The same
/// test as cube/depth.wgsl's vertex stage, made conservative (a relative margin of 1e-4 in
/// f64), so that a triangle kept by the GPU's f32 test is never dropped here. The cube map's
/// per-face triangle lists are built with it once for the static geometry.
pub fn outside_face(tri: &[Vec3; 3], light: Vec3, f: usize) -> bool {
    let face = FACES[f];
    let (n, u, v) = (face.n.as_dvec3(), face.u.as_dvec3(), face.v.as_dvec3());
    let mut outside = [true; 4];
    for p in tri {
        let d = (*p - light).as_dvec3();
        let (z, s, t) = (d.dot(n), d.dot(u), d.dot(v));
        let beyond = |a: f64| a - z > 1e-4 * (a.abs() + z.abs()) + 1e-30;
        let sides = [beyond(s), beyond(-s), beyond(t), beyond(-t)];
        for k in 0..4 {
            outside[k] &= sides[k];
        }
    }
    outside.iter().any(|o| *o)
}

/// Clips a triangle to face `f`'s frustum from `light`: in front of the plane at distance
/// `near` along the axis, and inside the square of half-width `tan_half` (1 = exactly 90
/// degrees; a little more keeps clipped edges outside the map). The part inside comes back as
/// a fan of triangles (none when the triangle misses the frustum); positions and texture
/// coordinates are interpolated, normal and material kept. Warped maps need this: their
/// per-vertex warp is undefined for vertices behind the light (w <= 0), which every big wall
/// of a room around a point light has.
pub fn clip_to_face(tri: &[Vertex; 3], light: Vec3, f: usize, near: f32, tan_half: f32) -> Vec<[Vertex; 3]> {
    let fc = &FACES[f];
    let planes = [fc.n * tan_half - fc.u, fc.n * tan_half + fc.u, fc.n * tan_half - fc.v, fc.n * tan_half + fc.v];
    let dist = |k: usize, v: &Vertex| {
        let d = Vec3::from(v.pos) - light;
        if k == 4 {
            d.dot(fc.n) - near
        } else {
            d.dot(planes[k])
        }
    };
    let mut poly: Vec<Vertex> = tri.to_vec();
    for k in 0..5 {
        let mut out = Vec::with_capacity(poly.len() + 1);
        for i in 0..poly.len() {
            let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
            let (da, db) = (dist(k, a), dist(k, b));
            if da >= 0.0 {
                out.push(*a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let t = da / (da - db);
                let lerp = |x: &[f32], y: &[f32], i: usize| x[i] + (y[i] - x[i]) * t;
                let mut v = *a;
                v.pos = std::array::from_fn(|i| lerp(&a.pos, &b.pos, i));
                v.uv = std::array::from_fn(|i| lerp(&a.uv, &b.uv, i));
                out.push(v);
            }
        }
        poly = out;
        if poly.len() < 3 {
            return Vec::new();
        }
    }
    (1..poly.len() - 1).map(|i| [poly[0], poly[i], poly[i + 1]]).collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn outside_face_drops_only_triangles_wholly_beyond_one_side() {
        let l = Vec3::ZERO;
        // face +x looks along +x; its side planes are |z| = x and |y| = x
        let inside = [Vec3::new(2.0, 0.1, 0.1), Vec3::new(2.0, -0.1, 0.2), Vec3::new(2.5, 0.0, -0.2)];
        assert!(!outside_face(&inside, l, 0));
        let beyond_z = [Vec3::new(1.0, 0.0, 2.0), Vec3::new(1.0, 0.5, 3.0), Vec3::new(0.5, -0.5, 2.5)];
        assert!(outside_face(&beyond_z, l, 0));
        // a triangle across the side plane (corners on both sides) is kept
        let across = [Vec3::new(1.0, 0.0, 2.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 3.0)];
        assert!(!outside_face(&across, l, 0));
        // corners exactly on the plane are kept (the margin is conservative)
        let on = [Vec3::new(1.0, 0.0, 1.0), Vec3::new(2.0, 0.0, 2.0), Vec3::new(3.0, 0.1, 3.0)];
        assert!(!outside_face(&on, l, 0));
        // behind the light: beyond every side at once
        let behind = [Vec3::new(-1.0, 0.0, 0.0), Vec3::new(-2.0, 0.1, 0.0), Vec3::new(-1.5, 0.0, 0.1)];
        assert!(outside_face(&behind, l, 0));
        // each triangle lands in at least one face
        for tri in [inside, beyond_z, across, on, behind] {
            assert!((0..6).any(|f| !outside_face(&tri, l, f)));
        }
    }

    use super::*;
    use glam::Vec4Swizzles;

    #[test]
    fn faces_are_right_handed_and_orthonormal() {
        for fc in FACES {
            assert_eq!(fc.u.cross(fc.v), -fc.n, "{}", fc.name);
            assert!(fc.u.dot(fc.n) == 0.0 && fc.v.dot(fc.n) == 0.0);
        }
        // the six axes are all different
        for (a, fa) in FACES.iter().enumerate() {
            for (b, fb) in FACES.iter().enumerate() {
                assert_eq!(fa.n == fb.n, a == b);
            }
        }
    }

    #[test]
    fn face_selection_by_hand() {
        assert_eq!(face_of(Vec3::new(1.0, 0.2, -0.3)), 0);
        assert_eq!(face_of(Vec3::new(-2.0, 1.9, 0.0)), 1);
        assert_eq!(face_of(Vec3::new(0.1, 0.5, 0.2)), 2);
        assert_eq!(face_of(Vec3::new(0.0, -1.0, 0.0)), 3);
        assert_eq!(face_of(Vec3::new(0.3, -0.3, 0.31)), 4);
        assert_eq!(face_of(Vec3::new(0.0, 0.0, -5.0)), 5);
        // ties: x before y before z
        assert_eq!(face_of(Vec3::new(1.0, 1.0, 1.0)), 0);
        assert_eq!(face_of(Vec3::new(-1.0, 1.0, 0.0)), 1);
        assert_eq!(face_of(Vec3::new(0.0, -1.0, 1.0)), 3);
        // every axis direction lands in the centre of its own face
        for (f, fc) in FACES.iter().enumerate() {
            assert_eq!(face_of(fc.n), f);
            assert_eq!(project(f, fc.n * 3.0), [0.5, 0.5]);
        }
    }

    #[test]
    fn projection_by_hand_and_inverse() {
        // +x face: u = +z (right), v = +y (up): a direction towards -z and up is left and top
        assert_eq!(project(0, Vec3::new(1.0, 0.5, -0.5)), [0.25, 0.25]);
        // -y face (looking down): u = +x, v = -z; -x is left, +z is down (bottom rows)
        assert_eq!(project(3, Vec3::new(-1.0, -2.0, 1.0)), [0.25, 0.75]);
        for f in 0..6 {
            for &(x, y) in &[(0.1, 0.9), (0.5, 0.5), (0.99, 0.01), (1.3, 0.4)] {
                let [px, py] = project(f, direction(f, x, y) * 2.5);
                assert!((px - x).abs() < 1e-6 && (py - y).abs() < 1e-6, "face {f}");
            }
        }
    }

    #[test]
    fn face_view_proj_agrees_with_project() {
        let light = Vec3::new(1.0, 2.0, -3.0);
        for f in 0..6 {
            let m = face_view_proj(light, f, 0.01, 100.0);
            for &(x, y) in &[(0.2, 0.7), (0.5, 0.5), (0.9, 0.1)] {
                let p = light + direction(f, x, y) * 4.0;
                let c = m * p.extend(1.0);
                let ndc = c.xyz() / c.w;
                let (mx, my) = (ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
                assert!((mx - x).abs() < 1e-5 && (my - y).abs() < 1e-5, "face {f}: {mx} {my} vs {x} {y}");
                assert!(ndc.z > 0.0 && ndc.z < 1.0);
            }
        }
    }

    #[test]
    fn taps_inside_a_face_stay_on_it() {
        let res = 8;
        assert_eq!(tap_texel(0, 0.5 / 8.0, 0.5 / 8.0, res), (0, 0, 0));
        assert_eq!(tap_texel(2, 7.5 / 8.0, 3.5 / 8.0, res), (2, 7, 3));
        assert_eq!(tap_texel(5, 0.5, 0.5, res), (5, 4, 4));
    }

    #[test]
    fn seam_taps_sample_the_neighbour_face() {
        let res = 8;
        // +x face, half a texel right of its right edge (x > 1): u = +z, so the tap's direction
        // turns towards +z and lands on the +z face at that face's left column (+z: u = -x),
        // at the same height: +x row 3 (t = 0.125) is +z's row 3.
        assert_eq!(tap_texel(0, 1.0 + 0.5 / 8.0, 3.5 / 8.0, res), (4, 0, 3));
        // +x face, left of its left edge: towards -z, onto -z's right column (-z: u = +x)
        assert_eq!(tap_texel(0, -0.5 / 8.0, 4.5 / 8.0, res), (5, 7, 4));
        // +x face above its top edge (y < 0): towards +y, onto +y's right column (+y: u = +x);
        // +x column 2 is at z = 2 x 2.5/8 - 1 = -0.375, on +y (v = +z) below the middle:
        // row (1 + 0.375 / 1.125) / 2 x 8 = 5.33 -> 5
        assert_eq!(tap_texel(0, 2.5 / 8.0, -0.5 / 8.0, res), (2, 7, 5));
        // -y face (looking down) below its bottom edge (y > 1): v = -z, so towards +z: onto
        // +z's bottom row
        let (g, _, cy) = tap_texel(3, 0.5, 1.0 + 0.5 / 8.0, res);
        assert_eq!((g, cy), (4, 7));
        // a diagonal step off a corner lands on one of the three faces sharing the corner
        let (g, _, _) = tap_texel(0, 1.0 + 0.5 / 8.0, -0.5 / 8.0, res);
        assert!([0, 2, 4].contains(&g), "{g}");
    }

    #[test]
    fn seam_texels_are_neighbours_in_world_space() {
        // the texel a seam tap reads is the nearest texel of the neighbour face: its centre's
        // direction is within ~1.5 texels of the tap's direction, on every edge of every face
        let res = 64;
        let step = 2.0 / res as f32;
        for f in 0..6 {
            for k in 0..res {
                let a = (k as f32 + 0.5) / res as f32;
                for (x, y) in [(1.0 + 0.5 / res as f32, a), (-0.5 / res as f32, a), (a, -0.5 / res as f32), (a, 1.0 + 0.5 / res as f32)] {
                    let d = direction(f, x, y).normalize();
                    let (g, cx, cy) = tap_texel(f, x, y, res);
                    assert_ne!(g, f);
                    let c = direction(g, (cx as f32 + 0.5) / res as f32, (cy as f32 + 0.5) / res as f32).normalize();
                    assert!(d.angle_between(c) < 1.5 * step, "face {f} tap ({x}, {y}) -> {g} ({cx}, {cy})");
                }
            }
        }
    }

    #[test]
    fn texel_size_is_continuous_across_seams() {
        // at an edge between +x and +y (|d.x| == |d.y|) both faces' texels are equally large
        let d = Vec3::new(2.0, 2.0, 0.5);
        assert_eq!(texel_size(0, d, 512), texel_size(2, d, 512));
        assert_eq!(texel_size(0, Vec3::new(3.0, 0.0, 0.0), 300), 0.02);
    }

    fn vert(p: [f32; 3], uv: [f32; 2]) -> Vertex {
        Vertex { pos: p, uv, material: 7, ..Default::default() }
    }

    fn area(t: &[Vertex; 3]) -> f32 {
        let p = t.map(|v| Vec3::from(v.pos));
        (p[1] - p[0]).cross(p[2] - p[0]).length() * 0.5
    }

    #[test]
    fn clipping_by_hand() {
        let l = Vec3::ZERO;
        // inside +x's frustum: unchanged
        let t = [vert([2.0, 0.0, 0.0], [0.0, 0.0]), vert([2.0, 1.0, 0.0], [1.0, 0.0]), vert([2.0, 0.0, 1.0], [0.0, 1.0])];
        assert_eq!(clip_to_face(&t, l, 0, 0.01, 1.0), vec![t]);
        // behind the light (for +x) or outside a side plane: nothing
        let back = t.map(|mut v| {
            v.pos[0] = -2.0;
            v
        });
        assert!(clip_to_face(&back, l, 0, 0.01, 1.0).is_empty());
        assert!(clip_to_face(&t, l, 2, 0.01, 1.0).is_empty());
        // a wall x = 1 from y = -5..5, z = -5..5 (two triangles) clipped to +x: the square
        // |y|, |z| <= 1 (area 4), texture coordinates interpolated linearly in position
        let q = [[1.0, -5.0, -5.0], [1.0, 5.0, -5.0], [1.0, 5.0, 5.0], [1.0, -5.0, 5.0]];
        let v = |i: usize| vert(q[i], [(q[i][1] + 5.0) / 10.0, (q[i][2] + 5.0) / 10.0]);
        let mut total = 0.0;
        for tri in [[v(0), v(1), v(2)], [v(0), v(2), v(3)]] {
            for c in clip_to_face(&tri, l, 0, 0.01, 1.0) {
                total += area(&c);
                for p in c {
                    assert!(p.pos[1].abs() <= 1.0 + 1e-5 && p.pos[2].abs() <= 1.0 + 1e-5, "{:?}", p.pos);
                    assert!((p.uv[0] - (p.pos[1] + 5.0) / 10.0).abs() < 1e-5 && (p.uv[1] - (p.pos[2] + 5.0) / 10.0).abs() < 1e-5);
                    assert_eq!(p.material, 7);
                }
            }
        }
        assert!((total - 4.0).abs() < 1e-4, "{total}");
        // a floor triangle under the light crossing behind it (y = -1, x from -3 to 3): the +x
        // part keeps x >= near and |z| <= x, |y| = 1 <= x
        let floor = [vert([-3.0, -1.0, -3.0], [0.0; 2]), vert([3.0, -1.0, -3.0], [0.0; 2]), vert([0.0, -1.0, 3.0], [0.0; 2])];
        let c = clip_to_face(&floor, l, 0, 0.01, 1.0);
        assert!(!c.is_empty());
        for p in c.iter().flatten() {
            assert!(p.pos[0] >= 1.0 - 1e-5 && p.pos[2].abs() <= p.pos[0] + 1e-5, "{:?}", p.pos);
        }
    }
}
