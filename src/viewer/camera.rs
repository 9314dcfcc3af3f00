//! The viewer's camera: orbit around the look-at point, or fly.

use glam::{DQuat, DVec3};

use crate::model::scene::Camera;

/// Closest the eye may come to the look-at point, as a fraction of the
/// starting distance.
const MIN_DISTANCE: f64 = 1e-3;
/// Largest angle between the view direction and the up axis kept away from it (radians).
const POLE_MARGIN: f64 = 0.02;

/// A camera moved by mouse and keys. Orbiting turns the eye around the
/// look-at point; flying moves both, with steps proportional to their
/// distance so that the speed suits the scene's scale.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraController {
    /// The eye.
    pub position: DVec3,
    /// The look-at point.
    pub target: DVec3,
    up: DVec3,
    start_distance: f64,
    home: (DVec3, DVec3),
}

impl CameraController {
    /// Starts at the scene's camera.
    pub fn new(camera: &Camera) -> Self {
        let up = camera.up.try_normalize().unwrap_or(DVec3::Y);
        let start_distance = (camera.look_at - camera.position).length().max(1e-9);
        Self {
            position: camera.position,
            target: camera.look_at,
            up,
            start_distance,
            home: (camera.position, camera.look_at),
        }
    }

    /// Back to the scene's camera.
    pub fn reset(&mut self) {
        (self.position, self.target) = self.home;
    }

    fn distance(&self) -> f64 {
        (self.target - self.position).length()
    }

    /// Turns `v` (a direction from a centre) by `yaw` about the up axis and
    /// `pitch` about the horizontal axis across it, keeping it off the poles.
    fn turn(&self, v: DVec3, yaw: f64, pitch: f64) -> DVec3 {
        let v = DQuat::from_axis_angle(self.up, yaw) * v;
        let right = v.cross(self.up).try_normalize();
        let Some(right) = right else { return v };
        let turned = DQuat::from_axis_angle(right, pitch) * v;
        let angle = turned.normalize().dot(self.up).clamp(-1.0, 1.0).acos();
        if !(POLE_MARGIN..=std::f64::consts::PI - POLE_MARGIN).contains(&angle) {
            v
        } else {
            turned
        }
    }

    /// Orbits the eye around the look-at point (radians).
    pub fn orbit(&mut self, yaw: f64, pitch: f64) {
        let offset = self.position - self.target;
        self.position = self.target + self.turn(offset, yaw, pitch);
    }

    /// Turns the view direction around the eye (radians).
    pub fn look(&mut self, yaw: f64, pitch: f64) {
        let dir = self.target - self.position;
        self.target = self.position + self.turn(dir, yaw, -pitch);
    }

    /// Moves eye and target together, in steps of 5% of their distance:
    /// `forward` along the view, `right` across it, `up` along the up axis.
    pub fn fly(&mut self, forward: f64, right: f64, up: f64) {
        let dir = (self.target - self.position).normalize();
        let side = dir.cross(self.up).try_normalize().unwrap_or(DVec3::X);
        let step = 0.05 * self.distance();
        let delta = (dir * forward + side * right + self.up * up) * step;
        self.position += delta;
        self.target += delta;
    }

    /// Moves the eye toward the look-at point (positive) or away, by 10% of
    /// the distance per step.
    pub fn dolly(&mut self, steps: f64) {
        let offset = self.position - self.target;
        let d = offset.length();
        let new = (d * 0.9f64.powf(steps)).max(MIN_DISTANCE * self.start_distance);
        self.position = self.target + offset * (new / d);
    }

    /// Writes the eye and look-at point into `camera`.
    pub fn apply(&self, camera: &mut Camera) {
        camera.position = self.position;
        camera.look_at = self.target;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::still(DVec3::new(0.0, 1.0, 5.0), DVec3::ZERO, DVec3::Y, 40.0)
    }

    #[test]
    fn orbiting_keeps_the_distance_and_the_target() {
        let mut c = CameraController::new(&camera());
        let d = c.distance();
        c.orbit(0.7, 0.3);
        assert!((c.distance() - d).abs() < 1e-12);
        assert_eq!(c.target, DVec3::ZERO);
        assert_ne!(c.position, camera().position);
        c.reset();
        assert_eq!(c.position, camera().position);
    }

    #[test]
    fn orbiting_never_crosses_the_pole() {
        let mut c = CameraController::new(&camera());
        for _ in 0..100 {
            c.orbit(0.0, 0.2);
        }
        let dir = (c.position - c.target).normalize();
        assert!(dir.dot(DVec3::Y).abs() < 1.0 - 1e-5, "{dir}");
        assert!(c.position.is_finite());
    }

    #[test]
    fn flying_moves_eye_and_target_together() {
        let mut c = CameraController::new(&camera());
        let before = c.target - c.position;
        c.fly(1.0, 0.5, -0.5);
        assert!(((c.target - c.position) - before).length() < 1e-12);
        let mut d = CameraController::new(&camera());
        d.dolly(100.0);
        assert!(d.distance() > 0.0 && d.distance() < 0.01);
    }
}
