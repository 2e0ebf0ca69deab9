//! The conventions' per-pixel Stokes frame of a pinhole camera, in the camera frame
//! (x right, y up, z toward the viewer; the camera looks along −z; up `u = +y`).
//!
//! For the ray `d` through a pixel, `x_ref = normalize(d × u)` and `y_ref = x_ref × d`
//! (docs/conventions.md). Analysis code uses it to turn an AoLP, measured from `x_ref`
//! toward `y_ref`, into a direction in the camera frame. With an unknown field of view
//! the camera is taken as orthographic: `d = −z` everywhere, so `x_ref` and `y_ref` are
//! the image axes (exact at the image centre, a few degrees off in wide-angle corners).

use nalgebra::Vector3;

/// What the analysis knows of the camera: the horizontal field of view, if anything.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CameraModel {
    /// Parallel rays along −z (unknown field of view).
    Orthographic,
    /// A pinhole with this full horizontal field of view in degrees, square pixels.
    Pinhole {
        /// Full horizontal field of view, degrees, in (0, 180).
        fov_x_deg: f64,
    },
}

impl CameraModel {
    /// The unit ray direction (into the scene) through the centre of pixel `(x, y)` of a
    /// `width × height` image, in the camera frame.
    pub fn ray(&self, width: usize, height: usize, x: f64, y: f64) -> Vector3<f64> {
        match *self {
            CameraModel::Orthographic => -Vector3::z(),
            CameraModel::Pinhole { fov_x_deg } => {
                let tan_x = (0.5 * fov_x_deg.to_radians()).tan();
                let tan_y = tan_x * height as f64 / width as f64;
                let sx = (2.0 * (x + 0.5) / width as f64 - 1.0) * tan_x;
                let sy = (1.0 - 2.0 * (y + 0.5) / height as f64) * tan_y;
                Vector3::new(sx, sy, -1.0).normalize()
            }
        }
    }

    /// `(d, x_ref, y_ref)` at pixel `(x, y)`: the ray and the conventions' Stokes frame.
    pub fn frame(&self, width: usize, height: usize, x: f64, y: f64) -> PixelFrame {
        let d = self.ray(width, height, x, y);
        let x_ref = d.cross(&Vector3::y()).normalize();
        let y_ref = x_ref.cross(&d);
        PixelFrame { d, x_ref, y_ref }
    }
}

/// The ray through a pixel and the Stokes frame of the light arriving along it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelFrame {
    /// Unit ray direction from the camera into the scene.
    pub d: Vector3<f64>,
    /// Reference axis of the Stokes frame (angles are measured from it).
    pub x_ref: Vector3<f64>,
    /// `x_ref × d`: the axis angles turn toward.
    pub y_ref: Vector3<f64>,
}

impl PixelFrame {
    /// The unit vector in the frame's plane at angle `psi` from `x_ref` toward `y_ref`.
    pub fn in_plane(&self, psi: f64) -> Vector3<f64> {
        self.x_ref * psi.cos() + self.y_ref * psi.sin()
    }

    /// The surface normal facing the camera whose projection on the frame's plane lies at
    /// angle `azimuth` from `x_ref` and which makes angle `zenith` with the view vector `−d`.
    pub fn normal(&self, azimuth: f64, zenith: f64) -> Vector3<f64> {
        -self.d * zenith.cos() + self.in_plane(azimuth) * zenith.sin()
    }

    /// `(azimuth, zenith)` of a normal `n` (inverse of [`Self::normal`]); azimuth in `[0, 2π)`.
    pub fn angles(&self, n: &Vector3<f64>) -> (f64, f64) {
        let (a, b, c) = (n.dot(&self.x_ref), n.dot(&self.y_ref), -n.dot(&self.d));
        let azimuth = b.atan2(a).rem_euclid(std::f64::consts::TAU);
        (azimuth, a.hypot(b).atan2(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_frame_is_the_image_axes() {
        let cam = CameraModel::Pinhole { fov_x_deg: 60.0 };
        // Pixel (49.5, 24.5) of a 100x50 image is the exact centre.
        let f = cam.frame(100, 50, 49.5, 24.5);
        assert!((f.d + Vector3::z()).norm() < 1e-12);
        assert!((f.x_ref - Vector3::x()).norm() < 1e-12);
        assert!((f.y_ref - Vector3::y()).norm() < 1e-12);
        assert_eq!(CameraModel::Orthographic.frame(7, 3, 0.0, 0.0), f);
    }

    #[test]
    fn corner_frame_is_orthonormal_and_right_handed_against_the_light() {
        let cam = CameraModel::Pinhole { fov_x_deg: 90.0 };
        let f = cam.frame(64, 48, 0.0, 0.0);
        assert!(f.x_ref.dot(&f.d).abs() < 1e-12 && f.y_ref.dot(&f.d).abs() < 1e-12);
        assert!((f.x_ref.norm() - 1.0).abs() < 1e-12 && (f.y_ref.norm() - 1.0).abs() < 1e-12);
        // (x_ref, y_ref, −d) right-handed: x_ref × y_ref = −d.
        assert!((f.x_ref.cross(&f.y_ref) + f.d).norm() < 1e-12);
        // Top-left pixel: the ray goes left and up.
        assert!(f.d.x < 0.0 && f.d.y > 0.0);
    }

    #[test]
    fn normal_and_angles_are_inverse() {
        let f = CameraModel::Pinhole { fov_x_deg: 70.0 }.frame(32, 32, 3.0, 29.0);
        for &(az, ze) in &[(0.3, 0.2), (2.0, 1.2), (4.0, 0.01), (6.0, 1.5)] {
            let n = f.normal(az, ze);
            assert!((n.norm() - 1.0).abs() < 1e-12);
            let (a, z) = f.angles(&n);
            assert!((a - az).abs() < 1e-9 && (z - ze).abs() < 1e-9, "{a} {z}");
        }
    }
}
