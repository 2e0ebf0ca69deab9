//! Materials as written in the scene file (serde-friendly parameter structs) and
//! their validation; a material turns into a [`Bsdf`] at a hit point.
//!
//! TOML examples (a material is a table whose `type` key picks the variant):
//! ```toml
//! type = "conductor"
//! metal = "au"                 # or: n = 0.2, k = 3.0
//! roughness = [0.05, 0.3]      # alpha_x (tangent), alpha_y; or one number; 0 = mirror
//! ```
//! ```toml
//! type = "plastic"
//! albedo = { checkerboard = [0.2, 0.8], scale = 4.0 }
//! ior = 1.5
//! roughness = 0.1
//! ```

use crate::microfacet::Ggx;
use crate::{Bsdf, Conductor, Dielectric, Error, Lambertian, Plastic, Sheet, SheetKind};
use num_complex::Complex64;
use polar_optics::Polarization;
use serde::{Deserialize, Serialize};

/// A scene material.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Material {
    /// Ideal depolarizing Lambertian reflector.
    Lambertian(LambertianParams),
    /// Smooth or rough metal.
    Conductor(ConductorParams),
    /// Smooth or rough glass (reflection and transmission).
    Dielectric(DielectricParams),
    /// Polarized plastic (Mitsuba's `pplastic`): rough specular coating over a diffuse base.
    Plastic(PlasticParams),
    /// Thin ideal linear polarizer sheet.
    Polarizer(PolarizerParams),
    /// Thin linear retarder sheet.
    Retarder(RetarderParams),
}

/// A scalar texture over surface `(u, v)`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Texture {
    /// The same value everywhere.
    Constant(f64),
    /// Two values alternating on a checkerboard.
    Checkerboard(Checkerboard),
}

/// Checkerboard: `checkerboard[0]` where `floor(2 scale u) + floor(2 scale v)` is
/// even, `checkerboard[1]` where odd (with `scale = 1`, 2×2 checks over the unit
/// square, as Mitsuba's `checkerboard` texture).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Checkerboard {
    /// The two values.
    pub checkerboard: [f64; 2],
    /// Number of check pairs per unit of `u` and `v`.
    #[serde(default = "one")]
    pub scale: f64,
}

fn one() -> f64 {
    1.0
}

impl Texture {
    /// The value at `uv`.
    pub fn eval(&self, uv: [f64; 2]) -> f64 {
        match self {
            Texture::Constant(v) => *v,
            Texture::Checkerboard(c) => {
                let cell = |t: f64| (2.0 * c.scale * t).floor() as i64;
                c.checkerboard[(cell(uv[0]) + cell(uv[1])).rem_euclid(2) as usize]
            }
        }
    }

    /// The mean over the texture (what Mitsuba's `Texture::mean` gives).
    pub fn mean(&self) -> f64 {
        match self {
            Texture::Constant(v) => *v,
            Texture::Checkerboard(c) => 0.5 * (c.checkerboard[0] + c.checkerboard[1]),
        }
    }

    fn values(&self) -> Vec<f64> {
        match self {
            Texture::Constant(v) => vec![*v],
            Texture::Checkerboard(c) => c.checkerboard.to_vec(),
        }
    }

    fn validate_albedo(&self) -> Result<(), Error> {
        for v in self.values() {
            if !(0.0..=1.0).contains(&v) {
                return Err(Error::invalid(
                    "albedo",
                    format!("must lie in [0, 1], got {v}"),
                ));
            }
        }
        if let Texture::Checkerboard(c) = self {
            positive("scale", c.scale)?;
        }
        Ok(())
    }
}

/// GGX roughness `alpha` (the slope scale, as Mitsuba's `alpha`, not squared):
/// one number (isotropic) or `[alpha_x, alpha_y]` along the tangent x and y.
/// Zero means a smooth (delta) surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Roughness {
    /// Same alpha in every direction.
    Isotropic(f64),
    /// `[alpha_x, alpha_y]`.
    Anisotropic([f64; 2]),
}

impl Default for Roughness {
    fn default() -> Self {
        Roughness::Isotropic(0.0)
    }
}

impl Roughness {
    fn alphas(&self) -> [f64; 2] {
        match *self {
            Roughness::Isotropic(a) => [a, a],
            Roughness::Anisotropic(a) => a,
        }
    }

    /// The GGX distribution, or `None` for a smooth surface (both alphas 0).
    pub fn distribution(&self) -> Option<Ggx> {
        let [ax, ay] = self.alphas();
        (ax > 0.0 || ay > 0.0).then(|| Ggx::new(ax, ay))
    }

    fn validate(&self) -> Result<(), Error> {
        for a in self.alphas() {
            if !(a.is_finite() && a >= 0.0) {
                return Err(Error::invalid(
                    "roughness",
                    format!("must be finite and >= 0, got {a}"),
                ));
            }
        }
        Ok(())
    }
}

/// Parameters of [`Material::Lambertian`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LambertianParams {
    /// Reflectance in `[0, 1]`.
    pub albedo: Texture,
}

/// Metals with built-in complex indices at one wavelength, 548.6 nm (a
/// tabulated point of Johnson & Christy, near the 550 nm centre of the visible).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Metal {
    /// Gold: n = 0.43, k = 2.455 (Johnson & Christy 1972, Phys. Rev. B 6, 4370, at 548.6 nm).
    #[serde(alias = "Au")]
    Au,
    /// Silver: n = 0.06, k = 3.586 (Johnson & Christy 1972, at 548.6 nm).
    #[serde(alias = "Ag")]
    Ag,
    /// Aluminium: n = 1.009, k = 6.611 (Rakić 1995, Appl. Opt. 34, 4755, linearly
    /// interpolated to 548.6 nm between its 516.6 nm and 563.6 nm rows).
    #[serde(alias = "Al")]
    Al,
    /// Copper: n = 1.02, k = 2.577 (Johnson & Christy 1972, at 548.6 nm).
    #[serde(alias = "Cu")]
    Cu,
}

impl Metal {
    /// The complex index `n + ik` relative to vacuum, from the sources above.
    pub fn ior(self) -> Complex64 {
        match self {
            Metal::Au => Complex64::new(0.43, 2.455),
            Metal::Ag => Complex64::new(0.06, 3.586),
            Metal::Al => Complex64::new(1.009, 6.611),
            Metal::Cu => Complex64::new(1.02, 2.577),
        }
    }
}

/// Parameters of [`Material::Conductor`]: a preset `metal`, or `n` and `k`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConductorParams {
    /// A preset metal (exclusive with `n`/`k`).
    #[serde(default)]
    pub metal: Option<Metal>,
    /// Real part of the complex index.
    #[serde(default)]
    pub n: Option<f64>,
    /// Extinction coefficient (imaginary part, >= 0; default 0 when `n` is given).
    #[serde(default)]
    pub k: Option<f64>,
    /// GGX roughness; default 0 (mirror).
    #[serde(default)]
    pub roughness: Roughness,
}

impl ConductorParams {
    /// The complex index `n + ik` (relative to the outside, taken as vacuum/air).
    pub fn ior(&self) -> Complex64 {
        match self.metal {
            Some(m) => m.ior(),
            None => Complex64::new(self.n.unwrap_or(1.0), self.k.unwrap_or(0.0)),
        }
    }

    fn validate(&self) -> Result<(), Error> {
        match (self.metal, self.n, self.k) {
            (Some(_), None, None) => {}
            (Some(_), _, _) => {
                return Err(Error::invalid(
                    "metal",
                    "give either `metal` or `n`/`k`, not both",
                ));
            }
            (None, None, _) => {
                return Err(Error::invalid(
                    "n",
                    "missing: give `metal` or `n` (and `k`)",
                ));
            }
            (None, Some(n), k) => {
                positive("n", n)?;
                non_negative("k", k.unwrap_or(0.0))?;
            }
        }
        self.roughness.validate()
    }
}

/// Parameters of [`Material::Dielectric`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DielectricParams {
    /// Interior index of refraction (> 0).
    pub ior: f64,
    /// Exterior index of refraction (> 0, default 1).
    #[serde(default = "one")]
    pub ext_ior: f64,
    /// GGX roughness; default 0 (smooth).
    #[serde(default)]
    pub roughness: Roughness,
}

/// Parameters of [`Material::Plastic`]; defaults follow Mitsuba's `pplastic`
/// except the exterior index (1 here, Mitsuba's air is 1.000277) and the
/// distribution (always GGX here; Mitsuba defaults to Beckmann).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlasticParams {
    /// Diffuse reflectance in `[0, 1]` (default 0.5).
    #[serde(default = "half")]
    pub albedo: Texture,
    /// Interior index of the coating (default 1.49, polypropylene).
    #[serde(default = "polypropylene")]
    pub ior: f64,
    /// Exterior index (default 1).
    #[serde(default = "one")]
    pub ext_ior: f64,
    /// GGX roughness of the coating (default 0.1; 0 gives a smooth coating).
    #[serde(default = "default_plastic_roughness")]
    pub roughness: Roughness,
}

fn half() -> Texture {
    Texture::Constant(0.5)
}

fn polypropylene() -> f64 {
    1.49
}

fn default_plastic_roughness() -> Roughness {
    Roughness::Isotropic(0.1)
}

/// Parameters of [`Material::Polarizer`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolarizerParams {
    /// Transmission axis, degrees from the tangent x toward y.
    #[serde(default)]
    pub angle_deg: f64,
}

/// Parameters of [`Material::Retarder`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RetarderParams {
    /// Fast axis, degrees from the tangent x toward y.
    #[serde(default)]
    pub angle_deg: f64,
    /// Phase delay of the slow axis in degrees (90 = quarter-wave plate).
    pub retardance_deg: f64,
}

fn finite(field: &'static str, v: f64) -> Result<(), Error> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::invalid(field, format!("must be finite, got {v}")))
    }
}

fn positive(field: &'static str, v: f64) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and > 0, got {v}"),
        ))
    }
}

fn non_negative(field: &'static str, v: f64) -> Result<(), Error> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(Error::invalid(
            field,
            format!("must be finite and >= 0, got {v}"),
        ))
    }
}

impl Material {
    /// Checks every parameter's range; the error names the field and the reason.
    pub fn validate(&self) -> Result<(), Error> {
        match self {
            Material::Lambertian(p) => p.albedo.validate_albedo(),
            Material::Conductor(p) => p.validate(),
            Material::Dielectric(p) => {
                positive("ior", p.ior)?;
                positive("ext_ior", p.ext_ior)?;
                p.roughness.validate()
            }
            Material::Plastic(p) => {
                p.albedo.validate_albedo()?;
                positive("ior", p.ior)?;
                positive("ext_ior", p.ext_ior)?;
                p.roughness.validate()
            }
            Material::Polarizer(p) => finite("angle_deg", p.angle_deg),
            Material::Retarder(p) => {
                finite("angle_deg", p.angle_deg)?;
                finite("retardance_deg", p.retardance_deg)
            }
        }
    }

    /// Whether [`Self::bsdf`] depends on `uv` (a textured albedo); if not, a renderer
    /// need not compute surface coordinates.
    pub fn uses_uv(&self) -> bool {
        match self {
            Material::Lambertian(LambertianParams { albedo, .. })
            | Material::Plastic(PlasticParams { albedo, .. }) => {
                !matches!(albedo, Texture::Constant(_))
            }
            _ => false,
        }
    }

    /// The cheapest exact transport model the material needs (the same at every `uv`).
    pub fn polarization(&self) -> Polarization {
        self.bsdf([0.5, 0.5]).polarization()
    }

    /// The BSDF at surface coordinates `uv` (call [`Self::validate`] once first).
    #[inline(always)]
    pub fn bsdf(&self, uv: [f64; 2]) -> Bsdf {
        match self {
            Material::Lambertian(p) => Bsdf::Lambertian(Lambertian {
                albedo: p.albedo.eval(uv),
            }),
            Material::Conductor(p) => Bsdf::Conductor(Conductor {
                eta: p.ior(),
                roughness: p.roughness.distribution(),
            }),
            Material::Dielectric(p) => Bsdf::Dielectric(Dielectric {
                eta: p.ior / p.ext_ior,
                roughness: p.roughness.distribution(),
                importance: None,
            }),
            Material::Plastic(p) => Bsdf::Plastic(Plastic {
                eta: p.ior / p.ext_ior,
                roughness: p.roughness.distribution(),
                albedo: p.albedo.eval(uv),
                specular_prob: 1.0 / (1.0 + p.albedo.mean()),
            }),
            Material::Polarizer(p) => Bsdf::Sheet(Sheet {
                kind: SheetKind::Polarizer,
                angle: p.angle_deg.to_radians(),
            }),
            Material::Retarder(p) => Bsdf::Sheet(Sheet {
                kind: SheetKind::Retarder {
                    retardance: p.retardance_deg.to_radians(),
                },
                angle: p.angle_deg.to_radians(),
            }),
        }
    }
}
