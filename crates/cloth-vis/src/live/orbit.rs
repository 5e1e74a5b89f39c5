//! The viewer's orbit camera: the eye turns about a target, pans with it and moves towards it.

use glam::{Quat, Vec3};
use render::Camera;

/// The closest the view direction comes to the up axis in an orbit (degrees): the camera
/// never flips over the pole.
pub const POLE_MARGIN_DEG: f32 = 2.0;

/// An orbiting camera: `eye` turns about `target` around the fixed world `up` (yaw) and the
/// camera's right axis (pitch); pan moves both; zoom scales their distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// World-space eye.
    pub eye: Vec3,
    /// The point orbited and looked at.
    pub target: Vec3,
    /// World up (the yaw axis).
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub fov_y_deg: f32,
    /// The objects' bounding sphere (centre, radius): near and far planes enclose it.
    pub bounds: (Vec3, f32),
}

impl Orbit {
    /// The orbit starting at `camera`, with near and far planes kept around the sphere
    /// `bounds`.
    pub fn from_camera(camera: &Camera, bounds: (Vec3, f32)) -> Self {
        Self {
            eye: camera.eye,
            target: camera.target,
            up: camera.up.try_normalize().unwrap_or(Vec3::Y),
            fov_y_deg: camera.fov_y_deg,
            bounds,
        }
    }

    /// Turn the eye `yaw_deg` about the up axis through the target (right-handed: +90° takes
    /// an eye on +Z to +X for up = +Y) and `pitch_deg` about the camera's right axis (positive
    /// raises the eye), stopping [`POLE_MARGIN_DEG`] short of the poles.
    pub fn orbit(&mut self, yaw_deg: f32, pitch_deg: f32) {
        let offset = self.eye - self.target;
        let yawed = Quat::from_axis_angle(self.up, yaw_deg.to_radians()) * offset;
        let Some(right) = self.up.cross(yawed).try_normalize() else {
            self.eye = self.target + yawed;
            return;
        };
        // The angle from the up axis, kept inside (margin, 180° − margin).
        let polar = yawed.angle_between(self.up).to_degrees();
        let margin = POLE_MARGIN_DEG;
        let wanted = (polar - pitch_deg).clamp(margin, 180.0 - margin);
        let pitched = Quat::from_axis_angle(right, (wanted - polar).to_radians()) * yawed;
        self.eye = self.target + pitched;
    }

    /// Move eye and target across the view by `dx`, `dy` fractions of the view's height at
    /// the target's distance (positive: the scene moves right and up on screen).
    pub fn pan(&mut self, dx: f32, dy: f32) {
        let forward = (self.target - self.eye).normalize_or_zero();
        let right = forward.cross(self.up).normalize_or_zero();
        let up = right.cross(forward);
        let height = 2.0 * self.distance() * (0.5 * self.fov_y_deg.to_radians()).tan();
        let shift = (-dx * right - dy * up) * height;
        self.eye += shift;
        self.target += shift;
    }

    /// Scale the eye's distance to the target by `factor` (< 1 moves closer), kept above a
    /// thousandth of the objects' radius.
    pub fn zoom(&mut self, factor: f32) {
        let offset = self.eye - self.target;
        let min = 1e-3 * render::usable_radius(self.bounds.1);
        let length = (offset.length() * factor).max(min);
        self.eye = self.target + offset.normalize_or(Vec3::Z) * length;
    }

    /// The eye's distance to the target.
    pub fn distance(&self) -> f32 {
        self.eye.distance(self.target)
    }

    /// The camera of a `width × height` frame.
    pub fn camera(&self, width: u32, height: u32) -> Camera {
        let (centre, radius) = self.bounds;
        Camera::looking_at_sphere(
            self.eye,
            self.target,
            self.up,
            self.fov_y_deg,
            width,
            height,
            centre,
            render::usable_radius(radius),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn orbit() -> Orbit {
        let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 64, 64);
        Orbit::from_camera(&camera, (Vec3::ZERO, 1.0))
    }

    #[test]
    fn yaw_turns_about_up_right_handed() {
        let mut o = orbit();
        o.orbit(90.0, 0.0);
        assert!(
            (o.eye - Vec3::new(3.0, 0.0, 0.0)).length() < 1e-5,
            "{}",
            o.eye
        );
        o.orbit(-90.0, 0.0);
        assert!(
            (o.eye - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-5,
            "{}",
            o.eye
        );
    }

    #[test]
    fn pitch_raises_the_eye_and_stops_at_the_pole() {
        let mut o = orbit();
        o.orbit(0.0, 30.0);
        let expected = Vec3::new(0.0, 3.0 * 0.5, 3.0 * 0.75f32.sqrt());
        assert!((o.eye - expected).length() < 1e-5, "{}", o.eye);
        o.orbit(0.0, 500.0);
        let polar = o.eye.angle_between(Vec3::Y).to_degrees();
        assert!((polar - POLE_MARGIN_DEG).abs() < 1e-3, "{polar}");
        assert!((o.distance() - 3.0).abs() < 1e-5);
    }

    #[test]
    fn pan_moves_eye_and_target_together_and_zoom_keeps_the_direction() {
        let mut o = orbit();
        o.pan(0.5, 0.0);
        assert!((o.eye - o.target - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-5);
        let height = 2.0 * 3.0 * (20f32).to_radians().tan();
        assert!((o.target - Vec3::new(-0.5 * height, 0.0, 0.0)).length() < 1e-5);
        o.zoom(0.5);
        assert!((o.distance() - 1.5).abs() < 1e-5);
        o.zoom(0.0);
        assert!((o.distance() - 1e-3).abs() < 1e-6);
    }
}
