//! Zenith angles from DoLP for a whole image at one refractive index: the diffuse
//! closed form of [`polar_optics::reflection_dolp::diffuse_zenith`] and a tabulated
//! inverse of the specular model (the bisection of
//! [`polar_optics::reflection_dolp::specular_zenith`] costs ~130 model evaluations per
//! pixel; the table is built once from the same model and held equal to it by a test).
//!
//! Mixed reflection ([`ZenithModels::diffuse_mixed`], [`ZenithModels::specular_mixed`]):
//! a pixel's light is a diffuse part `I_d` (polarized parallel to the plane of incidence,
//! degree `ρ_d(θ)`), a specular part `I_s` (perpendicular, `ρ_s(θ)`) and unpolarized light
//! `I_u` (rough-surface depolarization, interreflections); the two polarized parts
//! share the plane of incidence, so their linear Stokes vectors are anti-parallel and
//! `DoLP = |I_d ρ_d(θ) − I_s ρ_s(θ)| / (I_d + I_s + I_u)` (Taamazyan, Kadambi & Raskar
//! 2016, "Shape from mixed polarization"; Atkinson & Hancock 2006 for `ρ_d`). With the
//! fractions unknown, one DoLP gives no zenith, but it bounds it: the measured DoLP
//! never exceeds the dominant part's model DoLP, `DoLP ≤ ρ_dom(θ)`. The zenith kept is
//! the one in that feasible set closest to a geometric prior (occluding contour,
//! convexity, smoothness); a pure reflection (no dilution) lies on the set's boundary,
//! where the pure models' inverses are.

use polar_optics::reflection_dolp::{
    brewster_angle, diffuse_dolp_max, diffuse_zenith, specular_dolp,
};
use std::f64::consts::FRAC_PI_2;

/// Samples per branch of the specular table.
const TABLE: usize = 2048;

/// The reflection models at one refractive index, inverted.
#[derive(Clone, Debug)]
pub struct ZenithModels {
    /// Relative refractive index.
    pub ior: f64,
    /// Largest diffuse DoLP, `(n² − 1)/(n² + 1)`.
    pub diffuse_max: f64,
    /// Brewster's angle, where the specular DoLP is 1.
    pub brewster: f64,
    /// Specular DoLP at `brewster · i / (TABLE − 1)` (rising branch).
    below: Vec<f64>,
    /// Specular DoLP at `brewster + (π/2 − brewster) · i / (TABLE − 1)` (falling branch).
    above: Vec<f64>,
}

impl ZenithModels {
    /// Tables for index `ior > 1`.
    pub fn new(ior: f64) -> Self {
        let brewster = brewster_angle(ior);
        let grid = |a: f64, b: f64| -> Vec<f64> {
            (0..TABLE)
                .map(|i| specular_dolp(a + (b - a) * i as f64 / (TABLE - 1) as f64, ior))
                .collect()
        };
        Self {
            ior,
            diffuse_max: diffuse_dolp_max(ior),
            brewster,
            below: grid(0.0, brewster),
            above: grid(brewster, FRAC_PI_2),
        }
    }

    /// Diffuse zenith (closed form; DoLP above the model maximum gives π/2).
    pub fn diffuse(&self, dolp: f64) -> f64 {
        diffuse_zenith(dolp, self.ior)
    }

    /// Specular zeniths `(below, above)` Brewster's angle; DoLP ≥ 1 gives Brewster's
    /// angle twice, DoLP ≤ 0 gives `(0, π/2)`.
    pub fn specular(&self, dolp: f64) -> (f64, f64) {
        if dolp.is_nan() {
            return (f64::NAN, f64::NAN);
        }
        let d = dolp.clamp(0.0, 1.0);
        let lo = invert(&self.below, d, 0.0, self.brewster, true);
        let hi = invert(&self.above, d, self.brewster, FRAC_PI_2, false);
        (lo, hi)
    }
}

impl ZenithModels {
    /// Zenith of a diffuse-dominated mixture (module doc): `θ ≥ θ_d(DoLP)` since `ρ_d`
    /// rises monotonically, so `max(prior, θ_d(DoLP))`. DoLP 0 gives the prior, DoLP
    /// at or above the diffuse maximum gives π/2; a NaN DoLP gives the prior and a NaN
    /// prior the pure diffuse zenith.
    pub fn diffuse_mixed(&self, dolp: f64, prior: f64) -> f64 {
        if dolp.is_nan() {
            return prior;
        }
        let bound = self.diffuse(dolp.max(0.0));
        if prior.is_nan() {
            bound
        } else {
            prior.max(bound)
        }
    }

    /// Zenith of a specular-dominated mixture (module doc): `ρ_s(θ) ≥ DoLP` holds on
    /// `[θ₋, θ₊]` between the two pure specular solutions ([`Self::specular`]), so the
    /// prior clamped to it. DoLP 0 gives the prior, DoLP ≥ 1 Brewster's angle; a NaN
    /// DoLP gives the prior and a NaN prior the lower solution.
    pub fn specular_mixed(&self, dolp: f64, prior: f64) -> f64 {
        if dolp.is_nan() {
            return prior;
        }
        let (lo, hi) = self.specular(dolp);
        if prior.is_nan() {
            lo
        } else {
            prior.clamp(lo, hi.max(lo))
        }
    }
}

/// The angle in `[a, b]` where the monotone tabulated function equals `d` (linear
/// interpolation between samples).
fn invert(table: &[f64], d: f64, a: f64, b: f64, rising: bool) -> f64 {
    let n = table.len();
    // Index of the first sample past d along the branch.
    let i = if rising {
        table.partition_point(|&v| v < d)
    } else {
        table.partition_point(|&v| v > d)
    };
    let step = (b - a) / (n - 1) as f64;
    if i == 0 {
        return a;
    }
    if i >= n {
        return b;
    }
    let (v0, v1) = (table[i - 1], table[i]);
    let t = if v1 != v0 { (d - v0) / (v1 - v0) } else { 0.0 };
    a + step * ((i - 1) as f64 + t.clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use polar_optics::reflection_dolp::{diffuse_dolp, specular_zenith};
    use std::f64::consts::FRAC_PI_2;

    /// Zeniths 0..90° in 1° steps (radians).
    fn zeniths() -> impl Iterator<Item = f64> {
        (0..=90).map(|d| f64::from(d).to_radians())
    }

    #[test]
    fn table_matches_bisection() {
        for n in [1.3, 1.5, 1.8, 2.4] {
            let m = ZenithModels::new(n);
            for i in 0..=200 {
                let d = i as f64 / 200.0;
                let (a, b) = m.specular(d);
                let (ea, eb) = specular_zenith(d, n);
                // Linear interpolation on a 2048-sample grid: ~1e-6 rad away from
                // Brewster; near the peak (slope → 0) the inverse itself is ill-posed,
                // 2e-3 rad covers d within 1e-6 of 1.
                let tol = if d > 0.999 { 2e-2 } else { 1e-4 };
                assert!(
                    (a - ea).abs() < tol && (b - eb).abs() < tol,
                    "{n} {d}: {a} {ea} {b} {eb}"
                );
            }
        }
    }

    /// A diluted mixture is feasible at its true zenith: for `DoLP = k ρ(θ)`, any
    /// dilution `k ∈ (0, 1]`, the true zenith as prior comes back unchanged (1e-9 rad:
    /// only clamping, no arithmetic, touches the prior; the table's interpolation error,
    /// 1e-4 rad, can move the bounds across the prior only where `k = 1`, tested apart).
    #[test]
    fn mixed_zenith_keeps_a_feasible_prior() {
        for n in [1.3, 1.5, 2.0] {
            let m = ZenithModels::new(n);
            for t in zeniths() {
                for k in [0.05, 0.3, 0.9] {
                    let d = diffuse_dolp(t, n) * k;
                    assert!((m.diffuse_mixed(d, t) - t).abs() < 1e-9, "{n} {t} {k}");
                    let s = specular_dolp(t, n) * k;
                    assert!((m.specular_mixed(s, t) - t).abs() < 1e-9, "{n} {t} {k}");
                }
            }
        }
    }

    /// An infeasible prior snaps to the nearer pure solution: for an undiluted DoLP the
    /// result is the pure model's inverse (table tolerance 1e-4 rad, see above).
    #[test]
    fn mixed_zenith_projects_an_infeasible_prior_onto_the_pure_solutions() {
        let n = 1.5;
        let m = ZenithModels::new(n);
        for t in [0.2, 0.5, 0.8] {
            let d = diffuse_dolp(t, n);
            assert!((m.diffuse_mixed(d, 0.0) - t).abs() < 1e-6, "diffuse {t}");
            assert!((m.diffuse_mixed(d, FRAC_PI_2) - FRAC_PI_2).abs() < 1e-12);
            let (lo, hi) = specular_zenith(specular_dolp(t, n), n);
            let s = specular_dolp(t, n);
            assert!((m.specular_mixed(s, 0.0) - lo).abs() < 1e-4, "below {t}");
            assert!(
                (m.specular_mixed(s, FRAC_PI_2) - hi).abs() < 1e-4,
                "above {t}"
            );
        }
    }

    /// DoLP 0 (a plane facing the camera, or cancelling parts) bounds nothing: the prior
    /// is kept exactly by both models.
    #[test]
    fn mixed_zenith_dolp_zero_keeps_the_prior() {
        let m = ZenithModels::new(1.5);
        for t in zeniths() {
            assert_eq!(m.diffuse_mixed(0.0, t), t);
            assert_eq!(m.specular_mixed(0.0, t), t);
        }
    }

    /// DoLP above a model's maximum: only grazing explains it diffusely, only Brewster's
    /// angle specularly (DoLP ≥ 1 arises from noise); table tolerance near the peak 2e-2
    /// rad as in `table_matches_bisection`.
    #[test]
    fn mixed_zenith_dolp_above_the_model_maximum() {
        let m = ZenithModels::new(1.5);
        for prior in [0.0, 0.7, FRAC_PI_2] {
            assert_eq!(m.diffuse_mixed(m.diffuse_max + 0.1, prior), FRAC_PI_2);
            for d in [1.0, 1.3] {
                let z = m.specular_mixed(d, prior);
                assert!((z - m.brewster).abs() < 2e-2, "{prior} {d}: {z}");
            }
        }
    }

    /// Undefined inputs give a finite zenith: a NaN DoLP (dark pixel) keeps the prior, a
    /// NaN prior gives the pure diffuse / lower specular solution.
    #[test]
    fn mixed_zenith_nan_inputs() {
        let m = ZenithModels::new(1.5);
        assert_eq!(m.diffuse_mixed(f64::NAN, 0.4), 0.4);
        assert_eq!(m.specular_mixed(f64::NAN, 0.4), 0.4);
        assert!((m.diffuse_mixed(0.1, f64::NAN) - m.diffuse(0.1)).abs() < 1e-12);
        assert!((m.specular_mixed(0.1, f64::NAN) - m.specular(0.1).0).abs() < 1e-12);
    }
}
