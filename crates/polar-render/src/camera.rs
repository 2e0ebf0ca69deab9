//! Pinhole camera in the conventions' camera frame: x right, y up, z toward
//! the viewer (the camera looks along -z), row 0 at the top.

use crate::math::Vec3;
use crate::scene::Camera;

/// A camera ready to generate rays.
#[derive(Clone, Debug)]
pub(crate) struct PinholeCamera {
    pub position: Vec3,
    /// Camera x axis (image right) in world space.
    right: Vec3,
    /// Camera y axis (image up) in world space.
    up: Vec3,
    /// Viewing direction (camera -z) in world space.
    forward: Vec3,
    /// The user's up vector `u` of the per-pixel Stokes reference frame.
    user_up: Vec3,
    tan_x: f64,
    tan_y: f64,
    width: f64,
    height: f64,
}

impl PinholeCamera {
    /// Sets up the camera; `camera` must have been validated (distinct position and
    /// look-at, up not parallel to the view direction).
    pub fn new(camera: &Camera) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        let right = forward.cross(&camera.up).normalize();
        let up = right.cross(&forward);
        let tan_x = (0.5 * camera.fov_deg.to_radians()).tan();
        let (width, height) = (camera.width as f64, camera.height as f64);
        Self {
            position: camera.position,
            right,
            up,
            forward,
            user_up: camera.up.normalize(),
            tan_x,
            tan_y: tan_x * height / width,
            width,
            height,
        }
    }

    /// Unit direction of the ray through image point `(x, y)` in pixel units
    /// (`(0, 0)` is the top-left corner of the image).
    pub fn direction(&self, x: f64, y: f64) -> Vec3 {
        let sx = (2.0 * x / self.width - 1.0) * self.tan_x;
        let sy = (1.0 - 2.0 * y / self.height) * self.tan_y;
        (self.forward + sx * self.right + sy * self.up).normalize()
    }

    /// A world vector in the camera frame (x right, y up, z toward the viewer).
    pub fn to_camera(&self, v: &Vec3) -> Vec3 {
        Vec3::new(v.dot(&self.right), v.dot(&self.up), -v.dot(&self.forward))
    }

    /// Depth of a world point: its distance along the viewing axis (camera -z).
    pub fn depth(&self, p: &Vec3) -> f64 {
        (p - self.position).dot(&self.forward)
    }

    /// The x axis of the conventions' per-pixel Stokes frame for the ray
    /// direction `d`: `x_ref = normalize(d × u)` (then `y_ref = x_ref × d`).
    /// Never inlined: the integrator asks for it only when needed, and inlined, the
    /// compiler hoisted its square root and division out of that condition.
    #[inline(never)]
    pub fn film_frame(&self, d: &Vec3) -> Vec3 {
        d.cross(&self.user_up).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> PinholeCamera {
        PinholeCamera::new(&Camera {
            position: Vec3::new(0.0, 0.0, 5.0),
            look_at: Vec3::zeros(),
            up: Vec3::y(),
            fov_deg: 90.0,
            width: 200,
            height: 100,
        })
    }

    #[test]
    fn image_corners_follow_the_horizontal_fov() {
        let c = cam();
        // fov 90° horizontal: the right edge of the centre row is 45° off axis; the top edge is atan(0.5).
        let d = c.direction(200.0, 50.0);
        assert!((d - Vec3::new(1.0, 0.0, -1.0).normalize()).norm() < 1e-12);
        let d = c.direction(100.0, 0.0);
        assert!((d - Vec3::new(0.0, 0.5, -1.0).normalize()).norm() < 1e-12);
        assert!((c.to_camera(&Vec3::z()) - Vec3::z()).norm() < 1e-12);
        assert!((c.depth(&Vec3::new(3.0, 1.0, 1.0)) - 4.0).abs() < 1e-12);
    }

    #[test]
    fn film_frame_at_the_centre_is_image_x() {
        // At the image centre x_ref is image right (world x here) and y_ref = x_ref × d is image up.
        let c = cam();
        let d = c.direction(100.0, 50.0);
        let x = c.film_frame(&d);
        assert!((x - Vec3::x()).norm() < 1e-12, "{x}");
        assert!((x.cross(&d) - Vec3::y()).norm() < 1e-12);
    }
}
