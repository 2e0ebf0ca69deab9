//! Stokes vectors and the scalar quantities derived from them.
//!
//! The scalar functions are generic over `f32`/`f64` so that image code runs the
//! very same formulas per pixel at full speed.

use crate::error::OpticsError;
use nalgebra::{Matrix3, Matrix3xX, OMatrix, U3, Vector3, Vector4};
use num_traits::Float;

/// A full Stokes vector `(S0, S1, S2, S3)` in some reference frame.
pub type Stokes = Vector4<f64>;

/// The linear part `(S0, S1, S2)` of a Stokes vector, for scenes that never
/// create circular polarization (no retarders, no total internal reflection, no
/// metals); pair it with [`crate::mueller::LinearMueller`].
pub type LinearStokes = Vector3<f64>;

/// Drops `S3`: the linear part `(S0, S1, S2)`.
pub fn to_linear(s: &Stokes) -> LinearStokes {
    s.fixed_rows::<3>(0).into_owned()
}

/// Extends a linear Stokes vector with `S3 = 0`.
pub fn from_linear(s: &LinearStokes) -> Stokes {
    Stokes::new(s[0], s[1], s[2], 0.0)
}

/// Unpolarized light of intensity `s0`.
pub fn unpolarized(s0: f64) -> Stokes {
    Stokes::new(s0, 0.0, 0.0, 0.0)
}

/// Fully linearly polarized light of intensity `s0` at angle `theta` (radians from x toward y).
pub fn linear(s0: f64, theta: f64) -> Stokes {
    let (s, c) = (2.0 * theta).sin_cos();
    Stokes::new(s0, s0 * c, s0 * s, 0.0)
}

/// Degree of linear polarization `sqrt(S1² + S2²) / S0`; NaN where `S0` is zero or not finite.
/// Formed as `hypot(S1/S0, S2/S0)`, which does not overflow for Stokes values near the
/// float maximum (`hypot(S1, S2)` alone can exceed it where `S0` does not).
#[inline]
pub fn dolp<T: Float>(s0: T, s1: T, s2: T) -> T {
    if s0 > T::zero() && s0.is_finite() {
        (s1 / s0).hypot(s2 / s0)
    } else {
        T::nan()
    }
}

/// Degree of polarization `sqrt(S1² + S2² + S3²) / S0`; NaN where `S0` is zero or not finite.
/// Scaled by `S0` first, as [`dolp`].
#[inline]
pub fn dop<T: Float>(s0: T, s1: T, s2: T, s3: T) -> T {
    if s0 > T::zero() && s0.is_finite() {
        (s1 / s0).hypot(s2 / s0).hypot(s3 / s0)
    } else {
        T::nan()
    }
}

/// Degree of circular polarization `S3 / S0` (signed); NaN where `S0` is zero or not finite.
#[inline]
pub fn docp<T: Float>(s0: T, s3: T) -> T {
    if s0 > T::zero() && s0.is_finite() {
        s3 / s0
    } else {
        T::nan()
    }
}

/// Angle of linear polarization `½ atan2(S2, S1)` wrapped to `[0, π)`.
///
/// Undefined (NaN) where `S0` is zero or not finite. Where `S1 = S2 = 0` the
/// angle is mathematically arbitrary; this returns 0 there (documented fallback).
#[inline]
pub fn aolp<T: Float>(s0: T, s1: T, s2: T) -> T {
    if !(s0 > T::zero() && s0.is_finite()) {
        return T::nan();
    }
    let half = T::from(0.5).unwrap();
    let pi = T::from(std::f64::consts::PI).unwrap();
    let a = half * s2.atan2(s1);
    let a = if a < T::zero() { a + pi } else { a };
    // `a + π` may round up to exactly π for tiny negative `a`.
    if a >= pi { T::zero() } else { a }
}

/// Ellipticity angle `χ = ½ asin(S3 / sqrt(S1² + S2² + S3²))` in `[−π/4, π/4]`;
/// 0 for unpolarized light, NaN where `S0` is zero or not finite.
#[inline]
pub fn ellipticity_angle<T: Float>(s0: T, s1: T, s2: T, s3: T) -> T {
    if !(s0 > T::zero() && s0.is_finite()) {
        return T::nan();
    }
    let p = s1.hypot(s2).hypot(s3);
    if p == T::zero() {
        return T::zero();
    }
    let r = (s3 / p).max(-T::one()).min(T::one());
    T::from(0.5).unwrap() * r.asin()
}

/// Maximum intensity behind a rotating ideal linear polarizer, `(S0 + sqrt(S1² + S2²)) / 2`.
#[inline]
pub fn imax<T: Float>(s0: T, s1: T, s2: T) -> T {
    T::from(0.5).unwrap() * (s0 + s1.hypot(s2))
}

/// Minimum intensity behind a rotating ideal linear polarizer, `(S0 − sqrt(S1² + S2²)) / 2`.
#[inline]
pub fn imin<T: Float>(s0: T, s1: T, s2: T) -> T {
    T::from(0.5).unwrap() * (s0 - s1.hypot(s2))
}

/// Intensity behind an ideal linear polarizer at `theta`:
/// `I(θ) = ½ (S0 + S1 cos 2θ + S2 sin 2θ)` (Malus's law for partially polarized light).
#[inline]
pub fn intensity_through_polarizer<T: Float>(s0: T, s1: T, s2: T, theta: T) -> T {
    let two = T::from(2.0).unwrap();
    let (s, c) = (two * theta).sin_cos();
    T::from(0.5).unwrap() * (s0 + s1 * c + s2 * s)
}

/// Linear Stokes `(S0, S1, S2)` from the four intensities behind polarizers at
/// 0°, 45°, 90° and 135°: `S0 = ½ΣI`, `S1 = I0 − I90`, `S2 = I45 − I135`.
///
/// This is the least-squares solution for those four angles in closed form.
#[inline]
pub fn linear_stokes_from_quad<T: Float>(i0: T, i45: T, i90: T, i135: T) -> [T; 3] {
    let half = T::from(0.5).unwrap();
    [half * (i0 + i45 + i90 + i135), i0 - i90, i45 - i135]
}

/// `true` when `S0 ≥ sqrt(S1² + S2² + S3²)` up to a relative tolerance `tol`
/// and every component is finite: the vector describes physical light.
pub fn is_physical(s: &Stokes, tol: f64) -> bool {
    s.iter().all(|v| v.is_finite())
        && s[0] >= 0.0
        && s[1].hypot(s[2]).hypot(s[3]) <= s[0] * (1.0 + tol) + tol * f64::MIN_POSITIVE.sqrt()
}

/// Least-squares linear Stokes from intensities behind ideal polarizers at any
/// set of angles, solved once per angle set and then applied to many pixels.
///
/// The model is `I(θ_i) = ½ (S0 + S1 cos 2θ_i + S2 sin 2θ_i)`, i.e. `I = A s` with
/// rows `A_i = ½ (1, cos 2θ_i, sin 2θ_i)`; the fit is `s = (AᵀA)⁻¹ Aᵀ I`, stored as the
/// 3×N pseudo-inverse. For 0°/45°/90°/135° it reduces to [`linear_stokes_from_quad`].
#[derive(Clone, Debug, PartialEq)]
pub struct LinearStokesFit {
    pinv: Matrix3xX<f64>,
}

/// Angles closer than this (radians, modulo π) count as the same polarizer.
const SAME_ANGLE: f64 = 1e-6;

impl LinearStokesFit {
    /// Prepares the fit for polarizer `angles` (radians from x toward y).
    ///
    /// Errors: a non-finite angle, or fewer than three angles distinct modulo π
    /// (three distinct points on the circle `2θ` always make `AᵀA` invertible).
    pub fn new(angles: &[f64]) -> Result<Self, OpticsError> {
        if let Some((index, &value)) = angles.iter().enumerate().find(|(_, a)| !a.is_finite()) {
            return Err(OpticsError::NonFinite {
                what: "angles",
                index,
                value,
            });
        }
        let distinct = count_distinct_mod_pi(angles);
        if distinct < 3 {
            return Err(OpticsError::TooFewAngles { distinct });
        }
        let a = OMatrix::<f64, nalgebra::Dyn, U3>::from_fn(angles.len(), |i, j| {
            let (s, c) = (2.0 * angles[i]).sin_cos();
            0.5 * [1.0, c, s][j]
        });
        let ata: Matrix3<f64> = a.transpose() * &a;
        let inv = ata
            .try_inverse()
            .ok_or(OpticsError::TooFewAngles { distinct })?;
        Ok(Self {
            pinv: inv * a.transpose(),
        })
    }

    /// The 3×N matrix `(AᵀA)⁻¹ Aᵀ`: row `j` holds the weights of each intensity in `S_j`.
    pub fn pseudo_inverse(&self) -> &Matrix3xX<f64> {
        &self.pinv
    }

    /// `(S0, S1, S2)` from one intensity per angle (same order as the angles).
    /// NaN or Inf intensities propagate into the result.
    pub fn fit(&self, intensities: &[f64]) -> Result<LinearStokes, OpticsError> {
        let n = self.pinv.ncols();
        if intensities.len() != n {
            return Err(OpticsError::LengthMismatch {
                angles: n,
                intensities: intensities.len(),
            });
        }
        Ok(self.pinv.columns(0, n) * nalgebra::DVector::from_column_slice(intensities))
    }
}

/// One-shot least-squares linear Stokes from `intensities` measured behind ideal
/// polarizers at `angles`; see [`LinearStokesFit`].
pub fn linear_stokes_least_squares(
    angles: &[f64],
    intensities: &[f64],
) -> Result<LinearStokes, OpticsError> {
    if angles.len() != intensities.len() {
        return Err(OpticsError::LengthMismatch {
            angles: angles.len(),
            intensities: intensities.len(),
        });
    }
    LinearStokesFit::new(angles)?.fit(intensities)
}

/// Number of angles distinct modulo π (a polarizer at θ and at θ + π is the same).
fn count_distinct_mod_pi(angles: &[f64]) -> usize {
    let pi = std::f64::consts::PI;
    let mut kept: Vec<f64> = Vec::new();
    for a in angles.iter().map(|a| a.rem_euclid(pi)) {
        let same = |b: &f64| {
            let d = (a - b).abs();
            d.min(pi - d) < SAME_ANGLE
        };
        if !kept.iter().any(same) {
            kept.push(a);
        }
    }
    kept.len()
}
