//! Per-pixel cues shared by both methods: brightness normalised by the observation's
//! robust scale (so exposure, bit depth and global scale drop out), DoLP, AoLP, the
//! candidate zeniths of the reflection models and a confidence.
//!
//! Confidence of the polarization cue: DoLP is biased up and noisy where little light
//! arrives; with `σ(s) = σ₁ / √s` the DoLP noise of a photon-limited pixel of normalised
//! brightness `s` (`σ₁ = 0.01`: about 10⁴ photo-electrons at the image's bright level),
//! `c = ρ² / (ρ² + σ(s)²)` (a Wiener-like weight in `[0, 1)`). Invalid pixels
//! (saturated, zero or non-finite S0, non-finite S1/S2) get 0.

use polar_optics::pixel_frame::{CameraModel, PixelFrame};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::ShapeError;
use crate::zenith::ZenithModels;

/// DoLP noise at normalised brightness 1 (see the module doc).
pub const DOLP_NOISE_AT_SCALE: f64 = 0.01;

/// Normalised brightness above which a pixel counts as a highlight (specular): the
/// observation's 99th percentile of S0 is 1, so only the brightest percent of the
/// frame, where a mirror reflection of a light source sits, exceeds it.
pub const HIGHLIGHT: f64 = 1.0;

/// DoLP excess over the diffuse maximum still read as (noisy) diffuse at grazing.
pub const DIFFUSE_MARGIN: f64 = 0.05;

/// Cues of one observation.
#[derive(Clone, Debug)]
pub struct Cues {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// The camera model of the observation (for per-pixel frames).
    pub camera: CameraModel,
    /// S0 divided by the observation's scale.
    pub s0n: Vec<f32>,
    /// DoLP (0 where invalid).
    pub dolp: Vec<f32>,
    /// AoLP in `[0, π)` (0 where invalid).
    pub aolp: Vec<f32>,
    /// Pixel is valid (flags clear, finite Stokes, S0 > 0).
    pub valid: Vec<bool>,
    /// Confidence of the polarization cue in `[0, 1]`.
    pub confidence: Vec<f32>,
    /// The reflection models at the index in use.
    pub models: ZenithModels,
}

impl Cues {
    /// Cues of `obs` for refractive index `ior`.
    pub fn new(obs: &Observation, ior: f64) -> Result<Self, ShapeError> {
        let (width, height) = obs.size();
        let scale = f64::from(obs.s0_scale());
        let p = &obs.planes;
        let (s0, s1, s2) = (p.s0.as_slice(), p.s1.as_slice(), p.s2.as_slice());
        let per_pixel: Vec<(f32, f32, f32, bool, f32)> = (0..width * height)
            .into_par_iter()
            .map(|k| {
                let (a, b, c) = (f64::from(s0[k]), f64::from(s1[k]), f64::from(s2[k]));
                if !usable(obs, k) {
                    return (0.0, 0.0, 0.0, false, 0.0);
                }
                let s = a / scale;
                let d = (b.hypot(c) / a).min(1.0);
                let ang = (0.5 * c.atan2(b)).rem_euclid(std::f64::consts::PI);
                let sigma2 = DOLP_NOISE_AT_SCALE * DOLP_NOISE_AT_SCALE / s.max(1e-6);
                let conf = d * d / (d * d + sigma2);
                (s as f32, d as f32, ang as f32, true, conf as f32)
            })
            .collect();
        Ok(Self {
            width,
            height,
            camera: obs.camera,
            s0n: per_pixel.iter().map(|v| v.0).collect(),
            dolp: per_pixel.iter().map(|v| v.1).collect(),
            aolp: per_pixel.iter().map(|v| v.2).collect(),
            valid: per_pixel.iter().map(|v| v.3).collect(),
            confidence: per_pixel.iter().map(|v| v.4).collect(),
            models: ZenithModels::new(ior),
        })
    }

    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    /// `true` for an image without pixels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The per-pixel Stokes frame of pixel index `k`.
    pub fn frame(&self, k: usize) -> PixelFrame {
        let (x, y) = (k % self.width, k / self.width);
        self.camera
            .frame(self.width, self.height, x as f64, y as f64)
    }

    /// `true` where the polarization is specular beyond doubt: DoLP more than
    /// [`DIFFUSE_MARGIN`] above what diffuse reflection can produce, or a highlight.
    /// DoLP between the diffuse maximum and the margin is taken as diffuse at grazing
    /// (noise biases DoLP up; the diffuse inverse clamps it to 90°).
    pub fn surely_specular(&self, k: usize) -> bool {
        self.valid[k]
            && (f64::from(self.dolp[k]) > self.models.diffuse_max + DIFFUSE_MARGIN
                || f64::from(self.s0n[k]) > HIGHLIGHT)
    }
}

/// `true` where pixel `k` of `obs` is valid (flags clear) with finite Stokes and S0 > 0.
pub fn usable(obs: &Observation, k: usize) -> bool {
    let p = &obs.planes;
    let s0 = p.s0.as_slice()[k];
    obs.is_valid(k)
        && s0 > 0.0
        && [s0, p.s1.as_slice()[k], p.s2.as_slice()[k]]
            .iter()
            .all(|v| v.is_finite())
}

/// The frame angle (from `x_ref` toward `y_ref`) of an image-plane direction
/// `(dx, dy)` given in image coordinates (x right, y down), at frame `f`.
pub fn image_direction_angle(f: &PixelFrame, dx: f64, dy: f64) -> f64 {
    let v = nalgebra::Vector3::new(dx, -dy, 0.0);
    v.dot(&f.y_ref).atan2(v.dot(&f.x_ref))
}

/// The unit vector of the frame's plane along the image-plane direction `(dx, dy)`
/// (image coordinates): `f.in_plane(image_direction_angle(f, dx, dy))`, without
/// trigonometry; `None` for a zero direction.
pub fn image_direction(f: &PixelFrame, dx: f64, dy: f64) -> Option<nalgebra::Vector3<f64>> {
    let v = nalgebra::Vector3::new(dx, -dy, 0.0);
    (f.x_ref * v.dot(&f.x_ref) + f.y_ref * v.dot(&f.y_ref)).try_normalize(1e-12)
}
