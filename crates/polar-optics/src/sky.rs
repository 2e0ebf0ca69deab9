//! A single-scattering Rayleigh sky: polarized sky radiance from a plane-parallel,
//! homogeneous, purely scattering atmosphere above a flat, black ground.
//!
//! Model (Chandrasekhar 1950 §1; Liou, *An Introduction to Atmospheric Radiation*, 2002,
//! §6.2, single-scattering term): sunlight of irradiance `E` (on a plane normal to the
//! beam, at the top of the atmosphere) crosses a layer of vertical optical depth `τ`;
//! each layer element scatters it once with the Rayleigh phase matrix `P(Θ)`, and the
//! scattered light is attenuated on its way down. Integrating over the layer, the radiance
//! reaching the ground from a sky direction of zenith cosine `μ > 0` with the sun at zenith
//! cosine `μ0 > 0` is
//! `L = E · P(Θ) S_sun · μ0/(μ0 − μ) · (e^{−τ/μ0} − e^{−τ/μ})`,
//! `S_sun = (1, 0, 0, 0)`, `cos Θ` the scattering angle between the sunlight and the light
//! reaching the observer. Equivalently `L = E P(Θ) S_sun e^{−τ/μ0} (τ/μ) h(τ(1/μ − 1/μ0))`
//! with `h(y) = (1 − e^{−y})/y`, `h(0) = 1`: the form evaluated here, exact at `μ = μ0`
//! (`L = E P S_sun (τ/μ0) e^{−τ/μ0}`) and finite at the horizon (`μ → 0`:
//! `L → E P S_sun e^{−τ/μ0}`).
//!
//! Limits of the model: single scattering only (so the degree of linear polarization is
//! exactly `sin²Θ/(1 + cos²Θ)`, reaching 1 at 90° from the sun; the real clear sky peaks
//! near 0.7–0.8 because of multiple scattering, aerosols and ground reflection), no ground
//! reflection, no absorption (ozone) or aerosols, no curvature of the Earth (the horizon
//! radiance is the plane-parallel limit), one wavelength band per `τ`.

use crate::error::OpticsError;
use crate::scatter::PhaseFunction;
use crate::stokes::{Stokes, unpolarized};
use nalgebra::Vector3;

/// Above this `y` the factor `e^{−y}` is below `f64` precision: `h(y) = 1/y`.
const EXP_NEGLIGIBLE: f64 = 700.0;

/// Allowed deviation of a direction's length from 1 in [`RayleighSky::validate`].
const UNIT_TOLERANCE: f64 = 1e-9;

/// A single-scattering Rayleigh sky (see the module docs for the model and its limits).
#[derive(Clone, Debug, PartialEq)]
pub struct RayleighSky {
    /// Unit vector from the ground toward the sun (above the horizon: `· up > 0`).
    pub sun_direction: Vector3<f64>,
    /// Unit zenith vector.
    pub up: Vector3<f64>,
    /// Vertical optical depth `τ ≥ 0` of the atmosphere (≈ 0.1 at 550 nm for the Earth).
    pub optical_depth: f64,
    /// Solar irradiance `E ≥ 0` on a plane normal to the sunlight, above the atmosphere.
    pub sun_irradiance: f64,
}

impl RayleighSky {
    /// A validated sky; the two directions are normalised first.
    ///
    /// Errors: see [`RayleighSky::validate`] (zero-length or non-finite directions fail it).
    pub fn new(
        sun_direction: Vector3<f64>,
        up: Vector3<f64>,
        optical_depth: f64,
        sun_irradiance: f64,
    ) -> Result<Self, OpticsError> {
        let sky = Self {
            sun_direction: sun_direction.normalize(),
            up: up.normalize(),
            optical_depth,
            sun_irradiance,
        };
        sky.validate()?;
        Ok(sky)
    }

    /// Checks the fields: unit directions (within 1e-9), the sun above the horizon
    /// (`μ0 = sun_direction · up > 0`), finite `τ ≥ 0` and `E ≥ 0`.
    pub fn validate(&self) -> Result<(), OpticsError> {
        for (name, v) in [("|sun_direction|", &self.sun_direction), ("|up|", &self.up)] {
            let n = v.norm();
            if n.is_nan() || (n - 1.0).abs() > UNIT_TOLERANCE {
                return Err(out_of_range(name, n, "1 (unit vector)"));
            }
        }
        let mu0 = self.sun_cosine();
        if mu0.is_nan() || mu0 <= 0.0 {
            return Err(out_of_range(
                "sun_direction . up",
                mu0,
                "(0, 1] (sun above the horizon)",
            ));
        }
        for (name, v) in [
            ("optical_depth", self.optical_depth),
            ("sun_irradiance", self.sun_irradiance),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(out_of_range(name, v, "[0, inf)"));
            }
        }
        Ok(())
    }

    /// The sun's zenith cosine `μ0`.
    pub fn sun_cosine(&self) -> f64 {
        self.sun_direction.dot(&self.up)
    }

    /// The direct sun's transmittance through the atmosphere, `e^{−τ/μ0}`: what a renderer's
    /// sun light should be scaled by to match this sky.
    pub fn sun_transmittance(&self) -> f64 {
        (-self.optical_depth / self.sun_cosine()).exp()
    }

    /// Stokes radiance of the light arriving at the ground and propagating along the unit
    /// vector `k` (so it comes from the sky direction `−k`), in the frame `stokes_basis(k)`.
    /// Zero for light from the horizon or below (`−k · up ≤ 0`); NaN for a NaN `k`.
    pub fn radiance(&self, k: &Vector3<f64>) -> Stokes {
        let mu = -k.dot(&self.up);
        if mu <= 0.0 {
            return Stokes::zeros();
        }
        let factor = self.sun_irradiance
            * self.sun_transmittance()
            * path_factor(self.optical_depth, mu, self.sun_cosine());
        PhaseFunction::Rayleigh.eval(&-self.sun_direction, k) * unpolarized(factor)
    }
}

/// `(τ/μ) h(τ(1/μ − 1/μ0))` with `h(y) = (1 − e^{−y})/y` (`h(0) = 1`): the layer integral
/// `∫₀^τ e^{t/μ0 − t/μ} dt/μ`, without 0/0 at `μ = μ0` or overflow as `μ → 0` (→ 1).
fn path_factor(tau: f64, mu: f64, mu0: f64) -> f64 {
    let y = tau / mu - tau / mu0;
    if y > EXP_NEGLIGIBLE {
        1.0 + tau / (mu0 * y)
    } else if y == 0.0 {
        tau / mu
    } else {
        tau / mu * (-(-y).exp_m1() / y)
    }
}

fn out_of_range(name: &'static str, value: f64, expected: &'static str) -> OpticsError {
    OpticsError::OutOfRange {
        name,
        value,
        expected,
    }
}
