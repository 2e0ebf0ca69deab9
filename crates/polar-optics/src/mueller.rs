//! Mueller matrices: small pure builders for the common optical elements.

use nalgebra::Matrix4;
use num_complex::Complex64;

/// A 4×4 Mueller matrix acting on [`crate::Stokes`] vectors.
pub type Mueller = Matrix4<f64>;

/// Re-expresses a Stokes vector in a reference frame rotated by `theta` (from x toward y):
/// light polarized at `α` in the old frame is at `α − θ` in the new one.
///
/// `R(θ) = [[1,0,0,0],[0,cos2θ,sin2θ,0],[0,−sin2θ,cos2θ,0],[0,0,0,1]]`.
pub fn rotator(theta: f64) -> Mueller {
    let (s, c) = (2.0 * theta).sin_cos();
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
pub fn from_diagonal_jones(a_x: Complex64, a_y: Complex64) -> Mueller {
    let (rx, ry) = (a_x.norm_sqr(), a_y.norm_sqr());
    let a = 0.5 * (rx + ry);
    let b = 0.5 * (rx - ry);
    let w = a_x * a_y.conj();
    #[rustfmt::skip]
    let m = Mueller::new(
          a,   b, 0.0,   0.0,
          b,   a, 0.0,   0.0,
        0.0, 0.0, w.re, -w.im,
        0.0, 0.0, w.im,  w.re,
    );
    m
}
