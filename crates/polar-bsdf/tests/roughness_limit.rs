//! Analytic validation of the rough lobes (rough glass cannot be checked against
//! Mitsuba, whose `roughdielectric` depolarizes): as the roughness vanishes, the
//! Mueller matrix integrated over each rough lobe must converge to the smooth
//! interface's Fresnel matrix, element by element, including the TIR phase.

mod common;

use common::*;
use polar_bsdf::microfacet::Ggx;
use polar_bsdf::{Bsdf, Conductor, Dielectric, Plastic};
use polar_optics::Mueller;

const ALPHA: f64 = 1e-3;
const SAMPLES: usize = 20_000;

/// `E[weight]` split into the reflected and the transmitted lobe: the lobe's
/// `∫ f |cos θi| dωi` as a Mueller matrix.
fn rough_lobes(bsdf: &Bsdf, wo: &V3) -> (Mueller, Mueller) {
    let mut rng = rng(17);
    let (mut r, mut t) = (Mueller::zeros(), Mueller::zeros());
    for _ in 0..SAMPLES {
        let Some(s) = bsdf.sample(wo, u3(&mut rng)) else {
            continue;
        };
        *(if s.is_transmission { &mut t } else { &mut r }) += s.weight / SAMPLES as f64;
    }
    (r, t)
}

/// The smooth BSDF's delta lobes as Mueller matrices (weight × probability).
fn smooth_lobes(bsdf: &Bsdf, wo: &V3) -> (Mueller, Mueller) {
    let (mut r, mut t) = (Mueller::zeros(), Mueller::zeros());
    for u0 in [0.0, 1.0 - 1e-15] {
        let s = bsdf.sample(wo, [u0, 0.5, 0.5]).expect("delta sample");
        *(if s.is_transmission { &mut t } else { &mut r }) = s.weight * s.pdf;
    }
    (r, t)
}

#[test]
fn rough_lobes_converge_to_smooth_fresnel_matrices() {
    let pairs = [
        (
            "dielectric",
            Bsdf::Dielectric(Dielectric {
                eta: 1.5,
                roughness: Some(Ggx::new(ALPHA, ALPHA)),
                importance: None,
            }),
            Bsdf::Dielectric(Dielectric {
                eta: 1.5,
                roughness: None,
                importance: None,
            }),
        ),
        (
            "conductor",
            Bsdf::Conductor(Conductor {
                eta: gold(),
                roughness: Some(Ggx::new(ALPHA, 2.0 * ALPHA)),
            }),
            Bsdf::Conductor(Conductor {
                eta: gold(),
                roughness: None,
            }),
        ),
    ];
    for (name, rough, smooth) in pairs {
        // Outside, and for glass also inside below and beyond the critical angle (41.8°).
        let thetas: &[f64] = if two_sided(&rough) {
            &[0.0, 30.0, 60.0, 160.0, 130.0]
        } else {
            &[0.0, 30.0, 60.0]
        };
        for &theta in thetas {
            let wo = dir(theta, 40.0);
            let (rr, rt) = rough_lobes(&rough, &wo);
            let (sr, st) = smooth_lobes(&smooth, &wo);
            // Tolerance 5e-3: at alpha = 1e-3 the lobes differ from the smooth one by
            // O(alpha) in direction (so in frame rotation and Fresnel angle) and by
            // masking 1 − G1 = O(alpha² tan² θ); the random Fresnel choice between the
            // lobes adds binomial noise sqrt(R (1 − R) / N) ≈ 1.4e-3 for glass. Observed
            // errors are at most 6e-4.
            let err = (rr - sr).abs().max().max((rt - st).abs().max());
            assert!(
                err < 5e-3,
                "{name} theta {theta}: rough {rr}{rt} vs smooth {sr}{st}"
            );
        }
    }
}

#[test]
fn rough_plastic_specular_lobe_converges_to_smooth() {
    // Compare the specular parts only: zero albedo leaves just the coating.
    let plastic = |roughness| {
        Bsdf::Plastic(Plastic {
            eta: 1.5,
            roughness,
            albedo: 0.0,
            specular_prob: 1.0,
        })
    };
    let (rough, smooth) = (plastic(Some(Ggx::new(ALPHA, ALPHA))), plastic(None));
    for theta in [0.0, 45.0, 56.3, 70.0] {
        let wo = dir(theta, 200.0);
        let (rr, _) = rough_lobes(&rough, &wo);
        let s = smooth.sample(&wo, [0.0, 0.5, 0.5]).expect("delta");
        let err = (rr - s.weight * s.pdf).abs().max();
        assert!(
            err < 5e-3,
            "theta {theta}: rough {rr} vs smooth {}",
            s.weight * s.pdf
        );
    }
}
