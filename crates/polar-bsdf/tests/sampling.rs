//! Sampling against pdf and eval, per BSDF:
//! - a Pearson chi-square test of the histogram of sampled `wi` over a (θ, φ)
//!   grid of the whole sphere against the integrated `pdf` (θ rather than cos θ
//!   so that the narrow refracted lobe around the pole is resolved);
//! - for every non-delta sample, `pdf(wo, wi)` equals the sample's pdf and the
//!   weight equals `eval / pdf`.
//!
//! Both also for the lobe choice aimed at a polarized camera row
//! ([`Bsdf::with_importance`]), which must keep `pdf` and `sample` consistent.

mod common;

use common::*;
use polar_bsdf::Bsdf;
use polar_optics::Stokes;
use polar_testkit::{chi2_critical, pearson};
use std::f64::consts::PI;

const THETA_BINS: usize = 36;
const PHI_BINS: usize = 40;
/// Midpoint sub-samples per bin side when integrating the pdf over a bin: at 8
/// the rule under-integrates the anisotropic rough dielectric's transmission just
/// below the horizon at grazing `wo` by 9%, enough to fail with some seeds.
const SUB: usize = 16;
const SAMPLES: usize = 200_000;

fn bin_of(w: &V3) -> usize {
    let t = ((w.z.clamp(-1.0, 1.0).acos() / PI * THETA_BINS as f64) as usize).min(THETA_BINS - 1);
    let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    t * PHI_BINS + p
}

/// `∫ pdf dω` over each bin (dω = sin θ dθ dφ), by the midpoint rule.
fn expected_mass(bsdf: &Bsdf, wo: &V3) -> Vec<f64> {
    let (dt, dp) = (PI / THETA_BINS as f64, 2.0 * PI / PHI_BINS as f64);
    let (st, sp) = (dt / SUB as f64, dp / SUB as f64);
    let mut mass = vec![0.0; THETA_BINS * PHI_BINS];
    for (b, m) in mass.iter_mut().enumerate() {
        let (t0, p0) = ((b / PHI_BINS) as f64 * dt, (b % PHI_BINS) as f64 * dp);
        for i in 0..SUB {
            let (sin_t, cos_t) = (t0 + (i as f64 + 0.5) * st).sin_cos();
            for j in 0..SUB {
                let (sin_p, cos_p) = (p0 + (j as f64 + 0.5) * sp).sin_cos();
                let wi = V3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
                *m += bsdf.pdf(wo, &wi) * sin_t * st * sp;
            }
        }
    }
    mass
}

/// The three bins contributing most to the statistic, for failure messages.
fn worst_bins(observed: &[f64], expected: &[f64]) -> String {
    let mut bins: Vec<(f64, usize)> = (0..observed.len())
        .filter(|&b| expected[b] >= 5.0)
        .map(|b| ((observed[b] - expected[b]).powi(2) / expected[b], b))
        .collect();
    bins.sort_by(|a, b| b.0.total_cmp(&a.0));
    let show = |&(_, b): &(f64, usize)| {
        format!(
            "(theta bin {}, phi bin {}: {} vs {:.1})",
            b / PHI_BINS,
            b % PHI_BINS,
            observed[b],
            expected[b]
        )
    };
    bins.iter().take(3).map(show).collect::<Vec<_>>().join(", ")
}

/// A partially polarized camera row (`t_0 > |t_1..3|`) that changes every lobe choice.
fn camera_row() -> Stokes {
    Stokes::new(1.0, 0.7, -0.4, 0.3)
}

/// `bsdf` as sampled, and aimed at [`camera_row`] when that changes it.
fn variants(bsdf: &Bsdf, wo: &V3) -> Vec<(&'static str, Bsdf)> {
    let aimed = bsdf.with_importance(wo, &camera_row());
    let mut v = vec![("unaimed", *bsdf)];
    if aimed != *bsdf {
        v.push(("aimed", aimed));
    }
    v
}

/// Chi-square test of one named BSDF of [`smooth_lobed`] at several `wo`,
/// including grazing and (for transmissive ones) from inside.
fn chi_square(case: &str) {
    let (name, bsdf) = smooth_lobed()
        .into_iter()
        .find(|(n, _)| *n == case)
        .expect("known case");
    {
        let mut wos = vec![
            dir(0.0, 0.0),
            dir(35.0, 20.0),
            dir(70.0, 200.0),
            dir(87.0, 300.0),
        ];
        if two_sided(&bsdf) {
            wos.extend([dir(160.0, 50.0), dir(120.0, 10.0)]);
        }
        let cases = wos
            .iter()
            .enumerate()
            .flat_map(|(k, wo)| variants(&bsdf, wo).into_iter().map(move |v| (k, wo, v)));
        for (k, wo, (aim, bsdf)) in cases {
            let name = format!("{name} ({aim})");
            let mut rng = rng(42 + k as u64);
            let mut observed = vec![0.0; THETA_BINS * PHI_BINS];
            for _ in 0..SAMPLES {
                if let Some(s) = bsdf.sample(wo, u3(&mut rng)).filter(|s| !s.is_delta) {
                    observed[bin_of(&s.wi)] += 1.0;
                }
            }
            let mass = expected_mass(&bsdf, wo);
            let expected: Vec<f64> = mass.iter().map(|m| m * SAMPLES as f64).collect();
            // Total mass: the fraction of samples that are non-delta and not rejected.
            let (n_obs, n_exp) = (observed.iter().sum::<f64>(), expected.iter().sum::<f64>());
            // 5 binomial standard deviations, plus 0.2% for the midpoint rule on peaked lobes.
            let tol = 5.0 * n_obs.max(1.0).sqrt() + 2e-3 * SAMPLES as f64;
            assert!(
                (n_obs - n_exp).abs() < tol,
                "{name} wo={wo:?}: {n_obs} samples, pdf integrates to {n_exp}"
            );
            let (stat, dof) = pearson(&observed, &expected);
            let critical = chi2_critical(dof);
            assert!(
                stat < critical,
                "{name} wo={wo:?}: chi2 {stat:.1} >= {critical:.1} (dof {dof}); worst bins {}",
                worst_bins(&observed, &expected)
            );
        }
    }
}

#[test]
fn sample_weight_is_eval_over_pdf_and_pdf_matches() {
    for (name, bsdf) in smooth_lobed() {
        let mut rng = rng(7);
        let mut checked = 0;
        for _ in 0..2000 {
            let mut wo = if two_sided(&bsdf) {
                sphere(&mut rng)
            } else {
                hemisphere(&mut rng)
            };
            wo.normalize_mut();
            let bsdf = if checked % 2 == 0 {
                bsdf
            } else {
                bsdf.with_importance(&wo, &camera_row())
            };
            let Some(s) = bsdf.sample(&wo, u3(&mut rng)) else {
                continue;
            };
            if s.is_delta {
                continue;
            }
            let pdf = bsdf.pdf(&wo, &s.wi);
            // Relative 1e-9: pdf and eval recompute the half vector from (wo, wi),
            // which differs from the sampled normal by rounding only.
            assert!(
                (pdf - s.pdf).abs() <= 1e-9 * s.pdf,
                "{name}: pdf {pdf} vs sampled {}",
                s.pdf
            );
            let expected = bsdf.eval(&wo, &s.wi) / s.pdf;
            let err = (expected - s.weight).abs().max();
            assert!(
                err <= 1e-9 * expected.abs().max().max(1e-300),
                "{name}: weight differs by {err}"
            );
            assert!(
                s.weight.iter().all(|v| v.is_finite()),
                "{name}: non-finite weight"
            );
            checked += 1;
        }
        assert!(checked > 500, "{name}: only {checked} non-delta samples");
    }
}

#[test]
fn chi_square_lambertian() {
    chi_square("lambertian");
}

#[test]
fn chi_square_rough_conductor_iso() {
    chi_square("rough_conductor_iso");
}

#[test]
fn chi_square_rough_conductor_aniso() {
    chi_square("rough_conductor_aniso");
}

#[test]
fn chi_square_rough_dielectric() {
    chi_square("rough_dielectric");
}

#[test]
fn chi_square_rough_dielectric_aniso() {
    chi_square("rough_dielectric_aniso");
}

#[test]
fn chi_square_rough_plastic() {
    chi_square("rough_plastic");
}

#[test]
fn chi_square_smooth_plastic() {
    chi_square("smooth_plastic");
}

#[test]
fn anisotropic_roughness_spreads_along_the_tangent() {
    // alpha_x = 0.5 along the tangent x, alpha_y = 0.05: seen from the normal,
    // the mirror lobe is wide in x and narrow in y.
    let bsdf = Bsdf::Conductor(polar_bsdf::Conductor {
        eta: gold(),
        roughness: Some(polar_bsdf::microfacet::Ggx::new(0.5, 0.05)),
    });
    let mut rng = rng(9);
    let (mut xx, mut yy) = (0.0, 0.0);
    for _ in 0..5000 {
        let Some(s) = bsdf.sample(&V3::z(), u3(&mut rng)) else {
            continue;
        };
        xx += s.wi.x * s.wi.x;
        yy += s.wi.y * s.wi.y;
    }
    // The slope variances scale as alpha²: a ratio of 100; 10 leaves a wide margin.
    assert!(xx > 10.0 * yy, "spread x {xx} vs y {yy}");
}
