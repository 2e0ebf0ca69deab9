//! Polarized plastic, the model of Mitsuba 3's `pplastic` (Baek et al. 2018,
//! "Simultaneous acquisition of polarimetric SVBRDF and normals"):
//! - a specular lobe: GGX microfacet reflection with the polarized Fresnel matrix
//!   of the dielectric coating (or a smooth mirror lobe when the roughness is 0,
//!   an extension: Mitsuba's plugin is always rough);
//! - a diffuse lobe: light refracts in (`T_in(θi)`), is depolarized by subsurface
//!   scattering, and refracts out (`T_out(θo)`):
//!   `M = T_out · D · T_in · albedo/π · cos θi` with `D = diag(1, 0, 0, 0)`; the
//!   exit refraction gives the weak, 90°-rotated diffuse polarization that shape
//!   from polarization relies on. Both transmissions are in flux units, as in Mitsuba.
//!
//! The two lobes are added (not energy conserving, as the original) and sampled
//! as Mitsuba does: the specular lobe with probability `specular_prob`
//! (`1 / (1 + mean albedo)`), the diffuse lobe by cosine sampling, and the
//! weight of a non-delta sample is the full `eval / pdf` of the mixture. Given the
//! camera row of the path, [`Plastic::with_importance`] reweighs that probability
//! by the S0 each lobe brings to the camera (crate `lobe`).

use crate::conductor::{microfacet_reflection, microfacet_reflection_pdf};
use crate::geometry::{
    V3, cosine_hemisphere, cosine_hemisphere_pdf, rank_one_to_bsdf_bases, reflect, reflect_z,
    reflection, s_axis, sp_column_to_wo_basis,
};
use crate::lobe::first_lobe_probability;
use crate::microfacet::Ggx;
use crate::{BsdfSample, LobeOutcome, Model};
use polar_optics::Polarization;
use polar_optics::fresnel::fresnel_amplitudes;
use polar_optics::{Mueller, Stokes};
use std::f64::consts::FRAC_1_PI;

/// Polarized plastic at one surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plastic {
    /// Interior over exterior index of the coating.
    pub eta: f64,
    /// Microfacet distribution of the specular lobe; `None` for a smooth coating.
    pub roughness: Option<Ggx>,
    /// Diffuse reflectance (Mitsuba's `diffuse_reflectance`) at this point.
    pub albedo: f64,
    /// Probability of sampling the specular lobe, in `[0, 1]`.
    pub specular_prob: f64,
}

impl Plastic {
    /// The diffuse lobe `T_out(θo) · D · T_in(θi) · albedo cos θi / π`, in the BSDF bases.
    #[inline(always)]
    fn diffuse(&self, wo: &V3, wi: &V3) -> Mueller {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return Mueller::zeros();
        }
        let t_in = fresnel_amplitudes(wi.z, self.eta.into()).transmitted_unpolarized();
        // D = diag(1, 0, 0, 0) keeps column 0 of T_out and row 0 of T_in: rank one.
        let k_in = -wi;
        rank_one_to_bsdf_bases(
            &self.exit_transmission(wo),
            &(t_in * (self.albedo * wi.z * FRAC_1_PI)),
            &k_in,
            &s_axis(&V3::z(), &k_in),
            wo,
            &s_axis(&V3::z(), wo),
        )
    }

    /// Column 0 of `T_out(θo)` in the s/p frame: unpolarized light from inside
    /// (the internal direction that refracts out along `wo`) leaving along `wo`.
    #[inline(always)]
    fn exit_transmission(&self, wo: &V3) -> Stokes {
        let cos_inside = (1.0 - (1.0 - wo.z * wo.z) / (self.eta * self.eta))
            .max(0.0)
            .sqrt();
        fresnel_amplitudes(cos_inside, (1.0 / self.eta).into()).transmitted_unpolarized()
    }

    /// This plastic with `specular_prob` reweighed for the camera row `t` (first
    /// row of the path throughput in the output basis of `wo`). The diffuse lobe's
    /// column is exact (its polarization is the exit transmission's, whatever
    /// `wi`); the specular one is the coating's Fresnel reflection at `wo`, exact
    /// when smooth and the smooth limit when rough (where only the choice, not the
    /// estimate, depends on it: `pdf` and `sample` use the same probability).
    pub fn with_importance(&self, wo: &V3, t: &Stokes) -> Self {
        if wo.z <= 0.0 {
            return *self;
        }
        let specular = fresnel_amplitudes(wo.z, self.eta.into()).reflected_unpolarized();
        let c_s = sp_column_to_wo_basis(&specular, &V3::z(), wo);
        let c_d = sp_column_to_wo_basis(&self.exit_transmission(wo), &V3::z(), wo);
        Self {
            specular_prob: first_lobe_probability(self.specular_prob, &c_s, &c_d, t),
            ..*self
        }
    }

    fn diffuse_prob(&self) -> f64 {
        1.0 - self.specular_prob
    }

    /// Samples the specular lobe (`specular`) or the diffuse one with the 2-D point
    /// `u`; the weight is the whole BSDF over the mixture's density (a delta
    /// specular lobe: its matrix over its probability), as [`Model::sample`].
    #[inline(always)]
    fn sample_lobe(&self, specular: bool, wo: &V3, u: [f64; 2]) -> Option<BsdfSample> {
        let wi = match (&self.roughness, specular) {
            (None, true) => {
                let wi = reflect_z(wo);
                let weight = reflection(self.eta.into(), &V3::z(), wo, &wi) / self.specular_prob;
                let pdf = self.specular_prob;
                return Some(BsdfSample::reflection(wi, weight, pdf, true));
            }
            (Some(ggx), true) => reflect(wo, &ggx.sample_visible(wo, u)),
            (_, false) => cosine_hemisphere(u),
        };
        let pdf = self.pdf(wo, &wi);
        if pdf <= 0.0 {
            return None;
        }
        let weight = self.eval(wo, &wi) / pdf;
        Some(BsdfSample::reflection(wi, weight, pdf, false))
    }

    /// Both outcomes of the lobe choice, specular first, with the 2-D point `u`
    /// (see [`crate::Bsdf::lobe_outcomes`]); `None` when only one is possible.
    pub(crate) fn lobe_outcomes(&self, wo: &V3, u: [f64; 2]) -> Option<[LobeOutcome; 2]> {
        let both = wo.z > 0.0 && self.specular_prob > 0.0 && self.specular_prob < 1.0;
        both.then(|| {
            [(true, self.specular_prob), (false, self.diffuse_prob())].map(
                |(specular, probability)| LobeOutcome {
                    probability,
                    sample: self.sample_lobe(specular, wo, u),
                },
            )
        })
    }
}

impl Model for Plastic {
    #[inline(always)]
    fn eval(&self, wo: &V3, wi: &V3) -> Mueller {
        let diffuse = self.diffuse(wo, wi);
        match &self.roughness {
            Some(ggx) => diffuse + microfacet_reflection(ggx, self.eta.into(), wo, wi),
            None => diffuse,
        }
    }

    #[inline(always)]
    fn pdf(&self, wo: &V3, wi: &V3) -> f64 {
        if wo.z <= 0.0 || wi.z <= 0.0 {
            return 0.0;
        }
        let specular = self
            .roughness
            .as_ref()
            .map_or(0.0, |ggx| microfacet_reflection_pdf(ggx, wo, wi));
        self.specular_prob * specular + self.diffuse_prob() * cosine_hemisphere_pdf(wi)
    }

    #[inline(always)]
    fn sample(&self, wo: &V3, u: [f64; 3]) -> Option<BsdfSample> {
        if wo.z <= 0.0 {
            return None;
        }
        self.sample_lobe(u[0] < self.specular_prob, wo, [u[1], u[2]])
    }

    fn has_delta(&self) -> bool {
        self.roughness.is_none()
    }

    /// Real Fresnel amplitudes from outside (`η ≥ 1`) never couple S3; a coating
    /// thinner than the outside medium can totally reflect and so needs `Full`.
    fn polarization(&self) -> Polarization {
        if self.eta >= 1.0 {
            Polarization::Linear
        } else {
            Polarization::Full
        }
    }
}
