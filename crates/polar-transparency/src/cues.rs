//! Cue maps for transparent objects and the combined score.
//!
//! - `dolp`: DoLP of the normalised Stokes vector `(S1/S0, S2/S0)`, median-filtered
//!   ([`MEDIAN`]², against isolated outliers) and averaged over a [`WINDOW`]² window of
//!   valid pixels (scale-free).
//! - `coherence`: that DoLP over the window's mean per-pixel DoLP, in `[0, 1]`: `1` where
//!   the AoLP is the same over the window (light polarized by a surface), near `0` where
//!   the per-pixel polarization points anywhere (noise; demosaicing artefacts at texture
//!   edges, whose sign flips from one side of the edge to the other).
//! - The score is `e / (e + HALF_DOLP)` with `e = dolp · coherence`, in `[0, 1)`.

use polar_image::{Gray, par_map};
use polar_imgproc::{Border, box_filter, median_blur};
use polar_sensor::Observation;

use crate::{TransparencyError, norm};

/// Side of the averaging window (pixels, odd).
pub const WINDOW: usize = 5;
/// Coherent DoLP at which the score is one half.
pub const HALF_DOLP: f32 = 0.05;

/// The cue planes of one observation.
#[derive(Clone, Debug)]
pub struct CueMaps {
    /// Per-pixel DoLP of the median-filtered `(S1/S0, S2/S0)`, before the window: edges
    /// stay where they are.
    pub pixel_dolp: Vec<f32>,
    /// Windowed DoLP in `[0, 1]` (0 where no valid pixel is in the window).
    pub dolp: Vec<f32>,
    /// Coherence of the polarization over the window, in `[0, 1]`.
    pub coherence: Vec<f32>,
    /// The windowed normalised Stokes vector `(S1/S0, S2/S0)` whose length is `dolp`
    /// (scaled down where that length is clamped to 1).
    pub q: Vec<f32>,
    /// Its second component.
    pub u: Vec<f32>,
}

/// Windowed mean of `v` where `valid`, 0 where the window holds no valid pixel.
fn masked_mean(
    v: &[f32],
    valid: &[f32],
    mean_w: &[f32],
    w: usize,
    h: usize,
) -> Result<Vec<f32>, TransparencyError> {
    let src =
        Gray::from_vec(w, h, par_map(w * h, |k| v[k] * valid[k])).expect("size of the planes");
    let mut dst = Gray::new(w, h);
    box_filter(&src, &mut dst, WINDOW, WINDOW, Border::Reflect101)?;
    let sum = dst.as_slice();
    Ok(par_map(w * h, |k| {
        let m = mean_w[k];
        if m > 0.0 { sum[k] / m } else { 0.0 }
    }))
}

/// Side of the median filter applied to `S1/S0` and `S2/S0` before averaging.
pub const MEDIAN: usize = 5;

/// [`MEDIAN`]² median of a plane: removes isolated outliers (hot pixels, Monte Carlo
/// fireflies, demosaicing spikes at single bright pixels) that a mean would spread.
fn median(v: Vec<f32>, w: usize, h: usize) -> Result<Vec<f32>, TransparencyError> {
    let k = MEDIAN;
    if w < 2 || h < 2 {
        return Ok(v);
    }
    let src = Gray::from_vec(w, h, v).expect("size of the planes");
    let mut dst = Gray::new(w, h);
    median_blur(&src, &mut dst, k)?;
    Ok(dst.into_vec())
}

/// The cue maps of `obs`.
pub fn cue_maps(obs: &Observation) -> Result<CueMaps, TransparencyError> {
    let (w, h) = obs.size();
    let p = &obs.planes;
    let (s0, s1, s2) = (p.s0.as_slice(), p.s1.as_slice(), p.s2.as_slice());
    let n = w * h;
    let valid: Vec<f32> = par_map(n, |k| {
        let ok =
            obs.is_valid(k) && s0[k] > 0.0 && [s0[k], s1[k], s2[k]].iter().all(|v| v.is_finite());
        f32::from(u8::from(ok))
    });
    // Stokes divided by S0 per pixel: the window then averages polarization states with
    // equal weight, whatever the texture's brightness, and the scale drops out.
    let normalised = |s: &[f32]| par_map(n, |k| if valid[k] > 0.0 { s[k] / s0[k] } else { 0.0 });
    let (q, u) = (median(normalised(s1), w, h)?, median(normalised(s2), w, h)?);
    let d = par_map(n, |k| norm(q[k], u[k]).min(1.0));
    let wsrc = Gray::from_vec(w, h, valid.clone()).expect("size of the planes");
    let mut wmean = Gray::new(w, h);
    box_filter(&wsrc, &mut wmean, WINDOW, WINDOW, Border::Reflect101)?;
    let mw = wmean.as_slice();
    let (qm, um, dm) = (
        masked_mean(&q, &valid, mw, w, h)?,
        masked_mean(&u, &valid, mw, w, h)?,
        masked_mean(&d, &valid, mw, w, h)?,
    );
    // The windowed vector's length, clamped to 1 (the vector scaled down with it); 0 where
    // not finite.
    let r = par_map(n, |k| norm(qm[k], um[k]));
    let scaled = |v: &[f32]| {
        par_map(n, |k| match r[k] {
            l if !l.is_finite() => 0.0,
            l if l > 1.0 => v[k] / l,
            _ => v[k],
        })
    };
    let (qw, uw) = (scaled(&qm), scaled(&um));
    let dolp = par_map(n, |k| if r[k].is_finite() { r[k].min(1.0) } else { 0.0 });
    let coherence = par_map(n, |k| {
        if dm[k] > 0.0 {
            (dolp[k] / dm[k]).clamp(0.0, 1.0)
        } else {
            0.0
        }
    });
    Ok(CueMaps {
        pixel_dolp: d,
        dolp,
        coherence,
        q: qw,
        u: uw,
    })
}

/// The per-pixel transparency score in `[0, 1)` of the cue maps of a `w x h` frame (see
/// the module docs).
pub fn score(c: &CueMaps, w: usize, h: usize) -> Gray<f32> {
    let s = par_map(w * h, |k| score_of(c.dolp[k] * c.coherence[k]));
    Gray::from_vec(w, h, s).expect("size of the cue maps")
}

/// The score `e / (e + HALF_DOLP)` of a coherent DoLP `e` (dolp · coherence).
pub fn score_of(e: f32) -> f32 {
    e / (e + HALF_DOLP)
}

/// The coherent DoLP whose score is `s` ([`score_of`] inverted; infinite at `s = 1`).
pub fn coherent_dolp(s: f32) -> f32 {
    HALF_DOLP * s / (1.0 - s)
}
