use super::*;
use glam::DVec4;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn bounds() -> Bounds {
    Bounds { min: Vec3::new(-5.0, 0.0, -4.0), max: Vec3::new(5.0, 3.0, 4.0) }
}

/// Map coordinates (x, y in -1..1, z in 0..1) of a world point, in f64 and through the f32 matrix.
fn ndc(m: &MinFrustum, p: DVec3) -> [DVec3; 2] {
    let c = m.view_proj * DVec4::new(p.x, p.y, p.z, 1.0);
    let c32 = m.view_proj_f32() * p.as_vec3().extend(1.0);
    [c.truncate() / c.w, (c32.truncate() / c32.w).as_dvec3()]
}

fn samples_in(rng: &mut Rng, n: usize, lo: DVec3, hi: DVec3) -> Vec<DVec3> {
    (0..n).map(|_| lo + (hi - lo) * DVec3::new(rng.next(), rng.next(), rng.next())).collect()
}

/// Every sample lands inside the map at least `inset` texels from its border, in front of the far
/// plane, and every point between it and the light (inside the scene bounds, beyond the near plane
/// of a spot) lands on the same texel, nearer.
fn check_fit(light: &Light, pts: &[DVec3], res: u32, pad: f64) -> MinFrustum {
    let side = check_fit_shape(light, pts, res, pad, RectFit::Side);
    let area = check_fit_shape(light, pts, res, pad, RectFit::Area);
    assert!(side.texel <= area.texel * (1.0 + 1e-9) && side.rect.area() >= area.rect.area() * (1.0 - 1e-9));
    area
}

fn check_fit_shape(light: &Light, pts: &[DVec3], res: u32, pad: f64, shape: RectFit) -> MinFrustum {
    let b = bounds();
    let frame = light_frame(light, &b).unwrap();
    let proj: Vec<(DVec2, f64)> = pts.iter().map(|p| frame.project(*p)).collect();
    let red = Reduction::from_samples(&proj, 1024, None).unwrap();
    assert_eq!(red.count, pts.len() as u64);
    let m = fit(light, &b, &frame, &red, res, pad, shape).unwrap();
    assert!(m.view_proj.is_finite() && m.texel > 0.0 && m.near < m.far);
    let inset = 1.0 - 2.0 * (pad - 0.5).max(0.0) / res as f64;
    for p in pts {
        for q in ndc(&m, *p) {
            assert!(q.x.abs() <= inset && q.y.abs() <= inset, "{p} maps to {q} (inset {inset})");
            assert!(q.z > 0.0 && q.z < 1.0, "{p} depth {q}");
        }
        let [q, _] = ndc(&m, *p);
        let to_light = match *light {
            Light::Directional { direction } => -direction.as_dvec3().normalize(),
            Light::Spot { position, .. } | Light::Point { position } => (position.as_dvec3() - *p).normalize(),
        };
        for t in 1..40 {
            let o = *p + to_light * (t as f64 * 0.25);
            let inside = o.cmpge(b.min.as_dvec3()).all() && o.cmple(b.max.as_dvec3()).all();
            if !inside || frame.project(o).1 < m.near {
                break;
            }
            let [r, _] = ndc(&m, o);
            assert!((r.truncate() - q.truncate()).length() < 1e-9, "occluder {o} of {p}: {r} vs {q}");
            assert!(r.z >= 0.0 && r.z < q.z, "occluder {o} of {p} at depth {} behind {}", r.z, q.z);
        }
    }
    m
}

#[test]
fn codes_keep_float_order() {
    let xs = [-1e30f32, -2.5, -1.0, -1e-30, -0.0, 0.0, 1e-30, 0.5, 3.0, 1e30];
    for w in xs.windows(2) {
        assert!(encode_max(w[0]) <= encode_max(w[1]), "{w:?}");
        assert!(encode_min(w[0]) >= encode_min(w[1]), "{w:?}");
    }
    for x in xs {
        assert_eq!(decode_max(encode_max(x)).to_bits(), x.to_bits());
        assert_eq!(decode_min(encode_min(x)).to_bits(), x.to_bits());
        assert_ne!(encode_max(x), 0);
        assert_ne!(encode_min(x), 0);
    }
    assert_eq!(band_of(0.0, 0.0, 1.0, 4, false), 0);
    assert_eq!(band_of(1.0, 0.0, 1.0, 4, false), 3);
    assert_eq!(band_of(0.5, 0.0, 1.0, 4, false), 2);
    assert_eq!(band_of(-0.5, 0.0, 1.0, 4, false), 0);
    assert_eq!(band_of(-0.5, 0.0, 1.0, 4, true), 4);
    assert_eq!(band_of(1.5, 0.0, 1.0, 4, true), 5);
    assert_eq!(band_of(1.0, 0.0, 1.0, 4, true), 3);
}

#[test]
fn directional_close_up_is_tight_and_contains_every_sample_and_occluder() {
    let mut rng = Rng(3);
    let light = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) };
    // a small patch of floor and a post on it
    let mut pts = samples_in(&mut rng, 3000, DVec3::new(1.0, 0.0, 0.0), DVec3::new(2.0, 0.0, 1.5));
    pts.extend(samples_in(&mut rng, 500, DVec3::new(1.4, 0.0, 0.4), DVec3::new(1.5, 1.0, 0.5)));
    let m = check_fit(&light, &pts, 512, 2.0);
    assert!(m.area_ratio < 0.05, "close-up rectangle covers {} of the scene map", m.area_ratio);
    assert!(!m.perspective);
}

#[test]
fn spot_close_up_contains_every_sample_and_occluder() {
    let mut rng = Rng(5);
    let light = Light::Spot { position: Vec3::new(0.0, 2.9, 0.0), direction: Vec3::new(0.1, -1.0, 0.0), cone_deg: 50.0 };
    let pts = samples_in(&mut rng, 3000, DVec3::new(-1.0, 0.0, 0.5), DVec3::new(0.5, 0.3, 2.0));
    let m = check_fit(&light, &pts, 512, 2.5);
    assert!(m.perspective && m.area_ratio < 0.5, "{}", m.area_ratio);
}

#[test]
fn full_scene_samples_give_at_most_the_scene_map() {
    let mut rng = Rng(9);
    let light = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) };
    let b = bounds();
    let pts = samples_in(&mut rng, 5000, b.min.as_dvec3(), b.max.as_dvec3());
    let m = check_fit(&light, &pts, 512, 1.0);
    assert!(m.area_ratio <= 1.02, "{}", m.area_ratio);
}

#[test]
fn reduced_hull_is_a_tight_superset_of_the_exact_one() {
    let mut rng = Rng(13);
    let light = Light::Directional { direction: Vec3::new(-0.5, -1.0, 0.1) };
    let b = bounds();
    let frame = light_frame(&light, &b).unwrap();
    // an irregular cloud: a disc on the floor
    let pts: Vec<DVec3> = (0..20000)
        .map(|_| {
            let (r, a) = (rng.next().sqrt() * 2.0, rng.next() * std::f64::consts::TAU);
            DVec3::new(r * a.cos(), 0.0, r * a.sin())
        })
        .collect();
    let proj: Vec<(DVec2, f64)> = pts.iter().map(|p| frame.project(*p)).collect();
    let exact = min_area_rect(&convex_hull(&proj.iter().map(|p| p.0).collect::<Vec<_>>())).unwrap();
    for grid in [16usize, 256, 1024] {
        let red = Reduction::from_samples(&proj, grid, None).unwrap();
        let reduced = min_area_rect(&convex_hull(&red.points())).unwrap();
        let band = (red.hi.y - red.lo.y) / grid as f64;
        assert!(reduced.area() >= exact.area() * (1.0 - 1e-6), "grid {grid}");
        // at most one band thicker on every side
        let bound = (exact.half + DVec2::splat(band)).x * (exact.half + DVec2::splat(band)).y * 4.0;
        assert!(reduced.area() <= bound * (1.0 + 1e-6), "grid {grid}: {} > {bound}", reduced.area());
        for p in &proj {
            assert!(reduced.contains(p.0, 1e-5), "grid {grid}: {} outside", p.0);
        }
    }
}

#[test]
fn degenerate_sample_sets_give_valid_maps() {
    let light = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) };
    // one sample (repeated)
    let one = vec![DVec3::new(1.0, 0.5, 1.0); 3];
    let m = check_fit(&light, &one, 512, 1.0);
    let [q, _] = ndc(&m, one[0]);
    assert!(q.x.abs() < 1e-4 && q.y.abs() < 1e-4, "{q}"); // f32 plane coordinates of the reduction
    assert_eq!(m.hull_points, 1); // one band, its x range and y range both a point
                                  // samples on a line in the light plane (a vertical edge seen along the light)
    let line: Vec<DVec3> = (0..50).map(|i| DVec3::new(-2.0, 0.0, -1.0) + DVec3::new(0.3, 0.0, 0.2) * (i as f64 * 0.1)).collect();
    check_fit(&light, &line, 512, 1.0);
    let spot = Light::Spot { position: Vec3::new(0.0, 2.9, 0.0), direction: -Vec3::Y, cone_deg: 40.0 };
    check_fit(&spot, &[DVec3::new(0.3, 0.0, 0.2)], 256, 1.0);
    // no samples: nothing to fit
    assert!(Reduction::from_samples(&[], 64, None).is_none());
    assert!(light_frame(&Light::Point { position: Vec3::ZERO }, &bounds()).is_none());
}

/// One-pass mode: bands over a prior range (the previous frame's). With the exact range it is
/// the two-pass reduction; with a wrong one every sample is still inside the hull.
#[test]
fn prior_band_range_keeps_every_sample_inside() {
    let mut rng = Rng(17);
    let light = Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) };
    let b = bounds();
    let frame = light_frame(&light, &b).unwrap();
    let pts = samples_in(&mut rng, 4000, DVec3::new(-1.0, 0.0, -1.0), DVec3::new(2.0, 1.0, 1.0));
    let proj: Vec<(DVec2, f64)> = pts.iter().map(|p| frame.project(*p)).collect();
    let two = Reduction::from_samples(&proj, 256, None).unwrap();
    let exact = Some((two.lo.y as f32, two.hi.y as f32));
    let one = Reduction::from_samples(&proj, 256, exact).unwrap();
    assert_eq!(one.points(), two.points());
    assert!(one.under.is_none() && one.over.is_none());
    let area = |r: &Reduction| min_area_rect(&convex_hull(&r.points())).unwrap().area();
    let (ylo, yhi) = (two.lo.y as f32, two.hi.y as f32);
    let h = yhi - ylo;
    for prior in [(ylo + 0.3 * h, yhi - 0.2 * h), (ylo - h, ylo - 0.5 * h), (yhi + 1.0, yhi + 2.0), (ylo + 0.5 * h, ylo + 0.5 * h)] {
        let red = Reduction::from_samples(&proj, 256, Some(prior)).unwrap();
        let hull = convex_hull(&red.points());
        let r = min_area_rect(&hull).unwrap();
        for p in &proj {
            assert!(r.contains(p.0, 1e-5), "prior {prior:?}: {} outside", p.0);
        }
        assert!(area(&red) >= area(&two) * (1.0 - 1e-9), "prior {prior:?}");
    }
}
