//! Physical-validity tests for Mueller matrices: passivity (energy) and
//! realizability (Cloude 1986).
//!
//! (For Stokes vectors see [`crate::stokes::is_physical`].)

use crate::mueller::{Mueller, coherence_to_stokes};
use nalgebra::{Matrix4, Vector4};
use num_complex::Complex64;

/// The largest output intensity over all physical unit-intensity inputs:
/// `m00 + sqrt(m01² + m02² + m03²)`, reached for the fully polarized input along
/// the first row's diattenuation vector (`S0' = m00 + (m01, m02, m03)·(S1, S2, S3)`).
pub fn max_transmittance(m: &Mueller) -> f64 {
    m[(0, 0)] + m[(0, 1)].hypot(m[(0, 2)]).hypot(m[(0, 3)])
}

/// `true` for a passive element: it never outputs more intensity than it
/// receives, `max_transmittance(m) ≤ 1 + tol`. NaN entries give `false`.
pub fn is_passive(m: &Mueller, tol: f64) -> bool {
    max_transmittance(m) <= 1.0 + tol
}

/// Cloude's coherency matrix `H` (Hermitian 4×4, trace `m00`): the reshuffled
/// `A⁻¹ M A` (see [`crate::mueller::from_jones`]), half of the covariance that is
/// `vec(J) vec(J)ᴴ` for a single Jones matrix `J`. A convex sum of Jones elements
/// gives a positive semi-definite `H` (S. R. Cloude, "Group theory and polarisation
/// algebra", Optik 75, 26–36, 1986; Gil & Ossikovski, *Polarized Light and the
/// Mueller Matrix Approach*, 2016, §5.2).
pub fn coherency_matrix(m: &Mueller) -> Matrix4<Complex64> {
    let (a, a_inv) = coherence_to_stokes();
    let n = a_inv * m.map(|v| Complex64::new(v, 0.0)) * a;
    // N[(2i+k), (2j+l)] = J_ij J*_kl  ->  C[(2i+j), (2k+l)] = J_ij J*_kl.
    Matrix4::from_fn(|r, c| {
        let (i, j, k, l) = (r / 2, r % 2, c / 2, c % 2);
        n[(2 * i + k, 2 * j + l)] * 0.5
    })
}

/// Eigenvalues of the coherency matrix, in descending order. They sum to `m00`;
/// a single nonzero value means a non-depolarizing (Jones) element.
pub fn coherency_eigenvalues(m: &Mueller) -> Vector4<f64> {
    let mut ev = coherency_matrix(m).symmetric_eigenvalues();
    ev.as_mut_slice().sort_by(|a, b| b.total_cmp(a));
    ev
}

/// `true` when `m` is a convex sum of Jones elements (realizable by some passive or
/// active optical system): every coherency eigenvalue `≥ −tol · |m00|`. NaN gives `false`.
pub fn is_realizable(m: &Mueller, tol: f64) -> bool {
    m.iter().all(|v| v.is_finite())
        && coherency_eigenvalues(m)
            .iter()
            .all(|&e| e >= -tol * m[(0, 0)].abs())
}

/// `true` for a physical passive element: realizable and passive within `tol`.
pub fn is_physical_mueller(m: &Mueller, tol: f64) -> bool {
    is_realizable(m, tol) && is_passive(m, tol)
}
