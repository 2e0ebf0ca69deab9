//! Per-pixel polarization features shared by the physics rule and the kNN classifier.
//!
//! Stokes planes are divided by [`Observation::s0_scale`] (exposure drops out) and averaged
//! over a small window of valid pixels before DoLP and AoLP are formed: averaging `S1, S2`
//! first removes most of the upward bias that sensor noise gives a per-pixel DoLP.

use polar_image::Gray;
use polar_imgproc::{Border, box_filter};
use polar_sensor::Observation;

use crate::MaterialError;

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
        let valid: Vec<bool> = (0..n)
            .map(|k| {
                let s = [p.s0.as_slice()[k], p.s1.as_slice()[k], p.s2.as_slice()[k]];
                obs.is_valid(k) && s.iter().all(|v| v.is_finite())
            })
            .collect();
        let norm = |src: &Gray<f32>| -> Gray<f32> {
            let v = src
                .as_slice()
                .iter()
                .zip(&valid)
                .map(|(&s, &ok)| if ok { s / scale } else { 0.0 })
                .collect();
            Gray::from_vec(w, h, v).expect("size of the planes")
        };
        let weight = Gray::from_vec(
            w,
            h,
            valid.iter().map(|&v| f32::from(u8::from(v))).collect(),
        )
        .expect("size of the planes");
        let mean_w = boxed(&weight)?;
        let mean = |g: &Gray<f32>| -> Result<Vec<f32>, MaterialError> {
            let m = boxed(g)?;
            Ok(m.as_slice()
                .iter()
                .zip(mean_w.as_slice())
                .map(|(&v, &wt)| if wt > 0.0 { v / wt } else { 0.0 })
                .collect())
        };
        let (s0, s1, s2) = (
            mean(&norm(&p.s0))?,
            mean(&norm(&p.s1))?,
            mean(&norm(&p.s2))?,
        );
        let mut dolp = vec![0.0; n];
        let mut aolp = vec![0.0; n];
        for k in 0..n {
            (dolp[k], aolp[k]) = dolp_aolp(s0[k], s1[k], s2[k]);
        }
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
    let p = &obs.planes;
    let ratio = |s: &Gray<f32>| -> Gray<f32> {
        let v = (0..w * h)
            .map(|k| {
                let s0 = p.s0.as_slice()[k];
                if valid[k] && s0 > 0.0 {
                    (s.as_slice()[k] / s0).clamp(-1.0, 1.0)
                } else {
                    0.0
                }
            })
            .collect();
        Gray::from_vec(w, h, v).expect("size of the planes")
    };
    let mut var = vec![0.0f32; w * h];
    for g in [ratio(&p.s1), ratio(&p.s2)] {
        let sq = Gray::from_vec(w, h, g.as_slice().iter().map(|v| v * v).collect())
            .expect("size of the planes");
        let (mut m, mut m2) = (Gray::new(w, h), Gray::new(w, h));
        box_filter(&g, &mut m, 3, 3, Border::Reflect101)?;
        box_filter(&sq, &mut m2, 3, 3, Border::Reflect101)?;
        for (k, v) in var.iter_mut().enumerate() {
            let mu = m.as_slice()[k];
            *v += (m2.as_slice()[k] - mu * mu).max(0.0) * 9.0 / 8.0;
        }
    }
    let mut sd: Vec<f32> = (0..w * h)
        .filter(|&k| valid[k])
        .map(|k| (0.5 * var[k]).sqrt())
        .collect();
    if sd.is_empty() {
        return Ok(0.0);
    }
    let mid = sd.len() / 2;
    Ok(*sd.select_nth_unstable_by(mid, f32::total_cmp).1)
}
