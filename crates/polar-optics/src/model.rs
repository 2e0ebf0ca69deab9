//! Which Mueller model light transport needs: scalar, 3×3 linear or full 4×4
//! ([`crate::mueller::couples_circular`] tells the last two apart for one matrix). One
//! owner for the decision, so that the BSDFs, media, emitters and renderer agree.

use crate::scatter::PhaseFunction;

/// The cheapest exact light-transport model an element needs, ordered
/// `None < Linear < Full` so a scene needs the maximum over its elements
/// ([`Polarization::cheapest_exact`]).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum Polarization {
    /// Never polarizes and passes light on depolarized (only `M00` is non-zero):
    /// scalar transport is exact.
    None,
    /// Creates or changes linear polarization but never couples `S3` with
    /// `S0..S2` (`M[3][0..3] = M[0..3][3] = 0`): 3-component Stokes is exact.
    Linear,
    /// May create circular polarization or convert linear to circular
    /// (conductors, total internal reflection, retarders): full 4×4 Mueller.
    Full,
}

impl Polarization {
    /// The model exact for every element of `needs` (their maximum; `None` for none).
    pub fn cheapest_exact(needs: impl IntoIterator<Item = Polarization>) -> Self {
        needs.into_iter().max().unwrap_or(Self::None)
    }

    /// The model an emitter of normalised polarization `[S1, S2, S3] / S0` needs:
    /// `Full` if `S3` is non-zero, `Linear` if `S1` or `S2` is, else `None`.
    pub fn of_emission(polarization: &[f64; 3]) -> Self {
        match polarization {
            [_, _, s3] if *s3 != 0.0 => Self::Full,
            [s1, s2, _] if *s1 != 0.0 || *s2 != 0.0 => Self::Linear,
            _ => Self::None,
        }
    }

    /// The model scattering with phase function `phase` needs: `Full` when its plane
    /// matrix couples circular polarization (Mie), `None` for a fully depolarizing
    /// Henyey–Greenstein (`diag(p, 0, 0, 0)` in any frame), `Linear` otherwise.
    pub fn of_phase(phase: &PhaseFunction) -> Self {
        match phase {
            p if p.couples_circular() => Self::Full,
            PhaseFunction::HenyeyGreenstein { depolarization, .. } if *depolarization == 1.0 => {
                Self::None
            }
            _ => Self::Linear,
        }
    }
}
