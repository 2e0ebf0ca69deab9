//! Zenith angles from DoLP for a whole image at one refractive index: the diffuse
//! closed form of [`polar_optics::reflection_dolp::diffuse_zenith`] and a tabulated
//! inverse of the specular model (the bisection of
//! [`polar_optics::reflection_dolp::specular_zenith`] costs ~130 model evaluations per
//! pixel; the table is built once from the same model and held equal to it by a test).

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
    use polar_optics::reflection_dolp::specular_zenith;

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
}
