//! Shared fixtures for the BSDF tests: a named list of BSDFs covering every
//! model and regime, a seeded generator, and direction helpers.
#![allow(dead_code)]

use nalgebra::Vector3;
use num_complex::Complex64;
use polar_bsdf::microfacet::Ggx;
use polar_bsdf::{Bsdf, Conductor, Dielectric, Lambertian, Metal, Plastic, Sheet, SheetKind};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

pub type V3 = Vector3<f64>;

/// Deterministic generator: every test uses a fixed seed.
pub fn rng(seed: u64) -> Pcg64 {
    Pcg64::seed_from_u64(seed)
}

pub fn u3(rng: &mut Pcg64) -> [f64; 3] {
    [rng.random(), rng.random(), rng.random()]
}

/// Unit direction at polar angle `theta_deg` from +z and azimuth `phi_deg`.
pub fn dir(theta_deg: f64, phi_deg: f64) -> V3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    V3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

/// Uniform direction on the sphere.
pub fn sphere(rng: &mut Pcg64) -> V3 {
    let z: f64 = 2.0 * rng.random::<f64>() - 1.0;
    let phi = 2.0 * std::f64::consts::PI * rng.random::<f64>();
    let r = (1.0 - z * z).max(0.0).sqrt();
    V3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Uniform direction on the upper hemisphere.
pub fn hemisphere(rng: &mut Pcg64) -> V3 {
    let w = sphere(rng);
    V3::new(w.x, w.y, w.z.abs())
}

pub fn gold() -> Complex64 {
    Metal::Au.ior()
}

/// Every non-delta BSDF configuration, by name.
pub fn smooth_lobed() -> Vec<(&'static str, Bsdf)> {
    vec![
        ("lambertian", Bsdf::Lambertian(Lambertian { albedo: 0.8 })),
        (
            "rough_conductor_iso",
            Bsdf::Conductor(Conductor {
                eta: gold(),
                roughness: Some(Ggx::new(0.3, 0.3)),
            }),
        ),
        (
            "rough_conductor_aniso",
            Bsdf::Conductor(Conductor {
                eta: Metal::Al.ior(),
                roughness: Some(Ggx::new(0.15, 0.5)),
            }),
        ),
        (
            "rough_dielectric",
            Bsdf::Dielectric(Dielectric {
                eta: 1.5,
                roughness: Some(Ggx::new(0.3, 0.3)),
                importance: None,
            }),
        ),
        (
            "rough_dielectric_aniso",
            Bsdf::Dielectric(Dielectric {
                eta: 1.33,
                roughness: Some(Ggx::new(0.2, 0.45)),
                importance: None,
            }),
        ),
        (
            "rough_plastic",
            Bsdf::Plastic(Plastic {
                eta: 1.49,
                roughness: Some(Ggx::new(0.25, 0.25)),
                albedo: 0.6,
                specular_prob: 1.0 / 1.6,
            }),
        ),
        (
            "smooth_plastic",
            Bsdf::Plastic(Plastic {
                eta: 1.5,
                roughness: None,
                albedo: 0.9,
                specular_prob: 1.0 / 1.9,
            }),
        ),
    ]
}

/// Every delta-only BSDF configuration, by name.
pub fn delta_only() -> Vec<(&'static str, Bsdf)> {
    vec![
        (
            "smooth_conductor",
            Bsdf::Conductor(Conductor {
                eta: Metal::Cu.ior(),
                roughness: None,
            }),
        ),
        (
            "smooth_dielectric",
            Bsdf::Dielectric(Dielectric {
                eta: 1.5,
                roughness: None,
                importance: None,
            }),
        ),
        (
            "polarizer",
            Bsdf::Sheet(Sheet {
                kind: SheetKind::Polarizer,
                angle: 0.3,
            }),
        ),
        (
            "quarter_wave",
            Bsdf::Sheet(Sheet {
                kind: SheetKind::Retarder {
                    retardance: std::f64::consts::FRAC_PI_2,
                },
                angle: 0.7,
            }),
        ),
    ]
}

pub fn all_bsdfs() -> Vec<(&'static str, Bsdf)> {
    let mut v = smooth_lobed();
    v.extend(delta_only());
    v
}

/// Whether the BSDF transmits (so `wo` below the surface is meaningful).
pub fn two_sided(b: &Bsdf) -> bool {
    matches!(b, Bsdf::Dielectric(_) | Bsdf::Sheet(_))
}
