//! Light-space projections for shadow maps, fitted to the scene bounds (CPU half of `sm`).

use glam::{Mat4, Vec3, Vec4Swizzles};

use crate::camera::{look_at, orthographic, perspective};
use crate::light::Light;
use crate::scene::Bounds;

/// A shadow map's projection. Depth is post-projective, 0 near the light.
#[derive(Clone, Copy, Debug)]
pub struct LightProjection {
    pub view_proj: Mat4,
    /// Orthographic: world size of one texel. Perspective: the same per unit of light-view depth.
    pub texel: f32,
    pub perspective: bool,
}

fn up_for(dir: Vec3) -> Vec3 {
    if dir.normalize().cross(Vec3::Y).length_squared() < 1e-4 {
        Vec3::Z
    } else {
        Vec3::Y
    }
}

/// Directional light: an orthographic box around the scene bounds, looking along the light.
/// Spot light: a perspective frustum with the cone's angle (plus a one-texel margin), near and
/// far fitted to the bounds. Point lights need cube/paraboloid maps: `None`.
pub fn fit(light: &Light, bounds: &Bounds, res: u32) -> Option<LightProjection> {
    let diag = bounds.diagonal().max(1e-6);
    match *light {
        Light::Directional { direction } => {
            let d = direction.normalize();
            let c = bounds.center();
            let view = look_at(c - d * diag, c, up_for(d));
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for p in bounds.corners() {
                let q = (view * p.extend(1.0)).xyz();
                lo = lo.min(q);
                hi = hi.max(q);
            }
            // square texels: use the larger extent for both axes
            let ext = (hi.x - lo.x).max(hi.y - lo.y) * 0.5 * 1.001;
            let (cx, cy) = ((hi.x + lo.x) * 0.5, (hi.y + lo.y) * 0.5);
            let margin = diag * 1e-3;
            let proj = orthographic(cx - ext, cx + ext, cy - ext, cy + ext, -hi.z - margin, -lo.z + margin);
            Some(LightProjection { view_proj: proj * view, texel: 2.0 * ext / res as f32, perspective: false })
        }
        Light::Spot { position, direction, cone_deg } => {
            let d = direction.normalize();
            let view = look_at(position, position + d, up_for(d));
            let far = bounds.corners().iter().map(|p| (*p - position).length()).fold(0.0f32, f32::max).max(diag * 1e-3);
            let near = (far * 1e-3).max(1e-4);
            let half = cone_deg.to_radians();
            let half = (half.tan() * (1.0 + 2.0 / res as f32)).atan();
            let proj = perspective(2.0 * half, 1.0, near, far);
            Some(LightProjection { view_proj: proj * view, texel: 2.0 * half.tan() / res as f32, perspective: true })
        }
        Light::Point { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn directional_box_contains_the_scene() {
        let b = Bounds { min: Vec3::new(-5.0, 0.0, -3.0), max: Vec3::new(5.0, 2.0, 3.0) };
        let lp = fit(&Light::Directional { direction: Vec3::new(0.3, -1.0, 0.2) }, &b, 512).unwrap();
        for p in b.corners() {
            let c = lp.view_proj * p.extend(1.0);
            let n = c.xyz() / c.w;
            assert!(n.x.abs() <= 1.0 && n.y.abs() <= 1.0 && (0.0..=1.0).contains(&n.z), "{n}");
        }
        // a point further along the light direction is deeper
        let a = lp.view_proj * Vec3::new(0.0, 2.0, 0.0).extend(1.0);
        let z = lp.view_proj * Vec3::new(0.0, 0.0, 0.0).extend(1.0);
        assert!(a.z < z.z);
    }
    #[test]
    fn spot_frustum_covers_the_cone() {
        let b = Bounds { min: Vec3::splat(-4.0), max: Vec3::splat(4.0) };
        let l = Light::Spot { position: Vec3::new(0.0, 3.0, 0.0), direction: -Vec3::Y, cone_deg: 30.0 };
        let lp = fit(&l, &b, 256).unwrap();
        // a point on the cone's edge 2 m below the light maps inside the map
        let edge = Vec3::new(2.0 * 30f32.to_radians().tan() * 0.999, 1.0, 0.0);
        let c = lp.view_proj * edge.extend(1.0);
        let n = c.xyz() / c.w;
        assert!(n.x.abs() < 1.0 && n.y.abs() < 1.0 && (0.0..1.0).contains(&n.z), "{n}");
        assert!(fit(&Light::Point { position: Vec3::ZERO }, &b, 256).is_none());
    }
}
