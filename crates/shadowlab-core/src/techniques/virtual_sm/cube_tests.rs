//! Point lights in `virtual`: the six faces, their mip chains as one list of levels, face
//! choice, the per-face page projection and marking on the sample's own face.

use glam::{IVec2, Vec2, Vec3};

use super::*;
use crate::techniques::cube::{face_of, FACES};

fn room() -> Bounds {
    Bounds { min: Vec3::new(-10.0, 0.0, -10.0), max: Vec3::new(10.0, 5.0, 10.0) }
}

/// A point light 3 m up in the room; 2048 texels in 128^2 pages (16 x 16 pages at mip 0, 5
/// mips a face down to one page, so 30 levels, mip-major).
fn point() -> (Clipmap, Vec3) {
    let at = Vec3::new(1.0, 3.0, -2.0);
    (Clipmap::cube(at, &room(), 16, 2048, 128), at)
}

#[test]
fn six_faces_of_mip_chains_make_one_list_of_levels() {
    let (c, _) = point();
    assert_eq!((c.faces(), c.mips, c.levels), (6, 5, 30));
    assert_eq!(c.table_len(), 30 * 16 * 16);
    assert_eq!((c.face(15), c.mip(15), c.level_index(3, 2)), (3, 2, 15));
    assert_eq!((0..30).map(|k| c.side(k)).filter(|s| *s == 16).count(), 6);
    assert_eq!(c.side(29), 1);
    assert!((c.texel(13) - 2.0 * 4.0 / 2048.0).abs() < 1e-9, "face 1, mip 2: 4 level-0 texels");
    let key = PageKey { level: 17, x: 2, y: 1 };
    assert_eq!(c.key_of_index(c.table_index(17, IVec2::new(2, 1))), key);
    // a point light is a cube for `for_light`
    let l = crate::light::Light::Point { position: Vec3::new(1.0, 3.0, -2.0) };
    assert_eq!(Clipmap::for_light(&l, &room(), Vec3::ZERO, 16, 2048, 128, 1.0), c);
}

#[test]
fn each_direction_lands_on_its_major_axis_face_inside_the_map() {
    let (c, at) = point();
    for (f, face) in FACES.iter().enumerate() {
        let d = &face.n;
        let p = at + *d * 2.0;
        assert_eq!(c.face_of(p), f as u32);
        let (_, _, dir) = c.axes(f as u32);
        assert_eq!(dir, *d);
        assert!((c.light_coords(p) - Vec2::ONE).abs().max_element() < 1e-6, "face {f}: the axis is the centre");
    }
    // ties go to the lower axis; every direction's coordinates on its face lie in [0, 2]
    assert_eq!(face_of(Vec3::new(1.0, 1.0, 1.0)), 0);
    assert_eq!(face_of(Vec3::new(0.0, -1.0, 1.0)), 3);
    let mut seen = [0; 6];
    for i in 0..2000 {
        let t = i as f32 * 0.618;
        let v = Vec3::new((t * 1.3).sin(), (t * 0.7).cos() * 1.1, (t * 2.1).sin() * 0.9);
        let p = at + v * 3.0;
        let f = c.face_of(p);
        seen[f as usize] += 1;
        let g = c.light_coords(p);
        assert!(g.min_element() >= -1e-5 && g.max_element() <= 2.0 + 1e-5, "{v}: face {f} at {g}");
        assert!(c.light_coords_in_front(f, p).is_some());
        assert!(c.depth(p) > 0.0 && c.depth(p) < 1.0);
    }
    assert!(seen.iter().all(|n| *n > 100), "all faces are used: {seen:?}");
}

#[test]
fn a_cube_page_projection_maps_its_square_to_the_viewport_and_depth() {
    let (c, at) = point();
    for (key, (tx, ty), z) in [
        (PageKey { level: 0, x: 9, y: 4 }, (7.5, 5.5), 3.0),
        (PageKey { level: 7, x: 0, y: 3 }, (120.5, 0.5), 2.5),
        (PageKey { level: 16, x: 3, y: 0 }, (64.5, 100.5), 1.5),
        (PageKey { level: 29, x: 0, y: 0 }, (10.5, 64.5), 4.0),
    ] {
        let f = c.face(key.level);
        let (right, up, dir) = c.axes(f);
        let s = c.texel(key.level);
        let u = (key.x as f32 * 128.0 + tx) * s;
        let w = (key.y as f32 * 128.0 + ty) * s;
        let p = at + (dir + right * (u - 1.0) + up * (1.0 - w)) * z;
        assert_eq!(c.face_of(p), f, "{key:?}");
        let g = c.texel_coords(key.level, p);
        assert!((g - Vec2::new(key.x as f32 * 128.0 + tx, key.y as f32 * 128.0 + ty)).abs().max_element() < 2e-3, "{g}");
        let clip = c.page_view_proj(key) * p.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (px, py) = ((ndc.x + 1.0) * 64.0, (1.0 - ndc.y) * 64.0);
        assert!((px - tx).abs() < 2e-3 && (py - ty).abs() < 2e-3, "{key:?}: {px} {py}");
        assert!((ndc.z - c.depth(p)).abs() < 1e-6, "{} vs {}", ndc.z, c.depth(p));
    }
}

#[test]
fn a_cube_sample_marks_its_own_face_at_its_footprint() {
    let (c, at) = point();
    // on face -y (3), off its axis
    let p = at + Vec3::new(0.3, -1.0, 0.2) * 2.0;
    assert_eq!(c.face_of(p), 3);
    let t0 = c.texel0_at(p);
    assert!((t0 - 2.0 * 2.0 / 2048.0).abs() < 1e-7, "light depth 2, 90 degrees: {t0}");
    for (footprint, mip) in [(0.5 * t0, 0), (1.5 * t0, 1), (3.0 * t0, 2), (1e3 * t0, 4)] {
        let pages = c.sample_pages(p, footprint, 1.0, 1.5);
        assert!(pages.iter().all(|k| c.face(k.level) == 3), "{pages:?}");
        assert_eq!(pages.iter().map(|k| k.level).min().unwrap(), 3 + 6 * mip, "footprint {footprint}");
        assert!(pages.contains(&PageKey { level: 27, x: 0, y: 0 }), "the face's one-page mip");
    }
    // boxes: one around the light spans every face's map; one in front of a face its rectangle
    let around = Bounds { min: at - Vec3::splat(0.5), max: at + Vec3::splat(0.5) };
    assert!((0..6).all(|f| c.light_rect(f, &around).is_none()));
    let q = at + Vec3::new(0.0, 0.0, 3.0);
    let small = Bounds { min: q - Vec3::splat(0.01), max: q + Vec3::splat(0.01) };
    let touched = c.pages_touching(4, &small);
    assert!(!touched.is_empty() && touched.len() <= 4, "{touched:?}");
    assert!(touched.iter().all(|k| (7..=8).contains(&k.x) && (7..=8).contains(&k.y)));
    assert!(c.light_rect(5, &small).is_none(), "behind face -z");
}
