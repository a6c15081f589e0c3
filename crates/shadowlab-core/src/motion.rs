//! Rigid motions over time and the animations a scene records (which triangles move, how):
//! the data a `Scene` holds. Selecting triangles and moving them is `anim`.

use std::f32::consts::TAU;

use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// A rigid motion as a function of time in frames; `transform(0)` is the identity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
pub enum Motion {
    /// Back and forth along a segment: displacement `offset * (1 - cos(2 pi t / period)) / 2`
    /// (at rest at t = 0, at `offset` at half the period, smooth turns at both ends).
    Translate { offset: Vec3, period: f32 },
    /// Swinging about the line through `pivot` along `axis`: angle `amplitude_deg * sin(2 pi t / period)`
    /// (right-handed about `axis`). Wires, banners, pendulums.
    Sway { pivot: Vec3, axis: Vec3, amplitude_deg: f32, period: f32 },
    /// Full turns about the line through `center` along `axis`: angle `2 pi t / period`
    /// (negative period: the other way round). Fans, carousels.
    Orbit { center: Vec3, axis: Vec3, period: f32 },
}

/// Rotation by `angle` (radians) about the line through `p` along unit `axis`.
fn rotation_about(p: Vec3, axis: Vec3, angle: f32) -> Mat4 {
    Mat4::from_translation(p) * Mat4::from_axis_angle(axis, angle) * Mat4::from_translation(-p)
}

impl Motion {
    /// The object's transform at time `t` (frames), applied to its pose at t = 0.
    pub fn transform(&self, t: f32) -> Mat4 {
        match *self {
            Motion::Translate { offset, period } => {
                let s = 0.5 * (1.0 - (TAU * t / period).cos());
                Mat4::from_translation(offset * s)
            }
            Motion::Sway { pivot, axis, amplitude_deg, period } => {
                rotation_about(pivot, axis.normalize(), amplitude_deg.to_radians() * (TAU * t / period).sin())
            }
            Motion::Orbit { center, axis, period } => rotation_about(center, axis.normalize(), TAU * t / period),
        }
    }

    /// Bad periods, axes and amplitudes are errors (never NaN geometry later).
    pub fn validate(&self) -> Result<(), String> {
        let (period, finite) = match *self {
            Motion::Translate { offset, period } => (period, offset.is_finite()),
            Motion::Sway { pivot, axis, amplitude_deg, period } => {
                if axis.length() < 1e-6 {
                    return Err("sway axis must be non-zero".into());
                }
                if !(amplitude_deg.is_finite() && amplitude_deg.abs() <= 180.0) {
                    return Err(format!("sway amplitude_deg {amplitude_deg} must be in [-180, 180]"));
                }
                (period, pivot.is_finite() && axis.is_finite())
            }
            Motion::Orbit { center, axis, period } => {
                if axis.length() < 1e-6 {
                    return Err("orbit axis must be non-zero".into());
                }
                (period, center.is_finite() && axis.is_finite())
            }
        };
        let ok_period = match self {
            Motion::Orbit { .. } => period.is_finite() && period.abs() >= 1e-3,
            _ => period.is_finite() && period >= 1e-3,
        };
        if !ok_period {
            return Err(format!("period {period} must be a finite number of frames > 0 (orbit: != 0)"));
        }
        if !finite {
            return Err("motion vectors must be finite".into());
        }
        Ok(())
    }

    /// Largest rotation (radians) between two times `period / samples` apart (0 for translations).
    pub(crate) fn max_angle_step(&self, samples: usize) -> f32 {
        let phase_step = TAU / samples as f32;
        match *self {
            Motion::Translate { .. } => 0.0,
            // d/dphase (A sin phase) <= A
            Motion::Sway { amplitude_deg, .. } => amplitude_deg.abs().to_radians() * phase_step,
            Motion::Orbit { .. } => phase_step,
        }
    }

    /// One full period in frames.
    pub fn period(&self) -> f32 {
        match *self {
            Motion::Translate { period, .. } | Motion::Sway { period, .. } | Motion::Orbit { period, .. } => period.abs(),
        }
    }
}

/// An animation resolved against a scene: triangles `first..first + count` move with `motion`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Animation {
    pub name: String,
    pub first: usize,
    pub count: usize,
    pub motion: Motion,
}
