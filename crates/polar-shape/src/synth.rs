//! Analytic test scenes: Stokes planes rendered with the forward reflection models
//! through the per-pixel frame of a pinhole camera.

use nalgebra::Vector3;
use polar_image::{Gray, LinearStokesImage};
use polar_optics::pixel_frame::CameraModel;
use polar_optics::reflection_dolp::{diffuse_dolp, specular_dolp};
use polar_sensor::{Observation, StokesPlanes};

/// What a surface point reflects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// Diffuse polarization, AoLP = azimuth.
    Diffuse,
    /// Specular polarization, AoLP = azimuth + 90°.
    Specular,
}

/// One rendered pixel: the true normal (zero if background) and Stokes.
pub struct Scene {
    pub width: usize,
    pub height: usize,
    pub camera: CameraModel,
    pub normals: Vec<Vector3<f64>>,
    pub stokes: Vec<[f32; 3]>,
}

impl Scene {
    /// Renders `surface(d) -> Option<(normal, kind, s0)>` for each pixel ray `d`;
    /// background pixels get unpolarized `background` S0.
    pub fn render(
        width: usize,
        height: usize,
        fov_x_deg: f64,
        ior: f64,
        background: f64,
        surface: impl Fn(Vector3<f64>) -> Option<(Vector3<f64>, Kind, f64)>,
    ) -> Self {
        let camera = CameraModel::Pinhole { fov_x_deg };
        let mut normals = Vec::new();
        let mut stokes = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let f = camera.frame(width, height, x as f64, y as f64);
                match surface(f.d) {
                    Some((n, kind, s0)) => {
                        let (az, ze) = f.angles(&n);
                        let (rho, aolp) = match kind {
                            Kind::Diffuse => (diffuse_dolp(ze, ior), az),
                            Kind::Specular => {
                                (specular_dolp(ze, ior), az + std::f64::consts::FRAC_PI_2)
                            }
                        };
                        normals.push(n);
                        stokes.push([
                            s0 as f32,
                            (s0 * rho * (2.0 * aolp).cos()) as f32,
                            (s0 * rho * (2.0 * aolp).sin()) as f32,
                        ]);
                    }
                    None => {
                        normals.push(Vector3::zeros());
                        stokes.push([background as f32, 0.0, 0.0]);
                    }
                }
            }
        }
        Self {
            width,
            height,
            camera,
            normals,
            stokes,
        }
    }

    /// The observation of the rendered Stokes, scaled by `scale`.
    pub fn observation(&self, scale: f32) -> Observation {
        let data = self
            .stokes
            .iter()
            .flat_map(|s| s.map(|v| v * scale))
            .collect();
        let img = LinearStokesImage::from_vec(self.width, self.height, data).unwrap();
        Observation::new(StokesPlanes::from_linear_stokes(&img), self.camera)
    }

    /// Mask of pixels with a true normal.
    pub fn object_mask(&self) -> Gray<u8> {
        let data = self
            .normals
            .iter()
            .map(|n| u8::from(n.norm_squared() > 0.0))
            .collect();
        Gray::from_vec(self.width, self.height, data).unwrap()
    }

    /// True normals as an image.
    pub fn normal_image(&self) -> polar_image::NormalImage {
        let data = self
            .normals
            .iter()
            .flat_map(|n| [n.x as f32, n.y as f32, n.z as f32])
            .collect();
        polar_image::Image::from_vec(self.width, self.height, data).unwrap()
    }
}

/// Nearest intersection of ray `d` from the origin with a sphere; the outward normal.
pub fn sphere_hit(d: Vector3<f64>, centre: Vector3<f64>, r: f64) -> Option<Vector3<f64>> {
    let b = d.dot(&centre);
    let c = centre.norm_squared() - r * r;
    let disc = b * b - c;
    if disc <= 0.0 {
        return None;
    }
    let t = b - disc.sqrt();
    (t > 0.0).then(|| (d * t - centre) / r)
}

/// Lambertian shading of normal `n` under directional light `l` plus ambient.
pub fn lambert(n: &Vector3<f64>, l: &Vector3<f64>, albedo: f64, ambient: f64) -> f64 {
    albedo * (n.dot(l).max(0.0) + ambient)
}
