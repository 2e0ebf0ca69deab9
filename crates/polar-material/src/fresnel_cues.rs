//! Wolff's Fresnel cue (Wolff 1990, "Polarization-based material classification from
//! specular reflection"): unpolarized light specularly reflected by a dielectric is
//! strongly polarized near Brewster's angle, by a metal only weakly, because a metal's
//! large extinction coefficient keeps `R_p` close to `R_s`. The DoLP of specular
//! reflection is `(R_s − R_p)/(R_s + R_p)` at the angle of incidence.

use nalgebra::Complex;
use polar_optics::fresnel::fresnel_amplitudes;

/// Complex indices `n + ik` near 550 nm (Palik; Johnson & Christy) of the metals whose
/// specular DoLP envelope defines "metal": gold, silver, aluminium, copper. Iron, chromium,
/// nickel and titanium (`n ≈ 2–3`, `k ≈ 3–3.6`) polarize more near grazing incidence
/// (DoLP up to 0.67 at 80°) and fall outside this envelope there.
pub const METAL_INDICES: [(f64, f64); 4] = [(0.43, 2.455), (0.06, 3.586), (1.0, 6.6), (0.9, 2.6)];

/// Zenith sampling of the tabulated curves (degrees per entry, 0..=90).
const STEP_DEG: usize = 2;
const N: usize = 90 / STEP_DEG + 1;

/// DoLP of specular reflection of unpolarized light at incidence `theta` (radians) for a
/// relative index `n + ik`.
pub fn specular_dolp(theta: f64, n: f64, k: f64) -> f64 {
    let f = fresnel_amplitudes(theta.cos(), Complex::new(n, k));
    let (rs, rp) = f.reflectance();
    if rs + rp > 0.0 {
        ((rs - rp) / (rs + rp)).abs()
    } else {
        0.0
    }
}

/// Tabulated Fresnel DoLP envelopes over the zenith angle.
#[derive(Clone, Debug)]
pub struct FresnelTable {
    metal_max: [f32; N],
    dielectric_min: [f32; N],
}

impl FresnelTable {
    /// The envelopes: the largest specular DoLP of [`METAL_INDICES`] at any zenith up to
    /// the tabulated one (a running maximum: the metal curves fall back to 0 at grazing
    /// incidence, where a zenith error of a few degrees would otherwise matter), and the
    /// smallest of dielectrics with `1.3 <= n <= 1.8` at each tabulated zenith.
    pub fn new() -> Self {
        let mut metal_max = [0.0; N];
        let mut dielectric_min = [0.0; N];
        for i in 0..N {
            let t = ((i * STEP_DEG) as f64).to_radians();
            metal_max[i] = METAL_INDICES
                .iter()
                .map(|&(n, k)| specular_dolp(t, n, k))
                .fold(0.0, f64::max) as f32;
            if i > 0 {
                metal_max[i] = metal_max[i].max(metal_max[i - 1]);
            }
            dielectric_min[i] = (0..=10)
                .map(|j| specular_dolp(t, 1.3 + 0.05 * j as f64, 0.0))
                .fold(1.0, f64::min) as f32;
        }
        Self {
            metal_max,
            dielectric_min,
        }
    }

    /// Largest metal specular DoLP at zeniths up to `theta` (radians, linear interpolation).
    pub fn metal_max(&self, theta: f32) -> f32 {
        interp(&self.metal_max, theta)
    }

    /// Smallest dielectric specular DoLP at zenith `theta` (radians).
    pub fn dielectric_min(&self, theta: f32) -> f32 {
        interp(&self.dielectric_min, theta)
    }

    /// The largest metal specular DoLP over all zenith angles.
    pub fn metal_ceiling(&self) -> f32 {
        self.metal_max.iter().copied().fold(0.0, f32::max)
    }
}

impl Default for FresnelTable {
    fn default() -> Self {
        Self::new()
    }
}

fn interp(t: &[f32; N], theta: f32) -> f32 {
    let x = (theta.to_degrees() / STEP_DEG as f32).clamp(0.0, (N - 1) as f32);
    if !x.is_finite() {
        return t[0];
    }
    let i = (x as usize).min(N - 2);
    let f = x - i as f32;
    t[i] * (1.0 - f) + t[i + 1] * f
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brewster_angle_of_glass_is_fully_polarized() {
        // tan θB = 1.5: R_p = 0 exactly, DoLP 1 (to rounding).
        let tb = 1.5f64.atan();
        assert!((specular_dolp(tb, 1.5, 0.0) - 1.0).abs() < 1e-9);
    }

    #[test]
    fn metals_stay_weakly_polarized_where_dielectrics_are_strongly() {
        let t = FresnelTable::new();
        // Gold and aluminium at 45°: Wolff's example, DoLP well under 0.1.
        let t45 = 45f64.to_radians();
        assert!(specular_dolp(t45, 0.4, 2.4) < 0.1);
        assert!(specular_dolp(t45, 1.0, 6.6) < 0.05);
        // Between 40° and 70° every listed dielectric beats every listed metal.
        for deg in [40.0f32, 50.0, 60.0, 70.0] {
            let th = deg.to_radians();
            assert!(t.dielectric_min(th) > t.metal_max(th) + 0.1, "{deg}");
        }
        assert!(t.metal_ceiling() < 0.35 && t.metal_ceiling() > 0.25);
    }

    #[test]
    fn interpolation_handles_bad_angles() {
        let t = FresnelTable::new();
        // NaN and negative zeniths read the normal-incidence entry (DoLP 0, to rounding).
        assert!(t.metal_max(f32::NAN).abs() < 1e-6);
        assert!(t.metal_max(-1.0).abs() < 1e-6);
        assert_eq!(t.metal_max(10.0), t.metal_max(std::f32::consts::FRAC_PI_2));
    }
}
