//! Closed-form hazy observations for the tests: `S0 = L t + A_inf (1 - t)`, airlight
//! `A = A_inf (1 - t)` polarized with degree `p` along `alpha(x, y)`, direct light unpolarized.

#![allow(dead_code)]

use polar_image::{Gray, Image};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

/// An observation of the given planes (flags from S0).
pub fn observation(w: usize, h: usize, s0: Vec<f32>, s1: Vec<f32>, s2: Vec<f32>) -> Observation {
    let g = |v| Gray::from_vec(w, h, v).unwrap();
    let (s0, s1, s2) = (g(s0), g(s1), g(s2));
    let img = Image::from_channels([&s0, &s1, &s2]).unwrap();
    Observation::new(
        StokesPlanes::from_linear_stokes(&img),
        CameraModel::Orthographic,
    )
}

/// A hazy scene with known answers.
pub struct Haze {
    pub w: usize,
    pub h: usize,
    /// Object radiance.
    pub radiance: Vec<f32>,
    /// Transmission (0 on the sky).
    pub t: Vec<f32>,
    pub a_inf: f32,
    /// Change of `A_inf` from the left to the right edge's centre line: `A_inf (1 + a_tilt x)`,
    /// `x` in `[-1, 1]` (a sky brighter towards the sun).
    pub a_tilt: f32,
    pub p: f32,
    /// Airlight AoLP per pixel, radians.
    pub alpha: Vec<f32>,
    /// Global unit of the intensities.
    pub unit: f32,
}

impl Haze {
    /// 96x96: sky in the top `sky_rows` rows (t = 0), below it objects whose optical depth
    /// falls from 1.2 to 0.1 towards the bottom row (t from 0.30 to 0.90); radiance a smooth
    /// texture in [0.1, 0.6] with dark (0.03) squares; airlight AoLP 30 deg + 8 deg x + 4 deg y.
    pub fn standard(sky_rows: usize, p: f32) -> Self {
        let (w, h) = (96usize, 96usize);
        let mut radiance = vec![0.0; w * h];
        let mut t = vec![0.0; w * h];
        let mut alpha = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let k = y * w + x;
                let (xf, yf) = (x as f32, y as f32);
                radiance[k] = 0.35 + 0.25 * (xf / 5.3).sin() * (yf / 7.1).cos();
                if ((x / 6) + (y / 6)) % 4 == 0 {
                    radiance[k] = 0.03;
                }
                t[k] = if y < sky_rows {
                    0.0
                } else {
                    let s = (y - sky_rows) as f32 / (h - 1 - sky_rows).max(1) as f32;
                    (-(1.2 - 1.1 * s)).exp()
                };
                let (xn, yn) = (2.0 * xf / w as f32 - 1.0, 2.0 * yf / h as f32 - 1.0);
                alpha[k] = (30.0 + 8.0 * xn + 4.0 * yn).to_radians();
            }
        }
        Self {
            w,
            h,
            radiance,
            t,
            a_inf: 0.8,
            a_tilt: 0.0,
            p,
            alpha,
            unit: 500.0,
        }
    }

    /// `(S0, S1, S2)` of the scene, times `unit`.
    pub fn planes(&self) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let n = self.w * self.h;
        let (mut s0, mut s1, mut s2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for k in 0..n {
            let a = self.a_inf_at(k) * (1.0 - self.t[k]);
            s0[k] = self.unit * (self.radiance[k] * self.t[k] + a);
            s1[k] = self.unit * self.p * a * (2.0 * self.alpha[k]).cos();
            s2[k] = self.unit * self.p * a * (2.0 * self.alpha[k]).sin();
        }
        (s0, s1, s2)
    }

    /// `A_inf` at pixel `k`.
    pub fn a_inf_at(&self, k: usize) -> f32 {
        let x = (2 * (k % self.w) + 1) as f32 / self.w as f32 - 1.0;
        self.a_inf * (1.0 + self.a_tilt * x)
    }

    pub fn observation(&self) -> Observation {
        let (s0, s1, s2) = self.planes();
        observation(self.w, self.h, s0, s1, s2)
    }
}

/// Deterministic uniform noise in [-1, 1] (xorshift), for noise tests without a dependency.
pub fn noise(seed: u64, n: usize) -> Vec<f32> {
    let mut s = seed.max(1);
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 23) as f32 - 1.0
        })
        .collect()
}
