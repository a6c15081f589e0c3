//! `room`: a closed interior 8 m x 3 m x 6 m (floor, ceiling, four walls as thick boxes) with a
//! dining table, twelve chairs with thin (3 cm) legs, and shelves with boxes on the back wall.
//!
//! Lights: `lights[0]` is a spot light in the high back-right corner aimed at the table, `lights[1]`
//! a point light hanging above the table below the ceiling (omnidirectional shadows: cube or
//! dual-paraboloid maps, NoTW for point lights). The camera stands in the front-right corner and
//! looks at the table with the point light inside the view, so its shadows surround the viewer.
//! Moving object ([`animations`]): the chair at the +x end of the table slides out and back.

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{Mat4, Vec2, Vec3};

use super::{hash01, MeshBuilder};
use crate::camera::{Camera, CameraKey};
use crate::light::Light;
use crate::scene::{Material, Scene};

/// Interior: x in [-HALF_X, HALF_X], y in [0, HEIGHT], z in [-HALF_Z, HALF_Z]; walls WALL_T thick outside it.
const HALF_X: f32 = 4.0;
const HALF_Z: f32 = 3.0;
const HEIGHT: f32 = 3.0;
const WALL_T: f32 = 0.15;
/// Table top: half extents and height of its upper face.
const TABLE_HALF: Vec2 = Vec2::new(1.8, 0.6);
const TABLE_H: f32 = 0.76;
/// Chair legs: radius 1.5 cm (3 cm thick), and cylinder segments.
const LEG_R: f32 = 0.015;
const LEG_SEGMENTS: u32 = 8;

pub const SPOT_POSITION: Vec3 = Vec3::new(3.7, 2.85, -2.7);
pub const POINT_POSITION: Vec3 = Vec3::new(0.25, 2.45, -0.15);

pub fn build() -> Scene {
    let mut b = MeshBuilder::default();
    let floor = b.material(Material::solid("oak floor", [0.55, 0.38, 0.24]));
    let wall = b.material(Material::solid("wall paint", [0.84, 0.80, 0.72]));
    let ceiling = b.material(Material::solid("ceiling", [0.92, 0.92, 0.90]));
    let rug = b.material(Material::solid("rug", [0.52, 0.16, 0.13]));
    let table = b.material(Material::solid("walnut", [0.42, 0.26, 0.15]));
    let chair = b.material(Material::solid("chair beech", [0.72, 0.55, 0.36]));
    let metal = b.material(Material::solid("chair legs", [0.25, 0.25, 0.27]));
    let shelf = b.material(Material::solid("shelf pine", [0.80, 0.66, 0.45]));
    let boxes = [
        b.material(Material::solid("box teal", [0.16, 0.48, 0.50])),
        b.material(Material::solid("box ochre", [0.78, 0.58, 0.20])),
        b.material(Material::solid("box cream", [0.86, 0.82, 0.70])),
    ];

    // The shell: every face the camera sees points inwards from a closed box (materials are double-sided).
    let (hx, hz, t) = (HALF_X, HALF_Z, WALL_T);
    b.cuboid(Vec3::new(-hx - t, -t, -hz - t), Vec3::new(hx + t, 0.0, hz + t), floor);
    b.cuboid(Vec3::new(-hx - t, HEIGHT, -hz - t), Vec3::new(hx + t, HEIGHT + t, hz + t), ceiling);
    b.cuboid(Vec3::new(-hx - t, 0.0, -hz - t), Vec3::new(-hx, HEIGHT, hz + t), wall);
    b.cuboid(Vec3::new(hx, 0.0, -hz - t), Vec3::new(hx + t, HEIGHT, hz + t), wall);
    b.cuboid(Vec3::new(-hx, 0.0, -hz - t), Vec3::new(hx, HEIGHT, -hz), wall);
    b.cuboid(Vec3::new(-hx, 0.0, hz), Vec3::new(hx, HEIGHT, hz + t), wall);
    b.cuboid(Vec3::new(-2.4, 0.0, -1.6), Vec3::new(2.4, 0.012, 1.6), rug);

    // Table: top and four legs.
    let th = TABLE_HALF;
    b.cuboid(Vec3::new(-th.x, TABLE_H - 0.04, -th.y), Vec3::new(th.x, TABLE_H, th.y), table);
    for (sx, sz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let c = Vec2::new(sx * (th.x - 0.15), sz * (th.y - 0.12));
        b.cuboid(Vec3::new(c.x - 0.035, 0.0, c.y - 0.035), Vec3::new(c.x + 0.035, TABLE_H - 0.04, c.y + 0.035), table);
    }

    // Twelve chairs: five along each long side, one at each end, pulled out and turned a little.
    let mut seats: Vec<(Vec3, f32)> = vec![];
    for i in 0..5 {
        let x = (i as f32 - 2.0) * 0.72;
        seats.push((Vec3::new(x, 0.0, th.y + 0.3), 0.0));
        seats.push((Vec3::new(x, 0.0, -th.y - 0.3), PI));
    }
    seats.push((Vec3::new(th.x + 0.3, 0.0, 0.0), FRAC_PI_2));
    seats.push((Vec3::new(-th.x - 0.3, 0.0, 0.0), -FRAC_PI_2));
    for (i, (p, yaw)) in seats.into_iter().enumerate() {
        let pull = 0.15 * hash01(200 + i as u32);
        let yaw = yaw + 0.2 * (hash01(300 + i as u32) - 0.5);
        let out = Mat4::from_rotation_y(yaw).transform_vector3(Vec3::Z);
        let xf = Mat4::from_translation(p + out * pull) * Mat4::from_rotation_y(yaw);
        b.with_transform(xf, |b| chair_at_origin(b, chair, metal));
    }

    // Shelves on the back wall (left part): three uprights, six boards, boxes on five of them.
    let (sx0, sx1, depth) = (-3.6, -0.8, 0.35);
    let z0 = -hz;
    let uprights = [sx0, (sx0 + sx1) / 2.0, sx1];
    for x in uprights {
        b.cuboid(Vec3::new(x - 0.015, 0.0, z0), Vec3::new(x + 0.015, 2.2, z0 + depth), shelf);
    }
    for j in 0..6 {
        let y = 0.08 + 0.42 * j as f32;
        b.cuboid(Vec3::new(sx0 - 0.015, y, z0), Vec3::new(sx1 + 0.015, y + 0.025, z0 + depth), shelf);
        if j == 5 {
            continue;
        }
        let mut x = sx0 + 0.03;
        let mut n = 0u32;
        loop {
            let h = |k: u32| hash01(1000 + 97 * j + 13 * n + k);
            let (w, hgt, d) = (0.12 + 0.23 * h(0), 0.10 + 0.24 * h(1), 0.18 + 0.12 * h(2));
            x += 0.02 + 0.12 * h(3);
            if x + w > sx1 - 0.03 {
                break;
            }
            if x < uprights[1] + 0.03 && x + w > uprights[1] - 0.03 {
                x = uprights[1] + 0.03;
                continue;
            }
            let yb = y + 0.025;
            b.cuboid(Vec3::new(x, yb, z0 + 0.03), Vec3::new(x + w, yb + hgt, z0 + 0.03 + d), boxes[(h(4) * 3.0) as usize % 3]);
            x += w;
            n += 1;
        }
    }

    let cam = Camera::new(Vec3::new(3.3, 1.65, 2.5), Vec3::new(-0.2, 1.35, -0.5), 60.0, 0.05, 20.0);
    let path = (0..4)
        .map(|i| {
            let t = i as f32;
            CameraKey { position: Vec3::new(3.3 - 0.7 * t, 1.65, 2.5 + 0.05 * t.min(2.0)), target: cam.target }
        })
        .collect();
    let table_top = Vec3::new(0.0, TABLE_H, 0.0);
    let lights = vec![
        Light::Spot { position: SPOT_POSITION, direction: (table_top - SPOT_POSITION).normalize(), cone_deg: 38.0 },
        Light::Point { position: POINT_POSITION },
    ];
    let mut s = b.finish("room", cam, lights, path);
    crate::anim::apply(&mut s, &animations()).expect("room animations select their objects");
    s
}

/// Moving object (time in frames): the chair at the +x end of the table is pulled out by 0.5 m
/// and pushed back every 48 frames (seat, back and thin legs move under both lights).
pub fn animations() -> Vec<crate::anim::AnimationSpec> {
    use crate::anim::{AnimationSpec, Motion};
    vec![AnimationSpec {
        name: "end chair".into(),
        materials: vec!["chair beech".into(), "chair legs".into()],
        inside: Some([Vec3::new(TABLE_HALF.x + 0.02, -0.1, -0.6), Vec3::new(TABLE_HALF.x + 1.0, 1.2, 0.6)]),
        motion: Motion::Translate { offset: Vec3::new(0.5, 0.0, 0.0), period: 48.0 },
    }]
}

/// A chair centred on the origin, facing -z (the table side): seat, four thin round legs and a
/// slatted back (two posts, a top rail and a middle rail) on the +z edge.
fn chair_at_origin(b: &mut MeshBuilder, wood: u32, metal: u32) {
    let (s, seat_y) = (0.22, 0.44);
    b.cuboid(Vec3::new(-s, seat_y, -s), Vec3::new(s, seat_y + 0.04, s), wood);
    for (lx, lz) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = Vec3::new(lx * (s - 0.03), 0.0, lz * (s - 0.03));
        b.cylinder(p, p + Vec3::Y * seat_y, LEG_R, LEG_SEGMENTS, metal);
    }
    let (bz0, bz1, top) = (s - 0.03, s, 0.95);
    for x in [-s + 0.015, s - 0.015] {
        b.cuboid(Vec3::new(x - 0.015, seat_y + 0.04, bz0), Vec3::new(x + 0.015, top - 0.1, bz1), wood);
    }
    b.cuboid(Vec3::new(-s, top - 0.1, bz0), Vec3::new(s, top, bz1), wood);
    b.cuboid(Vec3::new(-s + 0.03, 0.66, bz0 + 0.005), Vec3::new(s - 0.03, 0.71, bz1 - 0.005), wood);
}

#[cfg(test)]
mod tests {
    use super::super::courtyard::tests::{assert_closed, first_hit};
    use super::*;

    fn inside(p: Vec3, margin: f32) -> bool {
        p.x.abs() < HALF_X - margin && p.z.abs() < HALF_Z - margin && p.y > margin && p.y < HEIGHT - margin
    }

    #[test]
    fn closed_solids_and_a_moderate_size() {
        let s = build();
        assert_closed(&s, |_| true);
        assert!((2_000..60_000).contains(&s.triangle_count()), "{}", s.triangle_count());
    }

    #[test]
    fn cameras_are_inside_and_see_the_point_light_and_the_table() {
        let s = build();
        let keys = s.camera_path.iter().map(|k| Camera { position: k.position, target: k.target, ..s.camera });
        for cam in keys.chain([s.camera]) {
            assert!(inside(cam.position, 0.3), "camera at {}", cam.position);
            let view = (cam.target - cam.position).normalize();
            assert!(view.dot(POINT_POSITION - cam.position) > 0.0, "point light behind the camera");
            let to_light = POINT_POSITION - cam.position;
            let hit = first_hit(&s, cam.position, to_light.normalize());
            assert!(hit.is_none_or(|(t, _)| t > to_light.length()), "point light hidden from {}", cam.position);
            for (what, p) in [("point light", POINT_POSITION), ("table", Vec3::new(0.0, TABLE_H, 0.0))] {
                let px = cam.project_to_pixel(p, 1024, 1024).unwrap();
                assert!(px.cmpgt(Vec2::splat(100.0)).all() && px.cmplt(Vec2::splat(924.0)).all(), "{what} at pixel {px}");
            }
        }
    }

    #[test]
    fn lights_sit_inside_and_reach_the_table() {
        let s = build();
        let table = Vec3::new(0.0, TABLE_H, 0.0);
        let Light::Spot { position, direction, cone_deg } = s.lights[0] else { panic!("light 0 must be a spot") };
        assert!(matches!(s.lights[1], Light::Point { .. }));
        assert!((35.0..=40.0).contains(&cone_deg));
        assert!(position.y > HEIGHT - 0.3 && position.x.abs() > HALF_X - 0.5 && position.z.abs() > HALF_Z - 0.5, "high corner");
        assert!(s.lights[0].in_cone(table) && s.lights[0].in_cone(Vec3::new(-1.7, TABLE_H, 0.5)), "{direction}");
        assert!(POINT_POSITION.y > TABLE_H + 1.0 && POINT_POSITION.y < HEIGHT - 0.3 && inside(POINT_POSITION, 0.3));
        for light in [position, POINT_POSITION] {
            assert!(inside(light, 0.1));
            let o = table + Vec3::Y * 1e-3;
            let hit = first_hit(&s, o, (light - o).normalize());
            assert!(hit.is_none_or(|(t, _)| t > o.distance(light)), "table top does not see the light at {light}");
        }
    }

    #[test]
    fn twelve_chairs_with_thin_legs() {
        let s = build();
        let leg_tris: Vec<usize> =
            (0..s.triangle_count()).filter(|&i| s.materials[s.vertices[3 * i].material as usize].name == "chair legs").collect();
        assert_eq!(leg_tris.len(), 12 * 4 * LEG_SEGMENTS as usize * 4);
        for i in leg_tris {
            let t = s.triangle(i).map(|p| Vec2::new(p.x, p.z));
            let width = t[0].distance(t[1]).max(t[1].distance(t[2])).max(t[2].distance(t[0]));
            assert!(width <= 2.0 * LEG_R + 1e-5, "leg {width} m thick");
        }
    }
}
