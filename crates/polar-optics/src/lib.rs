//! The physics of polarized light, written once and used by both the simulator
//! and the analysis: Stokes vectors, Mueller matrices, Fresnel equations for
//! dielectrics and conductors, and reference-frame rotations.
//!
//! Conventions (see the project README, "Conventions"):
//! - A Stokes vector is expressed in a reference frame `(x, y)` perpendicular to
//!   the propagation direction `k` with `x × y = k` (right-handed w.r.t. the light).
//! - Angles (polarizer, AoLP) run from `x` toward `y`; AoLP lies in `[0, π)`.
//! - `S1 = I0 − I90`, `S2 = I45 − I135`, `S3 = I_RCP − I_LCP`, right-handed meaning
//!   the field turns clockwise for an observer facing the source (as Mitsuba 3).
//! - Complex refractive indices are `n + ik` with `k ≥ 0` absorbing and the time
//!   dependence `exp(−iωt)`.

pub mod fresnel;
pub mod frame;
pub mod mueller;
pub mod stokes;

pub use fresnel::{FresnelAmplitudes, fresnel_amplitudes};
pub use frame::{rotate_mueller_basis, rotate_stokes_basis, stokes_basis};
pub use mueller::Mueller;
pub use stokes::Stokes;
