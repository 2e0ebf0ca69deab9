//! Fast path for the most common Mueller structure in a renderer: block-diagonal
//! `(S0, S1) ⊕ (S2, S3)`.
//!
//! Every element whose Jones matrix is diagonal in the current frame has this
//! form (see [`crate::mueller::from_diagonal_jones`]): Fresnel reflection and
//! transmission in the s/p frame, partial polarizers and retarders with axes
//! along x or y, absorbers and `diag(1, a, a, c)` depolarizers. Products of
//! such blocks cost 16 multiplications instead of 64, applying one to a
//! Stokes vector 8 instead of 16, and left-multiplying a general matrix 32.
//! Measured (benches/block_mueller.rs, batches of 1024): block·block 3.6×,
//! block·general 2.9× and block·Stokes 1.7× faster than the 4×4 equivalents.

use crate::mueller::Mueller;
use crate::stokes::Stokes;
use nalgebra::Matrix2;
use num_complex::Complex64;
use std::ops::Mul;

/// A block-diagonal Mueller matrix `[[upper, 0], [0, lower]]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BlockDiagonal {
    /// Acts on `(S0, S1)`.
    pub upper: Matrix2<f64>,
    /// Acts on `(S2, S3)`.
    pub lower: Matrix2<f64>,
}

impl BlockDiagonal {
    /// The identity.
    #[inline]
    pub fn identity() -> Self {
        Self {
            upper: Matrix2::identity(),
            lower: Matrix2::identity(),
        }
    }

    /// Block form of [`crate::mueller::from_diagonal_jones`]: with `w = a_x a_y*`,
    /// `upper = [[A, B], [B, A]]`, `lower = [[Re w, −Im w], [Im w, Re w]]`,
    /// `A = (|a_x|² + |a_y|²)/2`, `B = (|a_x|² − |a_y|²)/2`.
    #[inline]
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
    #[inline]
    pub fn from_mueller(m: &Mueller, tol: f64) -> Option<Self> {
        let small = |i: usize, j: usize| m[(i, j)].abs() <= tol && m[(j, i)].abs() <= tol;
        let off_diagonal_small = small(0, 2) && small(0, 3) && small(1, 2) && small(1, 3);
        off_diagonal_small.then(|| Self {
            upper: Matrix2::new(m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)]),
            lower: Matrix2::new(m[(2, 2)], m[(2, 3)], m[(3, 2)], m[(3, 3)]),
        })
    }

    /// `rotator(θo) · B · rotator(θi)` for `out = (cos 2θo, sin 2θo)` and
    /// `inp = (cos 2θi, sin 2θi)`: the element re-expressed in other bases (a Fresnel
    /// matrix leaving its s/p frame), written out. The same products as
    /// [`crate::frame::rotate_rows`] then [`crate::frame::rotate_columns`] on
    /// [`Self::to_mueller`] minus those with its zeros: 20 multiplications instead of 32.
    #[inline]
    pub fn rotated(&self, (co, so): (f64, f64), (ci, si): (f64, f64)) -> Mueller {
        let (u, l) = (&self.upper, &self.lower);
        // Rows 1 and 2 after the output rotation: (co u21, co u22, so l11, so l12)
        // and (−so u21, −so u22, co l11, co l12); then columns 1 and 2 mix.
        let (r1, r2) = ((co * u.m22, so * l.m11), (-(so * u.m22), co * l.m11));
        #[rustfmt::skip]
        let m = Mueller::new(
            u.m11, ci * u.m12, si * u.m12, 0.0,
            co * u.m21, ci * r1.0 - si * r1.1, si * r1.0 + ci * r1.1, so * l.m12,
            -(so * u.m21), ci * r2.0 - si * r2.1, si * r2.0 + ci * r2.1, co * l.m12,
            0.0, -(si * l.m21), ci * l.m21, l.m22,
        );
        m
    }

    /// The full 4×4 matrix.
    #[inline]
    pub fn to_mueller(&self) -> Mueller {
        let (u, l) = (&self.upper, &self.lower);
        #[rustfmt::skip]
        let m = Mueller::new(
            u.m11, u.m12, 0.0, 0.0,
            u.m21, u.m22, 0.0, 0.0,
            0.0, 0.0, l.m11, l.m12,
            0.0, 0.0, l.m21, l.m22,
        );
        m
    }
}

// The products below are written out entry by entry and marked #[inline]:
// with nalgebra sub-matrix views, or without cross-crate inlining, they were
// slower than nalgebra's full 4x4 product (benches/block_mueller.rs).

impl Mul for BlockDiagonal {
    type Output = BlockDiagonal;
    /// Block-wise product (16 multiplications).
    #[inline]
    fn mul(self, rhs: BlockDiagonal) -> BlockDiagonal {
        BlockDiagonal {
            upper: mul2(&self.upper, &rhs.upper),
            lower: mul2(&self.lower, &rhs.lower),
        }
    }
}

impl Mul<Stokes> for BlockDiagonal {
    type Output = Stokes;
    /// Applies the element to a Stokes vector (8 multiplications).
    #[inline]
    fn mul(self, s: Stokes) -> Stokes {
        let (u, l) = (&self.upper, &self.lower);
        Stokes::new(
            u.m11 * s.x + u.m12 * s.y,
            u.m21 * s.x + u.m22 * s.y,
            l.m11 * s.z + l.m12 * s.w,
            l.m21 * s.z + l.m22 * s.w,
        )
    }
}

impl Mul<Mueller> for BlockDiagonal {
    type Output = Mueller;
    /// `B · M` for a general `M`: rows 0–1 and 2–3 of `M` mixed by one block each
    /// (32 multiplications).
    #[inline]
    fn mul(self, m: Mueller) -> Mueller {
        let (u, l) = (&self.upper, &self.lower);
        let mut out = m;
        for mut c in out.column_iter_mut() {
            let (c0, c1, c2, c3) = (c.x, c.y, c.z, c.w);
            c.x = u.m11 * c0 + u.m12 * c1;
            c.y = u.m21 * c0 + u.m22 * c1;
            c.z = l.m11 * c2 + l.m12 * c3;
            c.w = l.m21 * c2 + l.m22 * c3;
        }
        out
    }
}

impl Mul<BlockDiagonal> for Mueller {
    type Output = Mueller;
    /// `M · B` for a general `M`: columns 0–1 and 2–3 of `M` mixed by one block each
    /// (32 multiplications).
    #[inline]
    fn mul(self, b: BlockDiagonal) -> Mueller {
        let (u, l) = (&b.upper, &b.lower);
        let (c0, c1, c2, c3) = (
            self.column(0),
            self.column(1),
            self.column(2),
            self.column(3),
        );
        Mueller::from_columns(&[
            c0 * u.m11 + c1 * u.m21,
            c0 * u.m12 + c1 * u.m22,
            c2 * l.m11 + c3 * l.m21,
            c2 * l.m12 + c3 * l.m22,
        ])
    }
}

/// 2×2 product written out (8 multiplications).
#[inline]
fn mul2(a: &Matrix2<f64>, b: &Matrix2<f64>) -> Matrix2<f64> {
    Matrix2::new(
        a.m11 * b.m11 + a.m12 * b.m21,
        a.m11 * b.m12 + a.m12 * b.m22,
        a.m21 * b.m11 + a.m22 * b.m21,
        a.m21 * b.m12 + a.m22 * b.m22,
    )
}
