//! Polarized BSDFs: every material of the simulator returns Mueller matrices
//! instead of spectra, following Mitsuba 3's recipe (Fresnel matrix in the s/p
//! frame, then rotated into the implicit Stokes bases of the two directions).
//!
//! Functions on the renderer's per-sample path are `#[inline(always)]` (and [`Bsdf`]
//! dispatches to its models by `match`, not `&dyn`): `polar-render` compiles its
//! sample loop once per SIMD target, and only code inlined into it gets the
//! target's instructions (`polar-render`'s `render.rs`, `TileOp`).
//!
//! # Interface contract (shared with `polar-render`)
//! - Directions are unit vectors in the local shading frame: `z` = shading
//!   normal, `x` = tangent (anisotropy and sheet axis), `y = z × x`.
//! - `wo` points from the surface toward the viewer (light leaves along `wo`);
//!   `wi` points toward the light (light arrives travelling along `-wi`).
//! - Every Mueller matrix maps incident Stokes vectors, expressed in the frame
//!   with x axis `polar_optics::stokes_basis(&-wi)`, to outgoing Stokes vectors
//!   in the frame with x axis `polar_optics::stokes_basis(&wo)`.
//! - [`Bsdf::eval`] is `f(wo, wi) |cos θi|`; delta lobes are excluded from `eval`
//!   and `pdf` and appear only in [`Bsdf::sample`].
//! - Camera paths carry radiance: refraction includes the `1/η²` radiance
//!   scaling, with `η = BsdfSample::eta = n(wi side) / n(wo side)`.
//! - Opaque materials (conductor, plastic, Lambertian) are one-sided: zero unless
//!   `wo.z > 0` and `wi.z > 0`. A renderer that wants two-sided opaque surfaces
//!   flips the shading frame (z and y) toward `wo` before calling.
//!
//! # Matching Mitsuba 3 (for the cross-check)
//! Masking–shadowing is Smith's separable `G1(wo) G1(wi)` and roughness is
//! GGX `alpha` as in Mitsuba; set `distribution = "ggx"` there (its default is
//! Beckmann), `ext_ior = 1` (its default is air, 1.000277), and pass conductor
//! presets as explicit `eta`/`k` (the values in [`Metal`]). [`Plastic`] is
//! `pplastic` term by term, including its lobe-selection probability.

mod conductor;
mod dielectric;
mod error;
mod geometry;
mod lambertian;
mod lobe;
mod material;
pub mod microfacet;
mod plastic;
mod sheet;

pub use conductor::Conductor;
pub use dielectric::Dielectric;
pub use error::Error;
pub use geometry::{cosine_hemisphere, cosine_hemisphere_pdf};
pub use lambertian::Lambertian;
pub use material::{
    Checkerboard, ConductorParams, DielectricParams, LambertianParams, Material, Metal,
    PlasticParams, PolarizerParams, RetarderParams, Roughness, Texture,
};
pub use plastic::Plastic;
pub use sheet::{Sheet, SheetKind};

use nalgebra::Vector3;
use polar_optics::{Mueller, Polarization, Stokes};

/// One sampled incident direction.
#[derive(Clone, Debug, PartialEq)]
pub struct BsdfSample {
    /// Sampled direction toward the light (unit, local frame).
    pub wi: Vector3<f64>,
    /// `f |cos θi| / pdf` for a smooth lobe, or the delta lobe's Mueller matrix
    /// divided by the probability of choosing it.
    pub weight: Mueller,
    /// Solid-angle density of `wi`; for a delta lobe the discrete probability of choosing it.
    pub pdf: f64,
    /// `wi` came from a delta (specular) lobe: skip MIS and light sampling for it.
    pub is_delta: bool,
    /// `wi` lies on the other side of the surface from `wo`.
    pub is_transmission: bool,
    /// Relative index crossed, `n(wi side) / n(wo side)`; 1 for reflection.
    pub eta: f64,
}

impl BsdfSample {
    /// A sample that stays on `wo`'s side (reflection, `eta = 1`).
    pub fn reflection(wi: Vector3<f64>, weight: Mueller, pdf: f64, is_delta: bool) -> Self {
        Self {
            wi,
            weight,
            pdf,
            is_delta,
            is_transmission: false,
            eta: 1.0,
        }
    }
}

/// One outcome of a BSDF's lobe choice ([`Bsdf::lobe_outcomes`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LobeOutcome {
    /// Probability with which [`Bsdf::sample`] makes this choice.
    pub probability: f64,
    /// What `sample` returns with this choice (`None`: no light arrives).
    pub sample: Option<BsdfSample>,
}

/// A polarized BSDF at one surface point (a closed set, one `match` per method).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// Ideal depolarizing Lambertian reflector.
    Lambertian(Lambertian),
    /// Smooth or GGX-rough conductor with complex index.
    Conductor(Conductor),
    /// Smooth or GGX-rough dielectric interface (reflection and transmission).
    Dielectric(Dielectric),
    /// Polarized plastic as Mitsuba 3's `pplastic` (Baek et al. 2018).
    Plastic(Plastic),
    /// Thin pass-through linear polarizer or retarder.
    Sheet(Sheet),
}

/// What every BSDF model provides; [`Bsdf`] dispatches to it.
trait Model {
    fn eval(&self, wo: &Vector3<f64>, wi: &Vector3<f64>) -> Mueller;
    fn pdf(&self, wo: &Vector3<f64>, wi: &Vector3<f64>) -> f64;
    fn sample(&self, wo: &Vector3<f64>, u: [f64; 3]) -> Option<BsdfSample>;
    fn has_delta(&self) -> bool;
    fn polarization(&self) -> Polarization;
}

/// `$call` on the model inside the [`Bsdf`] `$bsdf`, bound to `$m`: a `match` (static
/// dispatch, so each model's method can be inlined into a caller, which a call
/// through `&dyn Model` prevents).
macro_rules! with_model {
    ($bsdf:expr, $m:ident => $call:expr) => {
        match $bsdf {
            Bsdf::Lambertian($m) => $call,
            Bsdf::Conductor($m) => $call,
            Bsdf::Dielectric($m) => $call,
            Bsdf::Plastic($m) => $call,
            Bsdf::Sheet($m) => $call,
        }
    };
}

impl Bsdf {
    /// `f(wo, wi) |cos θi|` as a Mueller matrix (zero for delta lobes).
    #[inline(always)]
    pub fn eval(&self, wo: &Vector3<f64>, wi: &Vector3<f64>) -> Mueller {
        with_model!(self, m => m.eval(wo, wi))
    }

    /// Solid-angle density with which [`Self::sample`] returns `wi` (0 for delta lobes).
    #[inline(always)]
    pub fn pdf(&self, wo: &Vector3<f64>, wi: &Vector3<f64>) -> f64 {
        with_model!(self, m => m.pdf(wo, wi))
    }

    /// Samples `wi` given `wo` and three uniform numbers in `[0, 1)` (the first
    /// picks a lobe where there are several). `None` when no light can arrive.
    #[inline(always)]
    pub fn sample(&self, wo: &Vector3<f64>, u: [f64; 3]) -> Option<BsdfSample> {
        with_model!(self, m => m.sample(wo, u))
    }

    /// This BSDF with its lobe choice made for what the camera measures: `t` is
    /// the first row of the path throughput (the S0 at the camera per unit of
    /// each Stokes component leaving along `wo`) in the output basis of `wo`.
    /// [`Self::sample`] and [`Self::pdf`] then weigh each lobe by the S0 it
    /// brings to the camera (glass: reflection against flux transmission, with
    /// probability `t · c_k / t_0` for column `c_k`; plastic: Mitsuba's specular
    /// probability reweighed by the same factor), and agree with each other, so
    /// MIS stays exact. Valid for this `wo` only; models with one lobe are
    /// returned unchanged.
    pub fn with_importance(&self, wo: &Vector3<f64>, t: &Stokes) -> Bsdf {
        match self {
            Bsdf::Dielectric(d) => Bsdf::Dielectric(Dielectric {
                importance: Some(*t),
                ..*d
            }),
            Bsdf::Plastic(p) => Bsdf::Plastic(p.with_importance(wo, t)),
            Bsdf::Lambertian(_) | Bsdf::Conductor(_) | Bsdf::Sheet(_) => *self,
        }
    }

    /// Both outcomes of the lobe choice that [`Self::sample`] makes with `u[0]`,
    /// each with its probability and the sample it gives with the 2-D point `u`
    /// (what `sample` returns for that choice): glass's reflection and
    /// transmission when smooth (except under total internal reflection),
    /// plastic's specular and diffuse lobes. A renderer that traces both and
    /// weighs each by its probability computes the expectation over the choice
    /// instead of drawing it (splitting, as branched path tracing does at the
    /// first hit); the samples' densities are those of `sample` and `pdf`, so MIS
    /// against light sampling is unchanged. `None` for every other BSDF.
    pub fn lobe_outcomes(&self, wo: &Vector3<f64>, u: [f64; 2]) -> Option<[LobeOutcome; 2]> {
        match self {
            Bsdf::Dielectric(d) => d.lobe_outcomes(wo),
            Bsdf::Plastic(p) => p.lobe_outcomes(wo, u),
            Bsdf::Lambertian(_) | Bsdf::Conductor(_) | Bsdf::Sheet(_) => None,
        }
    }

    /// Whether this BSDF chooses between lobes, i.e. whether
    /// [`Self::with_importance`] can change it (glass and plastic).
    pub fn chooses_lobes(&self) -> bool {
        matches!(self, Bsdf::Dielectric(_) | Bsdf::Plastic(_))
    }

    /// Whether some lobe is a delta (then light sampling cannot reach that lobe).
    pub fn has_delta(&self) -> bool {
        with_model!(self, m => m.has_delta())
    }

    /// Whether every lobe is a delta (smooth conductor or dielectric, sheets): then
    /// [`Self::eval`] is zero everywhere and a renderer can skip light sampling.
    pub fn is_delta(&self) -> bool {
        match self {
            Bsdf::Lambertian(_) | Bsdf::Plastic(_) => false,
            Bsdf::Conductor(_) | Bsdf::Dielectric(_) | Bsdf::Sheet(_) => self.has_delta(),
        }
    }

    /// The cheapest exact transport model this BSDF needs.
    pub fn polarization(&self) -> Polarization {
        with_model!(self, m => m.polarization())
    }

    /// Whether the surface looks the same from both sides (opaque models): a renderer
    /// shades it with the normal facing the viewer. Transmissive models (dielectric,
    /// sheets) are one-sided: the normal's orientation tells inside from outside.
    pub fn is_two_sided(&self) -> bool {
        match self {
            Bsdf::Lambertian(_) | Bsdf::Conductor(_) | Bsdf::Plastic(_) => true,
            Bsdf::Dielectric(_) | Bsdf::Sheet(_) => false,
        }
    }
}
