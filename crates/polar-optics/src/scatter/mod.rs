//! Phase matrices of participating media: Rayleigh, Henyey–Greenstein with a
//! depolarization parameter, Mie spheres ([`MieTable`]), and their sampling.
//!
//! Conventions:
//! - `k_in` is the propagation direction of the incident light, `k_out` that of the
//!   scattered light (unit vectors), `cos θ = k_in · k_out` (θ = 0 is forward).
//! - A world-frame phase matrix ([`PhaseFunction::eval`]) maps Stokes vectors in the
//!   implicit frame `stokes_basis(k_in)` to Stokes vectors in `stokes_basis(k_out)`,
//!   as the BSDFs do. Units 1/sr, normalised so that `∫ M00 dΩ(k_out) = 1`.
//! - The plane matrix ([`PhaseFunction::plane_matrix`]) is written in the
//!   scattering-plane frame: x axis `e_⊥ = normalize(k_in × k_out)`
//!   ([`crate::frame::scattering_axis`]) for both beams, `y = k × x` (so y lies in the
//!   scattering plane). Bohren & Huffman (1983, §3.2–3.3) order their basis
//!   `(e_∥, e_⊥)`, which is left-handed with respect to `k`; in this crate's right-handed
//!   frame their Stokes `(I, Q, U, V)` reads `(I, −Q, U, V)`, so their
//!   `[[S11,S12,0,0],[S12,S11,0,0],[0,0,S33,S34],[0,0,−S34,S33]]` becomes
//!   `[[S11,−S12,0,0],[−S12,S22,0,0],[0,0,S33,S34],[0,0,−S34,S44]]` here (with
//!   `S22 = S11`, `S44 = S33` for spheres). Rayleigh scattering of unpolarized light thus
//!   gives `S1 > 0`: polarized perpendicular to the scattering plane. Under `exp(−iωt)`
//!   the amplitude matrix `diag(S1, S2)` of B&H acts on `(E_⊥, E_∥)`, and the plane matrix
//!   is [`crate::mueller::from_diagonal_jones`]`(S1, S2)` up to normalisation.

mod mie;

pub use mie::{Amplitudes, MieCoefficients, MieTable};

use crate::block::BlockDiagonal;
use crate::error::OpticsError;
use crate::frame::{from_scattering_plane, stokes_basis};
use crate::mueller::Mueller;
use nalgebra::{Matrix2, Vector3};
use std::f64::consts::PI;
use std::sync::Arc;

/// `1 / 4π`: the isotropic phase function.
const INV_4PI: f64 = 0.25 / PI;

/// Rayleigh normalisation: `∫ 3/(16π) (1 + cos²θ) dΩ = 1`.
const RAYLEIGH_NORM: f64 = 3.0 / (16.0 * PI);

/// The six elements of a phase matrix of a macroscopically isotropic, mirror-symmetric
/// medium in the scattering-plane frame, named by their place in Bohren & Huffman's
/// matrix (their frame, their signs; see the module docs), normalised so that
/// `∫ s11 dΩ = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlaneElements {
    /// Phase function (1/sr).
    pub s11: f64,
    /// Polarization term; `−s12 / s11` is the degree of linear polarization of singly
    /// scattered unpolarized light, positive when perpendicular to the scattering plane.
    pub s12: f64,
    /// `S22`; equals `s11` for spheres.
    pub s22: f64,
    /// `S33`.
    pub s33: f64,
    /// `S34`: couples circular and linear (zero for Rayleigh and Henyey–Greenstein).
    pub s34: f64,
    /// `S44`; equals `s33` for spheres.
    pub s44: f64,
}

impl PlaneElements {
    /// The plane matrix in this crate's frame (x = `e_⊥`):
    /// `[[s11, −s12, 0, 0], [−s12, s22, 0, 0], [0, 0, s33, s34], [0, 0, −s34, s44]]`.
    #[inline(always)]
    pub fn to_block(&self) -> BlockDiagonal {
        BlockDiagonal {
            upper: Matrix2::new(self.s11, -self.s12, -self.s12, self.s22),
            lower: Matrix2::new(self.s33, self.s34, -self.s34, self.s44),
        }
    }

    /// The elements scaled by `f`.
    #[inline(always)]
    fn scaled(&self, f: f64) -> Self {
        Self {
            s11: self.s11 * f,
            s12: self.s12 * f,
            s22: self.s22 * f,
            s33: self.s33 * f,
            s34: self.s34 * f,
            s44: self.s44 * f,
        }
    }
}

/// A phase function with its polarization: what a participating medium scatters.
#[derive(Clone, Debug, PartialEq)]
pub enum PhaseFunction {
    /// Rayleigh (dipole) scattering by particles much smaller than the wavelength:
    /// `S11 = 3/(16π) (1 + cos²θ)`, `S12 = 3/(16π) (cos²θ − 1)`, `S22 = S11`,
    /// `S33 = S44 = 3/(16π) 2 cos θ`, `S34 = 0` (Bohren & Huffman §5.2, normalised).
    Rayleigh,
    /// Henyey–Greenstein phase function `p(θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2})`
    /// with Rayleigh's polarization structure kept with weight `1 − depolarization`:
    /// `p(θ) · [(1 − d) R̂(θ) + d · diag(1, 0, 0, 0)]`, `R̂` the Rayleigh matrix divided by
    /// its `S11`. So `S11 = p`, `S12 = (1 − d) p (cos²θ − 1)/(1 + cos²θ)`,
    /// `S22 = (1 − d) p`, `S33 = S44 = (1 − d) p 2cos θ/(1 + cos²θ)`, `S34 = 0`:
    /// a convex sum of a Jones element and an ideal depolarizer, hence realizable.
    /// A phenomenological model (no particle has it); build with
    /// [`PhaseFunction::henyey_greenstein`] to validate.
    HenyeyGreenstein {
        /// Asymmetry parameter `⟨cos θ⟩`, `|g| < 1` (positive: forward scattering).
        g: f64,
        /// Fraction of Rayleigh's polarization removed, in `[0, 1]` (1: scalar HG).
        depolarization: f64,
    },
    /// A homogeneous sphere (Mie theory), tabulated: see [`MieTable`] for the accuracy.
    /// Couples circular polarization (`S34 ≠ 0`). Shared, as tables can be large.
    Mie(Arc<MieTable>),
}

impl PhaseFunction {
    /// A validated Henyey–Greenstein phase function (see the variant).
    ///
    /// Errors: `|g| ≥ 1` or NaN, `depolarization` outside `[0, 1]` or NaN.
    pub fn henyey_greenstein(g: f64, depolarization: f64) -> Result<Self, OpticsError> {
        let p = Self::HenyeyGreenstein { g, depolarization };
        p.validate()?;
        Ok(p)
    }

    /// A Mie phase function for size parameter `x` and relative index `m` (table built
    /// once, see [`MieTable::new`] for the errors and the cost).
    pub fn mie(x: f64, m: num_complex::Complex64) -> Result<Self, OpticsError> {
        Ok(Self::Mie(Arc::new(MieTable::new(x, m)?)))
    }

    /// Checks the parameters of a variant built directly.
    pub fn validate(&self) -> Result<(), OpticsError> {
        match *self {
            Self::Rayleigh | Self::Mie(_) => Ok(()),
            Self::HenyeyGreenstein { g, depolarization } => {
                if g.is_nan() || g.abs() >= 1.0 {
                    return Err(OpticsError::OutOfRange {
                        name: "g",
                        value: g,
                        expected: "(-1, 1)",
                    });
                }
                if !(0.0..=1.0).contains(&depolarization) {
                    return Err(OpticsError::OutOfRange {
                        name: "depolarization",
                        value: depolarization,
                        expected: "[0, 1]",
                    });
                }
                Ok(())
            }
        }
    }

    /// The normalised elements at scattering cosine `cos_theta` (clamped to `[−1, 1]`
    /// against rounding; NaN gives NaN).
    #[inline(always)]
    pub fn plane_elements(&self, cos_theta: f64) -> PlaneElements {
        let mu = cos_theta.clamp(-1.0, 1.0);
        match self {
            Self::Rayleigh => rayleigh_shape(mu).scaled(RAYLEIGH_NORM),
            Self::HenyeyGreenstein { g, depolarization } => {
                let p = henyey_greenstein(*g, mu);
                let mut e = rayleigh_shape(mu).scaled((1.0 - depolarization) * p / (1.0 + mu * mu));
                e.s11 = p;
                e
            }
            Self::Mie(table) => table.plane_elements(mu),
        }
    }

    /// The phase matrix in the scattering-plane frame (x = `e_⊥`, see the module docs).
    #[inline(always)]
    pub fn plane_matrix(&self, cos_theta: f64) -> Mueller {
        self.plane_elements(cos_theta).to_block().to_mueller()
    }

    /// The world-frame phase matrix from `stokes_basis(k_in)` to `stokes_basis(k_out)`
    /// (unit directions of propagation). Finite for `k_out = ±k_in`, where the plane is
    /// undefined and the matrix does not depend on it.
    #[inline(always)]
    pub fn eval(&self, k_in: &Vector3<f64>, k_out: &Vector3<f64>) -> Mueller {
        from_scattering_plane(&self.plane_matrix(k_in.dot(k_out)), k_in, k_out)
    }

    /// Solid-angle density of [`PhaseFunction::sample`] at scattering cosine `cos_theta`;
    /// equal to `S11` (the `M00` of [`PhaseFunction::eval`]; for Mie, of the table).
    #[inline(always)]
    pub fn pdf(&self, cos_theta: f64) -> f64 {
        let mu = cos_theta.clamp(-1.0, 1.0);
        match self {
            Self::Rayleigh => RAYLEIGH_NORM * (1.0 + mu * mu),
            Self::HenyeyGreenstein { g, .. } => henyey_greenstein(*g, mu),
            Self::Mie(table) => table.pdf(mu),
        }
    }

    /// Samples a scattered direction for light propagating along `k_in` from two uniform
    /// numbers in `[0, 1)`: `u[0]` picks cos θ by exact inversion of the CDF, `u[1]` the
    /// azimuth. Returns `(k_out, pdf)`, the pdf per solid angle.
    #[inline(always)]
    pub fn sample(&self, k_in: &Vector3<f64>, u: [f64; 2]) -> (Vector3<f64>, f64) {
        let mu = self.sample_cos_theta(u[0]);
        (direction_about(k_in, mu, u[1]), self.pdf(mu))
    }

    /// The scattering cosine for the uniform number `u`, inverting the CDF in closed form.
    ///
    /// Rayleigh: `F(μ) = (μ³ + 3μ + 4)/8`, so `μ³ + 3μ = q` with `q = 8u − 4`; Cardano
    /// gives `μ = t − 1/t`, `t = ∛(q/2 + √(q²/4 + 1))`, evaluated for `|q|` and signed
    /// back (no cancellation; Frisvad 2011, "Importance sampling the Rayleigh phase
    /// function", JOSA A 28, 2436).
    /// Henyey–Greenstein: the usual inversion `μ = (1 + g² − s²)/2g`,
    /// `s = (1 − g²)/(1 + g v)`, `v = 2u − 1`, rewritten without the division by `g`:
    /// `μ = (v + g (3 − g² + (1 + g²) v² + 2g v)/2) / (1 + g v)²` (exact at `g = 0`).
    /// Mie: the tabulated CDF (see [`MieTable::sample_cos_theta`]).
    #[inline(always)]
    pub fn sample_cos_theta(&self, u: f64) -> f64 {
        let mu = match *self {
            Self::Rayleigh => {
                let q = 8.0 * u - 4.0;
                let h = 0.5 * q.abs();
                let t = (h + h.hypot(1.0)).cbrt();
                (t - 1.0 / t).copysign(q)
            }
            Self::HenyeyGreenstein { g, .. } => {
                let v = 2.0 * u - 1.0;
                let d = 1.0 + g * v;
                (v + 0.5 * g * (3.0 - g * g + (1.0 + g * g) * v * v + 2.0 * g * v)) / (d * d)
            }
            Self::Mie(ref table) => table.sample_cos_theta(u),
        };
        mu.clamp(-1.0, 1.0)
    }

    /// `true` when the plane matrix couples S3 with `(S0, S1, S2)` (`S34 ≠ 0`): then a
    /// renderer needs the full 4×4 model; otherwise the 3×3 linear one is exact.
    pub fn couples_circular(&self) -> bool {
        match self {
            Self::Rayleigh | Self::HenyeyGreenstein { .. } => false,
            Self::Mie(_) => true,
        }
    }

    /// The asymmetry parameter `⟨cos θ⟩ = ∫ S11 cos θ dΩ` (0 for Rayleigh, `g` for HG,
    /// the series value for Mie, which the table matches to its interpolation error).
    pub fn mean_cosine(&self) -> f64 {
        match self {
            Self::Rayleigh => 0.0,
            Self::HenyeyGreenstein { g, .. } => *g,
            Self::Mie(table) => table.coefficients().asymmetry(),
        }
    }
}

/// Rayleigh's elements up to the factor `RAYLEIGH_NORM`: `(1 + μ², μ² − 1, 1 + μ², 2μ, 0, 2μ)`.
#[inline(always)]
fn rayleigh_shape(mu: f64) -> PlaneElements {
    let a = 1.0 + mu * mu;
    PlaneElements {
        s11: a,
        s12: mu * mu - 1.0,
        s22: a,
        s33: 2.0 * mu,
        s34: 0.0,
        s44: 2.0 * mu,
    }
}

/// Henyey–Greenstein density per solid angle, with `1 + g² − 2gμ` written as
/// `(1 − |g|)² + 2|g| (1 ∓ μ)` and `1 − g²` as `(1 − |g|)(1 + |g|)`, so that the peak
/// of `|g| → 1` keeps full precision.
fn henyey_greenstein(g: f64, mu: f64) -> f64 {
    let a = g.abs();
    let one_minus = if g >= 0.0 { 1.0 - mu } else { 1.0 + mu };
    let d = (1.0 - a) * (1.0 - a) + 2.0 * a * one_minus;
    INV_4PI * (1.0 - a) * (1.0 + a) / (d * d.sqrt())
}

/// The unit direction at cosine `mu` from `k` and azimuth `2π u` about it, measured from
/// `stokes_basis(k)`.
#[inline(always)]
fn direction_about(k: &Vector3<f64>, mu: f64, u: f64) -> Vector3<f64> {
    let x = stokes_basis(k);
    let y = k.cross(&x);
    let sin = (1.0 - mu * mu).max(0.0).sqrt();
    let (sp, cp) = (2.0 * PI * u).sin_cos();
    (x * cp + y * sp) * sin + k * mu
}
