//! Fast path for the most common Mueller structure in a renderer: block-diagonal
//! `(S0, S1) ⊕ (S2, S3)`.
//!
//! Every element whose Jones matrix is diagonal in the current frame has this
//! form (see [`crate::mueller::from_diagonal_jones`]): Fresnel reflection and
//! transmission in the s/p frame, partial polarizers and retarders with axes
//! along x or y, absorbers and `diag(1, a, a, c)` depolarizers. Products of
//! such blocks cost 16 multiplications instead of 64, applying one to a
//! Stokes vector 8 instead of 16, and left-multiplying a general matrix 32.

use crate::mueller::Mueller;
use crate::stokes::Stokes;
use nalgebra::{Matrix2, Vector2};
use num_complex::Complex64;
use std::ops::Mul;

/// A block-diagonal Mueller matrix `[[upper, 0], [0, lower]]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlockDiagonal {
    /// Acts on `(S0, S1)`.
    pub upper: Matrix2<f64>,
    /// Acts on `(S2, S3)`.
    pub lower: Matrix2<f64>,
}

impl BlockDiagonal {
    /// The identity.
    pub fn identity() -> Self {
        Self {
            upper: Matrix2::identity(),
            lower: Matrix2::identity(),
        }
    }

    /// Block form of [`crate::mueller::from_diagonal_jones`]: with `w = a_x a_y*`,
    /// `upper = [[A, B], [B, A]]`, `lower = [[Re w, −Im w], [Im w, Re w]]`,
    /// `A = (|a_x|² + |a_y|²)/2`, `B = (|a_x|² − |a_y|²)/2`.
    pub fn from_diagonal_jones(a_x: Complex64, a_y: Complex64) -> Self {
        let (rx, ry) = (a_x.norm_sqr(), a_y.norm_sqr());
        let (a, b) = (0.5 * (rx + ry), 0.5 * (rx - ry));
        let w = a_x * a_y.conj();
        Self {
            upper: Matrix2::new(a, b, b, a),
            lower: Matrix2::new(w.re, -w.im, w.im, w.re),
        }
    }

    /// Detects the structure: `Some` when every entry outside the two blocks has
    /// magnitude `≤ tol`; those entries are then dropped.
    pub fn from_mueller(m: &Mueller, tol: f64) -> Option<Self> {
        let off_diagonal_small =
            (0..2).all(|i| (2..4).all(|j| m[(i, j)].abs() <= tol && m[(j, i)].abs() <= tol));
        off_diagonal_small.then(|| Self {
            upper: m.fixed_view::<2, 2>(0, 0).into_owned(),
            lower: m.fixed_view::<2, 2>(2, 2).into_owned(),
        })
    }

    /// The full 4×4 matrix.
    pub fn to_mueller(&self) -> Mueller {
        let mut m = Mueller::zeros();
        m.fixed_view_mut::<2, 2>(0, 0).copy_from(&self.upper);
        m.fixed_view_mut::<2, 2>(2, 2).copy_from(&self.lower);
        m
    }
}

impl Mul for BlockDiagonal {
    type Output = BlockDiagonal;
    /// Block-wise product (16 multiplications).
    fn mul(self, rhs: BlockDiagonal) -> BlockDiagonal {
        BlockDiagonal {
            upper: self.upper * rhs.upper,
            lower: self.lower * rhs.lower,
        }
    }
}

impl Mul<Stokes> for BlockDiagonal {
    type Output = Stokes;
    /// Applies the element to a Stokes vector (8 multiplications).
    fn mul(self, s: Stokes) -> Stokes {
        let u = self.upper * Vector2::new(s[0], s[1]);
        let l = self.lower * Vector2::new(s[2], s[3]);
        Stokes::new(u[0], u[1], l[0], l[1])
    }
}

impl Mul<Mueller> for BlockDiagonal {
    type Output = Mueller;
    /// `B · M` for a general `M`: rows 0–1 and 2–3 of `M` mixed by one block each
    /// (32 multiplications).
    fn mul(self, m: Mueller) -> Mueller {
        let mut out = Mueller::zeros();
        out.fixed_rows_mut::<2>(0)
            .copy_from(&(self.upper * m.fixed_rows::<2>(0)));
        out.fixed_rows_mut::<2>(2)
            .copy_from(&(self.lower * m.fixed_rows::<2>(2)));
        out
    }
}

impl Mul<BlockDiagonal> for Mueller {
    type Output = Mueller;
    /// `M · B` for a general `M`: columns 0–1 and 2–3 of `M` mixed by one block each
    /// (32 multiplications).
    fn mul(self, b: BlockDiagonal) -> Mueller {
        let mut out = Mueller::zeros();
        out.fixed_columns_mut::<2>(0)
            .copy_from(&(self.fixed_columns::<2>(0) * b.upper));
        out.fixed_columns_mut::<2>(2)
            .copy_from(&(self.fixed_columns::<2>(2) * b.lower));
        out
    }
}
