//! Dehazing of one polarization observation.
//!
//! The haze model (Koschmieder; Schechner, Narasimhan, Nayar 2001/2003) is
//! `S0 = L t + A`, `A = A_inf (1 - t)`: the object radiance `L` attenuated by the
//! transmission `t = exp(-beta z)` plus the airlight `A` scattered into the ray, which
//! tends to `A_inf` (the horizon's brightness) for distant objects. Two ways to find `t`:
//!
//! - [`Method::Polarization`] ([`polarization`]): the airlight is partially polarized
//!   (degree `p`, angle `alpha`) while the direct light is taken as unpolarized, so the
//!   projection of `(S1, S2)` on the airlight's polarization direction is `p A`:
//!   `A = (S1 cos 2alpha + S2 sin 2alpha) / p`, `t = 1 - A / A_inf`.
//!   Schechner, Narasimhan, Nayar, "Instant dehazing of images using polarization",
//!   CVPR 2001; "Polarization-based vision through haze", Applied Optics 2003.
//! - [`Method::DarkChannel`] ([`dark_channel`]): He, Sun, Tang's dark channel prior
//!   (CVPR 2009 / TPAMI 2011) on S0 alone, the baseline.
//!
//! Both refine `t` with a guided filter (guide S0; He, Sun, Tang, ECCV 2010), bound it
//! to `[t_min, 1]` and invert the model, `L = (S0 - A_inf) / t + A_inf` ([`Inversion`]:
//! the dark channel as He et al., the polarization method regularised where `t` is near
//! `t_min`, with `A_inf` varying over the frame where sky is seen).
//!
//! A frame in which the airlight found makes up little of the light on average is taken
//! as haze-free and left unchanged ([`DehazeOptions::min_airlight_share`]).
//!
//! All intensities are divided by [`Observation::s0_scale`] first, so the transmission
//! does not depend on the exposure and the radiance scales with it. Saturated and
//! zero pixels ([`Observation::is_valid`]) take no part in any estimate; their
//! transmission is filled in from valid neighbours (see [`refine`]).

pub mod airlight;
pub mod dark_channel;
pub mod polarization;
pub mod prep;
pub mod refine;

use std::fmt;
use std::str::FromStr;

use polar_image::Gray;
use polar_sensor::Observation;
use rayon::prelude::*;
use thiserror::Error;

pub use airlight::AirlightEstimate;

/// Errors of dehazing.
#[derive(Debug, Error, PartialEq)]
pub enum DehazeError {
    /// A method name that is not known.
    #[error("unknown dehazing method `{0}` (known: polarization, dark-channel)")]
    UnknownMethod(String),
    /// An option is out of its valid range.
    #[error("invalid option `{name}` = {value}: {reason}")]
    Option {
        /// Option name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// Valid range.
        reason: &'static str,
    },
    /// The observation has no pixels.
    #[error("empty observation ({0}x{1})")]
    Empty(usize, usize),
    /// An image-processing primitive failed (sizes are checked before, so this is a bug).
    #[error("image processing: {0}")]
    Imgproc(#[from] polar_imgproc::Error),
}

/// How the transmission is estimated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// Schechner-Narasimhan-Nayar polarization dehazing (needs polarized airlight).
    #[default]
    Polarization,
    /// He-Sun-Tang dark channel prior on S0 (ignores polarization), the baseline.
    DarkChannel,
}

impl Method {
    /// The names accepted by [`FromStr`], in the order of the variants.
    pub const NAMES: [&'static str; 2] = ["polarization", "dark-channel"];
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Polarization => Self::NAMES[0],
            Method::DarkChannel => Self::NAMES[1],
        })
    }
}

impl FromStr for Method {
    type Err = DehazeError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s {
            "polarization" => Ok(Method::Polarization),
            "dark-channel" => Ok(Method::DarkChannel),
            other => Err(DehazeError::UnknownMethod(other.to_string())),
        }
    }
}

/// What [`Method::Polarization`] does when the airlight is not (detectably) polarized.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WeakPolarization {
    /// Use the dark-channel transmission instead (a warning says so).
    #[default]
    DarkChannel,
    /// Return the input unchanged, `t = 1` (a warning says so).
    Identity,
}

/// Radius of the guided filter that refines `t`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GuidedRadius {
    /// This many pixels (window `2 r + 1`); 0 disables the filter.
    Pixels(usize),
    /// [`GuidedRadius::SHARE`] of the longer image side, the same part of the scene at any
    /// resolution (a window wider than the objects blends a distant object's transmission
    /// with its nearer surroundings wherever the haze leaves S0, the guide, too flat to
    /// separate them); widened where the raw transmission is noisy until the window's mean
    /// holds that noise to [`GuidedRadius::NOISE_TARGET`] (`sigma_t / (2 r + 1)` over its
    /// `(2 r + 1)^2` pixels), up to [`GuidedRadius::MAX_SHARE`] of the longer side.
    Adaptive,
}

impl GuidedRadius {
    /// Radius of [`GuidedRadius::Adaptive`] as a share of the longer side (4 pixels at 128,
    /// 16 at 512).
    pub const SHARE: f64 = 1.0 / 32.0;
    /// Largest radius of [`GuidedRadius::Adaptive`] as a share of the longer side.
    pub const MAX_SHARE: f64 = 1.0 / 8.0;
    /// Noise of the refined transmission that [`GuidedRadius::Adaptive`] widens its window
    /// for.
    pub const NOISE_TARGET: f32 = 0.002;

    /// The radius before any widening for noise: [`GuidedRadius::SHARE`] of the longer
    /// side (at least 1) for [`GuidedRadius::Adaptive`].
    pub fn base(self, w: usize, h: usize) -> usize {
        match self {
            GuidedRadius::Pixels(r) => r,
            GuidedRadius::Adaptive => ((w.max(h) as f64 * Self::SHARE).round() as usize).max(1),
        }
    }

    /// The radius for a `w x h` image whose raw transmission has the pixel noise `t_noise`
    /// (standard deviation; ignored by [`GuidedRadius::Pixels`]).
    pub fn pixels(self, w: usize, h: usize, t_noise: f32) -> usize {
        let base = self.base(w, h);
        if self != GuidedRadius::Adaptive || t_noise.is_nan() || t_noise <= Self::NOISE_TARGET {
            return base;
        }
        let for_noise = ((t_noise / Self::NOISE_TARGET - 1.0) / 2.0).ceil() as usize;
        let most = (w.max(h) as f64 * Self::MAX_SHARE) as usize;
        base.max(for_noise.min(most))
    }
}

/// Options of [`dehaze`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DehazeOptions {
    /// Transmission estimator.
    pub method: Method,
    /// Lower bound of the transmission (He et al.'s `t0`): bounds the amplification
    /// `1 / t` of noise in the radiance. In `(0, 1]`.
    pub t_min: f32,
    /// Radius of the guided filter that refines `t`.
    pub guided_radius: GuidedRadius,
    /// Guided-filter regularisation in squared units of the normalised S0 (`S0 / s0_scale`):
    /// larger smooths `t` more across weak edges of S0.
    pub guided_eps: f32,
    /// Dark channel patch size (odd), He et al.'s 15.
    pub dcp_patch: usize,
    /// Dark channel haze-keeping factor `omega`, He et al.'s 0.95.
    pub dcp_omega: f32,
    /// Below this estimated airlight degree of polarization `p` the polarization method
    /// gives up (the airlight cannot be told from noise) and applies [`Self::weak_fallback`].
    pub min_airlight_dolp: f32,
    /// What the polarization method does when `p < min_airlight_dolp`.
    pub weak_fallback: WeakPolarization,
    /// Let `p` and `A_inf` vary over the frame (planes fitted to the sky,
    /// [`airlight::SkyField`]) where enough sky is seen; `false` keeps Schechner et al.'s
    /// single `p` and `A_inf`.
    pub varying_airlight: bool,
    /// Radius of the edge-preserving denoising of S0 before the inversion (a self-guided
    /// filter with `eps` = 9 noise variances, [`refine::denoise`]); 0 inverts S0 as measured.
    /// The inversion multiplies noise by `1 / t`; on a noiseless image this is the identity.
    pub denoise_radius: usize,
    /// The polarization method (also after its dark-channel fallback) leaves the frame
    /// unchanged (`t = 1`, a warning) where the airlight it finds makes up less than this
    /// share of the light on average, `mean(1 - t)` over the valid pixels: a haze-free
    /// frame's polarized objects (glossy highlights, a weakly polarized floor) are
    /// otherwise read as a thin veil of haze and "dehazed". 0 never leaves a frame
    /// unchanged. In `[0, 1]`.
    pub min_airlight_share: f32,
}

/// The default [`DehazeOptions::min_airlight_share`]: between the haze-free frames' mean
/// airlight share and the hazy frames' (docs/benchmarks.md, "dehaze: a frame without
/// haze is left as it is").
pub const MIN_AIRLIGHT_SHARE: f32 = 0.15;

impl Default for DehazeOptions {
    /// Polarization, `t_min = 0.1`, guided filter of [`GuidedRadius::Adaptive`] radius and
    /// `eps = 1e-3`, dark channel patch 15 and `omega = 0.95` (He et al.),
    /// `min_airlight_dolp = 0.02`, dark-channel fallback, varying airlight, denoising
    /// radius 2, [`MIN_AIRLIGHT_SHARE`].
    fn default() -> Self {
        Self {
            method: Method::Polarization,
            t_min: 0.1,
            guided_radius: GuidedRadius::Adaptive,
            guided_eps: 1e-3,
            dcp_patch: 15,
            dcp_omega: 0.95,
            min_airlight_dolp: 0.02,
            weak_fallback: WeakPolarization::DarkChannel,
            varying_airlight: true,
            denoise_radius: 2,
            min_airlight_share: MIN_AIRLIGHT_SHARE,
        }
    }
}

impl DehazeOptions {
    /// Checks the ranges of the options.
    pub fn validate(&self) -> Result<(), DehazeError> {
        let bad = |name, value: f64, reason| {
            Err(DehazeError::Option {
                name,
                value,
                reason,
            })
        };
        if !(self.t_min > 0.0 && self.t_min <= 1.0) {
            return bad("t_min", self.t_min.into(), "must be in (0, 1]");
        }
        if !(self.guided_eps >= 0.0 && self.guided_eps.is_finite()) {
            return bad(
                "guided_eps",
                self.guided_eps.into(),
                "must be finite and >= 0",
            );
        }
        if self.dcp_patch == 0 || self.dcp_patch.is_multiple_of(2) {
            return bad("dcp_patch", self.dcp_patch as f64, "must be odd and >= 1");
        }
        if !(self.dcp_omega >= 0.0 && self.dcp_omega <= 1.0) {
            return bad("dcp_omega", self.dcp_omega.into(), "must be in [0, 1]");
        }
        if !(self.min_airlight_dolp >= 0.0 && self.min_airlight_dolp <= 1.0) {
            return bad(
                "min_airlight_dolp",
                self.min_airlight_dolp.into(),
                "must be in [0, 1]",
            );
        }
        if !(self.min_airlight_share >= 0.0 && self.min_airlight_share <= 1.0) {
            return bad(
                "min_airlight_share",
                self.min_airlight_share.into(),
                "must be in [0, 1]",
            );
        }
        Ok(())
    }
}

/// The result of [`dehaze`].
#[derive(Clone, Debug, PartialEq)]
pub struct Dehazed {
    /// Dehazed radiance (the haze model inverted, [`Inversion`]), clamped to `>= 0`, in the
    /// unit of S0.
    pub radiance: Gray<f32>,
    /// Transmission `t` in `[t_min, 1]`.
    pub transmission: Gray<f32>,
    /// Relative depth `-ln t` (optical depth, `beta z`), in `[0, -ln t_min]`.
    pub depth: Gray<f32>,
    /// Airlight at infinity `A_inf`, in the unit of S0 (at the image centre where it varies).
    pub airlight_inf: f32,
    /// Degree of polarization `p` of the airlight, at the image centre where it varies
    /// (0 for the dark channel method; the estimate that was too weak after a fallback).
    pub airlight_dolp: f32,
    /// The estimator that produced `t` (differs from the requested one after a fallback).
    pub method: Method,
    /// What went wrong or was assumed (fallbacks, excluded pixels, missing sky).
    pub warnings: Vec<String>,
}

/// Dehazes `obs` with `opts.method`: transmission, relative depth and radiance.
///
/// Never fails on the content of the image (NaN, all-zero, saturated, 1x1): those give a
/// finite result and a warning; it fails only on invalid options or an empty image.
pub fn dehaze(obs: &Observation, opts: &DehazeOptions) -> Result<Dehazed, DehazeError> {
    opts.validate()?;
    let (w, h) = obs.size();
    if w == 0 || h == 0 {
        return Err(DehazeError::Empty(w, h));
    }
    let input = prep::Normalized::new(obs);
    let mut warnings = input.warnings();
    let estimate = match opts.method {
        Method::DarkChannel => dark_channel::transmission(&input, opts)?,
        Method::Polarization => polarization::transmission(&input, opts)?,
    };
    warnings.extend(estimate.warnings.iter().cloned());
    let mut t = refine::refine(&input, &estimate.raw_t, opts, estimate.guided_eps)?;
    let share = (opts.method == Method::Polarization).then(|| airlight_share(&t, &input.valid));
    if let Some(share) = share.filter(|&s| s < opts.min_airlight_share) {
        warnings.push(format!(
            "no haze found: the airlight makes up {share:.3} of the light on average, \
             below min_airlight_share {}: image left unchanged (t = 1)",
            opts.min_airlight_share
        ));
        t.as_mut_slice().fill(1.0);
        // Denoising is blended in by 1 - t: nothing to do.
        return Ok(finish(
            &input, &input.s0, t, &estimate, opts.t_min, warnings,
        ));
    }
    let s0 = refine::denoise(&input, &t, opts.denoise_radius)?;
    Ok(finish(&input, &s0, t, &estimate, opts.t_min, warnings))
}

/// The airlight's mean share of the light, `mean(1 - t)` over the valid pixels (0 without
/// any).
fn airlight_share(t: &Gray<f32>, valid: &[bool]) -> f32 {
    let (sum, n) = (t.as_slice().iter().zip(valid))
        .filter(|&(t, &ok)| ok && t.is_finite())
        .fold((0.0f64, 0usize), |(s, n), (t, _)| {
            (s + f64::from(1.0 - t.clamp(0.0, 1.0)), n + 1)
        });
    if n == 0 { 0.0 } else { (sum / n as f64) as f32 }
}

/// A raw (unrefined) transmission and the airlight it assumes, in normalised units.
#[derive(Clone, Debug)]
pub struct RawEstimate {
    /// Per-pixel transmission before refinement (any finite value; NaN where unknown).
    pub raw_t: Gray<f32>,
    /// Airlight at infinity, normalised (`A_inf / s0_scale`); at the image centre where
    /// it varies.
    pub airlight_inf: f32,
    /// `A_inf` per pixel, normalised, where it varies over the frame.
    pub airlight_field: Option<Gray<f32>>,
    /// Degree of polarization of the airlight.
    pub airlight_dolp: f32,
    /// How the radiance is recovered from this estimate.
    pub inversion: Inversion,
    /// The method that produced `raw_t`.
    pub method: Method,
    /// The guided filter's regularisation for this estimate.
    pub guided_eps: f32,
    /// Warnings of the estimator.
    pub warnings: Vec<String>,
}

/// How the haze model `S0 - A_inf = t (L - A_inf)` is solved for `L`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Inversion {
    /// `L = (S0 - A_inf) / t + A_inf` with `t >= t_min` (He et al.; gain up to `1 / t_min`).
    Clamped,
    /// Tikhonov-regularised least squares, weight `w = t_min^2 (1 - t)` on `L - A_inf`:
    /// `L = A_inf + t (S0 - A_inf) / (t^2 + w)`. Where `t` is near `t_min` (sky, dense
    /// haze: the radiance is not recoverable) the result tends to the local airlight instead
    /// of multiplying the misfit of `A_inf` by `1 / t_min` (the gain `t / (t^2 + w)` peaks
    /// at `t = t_min` with `1 / (t_min (2 - t_min))`, about half); haze-free pixels
    /// (`t = 1`) are returned exactly, and in between `L - A_inf` is shrunk by the
    /// fraction `w / (t^2 + w)`.
    Regularized,
}

impl Inversion {
    /// `L` from `S0`, `t` and `A_inf` (normalised units).
    pub fn radiance(self, s0: f32, t: f32, a_inf: f32, t_min: f32) -> f32 {
        match self {
            Inversion::Clamped => (s0 - a_inf) / t + a_inf,
            Inversion::Regularized => {
                a_inf + t * (s0 - a_inf) / (t * t + t_min * t_min * (1.0 - t))
            }
        }
    }
}

/// Radiance by the estimate's [`Inversion`] (clamped to `>= 0`) and depth `-ln t`, back in
/// the unit of S0.
fn finish(
    input: &prep::Normalized,
    s0: &Gray<f32>,
    t: Gray<f32>,
    est: &RawEstimate,
    t_min: f32,
    warnings: Vec<String>,
) -> Dehazed {
    let (w, h) = input.s0.size();
    let a = est.airlight_inf;
    let scale = input.scale;
    let inversion = est.inversion;
    let invert = |i: f32, t: f32, a: f32| inversion.radiance(i, t, a, t_min).max(0.0) * scale;
    let radiance: Vec<f32> = match &est.airlight_field {
        Some(field) => s0
            .as_slice()
            .par_iter()
            .zip(t.as_slice())
            .zip(field.as_slice())
            .map(|((&i, &t), &a)| invert(i, t, a))
            .collect(),
        None => s0
            .as_slice()
            .par_iter()
            .zip(t.as_slice())
            .map(|(&i, &t)| invert(i, t, a))
            .collect(),
    };
    let depth: Vec<f32> = t
        .as_slice()
        .par_iter()
        .map(|&t| (-t.ln()).max(0.0))
        .collect();
    Dehazed {
        radiance: Gray::from_vec(w, h, radiance).expect("size matches"),
        depth: Gray::from_vec(w, h, depth).expect("size matches"),
        transmission: t,
        airlight_inf: a * scale,
        airlight_dolp: est.airlight_dolp,
        method: est.method,
        warnings,
    }
}

#[cfg(test)]
mod tests {
    use super::{GuidedRadius, Inversion};

    #[test]
    fn adaptive_guided_radius_is_a_share_of_the_frame_widened_for_noise() {
        let r = |w, h, noise| GuidedRadius::Adaptive.pixels(w, h, noise);
        assert_eq!(
            (r(128, 128, 0.0), r(512, 384, 0.0), r(384, 512, 0.0)),
            (4, 16, 16)
        );
        // Never 0 (which would switch the filter off), even for a 1x1 image.
        assert_eq!((r(1, 1, 0.0), r(20, 3, 0.0)), (1, 1));
        // t noise 0.02 needs a window of 10 pixels (r = 5) to reach 0.002; 0.05 needs 25
        // (r = 12), more than 1/8 of 64; NaN noise leaves the share.
        assert_eq!(
            (r(128, 128, 0.02), r(128, 128, 0.05), r(64, 64, 0.05)),
            (5, 12, 8)
        );
        assert_eq!(r(128, 128, f32::NAN), 4);
        assert_eq!(GuidedRadius::Pixels(0).pixels(512, 512, 1.0), 0);
        assert_eq!(GuidedRadius::Pixels(7).pixels(512, 512, 1.0), 7);
    }

    #[test]
    fn regularized_inversion_is_exact_without_haze_and_bounded_at_t_min() {
        let (s0, a, t_min) = (0.3f32, 0.8f32, 0.1f32);
        for inv in [Inversion::Clamped, Inversion::Regularized] {
            // t = 1: L = S0 (one rounding).
            assert!(
                (inv.radiance(s0, 1.0, a, t_min) - s0).abs() < 1e-6,
                "{inv:?}"
            );
        }
        // At t = t_min the clamped gain is 1 / t_min = 10; the regularised one is
        // t_min / (t_min^2 (2 - t_min)) = 5.26, its maximum over t.
        let gain = |inv: Inversion| (inv.radiance(s0, t_min, a, t_min) - a) / (s0 - a);
        assert!((gain(Inversion::Clamped) - 10.0).abs() < 1e-4);
        let g = gain(Inversion::Regularized);
        assert!((g - 1.0 / (t_min * (2.0 - t_min))).abs() < 1e-4, "gain {g}");
        // t = 0.5: within 2 % of the exact inverse.
        let (exact, reg) = (
            Inversion::Clamped.radiance(s0, 0.5, a, t_min),
            Inversion::Regularized.radiance(s0, 0.5, a, t_min),
        );
        assert!(
            ((reg - a) / (exact - a) - 1.0).abs() < 0.02,
            "{reg} vs {exact}"
        );
    }
}
