//! Dual-paraboloid mapping for point lights (seed 002 section 3.3.2, eq. 3.3-3.10): the CPU
//! reference of what `dpsm` and `dpsm-notw` do in WGSL (warp/params.wgsl `base_clip`).
//!
//! Split plane: the plane through the light perpendicular to the split axis `a` (default +Y:
//! a horizontal plane, so the floor is in one hemisphere and the ceiling in the other). The
//! *front* hemisphere holds the directions d with dot(d, a) >= 0, the *back* one the rest; a
//! point on the plane belongs to the front. Each hemisphere has a right-handed light space
//! whose +z is its axis (front: a, back: -a); the back basis is the front one turned 180 degrees
//! about its y axis, so neither map is mirrored.
//!
//! The mapping of a light-space direction n (unit, n.z >= 0) to the map plane is the point of the
//! paraboloid f(x, y) = 1/2 - (x^2 + y^2)/2 whose normal is n + (0, 0, 1) (eq. 3.8-3.10):
//! (X, Y) = (n.x, n.y) / (1 + n.z), |(X, Y)| <= 1 on the hemisphere. Map coordinates are
//! u = 0.5 + X/2, v = 0.5 - Y/2 (v down, like a texture); depth = distance / far (linear, 0 at
//! the light). The inverse is n = (2X, 2Y, 1 - X^2 - Y^2) / (1 + X^2 + Y^2).
//!
//! One map texel spans 2/res in X; the mapping is conformal with dtheta/dX = 1 + n.z, so a
//! texel covers 2 (1 + n.z) / res radians: twice as much at the centre as at the rim.

use glam::{Mat3, Mat4, Vec2, Vec3};

use crate::scene::Bounds;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hemisphere {
    Front,
    Back,
}

impl Hemisphere {
    pub const BOTH: [Hemisphere; 2] = [Hemisphere::Front, Hemisphere::Back];
    pub fn name(self) -> &'static str {
        match self {
            Hemisphere::Front => "front",
            Hemisphere::Back => "back",
        }
    }
}

/// Names of the split axes (`split` parameter): the axis of the front hemisphere.
pub const SPLIT_AXES: &[&str] = &["y", "x", "z"];

/// The axis of `SPLIT_AXES[i]`.
pub fn split_axis(i: usize) -> Option<Vec3> {
    [Vec3::Y, Vec3::X, Vec3::Z].get(i).copied()
}

/// A point light's two paraboloid maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DualParaboloid {
    pub position: Vec3,
    /// Axis of the front hemisphere (unit).
    pub axis: Vec3,
    /// Depth 1 (farther points are clamped out of the map); > 0.
    pub far: f32,
}

impl DualParaboloid {
    /// Maps for a light at `position`, `far` reaching every corner of `bounds` (1 % margin).
    /// None when the axis is zero or the light is not finite.
    pub fn fit(position: Vec3, axis: Vec3, bounds: &Bounds) -> Option<DualParaboloid> {
        let axis = axis.try_normalize()?;
        if !position.is_finite() || !bounds.is_valid() {
            return None;
        }
        let far = bounds.corners().iter().map(|c| c.distance(position)).fold(0.0f32, f32::max).max(1e-3) * 1.01;
        Some(DualParaboloid { position, axis, far })
    }

    /// The hemisphere `p` lies in (the plane belongs to the front).
    pub fn hemisphere_of(&self, p: Vec3) -> Hemisphere {
        if (p - self.position).dot(self.axis) >= 0.0 {
            Hemisphere::Front
        } else {
            Hemisphere::Back
        }
    }

    /// World-to-light rotation of hemisphere `h` (rows: x, y, z = hemisphere axis).
    pub fn rotation(&self, h: Hemisphere) -> Mat3 {
        let a = self.axis;
        // any vector not parallel to a gives the x axis
        let helper = if a.y.abs() < 0.9 { Vec3::Y } else { Vec3::Z };
        let x = helper.cross(a).normalize();
        let (x, z) = match h {
            Hemisphere::Front => (x, a),
            Hemisphere::Back => (-x, -a),
        };
        let y = z.cross(x);
        Mat3::from_cols(x, y, z).transpose()
    }

    /// The matrix the shaders receive: world -> light space of `h`, scaled by 1/far (so the
    /// length of the result is the stored depth and its direction is n).
    pub fn view(&self, h: Hemisphere) -> Mat4 {
        Mat4::from_scale(Vec3::splat(1.0 / self.far)) * Mat4::from_mat3(self.rotation(h)) * Mat4::from_translation(-self.position)
    }

    /// Map plane point (X, Y) of a light-space unit direction n (eq. 3.10).
    pub fn plane_point(n: Vec3) -> Vec2 {
        Vec2::new(n.x, n.y) / (1.0 + n.z)
    }

    /// Light-space unit direction of the map plane point (X, Y) (inverse of [`plane_point`](Self::plane_point)).
    pub fn plane_direction(xy: Vec2) -> Vec3 {
        let r2 = xy.length_squared();
        Vec3::new(2.0 * xy.x, 2.0 * xy.y, 1.0 - r2) / (1.0 + r2)
    }

    /// Map coordinates (u, v in [0,1] on the hemisphere, v down) and depth (distance / far) of
    /// world point `p` in the map of `h`. None at the light itself.
    pub fn project(&self, h: Hemisphere, p: Vec3) -> Option<(Vec2, f32)> {
        let l = self.view(h).transform_point3(p);
        let d = l.length();
        if d <= 1e-12 || 1.0 + l.z / d <= 1e-12 {
            return None;
        }
        let xy = Self::plane_point(l / d);
        Some((Vec2::new(0.5 + 0.5 * xy.x, 0.5 - 0.5 * xy.y), d))
    }

    /// The world point at map coordinates `uv` and depth `depth` of the map of `h`.
    pub fn unproject(&self, h: Hemisphere, uv: Vec2, depth: f32) -> Vec3 {
        let n = Self::plane_direction(Vec2::new(2.0 * uv.x - 1.0, 1.0 - 2.0 * uv.y));
        self.position + self.rotation(h).transpose() * n * (depth * self.far)
    }

    /// Angle (radians) one texel of a `res` map spans at world point `p` of hemisphere `h`.
    pub fn texel_angle(&self, h: Hemisphere, p: Vec3, res: u32) -> f32 {
        let n = (self.rotation(h) * (p - self.position)).normalize_or_zero();
        2.0 * (1.0 + n.z) / res as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lamp() -> DualParaboloid {
        let b = Bounds { min: Vec3::new(-5.0, 0.0, -4.0), max: Vec3::new(5.0, 3.0, 4.0) };
        DualParaboloid::fit(Vec3::new(0.5, 1.5, -0.3), Vec3::Y, &b).unwrap()
    }

    /// Directions on a Fibonacci sphere.
    fn sphere(n: usize) -> Vec<Vec3> {
        let g = std::f32::consts::PI * (3.0 - 5f32.sqrt());
        (0..n)
            .map(|i| {
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                let t = g * i as f32;
                Vec3::new(r * t.cos(), y, r * t.sin())
            })
            .collect()
    }

    #[test]
    fn far_reaches_every_corner() {
        let l = lamp();
        let b = Bounds { min: Vec3::new(-5.0, 0.0, -4.0), max: Vec3::new(5.0, 3.0, 4.0) };
        for c in b.corners() {
            assert!(c.distance(l.position) < l.far, "{c}");
        }
        assert!(DualParaboloid::fit(Vec3::ZERO, Vec3::ZERO, &b).is_none());
    }

    #[test]
    fn direction_round_trips_through_map_coordinates() {
        for axis in [Vec3::Y, Vec3::X, Vec3::new(0.3, -1.0, 0.2)] {
            let mut l = lamp();
            l.axis = axis.normalize();
            for d in sphere(2000) {
                let p = l.position + d * 2.7;
                let h = l.hemisphere_of(p);
                let (uv, depth) = l.project(h, p).unwrap();
                // the own hemisphere lands inside the disc inscribed in the map
                let r = (uv - Vec2::splat(0.5)).length() * 2.0;
                assert!(r <= 1.0 + 1e-5, "{d} -> {uv} (r {r})");
                assert!((depth * l.far - 2.7).abs() < 1e-4, "{depth}");
                let back = l.unproject(h, uv, depth);
                assert!(back.distance(p) < 1e-4 * 2.7, "{p} -> {uv} -> {back}");
            }
        }
    }

    #[test]
    fn known_directions_land_where_eq_3_10_puts_them() {
        let l = lamp();
        // straight along the front axis: the map centre; along the back axis: the back map's centre
        let (c, _) = l.project(Hemisphere::Front, l.position + Vec3::Y).unwrap();
        assert!(c.distance(Vec2::splat(0.5)) < 1e-6, "{c}");
        let (c, _) = l.project(Hemisphere::Back, l.position - Vec3::Y * 3.0).unwrap();
        assert!(c.distance(Vec2::splat(0.5)) < 1e-6, "{c}");
        // 90 degrees off the axis: on the rim (r = 1); 60 degrees: r = tan(30 deg)
        let (c, _) = l.project(Hemisphere::Front, l.position + Vec3::X).unwrap();
        assert!(((c - Vec2::splat(0.5)).length() * 2.0 - 1.0).abs() < 1e-6, "{c}");
        let d = Vec3::new(60f32.to_radians().sin(), 60f32.to_radians().cos(), 0.0);
        let (c, _) = l.project(Hemisphere::Front, l.position + d).unwrap();
        assert!(((c - Vec2::splat(0.5)).length() * 2.0 - 30f32.to_radians().tan()).abs() < 1e-5, "{c}");
        // the opposite direction has no image
        assert!(l.project(Hemisphere::Front, l.position - Vec3::Y).is_none());
    }

    #[test]
    fn hemisphere_split_is_consistent() {
        let l = lamp();
        for d in sphere(3000) {
            let p = l.position + d * 1.3;
            let h = l.hemisphere_of(p);
            assert_eq!(h == Hemisphere::Front, d.y >= 0.0, "{d}");
            let other = if h == Hemisphere::Front { Hemisphere::Back } else { Hemisphere::Front };
            let r_own = (l.project(h, p).unwrap().0 - Vec2::splat(0.5)).length() * 2.0;
            assert!(r_own <= 1.0 + 1e-5);
            // in the other map the point lies outside the disc (or has no image)
            if let Some((uv, _)) = l.project(other, p) {
                let r = (uv - Vec2::splat(0.5)).length() * 2.0;
                assert!(r >= 1.0 - 1e-5, "{d}: r {r} in the other map");
            }
        }
        // a point on the split plane lies on both rims, at the same world position
        let p = l.position + Vec3::new(0.6, 0.0, 0.8);
        let (a, da) = l.project(Hemisphere::Front, p).unwrap();
        let (b, db) = l.project(Hemisphere::Back, p).unwrap();
        assert!(((a - Vec2::splat(0.5)).length() * 2.0 - 1.0).abs() < 1e-5);
        assert!(((b - Vec2::splat(0.5)).length() * 2.0 - 1.0).abs() < 1e-5);
        assert!((da - db).abs() < 1e-6);
        assert!(l.unproject(Hemisphere::Back, b, db).distance(p) < 1e-5);
        // the back map is the front one turned about y, not mirrored: x flips, y stays
        assert!((a.x - 0.5 + (b.x - 0.5)).abs() < 1e-5 && (a.y - b.y).abs() < 1e-5, "{a} {b}");
    }

    #[test]
    fn texel_angle_doubles_from_rim_to_centre() {
        let l = lamp();
        let centre = l.texel_angle(Hemisphere::Front, l.position + Vec3::Y, 512);
        let rim = l.texel_angle(Hemisphere::Front, l.position + Vec3::X, 512);
        assert!((centre / rim - 2.0).abs() < 1e-5);
        // against a finite difference of the mapping
        let p = l.position + Vec3::new(0.3, 0.8, 0.1);
        let (uv, d) = l.project(Hemisphere::Front, p).unwrap();
        let q = l.unproject(Hemisphere::Front, uv + Vec2::new(1.0 / 512.0, 0.0), d);
        let angle = (p - l.position).angle_between(q - l.position);
        let expect = l.texel_angle(Hemisphere::Front, p, 512);
        assert!((angle / expect - 1.0).abs() < 0.01, "{angle} vs {expect}");
    }
}
