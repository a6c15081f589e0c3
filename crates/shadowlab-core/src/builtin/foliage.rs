//! `foliage`: thin and cut-out occluders, where shadow maps leak. A 60 m x 60 m ground, a large
//! wall, a street lamp 3 m in front of it with cables sagging to the wall and one dangling from the
//! arm, a wire fence (posts and 6 mm wires), and six trees whose leaves are alpha-tested cards
//! (one RGBA8 leaf texture, alpha 255 on leaves and twigs, 0 elsewhere; cutoff 0.5).
//!
//! The sun (37 degrees up) hits the wall at about 45 degrees, so the lamp, cable and leaf shadows
//! land on the wall the camera looks at; the fence wires' shadows lie on the ground.
//!
//! Moving objects ([`animations`], time in frames): a hand cart with a thin flag pole crosses
//! between the lamp and the wall, and the cables sway, so their shadows move across the wall.

use glam::{Vec2, Vec3};

use super::{hash01, MeshBuilder};
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene, Texture};

/// The wall's lit face is the plane z = WALL_Z, for x in [-WALL_HALF_W, WALL_HALF_W], y in [0, WALL_H].
const WALL_Z: f32 = -8.0;
const WALL_HALF_W: f32 = 16.0;
const WALL_H: f32 = 6.0;
/// Street lamp pole foot.
const LAMP: Vec3 = Vec3::new(1.0, 0.0, -5.0);
/// Fence line (post feet at both ends).
pub const FENCE: (Vec3, Vec3) = (Vec3::new(-6.0, 0.0, -3.0), Vec3::new(-1.0, 0.0, 5.0));
/// Tree feet (x, z): two near the wall, the rest around the lawn.
pub const TREES: [(f32, f32); 6] = [(-8.0, -4.5), (8.5, -5.0), (-4.0, 2.0), (7.0, 5.0), (-16.0, -2.0), (15.0, 9.0)];
/// Cable radius (8 mm) and fence-wire radius (6 mm); both are 6-sided cylinders.
pub const CABLE_R: f32 = 0.008;
pub const FENCE_WIRE_R: f32 = 0.006;
const WIRE_SEGMENTS: u32 = 6;
/// Leaf texture size and leaf cards per tree.
const LEAF_TEX: u32 = 128;
const CARDS_PER_TREE: u32 = 120;

/// Where the sunlight travels (pointing down, towards the wall).
pub fn sun_direction() -> Vec3 {
    Vec3::new(0.35, -0.6, -0.72).normalize()
}

/// Cables of the street lamp as (start, end, sag) in metres: two to the wall, one dangling.
pub fn cables() -> Vec<(Vec3, Vec3, f32)> {
    vec![
        (LAMP + Vec3::new(0.0, 4.6, 0.0), Vec3::new(-7.0, 4.9, WALL_Z), 0.6),
        (LAMP + Vec3::new(0.0, 4.4, 0.0), Vec3::new(8.0, 4.3, WALL_Z), 0.45),
        (LAMP + Vec3::new(0.8, 5.0, 0.0), LAMP + Vec3::new(0.9, 3.4, 0.05), 0.0),
    ]
}

/// Point `t` in [0, 1] along a cable sagging `sag` metres at its middle (parabola).
pub fn cable_point(a: Vec3, b: Vec3, sag: f32, t: f32) -> Vec3 {
    a.lerp(b, t) - Vec3::Y * (4.0 * sag * t * (1.0 - t))
}

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let ground = b.material(Material::solid("lawn", [0.34, 0.48, 0.22]));
    let wall = b.material(Material::solid("rendered wall", [0.86, 0.80, 0.70]));
    let metal = b.material(Material::solid("lamp metal", [0.22, 0.24, 0.26]));
    let glass = b.material(Material::solid("lamp glass", [0.95, 0.90, 0.70]));
    let cable = b.material(Material::solid("cable", [0.08, 0.08, 0.08]));
    let post = b.material(Material::solid("fence post", [0.50, 0.36, 0.22]));
    let wire = b.material(Material::solid("fence wire", [0.60, 0.62, 0.64]));
    let bark = b.material(Material::solid("bark", [0.36, 0.26, 0.18]));
    let tex = b.texture(leaf_texture());
    let leaves = b.material(Material {
        name: "leaves".into(),
        base_color: [1.0; 4],
        texture: Some(tex),
        alpha_cutoff: Some(0.5),
        double_sided: true,
    });

    b.cuboid(Vec3::new(-30.0, -0.2, -30.0), Vec3::new(30.0, 0.0, 30.0), ground);
    b.cuboid(Vec3::new(-WALL_HALF_W, 0.0, WALL_Z - 0.3), Vec3::new(WALL_HALF_W, WALL_H, WALL_Z), wall);

    // Street lamp: foot, pole, arm, head with a glass underside, and its cables.
    b.cuboid(LAMP + Vec3::new(-0.2, 0.0, -0.2), LAMP + Vec3::new(0.2, 0.4, 0.2), metal);
    b.cylinder(LAMP + Vec3::Y * 0.4, LAMP + Vec3::Y * 5.2, 0.07, 12, metal);
    b.cylinder(LAMP + Vec3::Y * 5.0, LAMP + Vec3::new(1.5, 5.0, 0.0), 0.04, 8, metal);
    b.cuboid(LAMP + Vec3::new(1.25, 4.8, -0.2), LAMP + Vec3::new(1.75, 5.1, 0.2), metal);
    b.cuboid(LAMP + Vec3::new(1.3, 4.72, -0.15), LAMP + Vec3::new(1.7, 4.8, 0.15), glass);
    for (a, c, sag) in cables() {
        let n = if sag > 0.0 { 16 } else { 4 };
        for i in 0..n {
            let (t0, t1) = (i as f32 / n as f32, (i + 1) as f32 / n as f32);
            b.cylinder(cable_point(a, c, sag, t0), cable_point(a, c, sag, t1), CABLE_R, WIRE_SEGMENTS, cable);
        }
    }

    // Wire fence running towards the camera on the left: 7 round posts, 4 wires per span.
    let (f0, f1) = (FENCE.0, FENCE.1);
    let spans = 6;
    for i in 0..=spans {
        let p = f0.lerp(f1, i as f32 / spans as f32);
        b.cylinder(p, p + Vec3::Y * 1.4, 0.05, 8, post);
    }
    for i in 0..spans {
        let (p, q) = (f0.lerp(f1, i as f32 / spans as f32), f0.lerp(f1, (i + 1) as f32 / spans as f32));
        for h in [0.35, 0.65, 0.95, 1.25] {
            b.cylinder(p + Vec3::Y * h, q + Vec3::Y * h, FENCE_WIRE_R, WIRE_SEGMENTS, wire);
        }
    }

    // A hand cart with a thin flag pole, crossing between the lamp and the wall (animated below).
    let cart = b.material(Material::solid("cart", [0.70, 0.20, 0.12]));
    let (c0, c1) = CART;
    b.cuboid(c0 + Vec3::Y * 0.35, c1, cart);
    for x in [c0.x + 0.25, c1.x - 0.25] {
        for z in [c0.z, c1.z] {
            b.cylinder(Vec3::new(x, 0.3, z), Vec3::new(x, 0.3, z + if z == c0.z { -0.06 } else { 0.06 }), 0.3, 12, cart);
        }
    }
    let pole = Vec3::new(c1.x - 0.1, c1.y, (c0.z + c1.z) / 2.0);
    b.cylinder(pole, pole + Vec3::Y * 2.2, 0.015, 8, cart);
    b.cuboid(pole + Vec3::new(0.0, 1.7, -0.005), pole + Vec3::new(0.7, 2.2, 0.005), cart);

    // Trees (the two near the wall throw leaf shadows on it).
    for (k, &(x, z)) in TREES.iter().enumerate() {
        tree(&mut b, Vec3::new(x, 0.0, z), 10_000 + 2_000 * k as u32, bark, leaves);
    }

    let cam = Camera::new(Vec3::new(1.5, 1.7, 16.0), Vec3::new(0.5, 2.5, WALL_Z), 55.0, 0.1, 100.0);
    let path = (0..4).map(|i| CameraKey { position: cam.position + Vec3::new(-0.7, 0.0, -0.4) * i as f32, target: cam.target }).collect();
    let mut s = b.finish("foliage", cam, vec![Light::Directional { direction: sun_direction() }], path);
    crate::anim::apply(&mut s, &animations()).expect("foliage animations select their objects");
    s
}

/// The hand cart's body at t = 0 (min, max corners); it crosses by `CART_TRAVEL` and back.
pub const CART: (Vec3, Vec3) = (Vec3::new(4.2, 0.0, -6.9), Vec3::new(5.8, 1.1, -6.1));
pub const CART_TRAVEL: Vec3 = Vec3::new(-9.0, 0.0, 0.0);

/// Moving objects (time in frames): the cart crossing in front of the wall and back (64 frames),
/// the two sagging cables swaying about their chords, the dangling one about its top.
pub fn animations() -> Vec<crate::anim::AnimationSpec> {
    use crate::anim::{AnimationSpec, Motion};
    let cab = cables();
    let cable_sway = |name: &str, inside: [Vec3; 2], pivot: Vec3, axis: Vec3, amplitude_deg: f32, period: f32| AnimationSpec {
        name: name.into(),
        materials: vec!["cable".into()],
        inside: Some(inside),
        motion: Motion::Sway { pivot, axis, amplitude_deg, period },
    };
    vec![
        AnimationSpec {
            name: "cart".into(),
            materials: vec!["cart".into()],
            inside: None,
            motion: Motion::Translate { offset: CART_TRAVEL, period: 64.0 },
        },
        cable_sway("west cable", [Vec3::new(-8.0, 0.0, -9.0), Vec3::new(0.95, 6.0, -4.0)], cab[0].0, cab[0].1 - cab[0].0, 9.0, 40.0),
        cable_sway("east cable", [Vec3::new(1.05, 0.0, -9.0), Vec3::new(9.0, 6.0, -5.1)], cab[1].0, cab[1].1 - cab[1].0, 7.0, 52.0),
        cable_sway("dangling cable", [Vec3::new(1.7, 3.0, -5.1), Vec3::new(2.0, 5.1, -4.9)], cab[2].0, Vec3::Z, 14.0, 30.0),
    ]
}

/// A tree at `foot`: trunk, four branches and `CARDS_PER_TREE` leaf cards in an ellipsoidal
/// crown; every third card is crossed with a second one at right angles.
fn tree(b: &mut MeshBuilder, foot: Vec3, seed: u32, bark: u32, leaves: u32) {
    let h = |k: u32| hash01(seed + k);
    let trunk_h = 2.6 + 1.0 * h(0);
    let radii = Vec3::new(1.8 + 0.8 * h(1), 1.4 + 0.6 * h(2), 1.8 + 0.8 * h(3));
    let crown = foot + Vec3::Y * (trunk_h + 0.8 * radii.y);
    b.cylinder(foot, foot + Vec3::Y * (trunk_h + 0.5), 0.16 + 0.08 * h(4), 12, bark);
    for i in 0..4 {
        let a = (i as f32 + h(10 + i)) * std::f32::consts::FRAC_PI_2;
        let tip = crown + Vec3::new(a.cos() * radii.x * 0.6, 0.3 * radii.y, a.sin() * radii.z * 0.6);
        b.cylinder(foot + Vec3::Y * (trunk_h - 0.3), tip, 0.06, 8, bark);
    }
    for i in 0..CARDS_PER_TREE {
        let r = |k: u32| h(100 + 8 * i + k);
        // A point in the unit ball (cube-root radius keeps the density uniform).
        let (phi, cos_t, rad) = (r(0) * std::f32::consts::TAU, 2.0 * r(1) - 1.0, r(2).cbrt());
        let sin_t = (1.0 - cos_t * cos_t).sqrt();
        let p = crown + Vec3::new(sin_t * phi.cos(), cos_t, sin_t * phi.sin()) * rad * radii;
        let (yaw, tilt, size) = (r(3) * std::f32::consts::TAU, 1.2 * (r(4) - 0.5), 0.9 + 0.4 * r(5));
        let u = Vec3::new(yaw.cos(), 0.0, yaw.sin());
        let n = Vec3::new(-yaw.sin(), 0.0, yaw.cos());
        let v = Vec3::Y * tilt.cos() + n * tilt.sin();
        b.quad(p - (u + v) * size * 0.5, u * size, v * size, Vec2::ONE, leaves);
        if i % 3 == 0 {
            let w = u.cross(v);
            b.quad(p - (w + v) * size * 0.5, w * size, v * size, Vec2::ONE, leaves);
        }
    }
}

/// 128x128 RGBA8 sprig: pointed leaves on thin twigs meeting near the centre. Alpha is 255 on
/// leaves and twigs, 0 on the background (whose colour matches the leaves to avoid dark fringes).
pub fn leaf_texture() -> Texture {
    let n = LEAF_TEX as usize;
    let mut rgba = vec![0u8; n * n * 4];
    for px in rgba.chunks_mut(4) {
        px.copy_from_slice(&[52, 96, 38, 0]);
    }
    let mut put = |x: i32, y: i32, c: [u8; 3]| {
        if (0..n as i32).contains(&x) && (0..n as i32).contains(&y) {
            let i = (y as usize * n + x as usize) * 4;
            rgba[i..i + 4].copy_from_slice(&[c[0], c[1], c[2], 255]);
        }
    };
    let hub = Vec2::new(64.0, 70.0);
    for k in 0..14u32 {
        let h = |j: u32| hash01(50_000 + 10 * k + j);
        let centre = Vec2::new(28.0 + 72.0 * h(0), 24.0 + 76.0 * h(1));
        let (len, half_w) = (15.0 + 8.0 * h(2), 5.5 + 3.0 * h(3));
        // Leaf axis points away from the hub, with some spread.
        let dir = Vec2::from_angle(0.8 * (h(4) - 0.5)).rotate((centre - hub).normalize_or(Vec2::Y));
        let shade = [(40.0 + 40.0 * h(5)) as u8, (105.0 + 50.0 * h(6)) as u8, (30.0 + 25.0 * h(7)) as u8];
        // Twig from the hub to the leaf base, 2 px wide.
        let base = centre - dir * len;
        for s in 0..=64 {
            let p = hub.lerp(base, s as f32 / 64.0);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                put(p.x as i32 + dx, p.y as i32 + dy, [88, 66, 40]);
            }
        }
        // Pointed leaf: |across| <= half_w * (1 - along^2 / len^2), midrib darker.
        for y in (centre.y - len) as i32..=(centre.y + len) as i32 {
            for x in (centre.x - len) as i32..=(centre.x + len) as i32 {
                let d = Vec2::new(x as f32 + 0.5, y as f32 + 0.5) - centre;
                let (along, across) = (d.dot(dir), d.perp_dot(dir).abs());
                if along.abs() < len && across <= half_w * (1.0 - (along / len).powi(2)) {
                    let rib = across < 0.7;
                    put(x, y, if rib { [shade[0] / 2, shade[1] / 2, shade[2] / 2] } else { shade });
                }
            }
        }
    }
    Texture { name: "leaf sprig".into(), width: LEAF_TEX, height: LEAF_TEX, rgba }
}

#[cfg(test)]
mod tests {
    use super::super::courtyard::tests::{assert_closed, first_hit};
    use super::*;

    fn material(s: &Scene, tri: usize) -> &Material {
        &s.materials[s.vertices[3 * tri].material as usize]
    }

    #[test]
    fn leaves_are_an_alpha_tested_cutout() {
        let s = build();
        let tex = leaf_texture();
        assert!(tex.rgba.chunks(4).all(|p| p[3] == 0 || p[3] == 255));
        let cover = tex.rgba.chunks(4).filter(|p| p[3] == 255).count() as f32 / (LEAF_TEX * LEAF_TEX) as f32;
        assert!((0.2..0.7).contains(&cover), "leaf coverage {cover}");
        let m = s.materials.iter().find(|m| m.name == "leaves").unwrap();
        assert!(m.alpha_cutoff == Some(0.5) && m.double_sided && m.texture.is_some() && s.has_cutouts());
        let cards = s.vertices.iter().filter(|v| s.materials[v.material as usize].name == "leaves");
        assert!(cards.clone().count() / 6 >= TREES.len() * CARDS_PER_TREE as usize);
        assert!(cards.flat_map(|v| v.uv).all(|c| (0.0..=1.0).contains(&c)));
    }

    #[test]
    fn solids_are_closed_and_wires_thin() {
        let s = build();
        assert_closed(&s, |name| name != "leaves");
        assert!((2_000..60_000).contains(&s.triangle_count()), "{}", s.triangle_count());
        for (name, r) in [("cable", CABLE_R), ("fence wire", FENCE_WIRE_R)] {
            let tris: Vec<usize> = (0..s.triangle_count()).filter(|&i| material(&s, i).name == name).collect();
            assert!(tris.len() >= 100, "{name}");
            for i in tris {
                let [a, b, c] = s.triangle(i);
                let longest = (b - a).length().max((c - b).length()).max((a - c).length());
                let width = (b - a).cross(c - a).length() / longest;
                assert!(width <= 2.0 * r + 1e-5, "{name} triangle {width} m wide");
            }
        }
    }

    #[test]
    fn lamp_and_cable_shadows_fall_on_the_wall() {
        let s = build();
        let d = sun_direction();
        let incidence = d.dot(-Vec3::Z).acos().to_degrees();
        assert!((30.0..60.0).contains(&incidence) && d.y < 0.0, "sun hits the wall at {incidence} deg");
        let mut points: Vec<Vec3> = cables().iter().flat_map(|&(a, b, sag)| [0.3, 0.5, 0.7].map(|t| cable_point(a, b, sag, t))).collect();
        points.push(LAMP + Vec3::Y * 3.0);
        for p in points {
            let to_wall = (WALL_Z - p.z) / d.z;
            let w = p + d * to_wall;
            assert!(w.x.abs() < WALL_HALF_W && w.y > 0.2 && w.y < WALL_H, "shadow of {p} misses the wall: {w}");
            let (t, i) = first_hit(&s, w + Vec3::Z * 1e-3, -d).expect("wall point lit");
            assert!((t - to_wall).abs() < 0.1, "{p}: blocked by {} at {t}", material(&s, i).name);
        }
        // The wall is mostly lit, with shadows on it (lamp, cables, leaves).
        let mut lit = 0;
        for j in 0..10 {
            for i in 0..20 {
                let w = Vec3::new(-12.0 + 24.0 * (i as f32 + 0.5) / 20.0, WALL_H * (j as f32 + 0.5) / 10.0, WALL_Z + 1e-3);
                lit += first_hit(&s, w, -d).is_none() as u32;
            }
        }
        assert!((100..195).contains(&lit), "{lit} of 200 wall samples lit");
    }

    #[test]
    fn camera_sees_wall_lamp_fence_and_trees() {
        let s = build();
        let cams = s.camera_path.iter().map(|k| Camera { position: k.position, target: k.target, ..s.camera });
        for cam in cams.chain([s.camera]) {
            let seen = |p: Vec3| {
                cam.project_to_pixel(p, 1024, 1024).is_some_and(|q| q.cmpgt(Vec2::splat(20.0)).all() && q.cmplt(Vec2::splat(1004.0)).all())
            };
            for p in [
                Vec3::new(0.0, 3.0, WALL_Z),
                LAMP + Vec3::new(1.5, 4.9, 0.0),
                LAMP + Vec3::Y * 0.5,
                FENCE.0 + Vec3::Y * 1.2,
                FENCE.1 + Vec3::Y * 1.2,
            ] {
                assert!(seen(p), "{p} not in view from {}", cam.position);
            }
            let trees = TREES.iter().filter(|&&(x, z)| seen(Vec3::new(x, 2.0, z))).count();
            assert!(trees >= 3, "{trees} trees in view from {}", cam.position);
        }
    }
}
