//! Light types. `direction` is where the light travels (the seeds' and the GUIDE's convention).

use glam::Vec3;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Light {
    Directional { direction: Vec3 },
    Spot { position: Vec3, direction: Vec3, cone_deg: f32 },
    Point { position: Vec3 },
}

impl Light {
    pub fn kind(&self) -> &'static str {
        match self {
            Light::Directional { .. } => "directional",
            Light::Spot { .. } => "spot",
            Light::Point { .. } => "point",
        }
    }
    /// Unit vector from a surface point towards the light.
    pub fn to_light(&self, p: Vec3) -> Vec3 {
        match *self {
            Light::Directional { direction } => -direction.normalize(),
            Light::Spot { position, .. } | Light::Point { position } => (position - p).normalize_or_zero(),
        }
    }
    /// Whether `p` is inside the spot cone (always true for other lights).
    pub fn in_cone(&self, p: Vec3) -> bool {
        match *self {
            Light::Spot { position, direction, cone_deg } => {
                (p - position).normalize_or_zero().dot(direction.normalize()) > cone_deg.to_radians().cos()
            }
            _ => true,
        }
    }
    pub fn validate(&self) -> Result<(), String> {
        let finite = match *self {
            Light::Directional { direction } => direction.is_finite() && direction.length() > 1e-6,
            Light::Spot { position, direction, cone_deg } => {
                if !(cone_deg > 0.0 && cone_deg < 90.0) {
                    return Err(format!("spot cone_deg {cone_deg} must be in (0, 90)"));
                }
                position.is_finite() && direction.is_finite() && direction.length() > 1e-6
            }
            Light::Point { position } => position.is_finite(),
        };
        if finite {
            Ok(())
        } else {
            Err(format!("{} light needs a finite position and a non-zero direction", self.kind()))
        }
    }
}

/// Whether a G-buffer sample is evaluated for this light: geometry present, facing the light,
/// inside a spot cone. The GPU computes the same test in `mask.wgsl`; this copy serves tests.
pub fn evaluated(light: &Light, pos: Vec3, normal: Vec3) -> bool {
    normal.dot(light.to_light(pos)) > 0.0 && light.in_cone(pos)
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn cone_and_facing() {
        let l = Light::Spot { position: Vec3::new(0.0, 5.0, 0.0), direction: -Vec3::Y, cone_deg: 30.0 };
        assert!(l.in_cone(Vec3::ZERO));
        assert!(!l.in_cone(Vec3::new(10.0, 0.0, 0.0)));
        assert!(evaluated(&l, Vec3::ZERO, Vec3::Y));
        assert!(!evaluated(&l, Vec3::ZERO, -Vec3::Y));
        let d = Light::Directional { direction: Vec3::new(0.0, -1.0, 0.0) };
        assert_eq!(d.to_light(Vec3::ZERO), Vec3::Y);
    }
}
