//! Dielectric interfaces (glass): smooth, or GGX-rough after Walter et al. 2007,
//! with polarized Fresnel reflection and transmission per (micro)facet and total
//! internal reflection. Two-sided: `wo.z < 0` means the viewer is inside.
//!
//! Transmission carries radiance: the flux-unit Fresnel matrix is scaled by
//! `1/η²` with `η = n(wi side) / n(wo side)` (the `eta` of the sample).
//!
//! Reflection or transmission is chosen with the unpolarized Fresnel reflectance
//! or, given the camera row of the path (`importance`), for the S0 each brings
//! to the camera (crate `lobe`); `pdf` and `sample` agree either way.

use crate::geometry::{
    V3, from_sp_frame, reflect, reflect_z, reflection, refract, sp_column_to_wo_basis, transmission,
};
use crate::lobe::first_lobe_probability;
use crate::microfacet::Ggx;
use crate::{BsdfSample, LobeOutcome, Model};
use polar_optics::Polarization;
use polar_optics::fresnel::fresnel_amplitudes;
use polar_optics::{Mueller, Stokes};

/// A dielectric interface: smooth when `roughness` is `None`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dielectric {
    /// Interior over exterior index, `n_inside / n_outside` (inside is `z < 0`).
    pub eta: f64,
    /// Microfacet distribution; `None` for a smooth interface.
    pub roughness: Option<Ggx>,
    /// First row of the path throughput in the output basis of the `wo` this
    /// BSDF is sampled for ([`crate::Bsdf::with_importance`]); `None` chooses
    /// lobes by unpolarized reflectance.
    pub importance: Option<Stokes>,
}

/// The reflect/refract choice at a smooth interface (one Fresnel evaluation).
struct SmoothChoice {
    fresnel: polar_optics::fresnel::FresnelAmplitudes,
    /// Probability of reflection (1 under total internal reflection).
    reflect_prob: f64,
    /// Refracted direction and relative index `n(wi side) / n(wo side)`; `None`
    /// under total internal reflection.
    transmitted: Option<(V3, f64)>,
}

impl SmoothChoice {
    /// The reflected lobe, its matrix divided by its probability.
    #[inline(always)]
    fn reflection(&self, wo: &V3) -> BsdfSample {
        let wr = reflect_z(wo);
        let r = from_sp_frame(&self.fresnel.reflection_block(), &V3::z(), wo, &wr);
        BsdfSample::reflection(wr, r / self.reflect_prob, self.reflect_prob, true)
    }

    /// The transmitted lobe (radiance: `1/η²`), its matrix divided by its
    /// probability; `None` under total internal reflection.
    #[inline(always)]
    fn transmission(&self, wo: &V3) -> Option<BsdfSample> {
        let (wt, etap) = self.transmitted?;
        let t =
            from_sp_frame(&self.fresnel.transmission_block(), &V3::z(), wo, &wt) / (etap * etap);
        let pt = 1.0 - self.reflect_prob;
        Some(BsdfSample {
            wi: wt,
            weight: t / pt,
            pdf: pt,
            is_delta: true,
            is_transmission: true,
            eta: etap,
        })
    }
}

impl Dielectric {
    /// `n(other side) / n(side of w)`.
    fn etap(&self, w: &V3) -> f64 {
        if w.z > 0.0 { self.eta } else { 1.0 / self.eta }
    }

    /// Probability of reflection at (micro)normal `m` given the reflected column
    /// `c_r` in its s/p frame (unpolarized input): `c_r,0`, or with a camera row
    /// the choice of crate `lobe` on the column in the output basis of `wo`; the
    /// other lobe's flux-unit column is `e0 − c_r` for a lossless interface
    /// (`R + T = 1` per s and p, tested in polar-optics).
    #[inline(always)]
    fn reflect_prob_of(&self, c_r: &Stokes, m: &V3, wo: &V3) -> f64 {
        match &self.importance {
            Some(t) => {
                let c = sp_column_to_wo_basis(c_r, m, wo);
                first_lobe_probability(c[0], &c, &(Stokes::x() - c), t)
            }
            None => c_r[0],
        }
    }

    /// The lobe choice of a smooth interface for light leaving along `wo`. One
    /// Fresnel evaluation serves both lobes: the flux-unit transmission matrix in
    /// the s/p frame is the same from either side (Stokes relations; tested in
    /// polar-optics), so that of light leaving along `wo` is used.
    #[inline(always)]
    fn smooth_choice(&self, wo: &V3) -> SmoothChoice {
        let etap = self.etap(wo);
        let fresnel = fresnel_amplitudes(wo.z.abs(), etap.into());
        let n = V3::z() * wo.z.signum();
        match refract(wo, &n, etap) {
            Some(wt) => SmoothChoice {
                // The choice needs column 0 only; the full reflection matrix is
                // formed only when reflection is taken (glass transmits most paths).
                reflect_prob: self.reflect_prob_of(&fresnel.reflected_unpolarized(), &V3::z(), wo),
                transmitted: Some((wt, etap)),
                fresnel,
            },
            None => SmoothChoice {
                reflect_prob: 1.0,
                transmitted: None,
                fresnel,
            },
        }
    }

    #[inline(always)]
    fn smooth_sample(&self, wo: &V3, u: f64) -> Option<BsdfSample> {
        let choice = self.smooth_choice(wo);
        Some(if u >= choice.reflect_prob {
            choice.transmission(wo)?
        } else {
            choice.reflection(wo)
        })
    }

    /// Both outcomes of the lobe choice of a smooth interface, reflection first,
    /// when both are possible (see [`crate::Bsdf::lobe_outcomes`]).
    pub(crate) fn lobe_outcomes(&self, wo: &V3) -> Option<[LobeOutcome; 2]> {
        if self.roughness.is_some() || wo.z == 0.0 {
            return None;
        }
        let choice = self.smooth_choice(wo);
        let both = choice.reflect_prob > 0.0 && choice.reflect_prob < 1.0;
        let outcome = |s: BsdfSample| LobeOutcome {
            probability: s.pdf,
            sample: Some(s),
        };
        both.then(|| {
            choice
                .transmission(wo)
                .map(|t| [outcome(choice.reflection(wo)), outcome(t)])
        })?
    }

    /// The generalized half vector of `(wo, wi)` facing `+z`, the relative index
    /// `n(wi side) / n(wo side)`, or `None` for grazing or back-facing configurations.
    fn half_vector(&self, wo: &V3, wi: &V3) -> Option<(V3, f64)> {
        if wo.z == 0.0 || wi.z == 0.0 {
            return None;
        }
        let etap = if wo.z * wi.z > 0.0 {
            1.0
        } else {
            self.etap(wo)
        };
        let h = wi * etap + wo;
        if h.norm_squared() == 0.0 {
            return None;
        }
        let h = h.normalize() * h.z.signum();
        let front = h.dot(wi) * wi.z > 0.0 && h.dot(wo) * wo.z > 0.0;
        front.then_some((h, etap))
    }

    /// Probability of choosing reflection at microfacet `h`, for light arriving
    /// from the side of `wo` ([`Self::reflect_prob_of`] at the facet).
    fn reflect_prob(&self, wo: &V3, h: &V3) -> f64 {
        let c_r = fresnel_amplitudes(wo.dot(h).abs(), self.etap(wo).into()).reflected_unpolarized();
        self.reflect_prob_of(&c_r, h, wo)
    }

    fn rough_eval(&self, ggx: &Ggx, wo: &V3, wi: &V3) -> Mueller {
        let Some((h, etap)) = self.half_vector(wo, wi) else {
            return Mueller::zeros();
        };
        let dg = ggx.d(&h) * ggx.g(wo, wi, &h);
        if wo.z * wi.z > 0.0 {
            return reflection(self.etap(wo).into(), &h, wo, wi) * (dg / (4.0 * wo.z.abs()));
        }
        let (ci, co) = (wi.dot(&h), wo.dot(&h));
        let denom = (ci + co / etap).powi(2) * wo.z.abs() * etap * etap;
        transmission(1.0 / etap, &h, wo, wi) * (dg * (ci * co).abs() / denom)
    }

    fn rough_pdf(&self, ggx: &Ggx, wo: &V3, wi: &V3) -> f64 {
        let Some((h, etap)) = self.half_vector(wo, wi) else {
            return 0.0;
        };
        let r = self.reflect_prob(wo, &h);
        let pdf_h = ggx.pdf_visible(wo, &h);
        if wo.z * wi.z > 0.0 {
            pdf_h * r / (4.0 * wo.dot(&h).abs())
        } else {
            let ci = wi.dot(&h);
            pdf_h * (1.0 - r) * ci.abs() / (ci + wo.dot(&h) / etap).powi(2)
        }
    }

    fn rough_sample(&self, ggx: &Ggx, wo: &V3, u: [f64; 3]) -> Option<BsdfSample> {
        let h = ggx.sample_visible(wo, [u[1], u[2]]);
        let reflected = u[0] < self.reflect_prob(wo, &h);
        let wi = if reflected {
            reflect(wo, &h)
        } else {
            let facing = h * wo.dot(&h).signum();
            refract(wo, &facing, self.etap(wo))?
        };
        // A mirror direction below the surface (or a refraction that stays on
        // the same side) is shadowed: no light, and it must not be mistaken for
        // the other lobe when the pdf is recomputed from (wo, wi).
        let is_transmission = wo.z * wi.z < 0.0;
        if is_transmission == reflected {
            return None;
        }
        let pdf = self.rough_pdf(ggx, wo, &wi);
        if pdf <= 0.0 {
            return None;
        }
        let eta = if is_transmission { self.etap(wo) } else { 1.0 };
        let weight = self.rough_eval(ggx, wo, &wi) / pdf;
        Some(BsdfSample {
            wi,
            weight,
            pdf,
            is_delta: false,
            is_transmission,
            eta,
        })
    }
}

impl Model for Dielectric {
    #[inline(always)]
    fn eval(&self, wo: &V3, wi: &V3) -> Mueller {
        self.roughness
            .as_ref()
            .map_or_else(Mueller::zeros, |ggx| self.rough_eval(ggx, wo, wi))
    }

    #[inline(always)]
    fn pdf(&self, wo: &V3, wi: &V3) -> f64 {
        self.roughness
            .as_ref()
            .map_or(0.0, |ggx| self.rough_pdf(ggx, wo, wi))
    }

    #[inline(always)]
    fn sample(&self, wo: &V3, u: [f64; 3]) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        match &self.roughness {
            Some(ggx) => self.rough_sample(ggx, wo, u),
            None => self.smooth_sample(wo, u[0]),
        }
    }

    fn has_delta(&self) -> bool {
        self.roughness.is_none()
    }

    /// Total internal reflection adds a phase between s and p: circular light.
    fn polarization(&self) -> Polarization {
        Polarization::Full
    }
}
