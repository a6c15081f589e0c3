use super::*;
use crate::builtin::{builtin, MeshBuilder};
use crate::camera::Camera;
use crate::scene::Material;

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

#[test]
fn translate_goes_back_and_forth() {
    let m = Motion::Translate { offset: Vec3::new(4.0, 0.0, -2.0), period: 8.0 };
    let p = Vec3::new(1.0, 2.0, 3.0);
    assert_eq!(m.transform(0.0), Mat4::IDENTITY);
    assert!(close(m.transform(4.0).transform_point3(p), p + Vec3::new(4.0, 0.0, -2.0)), "half period: at the far end");
    assert!(close(m.transform(2.0).transform_point3(p), p + Vec3::new(2.0, 0.0, -1.0)), "quarter period: half way");
    assert!(close(m.transform(6.0).transform_point3(p), p + Vec3::new(2.0, 0.0, -1.0)), "three quarters: half way back");
    assert!(close(m.transform(8.0).transform_point3(p), p), "full period: back home");
    assert!(close(m.transform(1.0).transform_vector3(Vec3::X), Vec3::X), "directions do not move");
}

#[test]
fn sway_rotates_about_its_pivot_line() {
    // pendulum hanging from (0, 2, 0), swinging about +z by 30 degrees
    let m = Motion::Sway { pivot: Vec3::new(0.0, 2.0, 0.0), axis: Vec3::Z * 3.0, amplitude_deg: 30.0, period: 12.0 };
    let bob = Vec3::new(0.0, 0.0, 0.5);
    assert!(close(m.transform(0.0).transform_point3(bob), bob));
    // t = T/4: +30 degrees about +z (right-handed): the bob swings towards +x
    let (s, c) = (30f32.to_radians().sin(), 30f32.to_radians().cos());
    assert!(close(m.transform(3.0).transform_point3(bob), Vec3::new(2.0 * s, 2.0 - 2.0 * c, 0.5)));
    assert!(close(m.transform(9.0).transform_point3(bob), Vec3::new(-2.0 * s, 2.0 - 2.0 * c, 0.5)));
    assert!(close(m.transform(6.0).transform_point3(bob), bob), "half period: through the rest pose");
    // points on the axis never move
    assert!(close(m.transform(2.3).transform_point3(Vec3::new(0.0, 2.0, 7.0)), Vec3::new(0.0, 2.0, 7.0)));
}

#[test]
fn orbit_turns_fully_once_per_period() {
    let m = Motion::Orbit { center: Vec3::new(1.0, 0.0, 1.0), axis: Vec3::Y, period: 20.0 };
    let p = Vec3::new(2.0, 5.0, 1.0);
    // right-handed about +y: +x goes to -z after a quarter turn
    assert!(close(m.transform(5.0).transform_point3(p), Vec3::new(1.0, 5.0, 0.0)));
    assert!(close(m.transform(10.0).transform_point3(p), Vec3::new(0.0, 5.0, 1.0)));
    assert!(close(m.transform(20.0).transform_point3(p), p));
    let back = Motion::Orbit { center: Vec3::new(1.0, 0.0, 1.0), axis: Vec3::Y, period: -20.0 };
    assert!(close(back.transform(5.0).transform_point3(p), Vec3::new(1.0, 5.0, 2.0)));
}

#[test]
fn bad_motions_are_errors() {
    let t = |period| Motion::Translate { offset: Vec3::X, period };
    assert!(t(0.0).validate().unwrap_err().contains("period"));
    assert!(t(-3.0).validate().is_err());
    assert!(t(f32::NAN).validate().is_err());
    assert!(t(2.0).validate().is_ok());
    assert!(Motion::Sway { pivot: Vec3::ZERO, axis: Vec3::ZERO, amplitude_deg: 5.0, period: 4.0 }.validate().unwrap_err().contains("axis"));
    assert!(Motion::Sway { pivot: Vec3::ZERO, axis: Vec3::X, amplitude_deg: 500.0, period: 4.0 }.validate().is_err());
    assert!(Motion::Orbit { center: Vec3::ZERO, axis: Vec3::Y, period: 0.0 }.validate().is_err());
    assert!(Motion::Orbit { center: Vec3::ZERO, axis: Vec3::Y, period: -4.0 }.validate().is_ok());
}

/// Ground quad (material "ground"), a box "crate" at x in [0, 1] and a box "crate" at x in [3, 4].
fn toy() -> Scene {
    let mut b = MeshBuilder::default();
    let g = b.material(Material::solid("ground", [0.5; 3]));
    let c = b.material(Material::solid("crate", [0.8; 3]));
    b.cuboid(Vec3::new(0.0, 0.0, 0.0), Vec3::ONE, c);
    b.quad(Vec3::new(-5.0, 0.0, -5.0), Vec3::Z * 10.0, Vec3::X * 10.0, glam::Vec2::ONE, g);
    b.cuboid(Vec3::new(3.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 1.0), c);
    b.finish("toy", Camera::new(Vec3::ONE * 5.0, Vec3::ZERO, 60.0, 0.1, 50.0), vec![], vec![])
}

fn spec(name: &str, materials: &[&str], inside: Option<[Vec3; 2]>) -> AnimationSpec {
    AnimationSpec {
        name: name.into(),
        materials: materials.iter().map(|s| s.to_string()).collect(),
        inside,
        motion: Motion::Translate { offset: Vec3::X, period: 10.0 },
    }
}

fn tri_key(v: &[Vertex]) -> Vec<u32> {
    v.iter().flat_map(|v| bytemuck::bytes_of(v).chunks(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect::<Vec<_>>()).collect()
}

#[test]
fn reorder_keeps_every_triangle_once_and_static_ones_in_order() {
    let s0 = toy();
    assert_eq!(s0.dynamic_first(), s0.triangle_count());
    let mut s = s0.clone();
    let right_box = [Vec3::new(2.5, -1.0, -1.0), Vec3::new(5.0, 2.0, 2.0)];
    apply(&mut s, &[spec("right", &["crate"], Some(right_box)), spec("left", &[], Some([Vec3::splat(-0.01), Vec3::splat(1.01)]))]).unwrap();
    assert_eq!(s.triangle_count(), s0.triangle_count());
    assert_eq!(s.animations.len(), 2);
    assert_eq!((s.animations[0].first, s.animations[0].count), (2, 12), "right box after the 2 ground triangles");
    assert_eq!((s.animations[1].first, s.animations[1].count), (14, 12));
    assert_eq!(s.dynamic_first(), 2);
    // static part: the ground quad, unchanged
    assert_eq!(&s.vertices[..6], &s0.vertices[36..42]);
    // every triangle exactly once
    let mut a: Vec<Vec<u32>> = s0.vertices.chunks(3).map(tri_key).collect();
    let mut b: Vec<Vec<u32>> = s.vertices.chunks(3).map(tri_key).collect();
    a.sort();
    b.sort();
    assert_eq!(a, b);
    // the right animation holds exactly the triangles with centroids at x > 3
    for i in 2..14 {
        let [p, q, r] = s.triangle(i);
        assert!((p + q + r).x / 3.0 >= 3.0);
    }
    // a second apply appends after the existing ones and keeps them
    let mut s2 = s0.clone();
    apply(&mut s2, &[spec("right", &["crate"], Some(right_box))]).unwrap();
    apply(&mut s2, &[spec("ground", &["ground"], None)]).unwrap();
    assert_eq!(s2.dynamic_first(), 12);
    assert_eq!(
        s2.animations.iter().map(|a| (a.name.as_str(), a.first, a.count)).collect::<Vec<_>>(),
        [("right", 12, 12), ("ground", 24, 2)]
    );
}

#[test]
fn selection_errors_are_clear() {
    let mut s = toy();
    let e = apply(&mut s, &[spec("x", &["crates"], None)]).unwrap_err();
    assert!(e.contains("unknown material 'crates'") && e.contains("'crate'"), "{e}");
    let e = apply(&mut s, &[spec("x", &["crate"], Some([Vec3::splat(10.0), Vec3::splat(11.0)]))]).unwrap_err();
    assert!(e.contains("selects no triangles"), "{e}");
    let e = apply(&mut s, &[spec("x", &[], None)]).unwrap_err();
    assert!(e.contains("materials") && e.contains("inside"), "{e}");
    let e = apply(&mut s, &[spec("a", &["crate"], None), spec("b", &["crate"], None)]).unwrap_err();
    assert!(e.contains("already moved by animation 'a'"), "{e}");
    let e = apply(&mut s, &[spec("a", &["crate"], None), spec("a", &["ground"], None)]).unwrap_err();
    assert!(e.contains("used twice"), "{e}");
    let mut bad = spec("p", &["crate"], None);
    bad.motion = Motion::Translate { offset: Vec3::X, period: 0.0 };
    assert!(apply(&mut s, &[bad]).unwrap_err().contains("animation 'p': period"));
    let e = apply(&mut s, &[spec("a", &["crate"], Some([Vec3::ONE, Vec3::ZERO]))]).unwrap_err();
    assert!(e.contains("min <= max"), "{e}");
    assert_eq!(s.vertices, toy().vertices, "failed applies leave the scene alone");
}

#[test]
fn animated_vertices_move_positions_and_normals() {
    let mut s = toy();
    let mut sp = spec("spin", &["crate"], Some([Vec3::splat(-0.1), Vec3::splat(1.1)]));
    sp.motion = Motion::Orbit { center: Vec3::ZERO, axis: Vec3::Y, period: 4.0 };
    apply(&mut s, &[sp]).unwrap();
    assert_eq!(s.animated_vertices(0.0), s.vertices[3 * s.dynamic_first()..].to_vec());
    let moved = s.animated_vertices(1.0); // quarter turn about +y: (x, y, z) -> (z, y, -x)
    for (a, b) in s.vertices[3 * s.dynamic_first()..].iter().zip(&moved) {
        let (p, n) = (Vec3::from(a.pos), Vec3::from(a.normal));
        assert!(close(Vec3::from(b.pos), Vec3::new(p.z, p.y, -p.x)));
        assert!(close(Vec3::from(b.normal), Vec3::new(n.z, n.y, -n.x)));
        assert_eq!((a.uv, a.material), (b.uv, b.material));
    }
    let at = s.at_time(1.0);
    assert_eq!(at.vertices[..3 * s.dynamic_first()], s.vertices[..3 * s.dynamic_first()]);
    assert_eq!(at.vertices[3 * s.dynamic_first()..], moved[..]);
    // swept bounds hold every sampled pose
    let b = s.swept_bounds();
    for k in 0..50 {
        for v in s.at_time(k as f32 * 0.173).vertices {
            let p = Vec3::from(v.pos);
            assert!(p.cmpge(b.min - 1e-5).all() && p.cmple(b.max + 1e-5).all(), "{p} outside {b:?}");
        }
    }
    assert!(b.min.z < -0.99 && b.max.x > 0.99, "a full turn of the unit box about the origin reaches -1 in x and z");
    assert_eq!(toy().swept_bounds(), toy().bounds());
}

#[test]
fn builtin_animations_move_at_t_not_at_zero() {
    for name in ["foliage", "room", "courtyard"] {
        let s = builtin(name).unwrap();
        assert!(!s.animations.is_empty(), "{name} has moving objects");
        assert!(s.dynamic_first() < s.triangle_count());
        let t = s.animations[0].motion.period() / 4.0;
        assert_eq!(s.at_time(0.0).vertices, s.vertices, "{name}: t = 0 is the rest pose");
        assert_ne!(s.at_time(t).vertices, s.vertices, "{name} moves");
        let mut sum = 0;
        for a in &s.animations {
            assert!(a.count > 0);
            sum += a.count;
        }
        assert_eq!(s.dynamic_first() + sum, s.triangle_count(), "{name}: the animations tile the dynamic range");
    }
    for name in ["planebox", "city"] {
        let s = builtin(name).unwrap();
        assert_eq!(s.dynamic_first(), s.triangle_count(), "{name} stays still");
    }
}

#[test]
fn loaded_files_select_by_material_name_and_box() {
    use crate::loaders::{load, SceneTransform};
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    // OBJ: `usemtl` names; the unit squares sit at x = 0, 2, 4, ...; scaled by 2 on load, so the
    // box is in scene coordinates after the transform
    let xf = SceneTransform { scale: 2.0, ..Default::default() };
    let mut s = load(&dir.join("quad.obj"), &xf).unwrap();
    let n = s.triangle_count();
    let solid = s.materials.iter().position(|m| m.name == "solid").unwrap() as u32;
    let count = |s: &Scene, m: u32| (0..s.triangle_count()).filter(|&i| s.vertices[3 * i].material == m).count();
    let solids = count(&s, solid);
    apply(
        &mut s,
        &[
            spec("solid squares", &["solid"], None),
            spec("first leaves", &["leaves"], Some([Vec3::new(3.9, -1.0, -1.0), Vec3::new(6.1, 3.0, 1.0)])),
        ],
    )
    .unwrap();
    assert_eq!(s.triangle_count(), n);
    assert_eq!(s.animations[0].count, solids);
    assert_eq!(s.animations[1].count, 2, "the 'leaves' square at x = 2 (4..6 after scaling)");
    assert!(s.vertices[3 * s.animations[0].first..3 * (s.animations[0].first + solids)].iter().all(|v| v.material == solid));
    // glTF: material names as written (unnamed ones are `material<i>`)
    let mut g = load(&dir.join("nested.gltf"), &SceneTransform::default()).unwrap();
    let cut = g.materials.iter().position(|m| m.name == "cutout").unwrap() as u32;
    let cuts = count(&g, cut);
    assert!(cuts > 0);
    apply(&mut g, &[spec("cut", &["cutout"], None)]).unwrap();
    assert_eq!(g.triangle_count() - g.dynamic_first(), cuts);
}
