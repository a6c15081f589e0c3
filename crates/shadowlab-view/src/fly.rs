//! Camera motion, pure: fly (WASD/QE and mouse look), orbit (the scripted runs' camera), light
//! direction from azimuth and elevation. The camera is the state: with no input it is returned
//! bit for bit, so an unmoved view is exactly the setup's.

use glam::{Quat, Vec3};
use shadowlab_core::camera::Camera;
use shadowlab_core::light::Light;

/// One frame's fly input: movement axes in -1..1 and mouse look in radians.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlyInput {
    /// +W / -S
    pub forward: f32,
    /// +D / -A
    pub right: f32,
    /// +E / -Q (world up)
    pub up: f32,
    /// Mouse look: yaw (to the right) and pitch (up), radians.
    pub yaw: f32,
    pub pitch: f32,
}

impl FlyInput {
    pub fn is_idle(&self) -> bool {
        *self == FlyInput::default()
    }
}

/// Steepest pitch the fly camera reaches (just short of vertical, where look-at flips).
const MAX_PITCH: f32 = 89.0_f32 * std::f32::consts::PI / 180.0;

/// Moves `cam` by `input` over `dt` seconds at `speed` world units per second.
pub fn fly(cam: &Camera, input: &FlyInput, dt: f32, speed: f32) -> Camera {
    if input.is_idle() {
        return *cam;
    }
    let mut c = *cam;
    let offset = cam.target - cam.position;
    let dist = offset.length().max(1e-3);
    let mut dir = offset / dist;
    if input.yaw != 0.0 || input.pitch != 0.0 {
        let pitch = dir.y.clamp(-1.0, 1.0).asin();
        let new_pitch = (pitch + input.pitch).clamp(-MAX_PITCH, MAX_PITCH);
        let flat = Vec3::new(dir.x, 0.0, dir.z).normalize_or(Vec3::NEG_Z);
        let flat = Quat::from_rotation_y(-input.yaw) * flat;
        dir = flat * new_pitch.cos() + Vec3::Y * new_pitch.sin();
    }
    let right = dir.cross(Vec3::Y).normalize_or(Vec3::X);
    let step = (dir * input.forward + right * input.right + Vec3::Y * input.up) * speed * dt;
    c.position += step;
    c.target = c.position + dir * dist;
    c
}

/// Turns the camera's position about the vertical axis through its target by `deg` degrees.
pub fn orbit(cam: &Camera, deg: f32) -> Camera {
    if deg == 0.0 {
        return *cam;
    }
    let mut c = *cam;
    c.position = cam.target + Quat::from_rotation_y(deg.to_radians()) * (cam.position - cam.target);
    c
}

/// Turns the light about the vertical axis by `deg` degrees: a sun's direction, a point or spot
/// light's position about the vertical through `about` (a spot's direction turns with it).
pub fn turn_light(light: &Light, deg: f32, about: Vec3) -> Light {
    let q = Quat::from_rotation_y(deg.to_radians());
    match *light {
        Light::Directional { direction } => Light::Directional { direction: q * direction },
        Light::Point { position } => Light::Point { position: about + q * (position - about) },
        Light::Spot { position, direction, cone_deg } => {
            Light::Spot { position: about + q * (position - about), direction: q * direction, cone_deg }
        }
    }
}

/// Where a directional light travels, from the sun's azimuth (degrees from +X towards +Z) and
/// elevation above the horizon (degrees).
pub fn sun_direction(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (a, e) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    -Vec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

/// The inverse of [`sun_direction`]: (azimuth, elevation) in degrees.
pub fn sun_angles(direction: Vec3) -> (f32, f32) {
    let to_sun = -direction.normalize_or(Vec3::NEG_Y);
    (to_sun.z.atan2(to_sun.x).to_degrees(), to_sun.y.clamp(-1.0, 1.0).asin().to_degrees())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> Camera {
        Camera::new(Vec3::new(1.0, 2.0, 5.0), Vec3::new(0.5, 1.0, -3.0), 60.0, 0.1, 100.0)
    }

    #[test]
    fn no_input_keeps_the_camera_bit_for_bit() {
        assert_eq!(fly(&cam(), &FlyInput::default(), 0.016, 3.0), cam());
        assert_eq!(orbit(&cam(), 0.0), cam());
    }

    #[test]
    fn forward_moves_along_the_view_and_keeps_the_direction() {
        let c = cam();
        let d = (c.target - c.position).normalize();
        let m = fly(&c, &FlyInput { forward: 1.0, ..Default::default() }, 0.5, 2.0);
        assert!((m.position - (c.position + d)).length() < 1e-5, "{:?}", m.position);
        assert!(((m.target - m.position).normalize() - d).length() < 1e-5);
        let up = fly(&c, &FlyInput { up: 1.0, ..Default::default() }, 1.0, 2.0);
        assert!((up.position - (c.position + Vec3::Y * 2.0)).length() < 1e-5);
    }

    #[test]
    fn look_turns_right_and_pitch_stops_short_of_vertical() {
        let c = Camera::new(Vec3::ZERO, Vec3::NEG_Z, 60.0, 0.1, 100.0);
        let r = fly(&c, &FlyInput { yaw: std::f32::consts::FRAC_PI_2, ..Default::default() }, 1.0, 1.0);
        assert!((r.target - Vec3::X).length() < 1e-5, "turning right from -Z faces +X: {:?}", r.target);
        let up = fly(&c, &FlyInput { pitch: 3.0, ..Default::default() }, 1.0, 1.0);
        let pitch = (up.target - up.position).normalize().y.asin();
        assert!((pitch - MAX_PITCH).abs() < 1e-4);
        assert!(up.validate().is_ok());
    }

    #[test]
    fn orbit_keeps_distance_and_target() {
        let c = cam();
        let o = orbit(&c, 90.0);
        assert_eq!(o.target, c.target);
        assert!(((o.position - o.target).length() - (c.position - c.target).length()).abs() < 1e-4);
        assert!((o.position.y - c.position.y).abs() < 1e-5);
        let back = orbit(&orbit(&c, 30.0), -30.0);
        assert!((back.position - c.position).length() < 1e-4);
    }

    #[test]
    fn sun_angles_round_trip() {
        for (a, e) in [(0.0, 45.0), (120.0, 10.0), (-60.0, 80.0)] {
            let d = sun_direction(a, e);
            assert!(d.y < 0.0, "the sun above the horizon shines down");
            let (a2, e2) = sun_angles(d);
            assert!((a2 - a).abs() < 1e-3 && (e2 - e).abs() < 1e-3, "{a},{e} -> {a2},{e2}");
        }
    }
}
