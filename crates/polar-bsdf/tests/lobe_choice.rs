//! Lobe choice for the camera ([`Bsdf::with_importance`]): unbiased for any
//! physical camera row (the expected sample weight is the sum of the lobes'
//! matrices), and for glass the camera's S0 no longer depends on the lobe taken.

mod common;

use common::*;
use polar_bsdf::{Bsdf, BsdfSample, Dielectric, Plastic};
use polar_optics::{Mueller, Stokes};
use rand::RngExt;

/// Brewster's angle of glass (η = 1.5) from outside and from inside, degrees.
const BREWSTER_OUT: f64 = 56.309_932_474_020_22;
const BREWSTER_IN: f64 = 180.0 - 33.690_067_525_979_78;

fn glass() -> Bsdf {
    Bsdf::Dielectric(Dielectric {
        eta: 1.5,
        roughness: None,
        importance: None,
    })
}

/// `wo` from normal to grazing outside, through Brewster from both sides, and
/// inside beyond the critical angle (41.8° from −z: total internal reflection).
fn glass_views() -> Vec<(&'static str, V3)> {
    vec![
        ("normal", dir(0.0, 0.0)),
        ("oblique", dir(35.0, 80.0)),
        ("brewster_outside", dir(BREWSTER_OUT, 200.0)),
        ("grazing", dir(88.0, 10.0)),
        ("inside", dir(160.0, 300.0)),
        ("brewster_inside", dir(BREWSTER_IN, 45.0)),
        ("total_internal_reflection", dir(120.0, 130.0)),
    ]
}

/// Camera rows of physical Mueller matrices (`t_0 ≥ |t_1..3|`): unpolarized, a
/// few fully polarized analysers (including the ones crossed with s and with p
/// light at Brewster's angle) and random partial ones.
fn camera_rows(seed: u64) -> Vec<Stokes> {
    let mut rows = vec![
        Stokes::new(1.0, 0.0, 0.0, 0.0),
        Stokes::new(1.0, 1.0, 0.0, 0.0),
        Stokes::new(1.0, -1.0, 0.0, 0.0),
        Stokes::new(0.5, 0.0, 0.3, 0.4),
    ];
    let mut rng = rng(seed);
    for _ in 0..20 {
        let v = sphere(&mut rng) * rng.random::<f64>();
        rows.push(Stokes::new(1.0, v.x, v.y, v.z) * (0.1 + rng.random::<f64>()));
    }
    rows
}

/// The delta samples of `bsdf` at `wo` with their probabilities: reflection with
/// `u = 0`, transmission with `u` just below 1 (one sample under TIR).
fn delta_samples(bsdf: &Bsdf, wo: &V3) -> Vec<BsdfSample> {
    let r = bsdf.sample(wo, [0.0, 0.5, 0.5]).expect("reflection");
    let t = bsdf
        .sample(wo, [1.0 - 1e-16, 0.5, 0.5])
        .expect("transmission");
    if t.is_transmission {
        vec![r, t]
    } else {
        vec![r]
    }
}

/// `Σ p_k W_k` over the delta lobes: the expected sample weight.
fn expected_weight(samples: &[BsdfSample]) -> Mueller {
    samples.iter().map(|s| s.weight * s.pdf).sum()
}

#[test]
fn smooth_dielectric_expected_weight_is_the_sum_of_the_lobes_for_any_camera_row() {
    // The lobes' matrices are the unaimed choice's p_k W_k; 1e-12 relative: two
    // roundings of a division and a product of numbers of order 1.
    for (view, wo) in glass_views() {
        let lobes = expected_weight(&delta_samples(&glass(), &wo));
        for t in camera_rows(1) {
            let aimed = glass().with_importance(&wo, &t);
            let samples = delta_samples(&aimed, &wo);
            let total_p: f64 = samples.iter().map(|s| s.pdf).sum();
            assert!(
                (total_p - 1.0).abs() < 1e-12,
                "{view} t={t}: Σp = {total_p}"
            );
            let err = (expected_weight(&samples) - lobes).amax();
            assert!(err < 1e-12 * lobes.amax(), "{view} t={t}: off by {err}");
            assert!(
                samples
                    .iter()
                    .all(|s| s.weight.iter().all(|v| v.is_finite()))
            );
        }
    }
}

/// The camera's S0 `(t W_k)_00` of lobe `k`, with transmission in flux units
/// (`η²` undone: radiance scales by `n²` across the interface).
fn camera_s0(t: &Stokes, s: &BsdfSample) -> f64 {
    (t.transpose() * s.weight)[0] * s.eta * s.eta
}

#[test]
fn smooth_dielectric_camera_s0_is_the_same_whichever_lobe() {
    // With p_k ∝ t · c_k every lobe brings t_0 (1e-12 relative, rounding),
    // except where the floor lifts a crossed lobe (t · c_k < 1e-6 t_0 c_k,0):
    // that lobe brings less, and the other up to 1e-6 more. The unaimed choice
    // misses by more than 1% on polarized rows at oblique angles: that is the
    // variance removed.
    let mut worst_unaimed: f64 = 0.0;
    for (view, wo) in glass_views() {
        for t in camera_rows(2) {
            let samples = delta_samples(&glass().with_importance(&wo, &t), &wo);
            let floored = |s: &BsdfSample| s.pdf < 1e-5;
            let tol = if samples.iter().any(floored) {
                2e-6
            } else {
                1e-12
            };
            for s in &samples {
                let s0 = camera_s0(&t, s);
                assert!(s0 <= t[0] * (1.0 + tol), "{view} t={t}: {s0}");
                assert!(
                    floored(s) || (s0 - t[0]).abs() < tol * t[0],
                    "{view} t={t}: {s0}"
                );
            }
            for s in delta_samples(&glass(), &wo) {
                worst_unaimed = worst_unaimed.max((camera_s0(&t, &s) / t[0] - 1.0).abs());
            }
        }
    }
    assert!(
        worst_unaimed > 0.01,
        "unaimed choice off by {worst_unaimed} only"
    );
}

#[test]
fn brewster_reflection_seen_through_a_p_analyser_keeps_a_floor() {
    // At Brewster's angle the reflection is s-polarized; a camera that only sees
    // p light gets nothing from it: the choice falls to the floor, and the
    // reflection's weight stays finite (bounded by 1/floor of the unaimed one).
    let wo = dir(BREWSTER_OUT, 0.0);
    // The s axis of the plane of incidence at φ = 0 is y, so p light is +S1 in
    // the basis of wo (x = stokes_basis(wo), which lies in the xz plane here).
    let x = polar_optics::stokes_basis(&wo);
    assert!(x.y.abs() < 1e-12, "basis x {x}");
    let p_analyser = Stokes::new(1.0, 1.0, 0.0, 0.0);
    let samples = delta_samples(&glass().with_importance(&wo, &p_analyser), &wo);
    let r = &samples[0];
    assert!(
        !r.is_transmission && r.pdf > 0.0 && r.pdf < 1e-6,
        "{}",
        r.pdf
    );
    assert!(r.weight.amax() < 2e6 && r.weight.iter().all(|v| v.is_finite()));
    assert!(camera_s0(&p_analyser, r).abs() < 1e-9);
}

fn plastic(roughness: Option<polar_bsdf::microfacet::Ggx>) -> Bsdf {
    Bsdf::Plastic(Plastic {
        eta: 1.5,
        roughness,
        albedo: 0.7,
        specular_prob: 1.0 / 1.7,
    })
}

#[test]
fn smooth_plastic_expected_weight_is_the_sum_of_the_lobes_for_any_camera_row() {
    // Specular: p_s W_s is the Fresnel matrix whatever p_s (1e-12 relative).
    // Diffuse: each sample's weight is eval / pdf with pdf = (1 − p_s) cos θ / π,
    // so its expectation is ∫ eval dω whatever p_s (1e-9: the sampling test's tolerance).
    let bsdf = plastic(None);
    let mut rng = rng(5);
    for theta in [0.0, 30.0, BREWSTER_OUT, 85.0] {
        let wo = dir(theta, 70.0);
        let specular = bsdf.sample(&wo, [0.0, 0.5, 0.5]).expect("specular");
        let fresnel = specular.weight * specular.pdf;
        for t in camera_rows(3) {
            let aimed = bsdf.with_importance(&wo, &t);
            let s = aimed.sample(&wo, [0.0, 0.5, 0.5]).expect("specular");
            assert!(s.is_delta && s.pdf > 0.0);
            let err = (s.weight * s.pdf - fresnel).amax();
            assert!(err < 1e-12 * fresnel.amax(), "theta {theta} t={t}: {err}");
            let p_s = s.pdf;
            for _ in 0..20 {
                let u = [
                    p_s + (1.0 - p_s) * rng.random::<f64>(),
                    rng.random(),
                    rng.random(),
                ];
                let Some(d) = aimed.sample(&wo, u) else {
                    continue;
                };
                let pdf = (1.0 - p_s) * d.wi.z / std::f64::consts::PI;
                assert!(
                    (d.pdf - pdf).abs() < 1e-12 * pdf,
                    "theta {theta}: pdf {}",
                    d.pdf
                );
                assert!((aimed.pdf(&wo, &d.wi) - pdf).abs() < 1e-12 * pdf);
                let err = (d.weight * d.pdf - bsdf.eval(&wo, &d.wi)).amax();
                assert!(err < 1e-9 * d.weight.amax() * d.pdf, "theta {theta}: {err}");
            }
        }
    }
}

#[test]
fn plastic_choice_follows_the_camera_row() {
    // An unpolarized camera keeps Mitsuba's probability exactly; one that sees
    // only the s light of the Brewster reflection picks the specular lobe more
    // often, one that sees only p light (the diffuse lobe's) less.
    let wo = dir(BREWSTER_OUT, 0.0);
    for bsdf in [
        plastic(None),
        plastic(Some(polar_bsdf::microfacet::Ggx::new(0.2, 0.2))),
    ] {
        let p = |t: Stokes| match bsdf.with_importance(&wo, &t) {
            Bsdf::Plastic(p) => p.specular_prob,
            _ => unreachable!(),
        };
        assert_eq!(p(Stokes::new(2.0, 0.0, 0.0, 0.0)), 1.0 / 1.7);
        assert!(p(Stokes::new(1.0, -1.0, 0.0, 0.0)) > 1.0 / 1.7);
        assert!(p(Stokes::new(1.0, 1.0, 0.0, 0.0)) < 1e-5);
    }
}

#[test]
fn glass_lobe_outcomes_are_the_two_samples_of_the_choice() {
    // `Bsdf::lobe_outcomes` gives exactly (same arithmetic, so bit for bit) the
    // reflection and the transmission that `sample` returns on either side of the
    // choice, unaimed and aimed, with the samples' probabilities, which sum to 1.
    // Under total internal reflection there is one outcome, so nothing to split.
    for (view, wo) in glass_views() {
        for bsdf in [glass(), glass().with_importance(&wo, &camera_rows(3)[5])] {
            let samples = delta_samples(&bsdf, &wo);
            match bsdf.lobe_outcomes(&wo, [0.3, 0.6]) {
                Some(both) => {
                    for (outcome, sample) in both.iter().zip(&samples) {
                        assert_eq!(outcome.sample.as_ref(), Some(sample), "{view}");
                        assert_eq!(outcome.probability, sample.pdf, "{view}");
                    }
                    let total: f64 = both.iter().map(|o| o.probability).sum();
                    assert!((total - 1.0).abs() < 1e-15, "{view}: Σp = {total}");
                }
                None => assert_eq!(samples.len(), 1, "{view}: two outcomes not split"),
            }
        }
    }
    assert!(
        glass()
            .lobe_outcomes(&dir(120.0, 130.0), [0.3, 0.6])
            .is_none()
    );
}

#[test]
fn plastic_lobe_outcomes_are_the_two_samples_of_the_choice() {
    // The specular and the diffuse outcome are what `sample` returns with u[0]
    // below and above the specular probability and the same 2-D point, bit for
    // bit, unaimed and aimed (smooth and rough coatings, random points and views);
    // the probabilities are the choice's. None seen from below the surface.
    let mut rng = rng(4);
    for (name, bsdf) in all_bsdfs()
        .into_iter()
        .filter(|(n, _)| n.ends_with("plastic"))
    {
        let Bsdf::Plastic(plastic) = bsdf else {
            unreachable!("{name}")
        };
        for _ in 0..50 {
            let (wo, u) = (hemisphere(&mut rng), u3(&mut rng));
            for b in [bsdf, bsdf.with_importance(&wo, &camera_rows(5)[7])] {
                let Bsdf::Plastic(p) = b else { unreachable!() };
                let both = b.lobe_outcomes(&wo, [u[1], u[2]]).expect(name);
                let (specular, diffuse) = (&both[0], &both[1]);
                assert_eq!(specular.probability, p.specular_prob, "{name}");
                assert_eq!(diffuse.probability, 1.0 - p.specular_prob, "{name}");
                assert_eq!(specular.sample, b.sample(&wo, [0.0, u[1], u[2]]), "{name}");
                assert_eq!(
                    diffuse.sample,
                    b.sample(&wo, [1.0 - 1e-16, u[1], u[2]]),
                    "{name}"
                );
            }
            let below = V3::new(wo.x, wo.y, -wo.z);
            assert!(bsdf.lobe_outcomes(&below, [u[1], u[2]]).is_none(), "{name}");
        }
        assert!(plastic.specular_prob > 0.0 && plastic.specular_prob < 1.0);
    }
}

#[test]
fn only_smooth_glass_and_plastic_have_lobe_outcomes() {
    // Rough glass draws its microfacet before its choice; the other BSDFs have
    // one lobe: none of them is split.
    let wo = dir(35.0, 80.0);
    for (name, bsdf) in all_bsdfs() {
        let split = bsdf.lobe_outcomes(&wo, [0.3, 0.6]).is_some();
        assert_eq!(
            split,
            name == "smooth_dielectric" || name.ends_with("plastic"),
            "{name}"
        );
    }
}
