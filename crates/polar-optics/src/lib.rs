//! The physics of polarized light, written once and used by both the simulator
//! and the analysis: Stokes vectors, Mueller matrices, Fresnel equations for
//! dielectrics and conductors, reference-frame rotations, validity checks,
//! the Lu–Chipman decomposition, and the phase matrices of participating media
//! ([`scatter`]: Rayleigh, Henyey–Greenstein with depolarization, Mie spheres) and a
//! single-scattering Rayleigh sky ([`sky`]).
//!
//! The Fresnel and phase-function code the renderer runs per sample is
//! `#[inline(always)]`, so that it is compiled into each SIMD version of the
//! renderer's sample loop (`polar-render`).
//!
//! Conventions (see the project README, "Conventions"):
//! - A Stokes vector is expressed in a reference frame `(x, y)` perpendicular to
//!   the propagation direction `k` with `x × y = k` (right-handed w.r.t. the light).
//! - Angles (polarizer, AoLP) run from `x` toward `y`; AoLP lies in `[0, π)`.
//! - `S1 = I0 − I90`, `S2 = I45 − I135`, `S3 = I_RCP − I_LCP`, right-handed meaning
//!   the field turns clockwise for an observer facing the source (as Mitsuba 3).
//!   In Jones terms `S3 = 2 Im(E_x E_y*)`; `E_y = −i E_x` is right-handed.
//! - Complex refractive indices are `n + ik` with `k ≥ 0` absorbing and the time
//!   dependence `exp(−iωt)`.
//! - Undefined results are NaN (e.g. DoLP of `S0 = 0`, Fresnel of a NaN angle);
//!   where a value is defined no NaN is produced (grazing incidence, the critical
//!   angle, `k → 0`, `k → ∞`, index matching).

pub mod block;
pub mod decompose;
pub mod error;
pub mod frame;
pub mod fresnel;
pub mod model;
pub mod mueller;
pub mod pixel_frame;
pub mod reflection_dolp;
pub mod scatter;
pub mod sky;
pub mod stokes;
pub mod validity;

pub use block::BlockDiagonal;
pub use decompose::{LuChipman, lu_chipman};
pub use error::OpticsError;
pub use frame::{rotate_mueller_basis, rotate_stokes, rotate_stokes_basis, stokes_basis};
pub use fresnel::{FresnelAmplitudes, fresnel_amplitudes};
pub use model::Polarization;
pub use mueller::{LinearMueller, Mueller};
pub use scatter::PhaseFunction;
pub use stokes::{LinearStokes, LinearStokesFit, Stokes};
