//! Mueller matrices: small pure builders for the common optical elements.

use crate::error::OpticsError;
use nalgebra::{Matrix2, Matrix3, Matrix4};
use num_complex::Complex64;

/// A 4×4 Mueller matrix acting on [`crate::Stokes`] vectors.
pub type Mueller = Matrix4<f64>;

/// The 3×3 linear part of a Mueller matrix, acting on [`crate::stokes::LinearStokes`].
///
/// Exact for a chain of elements none of which couples S3 with `(S0, S1, S2)`
/// (see [`couples_circular`]): rotators, polarizers, depolarizers, absorbers and
/// dielectric reflection/transmission outside total internal reflection.
pub type LinearMueller = Matrix3<f64>;

/// The upper-left 3×3 block of `m` (rows and columns S0, S1, S2).
#[inline]
pub fn linear_part(m: &Mueller) -> LinearMueller {
    m.fixed_view::<3, 3>(0, 0).into_owned()
}

/// `true` when `m` moves intensity between S3 and `(S0, S1, S2)` beyond `tol`
/// (any of `m03, m13, m23, m30, m31, m32` nonzero): then the 3×3 form is not exact.
pub fn couples_circular(m: &Mueller, tol: f64) -> bool {
    (0..3).any(|i| m[(i, 3)].abs() > tol || m[(3, i)].abs() > tol)
}

/// The 3×3 form of [`rotator`]: `[[1,0,0],[0,cos2θ,sin2θ],[0,−sin2θ,cos2θ]]`.
#[inline]
pub fn linear_rotator(theta: f64) -> LinearMueller {
    linear_part(&rotator(theta))
}

/// Re-expresses a Stokes vector in a reference frame rotated by `theta` (from x toward y):
/// light polarized at `α` in the old frame is at `α − θ` in the new one.
///
/// `R(θ) = [[1,0,0,0],[0,cos2θ,sin2θ,0],[0,−sin2θ,cos2θ,0],[0,0,0,1]]`.
#[inline]
pub fn rotator(theta: f64) -> Mueller {
    let (s, c) = (2.0 * theta).sin_cos();
    rotator_cos_sin(c, s)
}

/// [`rotator`] from `cos 2θ` and `sin 2θ` (see `frame::double_angle`, which needs no trigonometry).
#[inline]
pub fn rotator_cos_sin(c: f64, s: f64) -> Mueller {
    #[rustfmt::skip]
    let m = Mueller::new(
        1.0, 0.0, 0.0, 0.0,
        0.0,   c,   s, 0.0,
        0.0,  -s,   c, 0.0,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// The element `m` physically rotated by `theta` about the propagation axis:
/// `R(−θ) · M · R(θ)`.
#[inline]
pub fn rotated_element(m: &Mueller, theta: f64) -> Mueller {
    rotator(-theta) * m * rotator(theta)
}

/// Ideal linear polarizer with its transmission axis at `theta`.
pub fn linear_polarizer(theta: f64) -> Mueller {
    #[rustfmt::skip]
    let m = Mueller::new(
        0.5, 0.5, 0.0, 0.0,
        0.5, 0.5, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 0.0,
    );
    rotated_element(&m, theta)
}

/// Mueller matrix of a Jones matrix `diag(a_x, a_y)` in the current frame
/// (a diattenuating retarder with axes along x and y).
///
/// With `w = a_x · conj(a_y)`:
/// `M = [[A, B, 0, 0], [B, A, 0, 0], [0, 0, Re w, −Im w], [0, 0, Im w, Re w]]`,
/// `A = (|a_x|² + |a_y|²)/2`, `B = (|a_x|² − |a_y|²)/2`; the sign of the lower block
/// follows from `S3 = I_RCP − I_LCP` under `exp(−iωt)`.
#[inline]
pub fn from_diagonal_jones(a_x: Complex64, a_y: Complex64) -> Mueller {
    crate::block::BlockDiagonal::from_diagonal_jones(a_x, a_y).to_mueller()
}

/// Mueller matrix of a general Jones matrix `j` (acting on `(E_x, E_y)`):
/// `M = A (J ⊗ J*) A⁻¹` with `A = [[1,0,0,1],[1,0,0,−1],[0,1,1,0],[0,−i,i,0]]`,
/// i.e. `S3 = 2 Im(E_x E_y*)`, the sign that matches [`from_diagonal_jones`] and
/// `S3 = I_RCP − I_LCP` under `exp(−iωt)` (Chipman, Lam & Young, *Polarized
/// Light and Optical Systems*, 2018, ch. 6, up to that sign).
pub fn from_jones(j: &Matrix2<Complex64>) -> Mueller {
    let (a, a_inv) = coherence_to_stokes();
    (a * j.kronecker(&j.map(|z| z.conj())) * a_inv).map(|z| z.re)
}

/// `(A, A⁻¹)` with `S = A (E ⊗ E*)`, `E ⊗ E* = (E_x E_x*, E_x E_y*, E_y E_x*, E_y E_y*)`.
pub(crate) fn coherence_to_stokes() -> (Matrix4<Complex64>, Matrix4<Complex64>) {
    let (o, z, i) = (
        Complex64::new(1.0, 0.0),
        Complex64::new(0.0, 0.0),
        Complex64::new(0.0, 1.0),
    );
    #[rustfmt::skip]
    let a = Matrix4::new(
        o, z, z, o,
        o, z, z, -o,
        z, o, o, z,
        z, -i, i, z,
    );
    #[rustfmt::skip]
    let a_inv = Matrix4::new(
        o, o, z, z,
        z, z, o, i,
        z, z, o, -i,
        o, -o, z, z,
    ) * Complex64::new(0.5, 0.0);
    (a, a_inv)
}

/// Non-ideal (partial) linear polarizer with its transmission axis at `theta`,
/// intensity transmittance `t_max` along the axis and `t_min = t_max / extinction_ratio`
/// across it (extinction ratio as on datasheets, `≥ 1`; `f64::INFINITY` gives the ideal
/// polarizer scaled by `t_max`).
///
/// With `q = t_max`, `r = t_min`, before rotation:
/// `M = ½ [[q+r, q−r, 0, 0], [q−r, q+r, 0, 0], [0, 0, 2√(qr), 0], [0, 0, 0, 2√(qr)]]`,
/// the Mueller matrix of the Jones matrix `diag(√q, √r)`; diattenuation `(q−r)/(q+r)`.
pub fn partial_polarizer(
    theta: f64,
    t_max: f64,
    extinction_ratio: f64,
) -> Result<Mueller, OpticsError> {
    check_range("t_max", t_max, 0.0, 1.0, "[0, 1]")?;
    check_range(
        "extinction_ratio",
        extinction_ratio,
        1.0,
        f64::INFINITY,
        "[1, inf]",
    )?;
    let t_min = t_max / extinction_ratio;
    let m = from_diagonal_jones(
        Complex64::new(t_max.sqrt(), 0.0),
        Complex64::new(t_min.sqrt(), 0.0),
    );
    Ok(rotated_element(&m, theta))
}

/// Linear retarder of retardance `delta` (radians, any value) with its fast axis at `fast_axis`.
///
/// The slow axis lags by `δ`: Jones `diag(1, e^{iδ})` under `exp(−iωt)` before rotation, so
/// `M = [[1,0,0,0],[0,1,0,0],[0,0,cos δ, sin δ],[0,0,−sin δ, cos δ]]`, then
/// `R(−θ) M R(θ)`. Under this crate's convention a quarter-wave plate (`δ = π/2`) with
/// horizontal fast axis turns +45° linear light into `S3 = −1`: left-handed, the field
/// turning counterclockwise for an observer facing the source (`E_y = i E_x`).
pub fn retarder(delta: f64, fast_axis: f64) -> Mueller {
    let m = from_diagonal_jones(Complex64::new(1.0, 0.0), Complex64::from_polar(1.0, delta));
    rotated_element(&m, fast_axis)
}

/// Partial depolarizer `diag(1, a, a, c)`: keeps the fraction `a` of linear and `c`
/// of circular polarization (`a = c = 0` is the ideal depolarizer, `a = c = 1` the identity).
///
/// Its Cloude coherency eigenvalues are `(1+2a+c)/4, (1−c)/4, (1−c)/4, (1−2a+c)/4`, so it
/// is realizable only for `c ∈ [0, 1]`, `a ∈ [0, (1+c)/2]` (e.g. `diag(1,1,1,0)` is not);
/// other values are rejected.
pub fn depolarizer(linear_kept: f64, circular_kept: f64) -> Result<Mueller, OpticsError> {
    check_range("circular_kept", circular_kept, 0.0, 1.0, "[0, 1]")?;
    let a_max = 0.5 * (1.0 + circular_kept);
    check_range(
        "linear_kept",
        linear_kept,
        0.0,
        a_max,
        "[0, (1 + circular_kept) / 2]",
    )?;
    Ok(Mueller::from_diagonal(&nalgebra::Vector4::new(
        1.0,
        linear_kept,
        linear_kept,
        circular_kept,
    )))
}

/// Neutral absorber (attenuation without polarization change): `t · I`, `t ∈ [0, 1]`.
pub fn absorber(t: f64) -> Result<Mueller, OpticsError> {
    check_range("t", t, 0.0, 1.0, "[0, 1]")?;
    Ok(Mueller::identity() * t)
}

/// `Ok` when `lo ≤ value ≤ hi` (so NaN fails).
fn check_range(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    expected: &'static str,
) -> Result<(), OpticsError> {
    if (lo..=hi).contains(&value) {
        Ok(())
    } else {
        Err(OpticsError::OutOfRange {
            name,
            value,
            expected,
        })
    }
}
