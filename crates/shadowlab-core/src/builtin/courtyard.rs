//! `courtyard` (the default scene): a Sponza-like atrium. An open court 30 m x 14 m between two
//! storeys of arcades (columns, semicircular arches, an upper gallery with a balustrade and thin
//! hanging banners), 3 m deep loggias behind them closed by outer walls, a closed end behind the
//! camera and a single-storey open arcade at the far end onto a garden. No roof anywhere.
//!
//! The camera stands at the +x end at head height and looks down the length: the near floor is
//! large on screen, the far end small (perspective aliasing). The sun is low (18 degrees) and
//! comes from the far end towards the viewer, where a plain shadow map is worst off. Shadows in
//! view: the far arcade's arches stretched ~3x along the floor, the -z upper arcade, balustrade
//! and banners as long streaks across the court, the fountain, and the -z building's long edge.
//! Moving objects ([`animations`]): the banners swing about their rods.

use std::f32::consts::PI;

use glam::{Mat4, Vec2, Vec3};

use super::{hash01, MeshBuilder};
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene};

/// The court spans x in [-HALF_LEN, HALF_LEN] between the arcade lines z = +-COURT_Z.
const HALF_LEN: f32 = 15.0;
const COURT_Z: f32 = 7.0;
/// Inner face of the outer walls (loggias 3 m deep), wall thickness and height.
const OUTER_Z: f32 = 10.0;
const WALL_T: f32 = 0.4;
const WALL_TOP: f32 = 9.9;
/// Column spacing: 8 bays along each long side, 4 across the far end.
const SIDE_BAY: f32 = 3.75;
const END_BAY: f32 = 3.5;
const COLUMN_SEGMENTS: u32 = 16;
/// Boxes per semicircular arch.
const ARCH_SEGMENTS: u32 = 12;
/// Sun: elevation above the horizon and azimuth off the +x axis (towards +z), in degrees.
const SUN_ELEVATION_DEG: f32 = 18.0;
const SUN_AZIMUTH_DEG: f32 = 14.0;
/// Banner thickness (thin occluders): 2 cm.
const BANNER_T: f32 = 0.02;

/// One storey of an arcade: columns from `base` to the arch spring line, wall up to `top`.
struct Storey {
    base: f32,
    col_r: f32,
    spring: f32,
    top: f32,
    depth: f32,
}

const GROUND: Storey = Storey { base: 0.0, col_r: 0.3, spring: 3.3, top: 5.0, depth: 0.5 };
/// Gallery floor slab from GROUND.top to UPPER.base.
const UPPER: Storey = Storey { base: 5.3, col_r: 0.22, spring: 7.7, top: 9.6, depth: 0.4 };

struct Mats {
    stone: u32,
    column: u32,
}

/// Where the sunlight travels (pointing down): low, from the far (-x) end, slightly from -z.
pub fn sun_direction() -> Vec3 {
    let (e, a) = (SUN_ELEVATION_DEG.to_radians(), SUN_AZIMUTH_DEG.to_radians());
    Vec3::new(e.cos() * a.cos(), -e.sin(), e.cos() * a.sin())
}

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let m = Mats {
        stone: b.material(Material::solid("arcade stone", [0.78, 0.72, 0.62])),
        column: b.material(Material::solid("column marble", [0.86, 0.83, 0.77])),
    };
    let floor = b.material(Material::solid("floor paving", [0.62, 0.56, 0.49]));
    let plaster = b.material(Material::solid("wall plaster", [0.80, 0.64, 0.48]));
    let grass = b.material(Material::solid("garden grass", [0.32, 0.46, 0.21]));
    let hedge = b.material(Material::solid("hedge", [0.16, 0.30, 0.12]));
    let banners =
        [b.material(Material::solid("banner red", [0.62, 0.09, 0.08])), b.material(Material::solid("banner blue", [0.10, 0.22, 0.55]))];
    let bronze = b.material(Material::solid("bronze", [0.45, 0.33, 0.16]));
    let water = b.material(Material::solid("water", [0.20, 0.36, 0.42]));

    // Floor, outer walls, the closed end behind the camera.
    let (x0, x1) = (-HALF_LEN - 0.8, HALF_LEN + 0.9);
    let zo = OUTER_Z + WALL_T;
    b.cuboid(Vec3::new(x0, -0.2, -zo), Vec3::new(x1, 0.0, zo), floor);
    // A small garden closed by a hedge that hides the horizon (keeps the scene bounds tight).
    b.cuboid(Vec3::new(-31.0, -0.2, -16.0), Vec3::new(x0, 0.0, 16.0), grass);
    b.cuboid(Vec3::new(-31.0, 0.0, -16.0), Vec3::new(-30.0, 2.2, 16.0), hedge);
    for s in [-1.0f32, 1.0] {
        let (za, zb) = (s * OUTER_Z, s * zo);
        b.cuboid(Vec3::new(x0, 0.0, za.min(zb)), Vec3::new(x1, WALL_TOP, za.max(zb)), plaster);
        // Far-end wall closing the ground loggia, the gallery floor slab, and a balustrade where
        // the gallery ends open towards the garden (so the low sun reaches into the court).
        let (zc, zd) = (s * (COURT_Z - GROUND.depth / 2.0), s * OUTER_Z);
        let (zmin, zmax) = (zc.min(zd), zc.max(zd));
        b.cuboid(Vec3::new(x0, 0.0, zmin), Vec3::new(-HALF_LEN - 0.3, GROUND.top, zmax), plaster);
        b.cuboid(Vec3::new(x0, GROUND.top, zmin), Vec3::new(HALF_LEN + 0.4, UPPER.base, zmax), m.stone);
        b.cuboid(Vec3::new(-HALF_LEN - 0.3, UPPER.base, zmin), Vec3::new(-HALF_LEN - 0.06, UPPER.base + 0.95, zmax), m.stone);
    }
    b.cuboid(Vec3::new(HALF_LEN + 0.4, 0.0, -zo), Vec3::new(x1, WALL_TOP, zo), plaster);

    // Two storeys of arcades along both long sides (local row along +x, centred on the arcade line).
    for s in [-1.0f32, 1.0] {
        let at = Mat4::from_translation(Vec3::new(-HALF_LEN, 0.0, s * COURT_Z));
        b.with_transform(at, |b| {
            arcade(b, &GROUND, 8, SIDE_BAY, true, &m);
            arcade(b, &UPPER, 8, SIDE_BAY, true, &m);
            // Balustrade along the upper gallery.
            b.cuboid(Vec3::new(0.0, UPPER.base, -0.12), Vec3::new(8.0 * SIDE_BAY, UPPER.base + 0.95, 0.12), m.stone);
        });
    }
    // Single-storey open arcade across the far end (row along +z; corner columns already exist).
    let far = Mat4::from_translation(Vec3::new(-HALF_LEN, 0.0, -COURT_Z)) * Mat4::from_rotation_y(-PI / 2.0);
    b.with_transform(far, |b| arcade(b, &GROUND, 4, END_BAY, false, &m));

    // Banners hanging from rods in front of the upper arcade, every other bay on both sides.
    for (i, s) in [-1.0f32, 1.0].into_iter().enumerate() {
        for k in (0..8).filter(|k| k % 2 == 1) {
            let cx = -HALF_LEN + (k as f32 + 0.5) * SIDE_BAY;
            let z = s * (COURT_Z - 0.45);
            let bottom = 6.5 + 0.5 * hash01(100 + 10 * i as u32 + k);
            let mat = banners[(k as usize / 2 + i) % 2];
            b.cuboid(Vec3::new(cx - 0.75, bottom, z - BANNER_T / 2.0), Vec3::new(cx + 0.75, 9.4, z + BANNER_T / 2.0), mat);
            b.cylinder(Vec3::new(cx - 0.85, 9.45, z), Vec3::new(cx + 0.85, 9.45, z), 0.025, 8, bronze);
            for dx in [-0.8, 0.8] {
                let wall = s * (COURT_Z - UPPER.depth / 2.0);
                b.cuboid(Vec3::new(cx + dx - 0.02, 9.43, z.min(wall)), Vec3::new(cx + dx + 0.02, 9.47, z.max(wall)), bronze);
            }
        }
    }

    // Fountain in the sunlit half of the court: basin, water, pedestal, bowl, finial.
    let f = Vec3::new(-4.0, 0.0, 2.5);
    b.cylinder(f, f + Vec3::Y * 0.5, 1.8, 24, m.stone);
    b.cylinder(f + Vec3::Y * 0.5, f + Vec3::Y * 0.52, 1.6, 24, water);
    b.cylinder(f + Vec3::Y * 0.52, f + Vec3::Y * 1.6, 0.22, 12, m.column);
    b.cylinder(f + Vec3::Y * 1.6, f + Vec3::Y * 1.8, 0.7, 24, m.stone);
    b.cylinder(f + Vec3::Y * 1.8, f + Vec3::Y * 2.3, 0.08, 12, bronze);

    let cam = Camera::new(Vec3::new(13.6, 1.7, 1.0), Vec3::new(-15.0, 1.1, -0.5), 60.0, 0.1, 120.0);
    let path = (0..4)
        .map(|i| {
            let t = i as f32;
            CameraKey { position: Vec3::new(13.6 - 1.5 * t, 1.7 + 0.03 * (t * 2.1).sin(), 1.0 - 0.4 * t), target: cam.target }
        })
        .collect();
    let mut s = b.finish("courtyard", cam, vec![Light::Directional { direction: sun_direction() }], path);
    crate::anim::apply(&mut s, &animations()).expect("courtyard animations select their banners");
    s
}

/// Moving objects (time in frames): every banner swings about its rod (the x axis through the
/// rod), 6 to 9 degrees, with periods of 40 to 61 frames so that they do not move in step.
pub fn animations() -> Vec<crate::anim::AnimationSpec> {
    use crate::anim::{AnimationSpec, Motion};
    let mut v = Vec::new();
    for (i, s) in [-1.0f32, 1.0].into_iter().enumerate() {
        for k in (0..8).filter(|k| k % 2 == 1) {
            let cx = -HALF_LEN + (k as f32 + 0.5) * SIDE_BAY;
            let z = s * (COURT_Z - 0.45);
            let j = (4 * i as u32 + k) as f32;
            v.push(AnimationSpec {
                name: format!("banner {}{k}", if s < 0.0 { "north " } else { "south " }),
                materials: vec!["banner red".into(), "banner blue".into()],
                inside: Some([Vec3::new(cx - 0.8, 6.0, z - 0.2), Vec3::new(cx + 0.8, 9.5, z + 0.2)]),
                motion: Motion::Sway {
                    pivot: Vec3::new(cx, 9.45, z),
                    axis: Vec3::X,
                    amplitude_deg: 6.0 + 0.25 * j,
                    period: 40.0 + 3.0 * j,
                },
            });
        }
    }
    v
}

/// One storey of arcade in local coordinates: `bays` arches along +x from x = 0, centred on z = 0.
/// Each arch is a chain of closed prisms from the semicircular intrados up to the storey top, so
/// the arcade wall has real arched openings. `end_columns: false` leaves out the two end columns.
fn arcade(b: &mut MeshBuilder, s: &Storey, bays: u32, bay: f32, end_columns: bool, m: &Mats) {
    let hd = s.depth / 2.0;
    for k in 0..=bays {
        let x = k as f32 * bay;
        if end_columns || (k > 0 && k < bays) {
            let w = s.col_r + 0.08;
            b.cuboid(Vec3::new(x - w, s.base, -w), Vec3::new(x + w, s.base + 0.25, w), m.stone);
            b.cylinder(Vec3::new(x, s.base + 0.25, 0.0), Vec3::new(x, s.spring - 0.2, 0.0), s.col_r, COLUMN_SEGMENTS, m.column);
            b.cuboid(Vec3::new(x - w, s.spring - 0.2, -w), Vec3::new(x + w, s.spring, w), m.stone);
        }
        // Pier above the capital, between two arches.
        b.cuboid(Vec3::new(x - s.col_r, s.spring, -hd), Vec3::new(x + s.col_r, s.top, hd), m.stone);
    }
    let r = bay / 2.0 - s.col_r;
    for k in 0..bays {
        let cx = (k as f32 + 0.5) * bay;
        let pt = |i: u32| {
            let a = PI * (1.0 - i as f32 / ARCH_SEGMENTS as f32);
            Vec2::new(cx + r * a.cos(), s.spring + r * a.sin())
        };
        for i in 0..ARCH_SEGMENTS {
            let (p0, p1) = (pt(i), pt(i + 1));
            prism(b, [p0, p1, Vec2::new(p1.x, s.top), Vec2::new(p0.x, s.top)], -hd, hd, m.stone);
        }
    }
}

/// Closed prism: the quadrilateral `q` (counter-clockwise in the xy plane) extruded from z0 to z1.
fn prism(b: &mut MeshBuilder, q: [Vec2; 4], z0: f32, z1: f32, mat: u32) {
    let p = |v: Vec2, z: f32| Vec3::new(v.x, v.y, z);
    let uv = [Vec2::ZERO; 3];
    b.tri([p(q[0], z1), p(q[1], z1), p(q[2], z1)], uv, mat);
    b.tri([p(q[0], z1), p(q[2], z1), p(q[3], z1)], uv, mat);
    b.tri([p(q[0], z0), p(q[2], z0), p(q[1], z0)], uv, mat);
    b.tri([p(q[0], z0), p(q[3], z0), p(q[2], z0)], uv, mat);
    for i in 0..4 {
        let (a, c) = (q[i], q[(i + 1) % 4]);
        b.tri([p(a, z0), p(c, z0), p(c, z1)], uv, mat);
        b.tri([p(a, z0), p(c, z1), p(a, z1)], uv, mat);
    }
}

/// Test helpers shared with the other built-in scenes' tests (brute-force ray cast, closedness).
#[cfg(test)]
pub(super) mod tests {
    use std::collections::HashMap;

    use super::*;

    /// Nearest hit (distance, triangle) of the ray `o + t d`, brute force (Moller-Trumbore);
    /// cut-out texels of alpha-tested materials are skipped, as the renderers do.
    pub(in crate::builtin) fn first_hit(s: &Scene, o: Vec3, d: Vec3) -> Option<(f32, usize)> {
        let mut best: Option<(f32, usize)> = None;
        for i in 0..s.triangle_count() {
            let [a, b, c] = s.triangle(i);
            let (e1, e2) = (b - a, c - a);
            let p = d.cross(e2);
            let det = e1.dot(p);
            let (r, q) = (o - a, (o - a).cross(e1));
            let (u, v, t) = (r.dot(p) / det, d.dot(q) / det, e2.dot(q) / det);
            if det.abs() < 1e-12 || u < 0.0 || v < 0.0 || u + v > 1.0 || t <= 1e-4 || best.is_some_and(|(bt, _)| t >= bt) {
                continue;
            }
            let (m, uv) = (&s.materials[s.vertices[3 * i].material as usize], |k: usize| Vec2::from(s.vertices[3 * i + k].uv));
            if let (Some(cut), Some(tex)) = (m.alpha_cutoff, m.texture) {
                let at = uv(0) * (1.0 - u - v) + uv(1) * u + uv(2) * v;
                if (s.textures[tex as usize].alpha_at(at) as f32 / 255.0) < cut {
                    continue;
                }
            }
            best = Some((t, i));
        }
        best
    }

    /// Every edge of the selected triangles is shared by an even number of them (closed solids).
    /// Edges match exactly, or within 1e-5 m: `MeshBuilder::cylinder` closes its ring at angle
    /// TAU rather than 0, which leaves its seam a few ulps open.
    pub(in crate::builtin) fn assert_closed(s: &Scene, select: impl Fn(&str) -> bool) {
        let mut edges: HashMap<([u32; 3], [u32; 3]), u32> = HashMap::new();
        for i in (0..s.triangle_count()).filter(|&i| select(&s.materials[s.vertices[3 * i].material as usize].name)) {
            let t = s.triangle(i).map(|p| p.to_array().map(f32::to_bits));
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry(if a < b { (a, b) } else { (b, a) }).or_default() += 1;
            }
        }
        assert!(!edges.is_empty());
        let v = |a: [u32; 3]| Vec3::from_array(a.map(f32::from_bits));
        let mut open: Vec<(Vec3, Vec3)> = edges.iter().filter(|(_, &n)| n % 2 == 1).map(|(e, _)| (v(e.0), v(e.1))).collect();
        while let Some((a, b)) = open.pop() {
            let near = |p: Vec3, q: Vec3| p.distance(q) < 1e-5;
            let mate = open.iter().position(|&(c, d)| (near(a, c) && near(b, d)) || (near(a, d) && near(b, c)));
            assert!(mate.is_some(), "{}: open edge {a} {b}", s.name);
            open.swap_remove(mate.unwrap());
        }
    }

    #[test]
    fn all_geometry_is_closed_and_the_sun_grazes() {
        let s = build();
        assert_closed(&s, |_| true);
        let d = sun_direction();
        let elevation = (-d.y).asin().to_degrees();
        assert!((15.0..=20.0).contains(&elevation) && d.x > 0.0, "{elevation}");
        assert!((8_000..60_000).contains(&s.triangle_count()), "{}", s.triangle_count());
    }

    #[test]
    fn camera_path_walks_the_court_at_head_height() {
        let s = build();
        for k in s.camera_path.iter().chain([&CameraKey { position: s.camera.position, target: s.camera.target }]) {
            let p = k.position;
            assert!(p.x.abs() < HALF_LEN - 0.5 && p.z.abs() < COURT_Z - 1.0 && (1.5..1.9).contains(&p.y), "{p}");
            assert!((k.target - p).normalize().x < -0.95, "looks down the length towards -x");
        }
        // The far arcade is in view, small; the floor 3 m ahead is near the bottom of the image.
        let far = s.camera.project_to_pixel(Vec3::new(-HALF_LEN, 2.0, 0.0), 1024, 1024).unwrap();
        assert!((300.0..724.0).contains(&far.x) && (300.0..724.0).contains(&far.y), "{far}");
        let near = s.camera.project_to_pixel(s.camera.position + Vec3::new(-3.0, -1.7, 0.0), 1024, 1024).unwrap();
        assert!(near.y > 900.0 && near.y < 1024.0, "{near}");
    }

    #[test]
    fn banners_are_thin_and_hang_between_upper_columns() {
        let s = build();
        let mut zs: HashMap<bool, (f32, f32)> = HashMap::new();
        let mut n = 0;
        for v in s.vertices.iter().filter(|v| s.materials[v.material as usize].name.starts_with("banner")) {
            let p = Vec3::from(v.pos);
            let e = zs.entry(p.z > 0.0).or_insert((f32::MAX, f32::MIN));
            *e = (e.0.min(p.z.abs()), e.1.max(p.z.abs()));
            assert!(p.y > UPPER.base + 0.95 && p.y < UPPER.top, "{p}");
            let to_column = (p.x + HALF_LEN).rem_euclid(SIDE_BAY).min(SIDE_BAY - (p.x + HALF_LEN).rem_euclid(SIDE_BAY));
            assert!(to_column > UPPER.col_r + 0.1, "banner at {p} touches a column");
            n += 1;
        }
        assert_eq!(n, 8 * 36, "eight boxes");
        for (lo, hi) in zs.values() {
            assert!((hi - lo - BANNER_T).abs() < 1e-4, "banner thickness {}", hi - lo);
        }
    }

    /// The camera sees plenty of floor, and the grazing sun leaves part of it lit, part shadowed.
    #[test]
    fn sun_lights_part_of_the_visible_floor() {
        let s = build();
        let (n, res) = (24u32, 1024);
        let inv = s.camera.view_proj(res, res).inverse();
        let (mut floor, mut lit) = (0, 0);
        for j in 0..n {
            for i in 0..n {
                let ndc = Vec3::new((i as f32 + 0.5) / n as f32 * 2.0 - 1.0, 1.0 - (j as f32 + 0.5) / n as f32 * 2.0, 1.0);
                let d = (inv.project_point3(ndc) - s.camera.position).normalize();
                let Some((t, _)) = first_hit(&s, s.camera.position, d) else { continue };
                let p = s.camera.position + d * t;
                if p.y.abs() < 1e-3 && p.x > -HALF_LEN {
                    floor += 1;
                    lit += first_hit(&s, p + Vec3::Y * 1e-3, -sun_direction()).is_none() as u32;
                }
            }
        }
        let (f, l) = (floor as f32 / (n * n) as f32, lit as f32 / floor as f32);
        assert!(f > 0.3, "floor covers {f}");
        assert!((0.35..0.85).contains(&l), "lit fraction of the visible floor {l}");
    }
}
