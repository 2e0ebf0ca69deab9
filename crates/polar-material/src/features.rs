//! Per-pixel polarization features shared by the physics rule and the kNN classifier.
//!
//! Stokes planes are divided by [`Observation::s0_scale`] (exposure drops out) and averaged
//! over a small window of valid pixels before DoLP and AoLP are formed: averaging `S1, S2`
//! first removes most of the upward bias that sensor noise gives a per-pixel DoLP.

use polar_image::Gray;
use polar_image::quantile;
use polar_imgproc::{Border, box_filter};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::{CHUNK, MaterialError, par_map};

/// Side of the averaging window (pixels, odd).
pub const WINDOW: usize = 5;

/// Smoothed, scale-free polarization planes of one observation.
#[derive(Clone, Debug)]
pub struct Features {
    /// Image width.
    pub width: usize,
    /// Image height.
    pub height: usize,
    /// Windowed mean of `S0 / s0_scale` over valid pixels (0 where none is valid).
    pub s0: Vec<f32>,
    /// Windowed mean of `S1 / s0_scale`.
    pub s1: Vec<f32>,
    /// Windowed mean of `S2 / s0_scale`.
    pub s2: Vec<f32>,
    /// DoLP of the windowed Stokes vector, in `[0, 1]` (0 where undefined).
    pub dolp: Vec<f32>,
    /// AoLP of the windowed Stokes vector, in `[0, π)` (0 where undefined).
    pub aolp: Vec<f32>,
    /// `true` where the pixel itself is valid (neither saturated nor dark).
    pub valid: Vec<bool>,
    /// Robust DoLP noise level of one raw pixel: the median over valid pixels of the local
    /// standard deviation of `S1/S0` and `S2/S0` (sensor noise plus fine texture).
    pub pixel_noise: f32,
}

impl Features {
    /// Features of `obs`.
    pub fn new(obs: &Observation) -> Result<Self, MaterialError> {
        let (w, h) = obs.size();
        if w == 0 || h == 0 {
            return Err(MaterialError::Empty(w, h));
        }
        let scale = obs.s0_scale();
        let p = &obs.planes;
        let n = w * h;
        let (ps0, ps1, ps2) = (p.s0.as_slice(), p.s1.as_slice(), p.s2.as_slice());
        let valid: Vec<bool> = par_map(n, |k| {
            obs.is_valid(k) && [ps0[k], ps1[k], ps2[k]].iter().all(|v| v.is_finite())
        });
        let plane = |v: Vec<f32>| Gray::from_vec(w, h, v).expect("size of the planes");
        let mean_w = boxed(&plane(par_map(n, |k| f32::from(u8::from(valid[k])))))?;
        let mean_w = mean_w.as_slice();
        let mean = |src: &[f32]| -> Result<Vec<f32>, MaterialError> {
            let sum = boxed(&plane(par_map(n, |k| {
                if valid[k] { src[k] / scale } else { 0.0 }
            })))?;
            let sum = sum.as_slice();
            Ok(par_map(n, |k| {
                if mean_w[k] > 0.0 {
                    sum[k] / mean_w[k]
                } else {
                    0.0
                }
            }))
        };
        let (s0, s1, s2) = (mean(ps0)?, mean(ps1)?, mean(ps2)?);
        let (dolp, aolp) = (0..n)
            .into_par_iter()
            .with_min_len(CHUNK)
            .map(|k| dolp_aolp(s0[k], s1[k], s2[k]))
            .unzip();
        let pixel_noise = pixel_noise(obs, &valid)?;
        Ok(Self {
            width: w,
            height: h,
            s0,
            s1,
            s2,
            dolp,
            aolp,
            valid,
            pixel_noise,
        })
    }

    /// DoLP noise of the windowed DoLP: the raw pixel noise over the window's pixel count.
    pub fn window_noise(&self) -> f32 {
        self.pixel_noise / WINDOW as f32
    }
}

/// `(DoLP, AoLP)` of a linear Stokes vector, `(0, 0)` where `s0` is not positive; DoLP is
/// clamped to `[0, 1]`.
pub fn dolp_aolp(s0: f32, s1: f32, s2: f32) -> (f32, f32) {
    if s0.is_nan() || s0 <= 0.0 || !s1.is_finite() || !s2.is_finite() {
        return (0.0, 0.0);
    }
    let d = (s1.hypot(s2) / s0).min(1.0);
    let a = (0.5 * s2.atan2(s1)).rem_euclid(std::f32::consts::PI);
    (d, if a.is_finite() { a } else { 0.0 })
}

fn boxed(src: &Gray<f32>) -> Result<Gray<f32>, MaterialError> {
    let mut dst = Gray::new(src.width(), src.height());
    box_filter(src, &mut dst, WINDOW, WINDOW, Border::Reflect101)?;
    Ok(dst)
}

/// Median over valid pixels of the local standard deviation of the normalised Stokes
/// components `q = S1/S0`, `u = S2/S0` (`sqrt((var q + var u) / 2)` in a 3x3 window).
fn pixel_noise(obs: &Observation, valid: &[bool]) -> Result<f32, MaterialError> {
    let (w, h) = obs.size();
    let n = w * h;
    let p = &obs.planes;
    let s0 = p.s0.as_slice();
    let plane = |v: Vec<f32>| Gray::from_vec(w, h, v).expect("size of the planes");
    // Local mean and mean square of `s / S0` over 3x3 windows.
    let moments = |s: &[f32]| -> Result<(Gray<f32>, Gray<f32>), MaterialError> {
        let g = plane(par_map(n, |k| {
            if valid[k] && s0[k] > 0.0 {
                (s[k] / s0[k]).clamp(-1.0, 1.0)
            } else {
                0.0
            }
        }));
        let sq = plane(par_map(n, |k| g.as_slice()[k] * g.as_slice()[k]));
        let (mut m, mut m2) = (Gray::new(w, h), Gray::new(w, h));
        box_filter(&g, &mut m, 3, 3, Border::Reflect101)?;
        box_filter(&sq, &mut m2, 3, 3, Border::Reflect101)?;
        Ok((m, m2))
    };
    let (q, u) = (moments(p.s1.as_slice())?, moments(p.s2.as_slice())?);
    let var = |(m, m2): &(Gray<f32>, Gray<f32>), k: usize| {
        let mu = m.as_slice()[k];
        (m2.as_slice()[k] - mu * mu).max(0.0) * 9.0 / 8.0
    };
    let sd: Vec<f32> = par_map(n, |k| (0.5 * (var(&q, k) + var(&u, k))).sqrt());
    let valid_sd = (0..n).filter(|&k| valid[k]).map(|k| sd[k]);
    Ok(quantile(valid_sd, 0.5).unwrap_or(0.0))
}
