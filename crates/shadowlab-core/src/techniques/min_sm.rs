//! Planar convex hull (Andrew's monotone chain) and the minimum-area enclosing rectangle by
//! rotating calipers (Toussaint 1983), in f64. The CPU half of `min-sm` (the minimal shadow
//! frustum of seeds 000 section 3.2 / 002 section 4.1.5); [`frustum`] turns the rectangle into a
//! light projection.
//!
//! Robustness: non-finite points are dropped; exact duplicates are merged; collinear points are
//! dropped from the hull (`cross <= 0` pops), so the hull is strictly convex and counter-clockwise.
//! Degenerate inputs give degenerate but valid answers: no point -> empty hull and no rectangle;
//! one distinct point -> a one-vertex hull and a zero-size rectangle at it; collinear points ->
//! the two end points and a zero-width rectangle along the segment.

pub mod frustum;

use glam::DVec2;

/// z of the cross product (b - a) x (c - a): > 0 when a, b, c turn counter-clockwise.
fn cross(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    (b - a).perp_dot(c - a)
}

/// Convex hull, counter-clockwise from the lowest-x (then lowest-y) point, without collinear or
/// repeated vertices. O(n log n).
pub fn convex_hull(points: &[DVec2]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = points.iter().copied().filter(|q| q.is_finite()).collect();
    p.sort_unstable_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup();
    if p.len() < 3 {
        return p;
    }
    let mut h: Vec<DVec2> = Vec::with_capacity(p.len() + 1);
    // lower chain left to right, then upper chain right to left
    for pass in 0..2 {
        let start = h.len();
        let it: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 { Box::new(p.iter()) } else { Box::new(p.iter().rev()) };
        for &q in it {
            while h.len() >= start + 2 && cross(h[h.len() - 2], h[h.len() - 1], q) <= 0.0 {
                h.pop();
            }
            h.push(q);
        }
        h.pop(); // the last point of each chain starts the other
    }
    // all points collinear: the chains cancel down to the two end points
    if h.len() < 2 {
        return vec![p[0], p[p.len() - 1]];
    }
    h
}

/// A rectangle: `center + s * axis * half.x + t * axis.perp() * half.y` for s, t in [-1, 1].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    pub center: DVec2,
    /// Unit vector along the first side.
    pub axis: DVec2,
    /// Half extents along `axis` and `axis.perp()` (>= 0).
    pub half: DVec2,
}

impl Rect {
    pub fn area(&self) -> f64 {
        4.0 * self.half.x * self.half.y
    }
    /// Coordinates of `p` in the rectangle's frame, -1..1 inside (a zero half extent maps to 0).
    pub fn local(&self, p: DVec2) -> DVec2 {
        let d = p - self.center;
        let s = |v: f64, h: f64| if h > 0.0 { v / h } else { 0.0 };
        DVec2::new(s(d.dot(self.axis), self.half.x), s(d.dot(self.axis.perp()), self.half.y))
    }
    /// Whether `p` is inside, with an absolute tolerance `eps` on each side.
    pub fn contains(&self, p: DVec2, eps: f64) -> bool {
        let d = p - self.center;
        d.dot(self.axis).abs() <= self.half.x + eps && d.dot(self.axis.perp()).abs() <= self.half.y + eps
    }
}

/// The rectangle with sides along the unit `axis` that bounds `points` (tightest for that axis).
pub fn bounding_rect(points: &[DVec2], axis: DVec2) -> Option<Rect> {
    let n = axis.perp();
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for p in points.iter().filter(|p| p.is_finite()) {
        let q = DVec2::new(p.dot(axis), p.dot(n));
        lo = lo.min(q);
        hi = hi.max(q);
    }
    if !lo.is_finite() {
        return None;
    }
    let mid = (lo + hi) * 0.5;
    Some(Rect { center: axis * mid.x + n * mid.y, axis, half: (hi - lo) * 0.5 })
}

/// Minimum-area rectangle enclosing a hull from [`convex_hull`] (CCW, strictly convex), by
/// rotating calipers: one side of an optimal rectangle lies on a hull edge (Freeman & Shapira
/// 1975), and the extreme vertices along each edge direction and its normal move monotonically
/// around the hull, so all edges are tried in O(n).
pub fn min_area_rect(hull: &[DVec2]) -> Option<Rect> {
    let n = hull.len();
    match n {
        0 => return None,
        1 => return Some(Rect { center: hull[0], axis: DVec2::X, half: DVec2::ZERO }),
        2 => {
            let d = hull[1] - hull[0];
            let axis = d.try_normalize().unwrap_or(DVec2::X);
            return Some(Rect { center: (hull[0] + hull[1]) * 0.5, axis, half: DVec2::new(d.length() * 0.5, 0.0) });
        }
        _ => {}
    }
    let at = |i: usize| hull[i % n];
    // caliper indices: max along the edge (j), farthest from the edge (k), min along the edge (m)
    let (mut j, mut k, mut m) = (1usize, 1usize, 1usize);
    let mut best: Option<(f64, Rect)> = None;
    for i in 0..n {
        let Some(e) = (at(i + 1) - at(i)).try_normalize() else { continue };
        let nl = e.perp(); // inward normal of a CCW hull
        if i == 0 {
            j = 1;
        }
        let mut guard = 0;
        while at(j + 1).dot(e) > at(j).dot(e) && guard < n {
            j += 1;
            guard += 1;
        }
        if i == 0 {
            k = j;
        }
        guard = 0;
        while at(k + 1).dot(nl) > at(k).dot(nl) && guard < n {
            k += 1;
            guard += 1;
        }
        if i == 0 {
            m = k;
        }
        guard = 0;
        while at(m + 1).dot(e) < at(m).dot(e) && guard < n {
            m += 1;
            guard += 1;
        }
        let (lo_e, hi_e) = (at(m).dot(e), at(j).dot(e));
        let (lo_n, hi_n) = (at(i).dot(nl), at(k).dot(nl));
        let area = (hi_e - lo_e) * (hi_n - lo_n);
        if best.as_ref().is_none_or(|(a, _)| area < *a) {
            let center = e * (0.5 * (lo_e + hi_e)) + nl * (0.5 * (lo_n + hi_n));
            let half = DVec2::new(0.5 * (hi_e - lo_e), 0.5 * (hi_n - lo_n));
            best = Some((area, Rect { center, axis: e, half }));
        }
    }
    best.map(|(_, r)| r)
}

/// The enclosing rectangle whose longer side is shortest: for a square map it gives the smallest
/// (square) texel, where [`min_area_rect`] gives the most texels per area but may stretch them.
/// max(w, h) over the orientation is piecewise sinusoidal: w and h alone are concave between
/// the hull-edge orientations (their breakpoints), so the minimum is at a breakpoint or where
/// w = h inside an interval. All are tried; O(n^2) for n hull vertices (n is small here).
pub fn min_side_rect(hull: &[DVec2]) -> Option<Rect> {
    if hull.len() < 3 {
        return min_area_rect(hull);
    }
    let quarter = std::f64::consts::FRAC_PI_2;
    let n = hull.len();
    let mut cuts: Vec<f64> =
        (0..n).filter_map(|i| (hull[(i + 1) % n] - hull[i]).try_normalize()).map(|e| e.y.atan2(e.x).rem_euclid(quarter)).collect();
    cuts.sort_by(f64::total_cmp);
    let mut candidates = cuts.clone();
    for (i, &a) in cuts.iter().enumerate() {
        let b = if i + 1 < cuts.len() { cuts[i + 1] } else { cuts[0] + quarter };
        if b - a < 1e-15 {
            continue;
        }
        // extreme vertices are fixed inside (a, b): w = d1 . u, h = d2 . u.perp()
        let mid = DVec2::from_angle(0.5 * (a + b));
        let span = |dir: DVec2| {
            let (lo, hi) = hull.iter().fold((hull[0], hull[0]), |(lo, hi), p| {
                (if p.dot(dir) < lo.dot(dir) { *p } else { lo }, if p.dot(dir) > hi.dot(dir) { *p } else { hi })
            });
            hi - lo
        };
        let (d1, d2) = (span(mid), span(mid.perp()));
        // d1.x c + d1.y s = d2.y c - d2.x s
        let t = (d2.y - d1.x).atan2(d1.y + d2.x);
        for k in -2..=2 {
            let th = t + k as f64 * std::f64::consts::PI;
            if th > a && th < b {
                candidates.push(th);
            }
        }
    }
    candidates
        .iter()
        .filter_map(|&th| bounding_rect(hull, DVec2::from_angle(th)))
        .min_by(|r, s| r.half.max_element().total_cmp(&s.half.max_element()).then(r.area().total_cmp(&s.area())))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// splitmix64: a deterministic generator for the random point sets.
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

    /// Brute force: the best bounding rectangle over every hull-edge orientation.
    fn brute_min_area(points: &[DVec2], hull: &[DVec2]) -> f64 {
        (0..hull.len())
            .filter_map(|i| (hull[(i + 1) % hull.len()] - hull[i]).try_normalize())
            .map(|e| bounding_rect(points, e).unwrap().area())
            .fold(f64::INFINITY, f64::min)
    }

    fn check_hull(points: &[DVec2], hull: &[DVec2]) {
        let scale = points.iter().map(|p| p.abs().max_element()).fold(1.0, f64::max);
        for i in 0..hull.len() {
            assert!(points.contains(&hull[i]), "hull vertex {} is not an input point", hull[i]);
            if hull.len() >= 3 {
                let (a, b, c) = (hull[i], hull[(i + 1) % hull.len()], hull[(i + 2) % hull.len()]);
                assert!(cross(a, b, c) > 0.0, "hull not strictly convex CCW at {b}");
                for p in points {
                    assert!(cross(a, b, *p) >= -1e-12 * scale * scale, "{p} outside hull edge {a} {b}");
                }
            }
        }
    }

    fn random_set(rng: &mut Rng, n: usize, kind: usize) -> Vec<DVec2> {
        (0..n)
            .map(|_| {
                let (u, v) = (rng.next(), rng.next());
                match kind {
                    0 => DVec2::new(u * 10.0 - 5.0, v * 3.0 + 1.0),
                    // disc, rotated ellipse: many near-collinear hull vertices
                    1 => {
                        let (r, a) = (v.sqrt(), u * std::f64::consts::TAU);
                        let q = DVec2::new(r * a.cos() * 7.0, r * a.sin());
                        DVec2::from_angle(0.6).rotate(q) + DVec2::new(100.0, -40.0)
                    }
                    // on a coarse integer grid: duplicates and collinear runs
                    _ => DVec2::new((u * 6.0).floor(), (v * 4.0).floor()),
                }
            })
            .collect()
    }

    #[test]
    fn rotating_calipers_match_brute_force_on_random_sets() {
        let mut rng = Rng(7);
        for trial in 0..300 {
            let n = 3 + (rng.next() * 200.0) as usize;
            let pts = random_set(&mut rng, n, trial % 3);
            let hull = convex_hull(&pts);
            check_hull(&pts, &hull);
            let r = min_area_rect(&hull).unwrap();
            let brute = brute_min_area(&pts, &hull);
            assert!((r.area() - brute).abs() <= 1e-9 * brute.max(1e-12), "trial {trial}: calipers {} brute {brute}", r.area());
            let tol = 1e-9 * (1.0 + r.center.length() + r.half.max_element());
            assert!(pts.iter().all(|p| r.contains(*p, tol)), "trial {trial}: a point is outside the rectangle");
            // any other orientation is no smaller (sampled)
            for s in 0..16 {
                let a = bounding_rect(&pts, DVec2::from_angle(s as f64 * 0.19)).unwrap().area();
                assert!(a >= r.area() * (1.0 - 1e-9), "trial {trial}: angle {s} gives {a} < {}", r.area());
            }
        }
    }

    #[test]
    fn min_side_rect_beats_every_sampled_orientation() {
        let mut rng = Rng(21);
        for trial in 0..200 {
            let n = 3 + (rng.next() * 60.0) as usize;
            let pts = random_set(&mut rng, n, trial % 3);
            let hull = convex_hull(&pts);
            let r = min_side_rect(&hull).unwrap();
            let side = r.half.max_element();
            let tol = 1e-9 * (1.0 + r.center.length() + side);
            assert!(pts.iter().all(|p| r.contains(*p, tol)), "trial {trial}");
            for s in 0..2000 {
                let q = bounding_rect(&pts, DVec2::from_angle(s as f64 * std::f64::consts::FRAC_PI_2 / 2000.0)).unwrap();
                assert!(q.half.max_element() >= side - tol, "trial {trial}: angle {s} gives {} < {side}", q.half.max_element());
            }
            // never smaller in area than the minimum-area rectangle
            assert!(r.area() >= min_area_rect(&hull).unwrap().area() * (1.0 - 1e-9));
        }
        // a 4 x 1 rectangle: min area keeps it (4 x 1), min side turns it to 45 degrees (5/sqrt 2 square)
        let h = convex_hull(&[DVec2::ZERO, DVec2::new(4.0, 0.0), DVec2::new(4.0, 1.0), DVec2::new(0.0, 1.0)]);
        let r = min_side_rect(&h).unwrap();
        assert!((r.half.max_element() * 2.0 - 5.0 / 2f64.sqrt()).abs() < 1e-9, "{r:?}");
        assert!((min_area_rect(&h).unwrap().area() - 4.0).abs() < 1e-12);
    }

    #[test]
    fn known_rectangles() {
        // a unit square rotated by 30 degrees, plus interior points: area 1 at 30 degrees
        let rot = DVec2::from_angle(30f64.to_radians());
        let mut pts: Vec<DVec2> = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.5, 0.5), (0.2, 0.9)]
            .iter()
            .map(|&(x, y)| rot.rotate(DVec2::new(x, y)))
            .collect();
        pts.extend(pts.clone()); // duplicates
        let hull = convex_hull(&pts);
        assert_eq!(hull.len(), 4);
        let r = min_area_rect(&hull).unwrap();
        assert!((r.area() - 1.0).abs() < 1e-12, "{}", r.area());
        assert!((r.axis.dot(rot.rotate(DVec2::X)).abs() - 1.0).abs() < 1e-12 || r.axis.dot(rot.rotate(DVec2::X)).abs() < 1e-12);
        // a right triangle's best rectangle has one side on a leg: area = legs' product
        let tri = [DVec2::new(0.0, 0.0), DVec2::new(4.0, 0.0), DVec2::new(0.0, 3.0)];
        let r = min_area_rect(&convex_hull(&tri)).unwrap();
        assert!((r.area() - 12.0).abs() < 1e-12, "{}", r.area());
    }

    #[test]
    fn degenerate_inputs() {
        assert!(convex_hull(&[]).is_empty());
        assert!(min_area_rect(&[]).is_none());
        // one sample, repeated
        let p = DVec2::new(3.0, -2.0);
        let h = convex_hull(&[p, p, p]);
        assert_eq!(h, vec![p]);
        let r = min_area_rect(&h).unwrap();
        assert_eq!((r.center, r.area()), (p, 0.0));
        assert!(r.contains(p, 0.0));
        // two points
        let h = convex_hull(&[DVec2::new(1.0, 1.0), DVec2::new(0.0, 0.0)]);
        assert_eq!(h, vec![DVec2::new(0.0, 0.0), DVec2::new(1.0, 1.0)]);
        // collinear points (with duplicates and out of order): the end points, a zero-width rectangle
        let line: Vec<DVec2> = [3.0, 0.0, 1.0, 2.0, 2.0, -1.5].iter().map(|&t| DVec2::new(1.0, 2.0) + DVec2::new(2.0, 1.0) * t).collect();
        let h = convex_hull(&line);
        assert_eq!(h, vec![line[5], line[0]]);
        let r = min_area_rect(&h).unwrap();
        assert_eq!(r.area(), 0.0);
        assert!((r.half.x - 4.5 * 5f64.sqrt() * 0.5).abs() < 1e-12);
        assert!(line.iter().all(|q| r.contains(*q, 1e-12)));
        // vertical collinear points
        let v: Vec<DVec2> = (0..5).map(|i| DVec2::new(2.0, i as f64)).collect();
        assert_eq!(convex_hull(&v), vec![v[0], v[4]]);
        // non-finite points are ignored
        let h = convex_hull(&[DVec2::new(f64::NAN, 0.0), DVec2::new(0.0, 0.0), DVec2::new(f64::INFINITY, 1.0)]);
        assert_eq!(h, vec![DVec2::ZERO]);
        // collinear points plus one off the line: a triangle
        let mut t = line.clone();
        t.push(DVec2::new(0.0, 5.0));
        let h = convex_hull(&t);
        assert_eq!(h.len(), 3);
        check_hull(&t, &h);
    }

    #[test]
    fn hull_of_a_reduced_cloud_matches_brute_force() {
        // 4 points per light-space row for 1024 rows: what min-sm's GPU reduction reads back
        let mut rng = Rng(11);
        let pts: Vec<DVec2> = (0..4096).map(|_| DVec2::new(rng.next(), rng.next())).collect();
        let hull = convex_hull(&pts);
        check_hull(&pts, &hull);
        let r = min_area_rect(&hull).unwrap();
        assert!((r.area() - brute_min_area(&pts, &hull)).abs() < 1e-9);
    }
}
