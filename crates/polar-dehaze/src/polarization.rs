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
    let proj = est.field.project(&input.s1, &input.s2);
    let (p_inf, a_field) = polarized_infinity(est, w, h);
    let t: Vec<f32> = (0..w * h)
        .into_par_iter()
        .map(|k| {
            if input.valid[k] {
                1.0 - proj.as_slice()[k] / p_inf[k]
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
