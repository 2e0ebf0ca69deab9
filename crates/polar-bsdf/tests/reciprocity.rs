//! Helmholtz reciprocity of the intensity (M00) part of every non-delta BSDF:
//! `f(wo, wi) = f(wi, wo)` for reflection, and `f(wo, wi) / n_wo² = f(wi, wo) / n_wi²`
//! for the radiance BTDF of a refraction (Veach 1997, ch. 5).

mod common;

use common::*;
use polar_bsdf::Bsdf;

/// `M00` of the BSDF itself: `eval / |cos θi|`.
fn f00(bsdf: &Bsdf, wo: &V3, wi: &V3) -> f64 {
    bsdf.eval(wo, wi)[(0, 0)] / wi.z.abs()
}

/// Refractive index of the medium on the side of `w` (inside is `z < 0`).
fn index(bsdf: &Bsdf, w: &V3) -> f64 {
    match bsdf {
        Bsdf::Dielectric(d) if w.z < 0.0 => d.eta,
        _ => 1.0,
    }
}

#[test]
fn intensity_is_reciprocal_for_every_non_delta_bsdf() {
    for (name, bsdf) in smooth_lobed() {
        let mut rng = rng(5);
        let mut nonzero = 0;
        for _ in 0..3000 {
            let (wo, wi) = if two_sided(&bsdf) {
                (sphere(&mut rng), sphere(&mut rng))
            } else {
                (hemisphere(&mut rng), hemisphere(&mut rng))
            };
            let forward = f00(&bsdf, &wo, &wi) / index(&bsdf, &wo).powi(2);
            let backward = f00(&bsdf, &wi, &wo) / index(&bsdf, &wi).powi(2);
            // Relative 1e-7: the two evaluations differ only by rounding, which the
            // refraction Jacobian's denominator `(wi·h + wo·h / η)²` amplifies
            // (observed up to ~2e-9 relative).
            let scale = forward.abs().max(backward.abs());
            assert!(
                (forward - backward).abs() <= 1e-7 * scale,
                "{name}: f(wo, wi) = {forward}, f(wi, wo) = {backward} for wo={wo:?} wi={wi:?}"
            );
            nonzero += usize::from(scale > 0.0);
        }
        assert!(
            nonzero > 1000,
            "{name}: only {nonzero} non-zero pairs tested"
        );
    }
}
