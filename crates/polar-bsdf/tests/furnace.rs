//! White-furnace tests: no BSDF reflects or transmits more energy than it
//! receives, for any input polarization and any viewing angle up to grazing;
//! the smooth lossless dielectric conserves energy exactly (R + T = 1).

mod common;

use common::*;
use polar_bsdf::{Bsdf, Dielectric};
use polar_optics::frame::basis_angle;
use polar_optics::stokes::linear;
use polar_optics::stokes_basis;

/// Viewing polar angles (degrees), from normal to 0.1° above grazing.
const THETAS: [f64; 7] = [0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9];
const SAMPLES: usize = 20_000;

/// Monte Carlo estimate of the directional albedo seen from `wo` (unpolarized
/// light from every direction), with its standard error. Transmission weights
/// are multiplied by `eta²` to undo the radiance scaling: energy, not
/// radiance, is conserved. Every delta sample is also checked on its own: one
/// incident beam may not gain energy whatever its polarization.
fn backward_albedo(name: &str, bsdf: &Bsdf, wo: &V3, seed: u64) -> (f64, f64) {
    let mut rng = rng(seed);
    let (mut sum, mut sum_sq) = (0.0, 0.0);
    for _ in 0..SAMPLES {
        let Some(s) = bsdf.sample(wo, u3(&mut rng)) else {
            continue;
        };
        let flux = s.weight * (s.eta * s.eta);
        if s.is_delta {
            let beam = flux * s.pdf;
            let best = beam[(0, 0)] + beam.fixed_view::<1, 3>(0, 1).norm();
            assert!(
                best <= 1.0 + 1e-12,
                "{name} wo={wo:?}: delta beam gains energy: {best}"
            );
        }
        sum += flux[(0, 0)];
        sum_sq += flux[(0, 0)].powi(2);
    }
    let n = SAMPLES as f64;
    let mean = sum / n;
    (mean, ((sum_sq / n - mean * mean).max(0.0) / n).sqrt())
}

/// Forward estimate for one incident beam along `-wi`: the first row of
/// `∫ f(wo, wi) |cos θo| dωo` over uniformly sampled `wo`, with the standard
/// error of its (0, 0) entry. (Integrated over `wo`, the radiance BSDF of a
/// refraction already gives the transmitted energy fraction: the `1/η²` radiance
/// scaling is cancelled by the solid-angle compression.) Its `M00 + |(M01, M02, M03)|` is the most energy
/// that beam can send out for any polarization.
fn forward_albedo_row(bsdf: &Bsdf, wi: &V3, seed: u64) -> ([f64; 4], f64) {
    let mut rng = rng(seed);
    let (mut sum, mut sum_sq) = ([0.0; 4], 0.0);
    let inv_pdf = 4.0 * std::f64::consts::PI;
    for _ in 0..SAMPLES {
        let wo = sphere(&mut rng);
        let f = bsdf.eval(&wo, wi) * (wo.z.abs() / wi.z.abs() * inv_pdf);
        for (j, acc) in sum.iter_mut().enumerate() {
            *acc += f[(0, j)];
        }
        sum_sq += f[(0, 0)].powi(2);
    }
    let n = SAMPLES as f64;
    let mean = sum.map(|v| v / n);
    (mean, ((sum_sq / n - mean[0] * mean[0]).max(0.0) / n).sqrt())
}

#[test]
fn white_furnace_every_bsdf_every_angle() {
    for (name, bsdf) in all_bsdfs() {
        let sides: &[f64] = if two_sided(&bsdf) {
            &[1.0, -1.0]
        } else {
            &[1.0]
        };
        for (i, theta) in THETAS.iter().enumerate() {
            for &side in sides {
                let mut wo = dir(*theta, 37.0);
                wo.z *= side;
                let (albedo, se) = backward_albedo(name, &bsdf, &wo, 1000 + i as u64);
                // Tolerance: 4 standard errors of the estimate (false alarm ~1e-4)
                // plus 1e-9 for rounding in the exactly-conserving delta lobes.
                assert!(
                    albedo <= 1.0 + 4.0 * se + 1e-9,
                    "{name} wo={wo:?}: albedo {albedo} > 1 (se {se})"
                );
                assert!(albedo >= 0.0, "{name}: negative albedo {albedo}");
            }
        }
    }
}

#[test]
fn forward_furnace_any_input_polarization() {
    for (name, bsdf) in smooth_lobed() {
        let sides: &[f64] = if two_sided(&bsdf) {
            &[1.0, -1.0]
        } else {
            &[1.0]
        };
        for (i, theta) in THETAS.iter().enumerate() {
            for &side in sides {
                let mut wi = dir(*theta, -71.0);
                wi.z *= side;
                let (row, se) = forward_albedo_row(&bsdf, &wi, 2000 + i as u64);
                let best = row[0] + (row[1].powi(2) + row[2].powi(2) + row[3].powi(2)).sqrt();
                // 4 standard errors of M00, doubled to cover the polarized terms' noise.
                assert!(
                    best <= 1.0 + 8.0 * se,
                    "{name} wi={wi:?}: polarized albedo {best} > 1 (se {se})"
                );
            }
        }
    }
}

#[test]
fn lambertian_albedo_is_exact() {
    let bsdf = Bsdf::Lambertian(polar_bsdf::Lambertian { albedo: 0.8 });
    let (albedo, se) = backward_albedo("lambertian", &bsdf, &dir(50.0, 10.0), 7);
    // Every sample weighs exactly the albedo.
    // The standard error suffers cancellation in `E[x²] − E[x]²`; 1e-6 still means zero.
    assert!((albedo - 0.8).abs() < 1e-12 && se < 1e-6, "{albedo} ± {se}");
}

/// Linear light of unit intensity along `axis` (perpendicular to `k`), in the
/// BSDF basis of a beam travelling along `k`.
fn polarized_along(k: &V3, axis: &V3) -> polar_optics::Stokes {
    linear(1.0, basis_angle(k, &stokes_basis(k), axis))
}

/// Light leaving along `wo` comes from the mirror direction (reflected) and the
/// refracted direction (transmitted); in flux units their Mueller matrices must
/// add up to exactly 1 for unpolarized, s- and p-polarized light.
#[test]
fn smooth_lossless_dielectric_r_plus_t_is_one_for_s_p_and_unpolarized() {
    let bsdf = Bsdf::Dielectric(Dielectric {
        eta: 1.5,
        roughness: None,
        importance: None,
    });
    for theta in [
        0.0, 10.0, 40.0, 56.31, 70.0, 89.0, 100.0, 130.0, 139.0, 160.0, 180.0,
    ] {
        let wo = dir(theta, 123.0);
        // u = 0 always picks reflection; u just below 1 picks transmission.
        let r = bsdf.sample(&wo, [0.0, 0.5, 0.5]).unwrap();
        let t = bsdf.sample(&wo, [1.0 - 1e-15, 0.5, 0.5]).unwrap();
        let r_flux = r.weight * r.pdf;
        if !t.is_transmission {
            // Total internal reflection: everything is reflected.
            assert!(
                (r_flux[(0, 0)] - 1.0).abs() < 1e-12,
                "TIR at {theta}: R = {}",
                r_flux[(0, 0)]
            );
            continue;
        }
        let t_flux = t.weight * t.pdf * t.eta * t.eta;
        let total = r_flux[(0, 0)] + t_flux[(0, 0)];
        assert!(
            (total - 1.0).abs() < 1e-12,
            "theta {theta}: R + T = {total}"
        );
        // The same for s- and p-polarized light, each in its own plane of incidence.
        let z = V3::z();
        for perpendicular in [true, false] {
            let beam = |wi: &V3| {
                let k = -wi;
                let s = z.cross(&k);
                let s = if s.norm() > 1e-9 {
                    s.normalize()
                } else {
                    stokes_basis(&k)
                };
                polarized_along(&k, &if perpendicular { s } else { k.cross(&s) })
            };
            let out = (r_flux * beam(&r.wi))[0] + (t_flux * beam(&t.wi))[0];
            assert!(
                (out - 1.0).abs() < 1e-12,
                "theta {theta}, s={perpendicular}: R + T = {out}"
            );
        }
    }
}
