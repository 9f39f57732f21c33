//! An orbit camera: it looks at a target from a distance, turned by yaw and pitch; y is up.

use glam::{Mat4, Vec2, Vec3};

/// Vertical field of view, radians.
const FOV_Y: f32 = 0.8;

/// Where the viewer stands and looks.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct OrbitCamera {
    /// The point looked at and orbited around.
    pub target: Vec3,
    /// Turn about the y axis, radians.
    pub yaw: f32,
    /// Elevation above the horizontal, radians, within ±(π/2 − 0.01).
    pub pitch: f32,
    /// Distance from the target.
    pub distance: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self {
            target: Vec3::new(0.0, 0.5, 0.0),
            yaw: 0.6,
            pitch: 0.45,
            distance: 3.0,
        }
    }
}

impl OrbitCamera {
    /// A camera at the default angles that shows the whole box [lo, hi] in a view of the given
    /// aspect ratio (width / height).
    pub fn framing(lo: Vec3, hi: Vec3, aspect: f32) -> Self {
        let mut camera = OrbitCamera::default();
        camera.frame(lo, hi, aspect);
        camera
    }

    /// Keeps the angles and moves so that the box [lo, hi] fills a view of the given aspect
    /// ratio: its bounding sphere, with a margin for arrows, fits the narrower of the two fields
    /// of view.
    pub fn frame(&mut self, lo: Vec3, hi: Vec3, aspect: f32) {
        let radius = ((hi - lo).length() * 0.5).max(1e-3);
        let half_y = FOV_Y * 0.5;
        let half_x = (half_y.tan() * aspect.max(1e-3)).atan();
        self.target = (lo + hi) * 0.5;
        self.distance = radius / half_x.min(half_y).sin() * 1.25;
    }

    /// The camera's position.
    pub fn eye(&self) -> Vec3 {
        let direction = Vec3::new(
            self.pitch.cos() * self.yaw.sin(),
            self.pitch.sin(),
            self.pitch.cos() * self.yaw.cos(),
        );
        self.target + direction * self.distance
    }

    /// World to clip space for a view of the given aspect ratio (width / height).
    pub fn view_projection(&self, aspect: f32) -> Mat4 {
        let view = Mat4::look_at_rh(self.eye(), self.target, Vec3::Y);
        let projection = Mat4::perspective_rh(
            FOV_Y,
            aspect.max(1e-3),
            self.distance * 0.01,
            self.distance * 100.0,
        );
        projection * view
    }

    /// Brings a camera read from outside (a link) within the ranges the controls keep: the
    /// pitch short of straight up or down, the distance and target within 10⁶.
    pub fn keep_in_range(&mut self) {
        self.pitch = self.pitch.clamp(-1.56, 1.56);
        self.distance = self.distance.clamp(1e-3, 1e6);
        self.target = self.target.clamp(Vec3::splat(-1e6), Vec3::splat(1e6));
    }

    /// Turns the camera by a pointer movement of `delta` points.
    pub fn orbit(&mut self, delta: Vec2) {
        self.yaw -= delta.x * 0.008;
        self.pitch = (self.pitch + delta.y * 0.008).clamp(-1.56, 1.56);
    }

    /// Slides the target in the view plane by a pointer movement of `delta` points in a view
    /// `height` points tall, so the point under the pointer stays under it.
    pub fn pan(&mut self, delta: Vec2, height: f32) {
        let forward = (self.target - self.eye()).normalize();
        let right = forward.cross(Vec3::Y).normalize();
        let up = right.cross(forward);
        let units_per_point = 2.0 * self.distance * (FOV_Y * 0.5).tan() / height.max(1.0);
        self.target += (-right * delta.x + up * delta.y) * units_per_point;
    }

    /// Moves closer (`steps` > 0) or farther, 10 % per step.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * 0.9f32.powf(steps)).clamp(1e-3, 1e6);
    }

    /// The ray through a point of the view, with `ndc` in [−1, 1]² (y up): origin and unit
    /// direction.
    pub fn ray(&self, ndc: Vec2, aspect: f32) -> (Vec3, Vec3) {
        let inverse = self.view_projection(aspect).inverse();
        let near = inverse.project_point3(ndc.extend(0.0));
        let far = inverse.project_point3(ndc.extend(1.0));
        (near, (far - near).normalize())
    }

    /// The unit vector from the eye toward the target.
    pub fn forward(&self) -> Vec3 {
        (self.target - self.eye()).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_target_projects_to_the_centre_and_the_ray_there_hits_it() {
        let camera =
            OrbitCamera::framing(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0), 1.5);
        let clip = camera.view_projection(1.5).project_point3(camera.target);
        assert!(clip.truncate().length() < 1e-5);
        let (origin, direction) = camera.ray(Vec2::ZERO, 1.5);
        let to_target = camera.target - origin;
        assert!(to_target.cross(direction).length() < 1e-3 * to_target.length());
    }

    #[test]
    fn framing_keeps_the_whole_box_in_view() {
        let (lo, hi) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.5, 0.5));
        for aspect in [0.4, 1.0, 2.5] {
            let camera = OrbitCamera::framing(lo, hi, aspect);
            let m = camera.view_projection(aspect);
            for corner in 0..8 {
                let p = Vec3::new(
                    if corner & 1 == 0 { lo.x } else { hi.x },
                    if corner & 2 == 0 { lo.y } else { hi.y },
                    if corner & 4 == 0 { lo.z } else { hi.z },
                );
                let ndc = m.project_point3(p);
                assert!(
                    ndc.x.abs() <= 1.0 && ndc.y.abs() <= 1.0,
                    "aspect {aspect}: corner {p} at {ndc}"
                );
            }
        }
    }

    #[test]
    fn orbit_pan_and_zoom_move_the_camera_as_named() {
        let mut camera = OrbitCamera::default();
        let distance = camera.distance;
        camera.zoom(1.0);
        assert!((camera.distance - 0.9 * distance).abs() < 1e-6);
        let target = camera.target;
        camera.pan(Vec2::new(10.0, 0.0), 500.0);
        assert!(camera.target != target && (camera.target.y - target.y).abs() < 1e-6);
        camera.orbit(Vec2::new(0.0, 1e6));
        assert!(camera.pitch <= 1.56);
    }
}
