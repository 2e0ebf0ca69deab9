//! "Model only what a scene needs": one integrator, generic over how much of
//! the Mueller calculus it carries.
//!
//! - [`Scalar`] (`f64`): only `M00`; exact when nothing polarizes (every Mueller
//!   matrix on a path is `M00 · diag(1, 0, 0, 0)` and emitters are unpolarized).
//! - [`Linear`] (3×3): the `S0..S2` block; exact when no element couples `S3` with
//!   `S0..S2` and no emitter has `S3 ≠ 0` (then the block of a product is the product of blocks).
//! - [`Full`] (4×4): the complete Mueller calculus.

use nalgebra::{Matrix3, Vector3};
use polar_optics::Polarization;
use polar_optics::frame::rotate_rows;
use polar_optics::{Mueller, Stokes};

/// A path throughput representation: a (reduced) Mueller matrix.
pub trait Transport: Copy + Send + Sync + 'static {
    /// The Stokes representation this throughput acts on.
    type Stokes: Copy;
    /// The model this representation implements exactly.
    const MODEL: Polarization;
    /// The identity (an empty path).
    fn identity() -> Self;
    /// The reduction of a full Mueller matrix.
    fn from_mueller(m: &Mueller) -> Self;
    /// The reduction of `rotator(θ) · m` for `rot = (cos 2θ, sin 2θ)` (an output
    /// basis change), touching only the entries the model keeps: the rotation
    /// mixes rows 1 and 2, which `Scalar` drops and `Linear` keeps 3 columns of.
    fn from_rotated(m: &Mueller, rot: (f64, f64)) -> Self;
    /// The reduction of a Stokes vector.
    fn from_stokes(s: &Stokes) -> Self::Stokes;
    /// Expands back to a full Stokes vector (zeros for dropped components).
    fn to_stokes(s: &Self::Stokes) -> Stokes;
    /// `self · other` (apply `other` first).
    fn then(&self, other: &Self) -> Self;
    /// `self · s`.
    fn apply(&self, s: &Self::Stokes) -> Self::Stokes;
    /// `self · k`.
    fn scaled(&self, k: f64) -> Self;
    /// `M00`: the path's response to unpolarized light (for Russian roulette).
    fn m00(&self) -> f64;
    /// The first row as a full Stokes vector (zeros for dropped components): the
    /// S0 at the camera per unit of each Stokes component entering the path.
    fn first_row(&self) -> Stokes;
}

/// Scalar (unpolarized) transport.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scalar(pub f64);

/// Linear-Stokes transport (3×3 block).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Linear(pub Matrix3<f64>);

/// Full Mueller transport (4×4).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Full(pub Mueller);

impl Transport for Scalar {
    type Stokes = f64;
    const MODEL: Polarization = Polarization::None;
    fn identity() -> Self {
        Scalar(1.0)
    }
    fn from_mueller(m: &Mueller) -> Self {
        Scalar(m[(0, 0)])
    }
    /// `M00` is invariant under basis changes.
    fn from_rotated(m: &Mueller, _rot: (f64, f64)) -> Self {
        Self::from_mueller(m)
    }
    fn from_stokes(s: &Stokes) -> f64 {
        s[0]
    }
    fn to_stokes(s: &f64) -> Stokes {
        Stokes::new(*s, 0.0, 0.0, 0.0)
    }
    fn then(&self, other: &Self) -> Self {
        Scalar(self.0 * other.0)
    }
    fn apply(&self, s: &f64) -> f64 {
        self.0 * s
    }
    fn scaled(&self, k: f64) -> Self {
        Scalar(self.0 * k)
    }
    fn m00(&self) -> f64 {
        self.0
    }
    fn first_row(&self) -> Stokes {
        Stokes::new(self.0, 0.0, 0.0, 0.0)
    }
}

impl Transport for Linear {
    type Stokes = Vector3<f64>;
    const MODEL: Polarization = Polarization::Linear;
    fn identity() -> Self {
        Linear(Matrix3::identity())
    }
    fn from_mueller(m: &Mueller) -> Self {
        Linear(m.fixed_view::<3, 3>(0, 0).into_owned())
    }
    /// The same arithmetic as [`rotate_rows`] on the 3×3 block only (6 of its 8 pairs).
    fn from_rotated(m: &Mueller, (cos2, sin2): (f64, f64)) -> Self {
        Linear(Matrix3::from_fn(|i, j| match i {
            1 => cos2 * m[(1, j)] + sin2 * m[(2, j)],
            2 => cos2 * m[(2, j)] - sin2 * m[(1, j)],
            _ => m[(0, j)],
        }))
    }
    fn from_stokes(s: &Stokes) -> Vector3<f64> {
        s.fixed_rows::<3>(0).into_owned()
    }
    fn to_stokes(s: &Vector3<f64>) -> Stokes {
        Stokes::new(s[0], s[1], s[2], 0.0)
    }
    fn then(&self, other: &Self) -> Self {
        Linear(self.0 * other.0)
    }
    fn apply(&self, s: &Vector3<f64>) -> Vector3<f64> {
        self.0 * s
    }
    fn scaled(&self, k: f64) -> Self {
        Linear(self.0 * k)
    }
    fn m00(&self) -> f64 {
        self.0[(0, 0)]
    }
    fn first_row(&self) -> Stokes {
        Stokes::new(self.0[(0, 0)], self.0[(0, 1)], self.0[(0, 2)], 0.0)
    }
}

impl Transport for Full {
    type Stokes = Stokes;
    const MODEL: Polarization = Polarization::Full;
    fn identity() -> Self {
        Full(Mueller::identity())
    }
    fn from_mueller(m: &Mueller) -> Self {
        Full(*m)
    }
    fn from_rotated(m: &Mueller, rot: (f64, f64)) -> Self {
        Full(rotate_rows(m, rot))
    }
    fn from_stokes(s: &Stokes) -> Stokes {
        *s
    }
    fn to_stokes(s: &Stokes) -> Stokes {
        *s
    }
    fn then(&self, other: &Self) -> Self {
        Full(self.0 * other.0)
    }
    fn apply(&self, s: &Stokes) -> Stokes {
        self.0 * s
    }
    fn scaled(&self, k: f64) -> Self {
        Full(self.0 * k)
    }
    fn m00(&self) -> f64 {
        self.0[(0, 0)]
    }
    fn first_row(&self) -> Stokes {
        self.0.row(0).transpose()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_block_of_a_product_is_the_product_of_blocks_when_s3_decouples() {
        // Two dielectric reflections (real Fresnel amplitudes) with a frame rotation in between.
        let a =
            polar_optics::fresnel::reflection_mueller(0.6, num_complex::Complex64::new(1.5, 0.0));
        let r = polar_optics::mueller::rotator(0.3);
        let b =
            polar_optics::fresnel::reflection_mueller(0.2, num_complex::Complex64::new(1.5, 0.0));
        let full = a * r * b;
        let lin = Linear::from_mueller(&a)
            .then(&Linear::from_mueller(&r))
            .then(&Linear::from_mueller(&b));
        assert!((lin.0 - full.fixed_view::<3, 3>(0, 0)).norm() < 1e-15);
    }
}
