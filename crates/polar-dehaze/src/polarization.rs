//! Polarization dehazing (Schechner, Narasimhan, Nayar, CVPR 2001 / Applied Optics 2003).
//!
//! The direct light `L t` is taken as unpolarized and the airlight `A` as partially
//! polarized with degree `p` along `alpha(x, y)`, so the projection of the measured linear
//! polarization on the airlight's direction is `P = S1 cos 2alpha + S2 sin 2alpha = p A`
//! (with `I_max`, `I_min` along `alpha`: `P = I_max - I_min`). Hence `A = P / p` and
//! `t = 1 - A / A_inf`; `p`, `alpha` and `A_inf` (each varying over the frame where sky is
//! seen) come from [`crate::airlight::estimate`]. The radiance is recovered by
//! [`crate::Inversion::Regularized`]: sky and dense haze, where `t` is near `t_min`, tend to
//! the local airlight instead of amplifying the misfit of `A_inf`.
//! The raw `t` is left unclamped (noise makes it leave `[0, 1]`): clamping before the
//! guided filter would bias its local means (towards 0.5 where the truth is 0 or 1).
//!
//! Objects may polarize the light they send themselves (glossy surfaces, glass, water),
//! each at its own angle, which the model above would read as airlight. Airlight has no
//! component across its direction, `Q = S2 cos 2alpha − S1 sin 2alpha`, so `|Q|` beyond
//! the noise is evidence of such light, and `P` is reduced by [`ACROSS_WEIGHT`] times it
//! before `A = P / p`: a pixel polarized more than `atan(1/2)/2 ≈ 13°` off the airlight's
//! angle counts as no airlight at all. On a haze-free frame the polarized objects are then
//! mostly left as they are; in haze such an object is dehazed less than its distance asks
//! (its airlight is underestimated); an object whose angle matches the airlight's is
//! still read as haze, and where the angle field itself follows a large polarized object
//! (no haze around it to hold the field) nothing tells the two apart.

use polar_image::Gray;
use rayon::prelude::*;

use crate::airlight::{self, AirlightEstimate};
use crate::prep::Normalized;
use crate::{
    DehazeError, DehazeOptions, Inversion, Method, RawEstimate, WeakPolarization, dark_channel,
};

/// The guided filter's `eps` is at least this times the noise variance of the normalised
/// S0 ([`crate::refine::noise_sigma`]): windows whose guide varies by noise alone then average
/// `t` (its noise is `sigma_P / (p A_inf)`, large for weak polarization) instead of
/// copying the guide's noise into it.
pub const NOISE_EPS_FACTOR: f32 = 9.0;

/// Weight of the polarization across the airlight's direction taken off the part along it
/// (module doc).
pub const ACROSS_WEIGHT: f32 = 2.0;

/// `|Q|` within this many of its noise's standard deviations is taken as no evidence. That
/// deviation is the larger of `Q`'s robust one over the frame (`1.4826 median |Q|`: noise,
/// and the angle field's misfit) and `√2` times the normalised S0's ([`Normalized::noise`]:
/// `S1` and `S2` are differences of two samples, S0 half the sum of four).
pub const ACROSS_NOISE_MARGIN: f32 = 2.0;

/// Below this fraction of sky-like blocks a warning says that `A_inf` may be too low.
pub const MIN_SKY_FRACTION: f32 = 0.005;

/// Raw polarization transmission, or the fallback of `opts.weak_fallback` when the
/// airlight's polarization is too weak (or absent) to be used.
pub fn transmission(input: &Normalized, opts: &DehazeOptions) -> Result<RawEstimate, DehazeError> {
    let est = airlight::estimate(input, opts.varying_airlight);
    let usable = est
        .as_ref()
        .filter(|e| e.p >= opts.min_airlight_dolp && e.p > 0.0 && e.a_inf > 0.0);
    let Some(est) = usable else {
        let p = est.as_ref().map_or(0.0, |e| e.p);
        return fallback(input, opts, p);
    };
    let (w, h) = input.s0.size();
    let proj = airlight_projection(est, input);
    let (p_inf, a_field) = polarized_infinity(est, w, h);
    let t: Vec<f32> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            if input.valid[k] {
                1.0 - proj[k] / p_inf[k]
            } else {
                f32::NAN
            }
        })
        .collect();
    Ok(RawEstimate {
        raw_t: Gray::from_vec(w, h, t).expect("size matches"),
        airlight_inf: est.a_inf,
        airlight_field: a_field,
        airlight_dolp: est.p,
        inversion: Inversion::Regularized,
        method: Method::Polarization,
        guided_eps: opts.guided_eps.max(NOISE_EPS_FACTOR * input.noise.powi(2)),
        warnings: sky_warning(est),
    })
}

/// `p A` per pixel: the polarization along the airlight's direction less [`ACROSS_WEIGHT`]
/// times the part across it beyond the noise (module doc).
fn airlight_projection(est: &AirlightEstimate, input: &Normalized) -> Vec<f32> {
    let (along, across) = est.field.project(&input.s1, &input.s2);
    let noise = ACROSS_NOISE_MARGIN
        * robust_sigma(&across, &input.valid).max(std::f32::consts::SQRT_2 * input.noise);
    along
        .as_slice()
        .par_iter()
        .zip(across.as_slice())
        .map(|(p, q)| p - ACROSS_WEIGHT * (q.abs() - noise).max(0.0))
        .collect()
}

/// `P_inf = p A_inf` per pixel, and `A_inf` per pixel, from the sky planes where sky was
/// found (`None` for one `A_inf` over the frame).
fn polarized_infinity(est: &AirlightEstimate, w: usize, h: usize) -> (Vec<f32>, Option<Gray<f32>>) {
    let n = w * h;
    let Some(sky) = &est.sky else {
        return (vec![est.p * est.a_inf; n], None);
    };
    let (mut p_inf, mut a) = (vec![0.0f32; n], vec![0.0f32; n]);
    p_inf
        .par_chunks_mut(w)
        .zip(a.par_chunks_mut(w))
        .enumerate()
        .for_each(|(row, (p_row, a_row))| {
            let y = airlight::norm_coord(row, h);
            for (col, (p, a)) in p_row.iter_mut().zip(a_row.iter_mut()).enumerate() {
                let x = airlight::norm_coord(col, w);
                let a_inf = sky.airlight_at(x, y);
                (*p, *a) = ((sky.at(x, y) * a_inf) as f32, a_inf as f32);
            }
        });
    (p_inf, Some(Gray::from_vec(w, h, a).expect("size matches")))
}

/// A warning when no block looks like sky: `A_inf` is then the largest airlight seen.
fn sky_warning(est: &AirlightEstimate) -> Vec<String> {
    if est.sky_fraction >= MIN_SKY_FRACTION {
        return vec![];
    }
    vec![format!(
        "no sky-like region ({:.2} % of blocks): A_inf is the airlight of the most distant \
         region, so the transmission there is underestimated",
        100.0 * est.sky_fraction
    )]
}

/// The transmission when the airlight's polarization cannot be used.
fn fallback(input: &Normalized, opts: &DehazeOptions, p: f32) -> Result<RawEstimate, DehazeError> {
    let why = format!(
        "airlight degree of polarization {p:.4} below min_airlight_dolp {}",
        opts.min_airlight_dolp
    );
    match opts.weak_fallback {
        WeakPolarization::DarkChannel => {
            let mut est = dark_channel::transmission(input, opts)?;
            est.warnings
                .insert(0, format!("{why}: dark-channel transmission used instead"));
            est.airlight_dolp = p;
            Ok(est)
        }
        WeakPolarization::Identity => {
            let (w, h) = input.s0.size();
            Ok(RawEstimate {
                raw_t: Gray::from_vec(w, h, vec![1.0; w * h]).expect("size matches"),
                airlight_inf: 1.0,
                airlight_field: None,
                airlight_dolp: p,
                inversion: Inversion::Clamped,
                method: Method::Polarization,
                guided_eps: opts.guided_eps,
                warnings: vec![format!("{why}: image left unchanged (t = 1)")],
            })
        }
    }
}

/// Robust standard deviation `MAD_TO_SIGMA · median |v|` of a zero-mean plane over the valid pixels
/// (0 without any).
fn robust_sigma(v: &Gray<f32>, valid: &[bool]) -> f32 {
    let abs = v
        .as_slice()
        .iter()
        .zip(valid)
        .filter(|(_, ok)| **ok)
        .map(|(x, _)| x.abs());
    crate::refine::MAD_TO_SIGMA * polar_image::quantile(abs, 0.5).unwrap_or(0.0)
}
