//! Refinement of a raw transmission: fill the pixels where it is unknown, guided filter
//! (guide: normalised S0, as He et al. refine the dark channel), bound to `[t_min, 1]`.

use polar_image::Gray;
use polar_imgproc::{Border, box_filter, guided_filter};
use rayon::prelude::*;

use crate::prep::Normalized;
use crate::{DehazeError, DehazeOptions, GuidedRadius};

/// The raw transmission's noise is measured on about this many rows at most, evenly spaced
/// (the median of their responses: more rows only cost time).
pub const NOISE_ROWS: usize = 512;

/// Fills the NaN entries of `raw` (unknown: invalid pixels), runs the guided filter of
/// radius `opts.guided_radius` (skipped for 0 pixels; [`GuidedRadius::Adaptive`] measures
/// the filled raw `t`'s pixel noise with [`plane_noise`]) and regularisation `eps`, and
/// clamps to `[t_min, 1]`. Every output value is finite.
pub fn refine(
    input: &Normalized,
    raw: &Gray<f32>,
    opts: &DehazeOptions,
    eps: f32,
) -> Result<Gray<f32>, DehazeError> {
    let (w, h) = raw.size();
    let filled = fill_unknown(raw, opts.guided_radius.base(w, h).max(1))?;
    let t_noise = match opts.guided_radius {
        GuidedRadius::Adaptive => plane_noise(&filled, &input.valid, h.div_ceil(NOISE_ROWS)),
        GuidedRadius::Pixels(_) => 0.0,
    };
    let radius = opts.guided_radius.pixels(w, h, t_noise);
    let mut t = Gray::new(w, h);
    if radius > 0 {
        guided_filter(&input.s0, &filled, &mut t, radius, f64::from(eps))?;
    } else {
        t = filled;
    }
    let t_min = opts.t_min;
    t.as_mut_slice().par_iter_mut().for_each(|v| {
        *v = if v.is_finite() {
            v.clamp(t_min, 1.0)
        } else {
            1.0
        }
    });
    Ok(t)
}

/// Replaces NaN values by the mean of the known values in the `(2 radius + 1)^2` window
/// (normalised convolution), widening the window until some are known; all unknown gives 1.
pub fn fill_unknown(raw: &Gray<f32>, radius: usize) -> Result<Gray<f32>, DehazeError> {
    let (w, h) = raw.size();
    let known: Vec<bool> = raw.as_slice().par_iter().map(|v| v.is_finite()).collect();
    if known.iter().all(|&k| k) {
        return Ok(raw.clone());
    }
    if !known.iter().any(|&k| k) {
        return Ok(Gray::from_vec(w, h, vec![1.0; w * h]).expect("size matches"));
    }
    let mut out = raw.clone();
    let mut r = radius;
    loop {
        let (num, den) = window_sums(raw, &known, r)?;
        let mut missing = false;
        for (k, o) in out.as_mut_slice().iter_mut().enumerate() {
            if !known[k] && !o.is_finite() {
                if den[k] > 0.0 {
                    *o = num[k] / den[k];
                } else {
                    missing = true;
                }
            }
        }
        if !missing {
            return Ok(out);
        }
        r *= 2;
    }
}

/// Box means of `raw` where known (0 elsewhere) and of the known indicator.
fn window_sums(
    raw: &Gray<f32>,
    known: &[bool],
    r: usize,
) -> Result<(Vec<f32>, Vec<f32>), DehazeError> {
    let (w, h) = raw.size();
    let k = 2 * r + 1;
    let vals: Vec<f32> = raw
        .as_slice()
        .iter()
        .zip(known)
        .map(|(&v, &m)| if m { v } else { 0.0 })
        .collect();
    let ind: Vec<f32> = known.iter().map(|&m| f32::from(u8::from(m))).collect();
    let (vals, ind) = (
        Gray::from_vec(w, h, vals).expect("size matches"),
        Gray::from_vec(w, h, ind).expect("size matches"),
    );
    let (mut num, mut den) = (Gray::new(w, h), Gray::new(w, h));
    box_filter(&vals, &mut num, k, k, Border::Replicate)?;
    box_filter(&ind, &mut den, k, k, Border::Replicate)?;
    // The box sums run in f64 over 0/1 values, so `den > 0` exactly where a known pixel
    // is within reach.
    Ok((num.into_vec(), den.into_vec()))
}

/// Robust standard deviation of the pixel noise of the normalised S0 (Immerkaer, "Fast
/// noise variance estimation", CVIU 1996, with a median instead of the mean): the mask
/// `[1 -2 1] x [1 -2 1]` cancels every image term that is at most linear in x or in y (so
/// smooth shading and gradients drop out) and turns white noise of deviation `sigma` into
/// deviation `6 sigma`; `sigma = 1.4826 median(|response|) / 6` over the 3x3 windows of
/// valid pixels. 0 for a noiseless smooth image or one smaller than 3x3.
pub fn noise_sigma(input: &Normalized) -> f32 {
    plane_noise(&input.s0, &input.valid, 1)
}

/// Standard deviation over median absolute deviation for Gaussian noise (`1 / Φ⁻¹(3/4)`).
pub const MAD_TO_SIGMA: f32 = 1.4826;

/// [`noise_sigma`] of any plane over the pixels of `valid`, from every `row_step`-th row.
pub fn plane_noise(plane: &Gray<f32>, valid: &[bool], row_step: usize) -> f32 {
    let (w, h) = plane.size();
    if w < 3 || h < 3 {
        return 0.0;
    }
    let s0 = plane.as_slice();
    let rows: Vec<Vec<f32>> = (1..h - 1)
        .into_par_iter()
        .step_by(row_step.max(1))
        .map(|y| row_responses(s0, valid, w, y))
        .collect();
    polar_image::quantile(rows.iter().flatten().copied(), 0.5)
        .map_or(0.0, |med| MAD_TO_SIGMA * med / 6.0)
}

/// `|[1 -2 1] x [1 -2 1]|` responses of row `y` (`1 <= y < h - 1`) at the pixels whose 3x3
/// window is valid, left to right.
fn row_responses(s0: &[f32], valid: &[bool], w: usize, y: usize) -> Vec<f32> {
    let row = |dy: usize| (y + dy - 1) * w;
    let (a, b, c) = (row(0), row(1), row(2));
    let d2 = |k: usize| s0[k - 1] - 2.0 * s0[k] + s0[k + 1];
    let ok = |k: usize| valid[k - 1] && valid[k] && valid[k + 1];
    let mut out = Vec::with_capacity(w - 2);
    for x in 1..w - 1 {
        if ok(a + x) && ok(b + x) && ok(c + x) {
            out.push((d2(a + x) - 2.0 * d2(b + x) + d2(c + x)).abs());
        }
    }
    out
}

/// Edge-preserving denoising of the normalised S0 before the inversion: the guided filter
/// with S0 as its own guide, radius `radius` and `eps = 9 sigma^2` (`sigma` the noise of
/// [`noise_sigma`]): windows whose variance is noise are averaged, edges well above the
/// noise kept. Blended in by `1 - t` (`S0 + (1 - t)(S0_filtered - S0)`): the inversion
/// multiplies noise by `1 / t`, so the haze-free parts (`t = 1`) stay as measured.
/// Returns S0 unchanged for radius 0 or a noiseless image.
pub fn denoise(input: &Normalized, t: &Gray<f32>, radius: usize) -> Result<Gray<f32>, DehazeError> {
    let eps = 9.0 * f64::from(input.noise).powi(2);
    if radius == 0 || eps <= 0.0 || !eps.is_finite() {
        return Ok(input.s0.clone());
    }
    let mut out = Gray::new(input.s0.width(), input.s0.height());
    guided_filter(&input.s0, &input.s0, &mut out, radius, eps)?;
    out.as_mut_slice()
        .iter_mut()
        .zip(input.s0.as_slice().iter().zip(t.as_slice()))
        .for_each(|(d, (&s, &t))| *d = s + (1.0 - t) * (*d - s));
    Ok(out)
}
