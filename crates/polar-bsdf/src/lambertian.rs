//! Ideal depolarizing Lambertian reflector: `f = albedo / π`, output unpolarized
//! whatever the input.

use crate::geometry::{V3, cosine_hemisphere, cosine_hemisphere_pdf, depolarizer};
use crate::{BsdfSample, Model};
use polar_optics::Mueller;
use polar_optics::Polarization;
use std::f64::consts::FRAC_1_PI;

/// Lambertian reflector with the given albedo in `[0, 1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lambertian {
    /// Hemispherical reflectance.
    pub albedo: f64,
}

impl Model for Lambertian {
    #[inline(always)]
    fn eval(&self, wo: &V3, wi: &V3) -> Mueller {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Mueller::zeros();
        }
        depolarizer(self.albedo * FRAC_1_PI * wi.z)
    }

    fn pdf(&self, wo: &V3, wi: &V3) -> f64 {
        if wo.z <= 0.0 {
            0.0
        } else {
            cosine_hemisphere_pdf(wi)
        }
    }

    #[inline(always)]
    fn sample(&self, wo: &V3, u: [f64; 3]) -> Option<BsdfSample> {
        let wi = cosine_hemisphere([u[1], u[2]]);
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return None;
        }
        let pdf = cosine_hemisphere_pdf(&wi);
        Some(BsdfSample::reflection(
            wi,
            depolarizer(self.albedo),
            pdf,
            false,
        ))
    }

    fn has_delta(&self) -> bool {
        false
    }

    fn polarization(&self) -> Polarization {
        Polarization::None
    }
}
