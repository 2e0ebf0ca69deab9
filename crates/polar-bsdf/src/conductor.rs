//! Conductors with a complex index `η = n + ik`: a smooth mirror or a GGX
//! microfacet surface (Walter et al. 2007) whose every microfacet reflects with
//! the polarized Fresnel matrix.

use crate::geometry::{V3, reflect, reflect_z, reflection};
use crate::microfacet::Ggx;
use crate::{BsdfSample, Model};
use num_complex::Complex64;
use polar_optics::Mueller;
use polar_optics::Polarization;

/// A conductor: smooth when `roughness` is `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conductor {
    /// Complex index of the metal relative to the outside medium.
    pub eta: Complex64,
    /// Microfacet distribution; `None` for a perfect mirror.
    pub roughness: Option<Ggx>,
}

/// Microfacet reflection `F(h) D(h) G / (4 cos θo)` (that is `f cos θi`) about
/// the half vector `h`, for the relative index `eta`; zero unless both
/// directions are above the surface.
#[inline(always)]
pub(crate) fn microfacet_reflection(ggx: &Ggx, eta: Complex64, wo: &V3, wi: &V3) -> Mueller {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return Mueller::zeros();
    }
    let h = (wo + wi).normalize();
    let value = ggx.d(&h) * ggx.g(wo, wi, &h) / (4.0 * wo.z);
    reflection(eta, &h, wo, wi) * value
}

/// Density of `wi` when a visible normal `h` is sampled from `wo` and `wo` is
/// mirrored about it: `D_wo(h) / (4 wo·h)`.
#[inline(always)]
pub(crate) fn microfacet_reflection_pdf(ggx: &Ggx, wo: &V3, wi: &V3) -> f64 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let h = (wo + wi).normalize();
    ggx.pdf_visible(wo, &h) / (4.0 * wo.dot(&h))
}

impl Model for Conductor {
    #[inline(always)]
    fn eval(&self, wo: &V3, wi: &V3) -> Mueller {
        match &self.roughness {
            Some(ggx) => microfacet_reflection(ggx, self.eta, wo, wi),
            None => Mueller::zeros(),
        }
    }

    #[inline(always)]
    fn pdf(&self, wo: &V3, wi: &V3) -> f64 {
        self.roughness
            .as_ref()
            .map_or(0.0, |ggx| microfacet_reflection_pdf(ggx, wo, wi))
    }

    #[inline(always)]
    fn sample(&self, wo: &V3, u: [f64; 3]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        let Some(ggx) = &self.roughness else {
            let wi = reflect_z(wo);
            let weight = reflection(self.eta, &V3::z(), wo, &wi);
            return Some(BsdfSample::reflection(wi, weight, 1.0, true));
        };
        let m = ggx.sample_visible(wo, [u[1], u[2]]);
        let wi = reflect(wo, &m);
        let pdf = microfacet_reflection_pdf(ggx, wo, &wi);
        if pdf <= 0.0 {
            return None;
        }
        // f cos / pdf = F G1(wi): D and G1(wo) cancel.
        let weight = reflection(self.eta, &m, wo, &wi) * ggx.g1(&wi, &m);
        Some(BsdfSample::reflection(wi, weight, pdf, false))
    }

    fn has_delta(&self) -> bool {
        self.roughness.is_none()
    }

    fn polarization(&self) -> Polarization {
        Polarization::Full
    }
}
