//! Per-pixel polarization features shared by the physics rule and the kNN classifier.
//!
//! Stokes planes are divided by [`Observation::s0_scale`] (exposure drops out) and averaged
//! over a small window of valid pixels before DoLP and AoLP are formed: averaging `S1, S2`
//! first removes most of the upward bias that sensor noise gives a per-pixel DoLP.

use polar_image::{Gray, par_fill, par_map, quantile};
use polar_imgproc::{Border, box_filter};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::{CHUNK, MaterialError};

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
        let mut src = Gray::from_vec(w, h, par_map(n, |k| f32::from(u8::from(valid[k]))))
            .expect("size of the planes");
        let mean_w = boxed(&src)?;
        let mean_w = mean_w.as_slice();
        // Windowed mean of `plane / scale` over the valid pixels; `src` is scratch.
        let mut mean = |plane: &[f32]| -> Result<Vec<f32>, MaterialError> {
            par_fill(src.as_mut_slice(), |k| {
                if valid[k] { plane[k] / scale } else { 0.0 }
            });
            let mut sum = boxed(&src)?.into_vec();
            sum.par_iter_mut()
                .zip(mean_w)
                .with_min_len(CHUNK)
                .for_each(|(v, &wt)| *v = if wt > 0.0 { *v / wt } else { 0.0 });
            Ok(sum)
        };
        let (s0, s1, s2) = (mean(ps0)?, mean(ps1)?, mean(ps2)?);
        let dolp = par_map(n, |k| dolp(s0[k], s1[k], s2[k]));
        let pixel_noise = pixel_noise(obs, &valid)?;
        Ok(Self {
            width: w,
            height: h,
            s0,
            s1,
            s2,
            dolp,
            valid,
            pixel_noise,
        })
    }

    /// AoLP of the windowed Stokes vector at pixel `k`, in `[0, π)` (0 where undefined);
    /// on demand, as only the pixels whose phase is measured need it.
    pub fn aolp(&self, k: usize) -> f32 {
        aolp(self.s0[k], self.s1[k], self.s2[k])
    }

    /// DoLP noise of the windowed DoLP: the raw pixel noise over the window's pixel count.
    pub fn window_noise(&self) -> f32 {
        self.pixel_noise / WINDOW as f32
    }
}

/// `true` where a linear Stokes vector has a DoLP and an AoLP: `s0` positive, `s1` and
/// `s2` finite.
fn defined(s0: f32, s1: f32, s2: f32) -> bool {
    s0 > 0.0 && s1.is_finite() && s2.is_finite()
}

/// DoLP of a linear Stokes vector clamped to `[0, 1]`, 0 where not `defined`.
pub fn dolp(s0: f32, s1: f32, s2: f32) -> f32 {
    if !defined(s0, s1, s2) {
        return 0.0;
    }
    (s1.hypot(s2) / s0).min(1.0)
}

/// AoLP of a linear Stokes vector in `[0, π)`, 0 where not `defined`.
pub fn aolp(s0: f32, s1: f32, s2: f32) -> f32 {
    if !defined(s0, s1, s2) {
        return 0.0;
    }
    let a = (0.5 * s2.atan2(s1)).rem_euclid(std::f32::consts::PI);
    if a.is_finite() { a } else { 0.0 }
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
    let (mut g, mut sq) = (Gray::new(w, h), Gray::new(w, h));
    let (mut m, mut m2) = (Gray::new(w, h), Gray::new(w, h));
    let mut var = vec![0.0f32; n];
    for s in [p.s1.as_slice(), p.s2.as_slice()] {
        par_fill(g.as_mut_slice(), |k| {
            if valid[k] && s0[k] > 0.0 {
                (s[k] / s0[k]).clamp(-1.0, 1.0)
            } else {
                0.0
            }
        });
        let r = g.as_slice();
        par_fill(sq.as_mut_slice(), |k| r[k] * r[k]);
        box_filter(&g, &mut m, 3, 3, Border::Reflect101)?;
        box_filter(&sq, &mut m2, 3, 3, Border::Reflect101)?;
        let (m, m2) = (m.as_slice(), m2.as_slice());
        var.par_iter_mut()
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(k, v)| *v += (m2[k] - m[k] * m[k]).max(0.0) * 9.0 / 8.0);
    }
    let valid_sd = (0..n).filter(|&k| valid[k]).map(|k| (0.5 * var[k]).sqrt());
    Ok(quantile(valid_sd, 0.5).unwrap_or(0.0))
}
