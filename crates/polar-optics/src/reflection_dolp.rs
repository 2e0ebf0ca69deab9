//! Degree of linear polarization of light reflected by a surface, as a function of the
//! zenith angle `θ` between the surface normal and the viewing direction, and the
//! inverses that shape from polarization needs.
//!
//! - Diffuse (subsurface scattering, depolarized inside, refracted out): Atkinson &
//!   Hancock 2006, "Recovery of surface orientation from diffuse polarization", eq. (3):
//!   `ρ_d = (n − 1/n)² sin²θ / (2 + 2n² − (n + 1/n)² sin²θ + 4 cosθ √(n² − sin²θ))`,
//!   which is `(T_p − T_s)/(T_p + T_s)` of the exit refraction. It rises monotonically
//!   from 0 at `θ = 0` to `(n² − 1)/(n² + 1)` at grazing; its polarization is parallel to
//!   the plane of incidence (AoLP = azimuth of the normal).
//! - Specular (Fresnel reflection): `ρ_s = (R_s − R_p)/(R_s + R_p)` with the intensity
//!   reflectances of [`crate::fresnel`]; for a real index it rises from 0 to 1 at
//!   Brewster's angle `atan n` and falls back to 0 at grazing; polarization is
//!   perpendicular to the plane of incidence (AoLP = azimuth + 90°).
//!
//! Indices are relative (object over the medium the camera is in) and must be `> 1`
//! (finite) for the dielectric functions; otherwise they return NaN.

use num_complex::Complex64;
use std::f64::consts::FRAC_PI_2;

use crate::fresnel::fresnel_amplitudes;

/// `true` for an index the dielectric models accept: finite and `> 1`.
fn valid_index(n: f64) -> bool {
    n.is_finite() && n > 1.0
}

/// Diffuse DoLP at zenith angle `zenith` (radians) for relative index `n > 1`
/// (Atkinson & Hancock 2006, eq. 3). NaN for an invalid index or a NaN angle; the
/// zenith is clamped to `[0, π/2]`.
pub fn diffuse_dolp(zenith: f64, n: f64) -> f64 {
    if !valid_index(n) || zenith.is_nan() {
        return f64::NAN;
    }
    let t = zenith.clamp(0.0, FRAC_PI_2);
    let (s, c) = t.sin_cos();
    let s2 = s * s;
    let a = (n - 1.0 / n).powi(2);
    let b = (n + 1.0 / n).powi(2);
    let den = 2.0 + 2.0 * n * n - b * s2 + 4.0 * c * (n * n - s2).sqrt();
    a * s2 / den
}

/// The largest diffuse DoLP, reached at grazing: `(n² − 1)/(n² + 1)`.
pub fn diffuse_dolp_max(n: f64) -> f64 {
    if !valid_index(n) {
        return f64::NAN;
    }
    (n * n - 1.0) / (n * n + 1.0)
}

/// The zenith angle (radians, in `[0, π/2]`) whose diffuse DoLP is `dolp`, in closed form.
///
/// Derivation: with `s = sin²θ`, `A = (n − 1/n)²`, `B = (n + 1/n)²`, `C = 2 + 2n²`, the
/// model `ρ (C − B s + 4 cosθ √(n² − s)) = A s` isolates the root as
/// `ρC − (ρB + A) s = −4ρ √((1 − s)(n² − s))`; squaring and dividing by `A` (using
/// `(ρB + A)² − 16ρ² = A(1 + ρ)(ρ(B + 4) + A)` and `(n² − 1)² = n²A`) gives the quadratic
/// `(1 + ρ)(ρ(B + 4) + A) s² − 2ρC(1 + ρ) s + 4ρ²n² = 0`. Its larger root
/// `s = (b + √(b² − 4ac))/(2a)` is the one of the unsquared equation (the smaller one
/// belongs to the sign-flipped root term: for small `ρ` the roots are
/// `2ρ(n ± 1)²/A`, and the model's small-angle form is `ρ ≈ A s / (2(n + 1)²)`).
///
/// `dolp <= 0` gives 0; `dolp` at or above [`diffuse_dolp_max`] is clamped to that
/// maximum's zenith, `π/2` (noise pushes DoLP up; grazing is the only consistent
/// answer). NaN for a NaN DoLP or an invalid index.
pub fn diffuse_zenith(dolp: f64, n: f64) -> f64 {
    if !valid_index(n) || dolp.is_nan() {
        return f64::NAN;
    }
    if dolp <= 0.0 {
        return 0.0;
    }
    if dolp >= diffuse_dolp_max(n) {
        return FRAC_PI_2;
    }
    let r = dolp;
    let a = (n - 1.0 / n).powi(2);
    let b = (n + 1.0 / n).powi(2);
    let c = 2.0 + 2.0 * n * n;
    let qa = (1.0 + r) * (r * (b + 4.0) + a);
    let qb = 2.0 * r * c * (1.0 + r);
    let qc = 4.0 * r * r * n * n;
    let disc = (qb * qb - 4.0 * qa * qc).max(0.0);
    let s = (qb + disc.sqrt()) / (2.0 * qa);
    s.clamp(0.0, 1.0).sqrt().asin()
}

/// Specular DoLP `(R_s − R_p)/(R_s + R_p)` for incidence cosine `cos_i` and a complex
/// relative index `eta = n + ik` (conductors included), from [`fresnel_amplitudes`].
/// 0 where `R_s + R_p = 0` (index matching), NaN for undefined inputs.
pub fn specular_dolp_complex(cos_i: f64, eta: Complex64) -> f64 {
    let f = fresnel_amplitudes(cos_i, eta);
    let (rs, rp) = (f.r_s.norm_sqr(), f.r_p.norm_sqr());
    if rs.is_nan() || rp.is_nan() {
        return f64::NAN;
    }
    let sum = rs + rp;
    if sum > 0.0 { (rs - rp) / sum } else { 0.0 }
}

/// Specular DoLP of a dielectric of real relative index `n > 1` at zenith `zenith`
/// (angle of incidence = angle of reflection = zenith). NaN for an invalid index.
pub fn specular_dolp(zenith: f64, n: f64) -> f64 {
    if !valid_index(n) || zenith.is_nan() {
        return f64::NAN;
    }
    let t = zenith.clamp(0.0, FRAC_PI_2);
    specular_dolp_complex(t.cos(), Complex64::new(n, 0.0))
}

/// Brewster's angle `atan n`, where the dielectric specular DoLP is 1.
pub fn brewster_angle(n: f64) -> f64 {
    n.atan()
}

/// The two zenith angles whose dielectric specular DoLP is `dolp`:
/// `(below, above)` Brewster's angle, by bisection on each monotone branch
/// (`[0, θ_B]` rising, `[θ_B, π/2]` falling) to `1e-12` rad.
///
/// `dolp <= 0` gives `(0, π/2)`; `dolp >= 1` (the model maximum) is clamped to
/// `(θ_B, θ_B)`. NaN pair for a NaN DoLP or an invalid index.
pub fn specular_zenith(dolp: f64, n: f64) -> (f64, f64) {
    if !valid_index(n) || dolp.is_nan() {
        return (f64::NAN, f64::NAN);
    }
    let tb = brewster_angle(n);
    if dolp <= 0.0 {
        return (0.0, FRAC_PI_2);
    }
    if dolp >= 1.0 {
        return (tb, tb);
    }
    let f = |t: f64| specular_dolp(t, n) - dolp;
    (bisect(f, 0.0, tb), bisect(f, tb, FRAC_PI_2))
}

/// A root of `f` in `[lo, hi]` where `f(lo)` and `f(hi)` have opposite signs (or one is 0).
fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    let f_lo = f(lo);
    for _ in 0..64 {
        let mid = 0.5 * (lo + hi);
        if hi - lo < 1e-12 {
            break;
        }
        if (f(mid) > 0.0) == (f_lo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_4;

    const INDICES: [f64; 6] = [1.2, 1.33, 1.5, 1.7, 2.0, 2.5];

    #[test]
    fn diffuse_is_zero_at_normal_incidence_and_maximal_at_grazing() {
        for n in INDICES {
            assert_eq!(diffuse_dolp(0.0, n), 0.0);
            let g = diffuse_dolp(FRAC_PI_2, n);
            assert!((g - diffuse_dolp_max(n)).abs() < 1e-12, "{n}: {g}");
        }
        // n = 1.5: (2.25 - 1)/(2.25 + 1).
        assert!((diffuse_dolp_max(1.5) - 1.25 / 3.25).abs() < 1e-15);
    }

    #[test]
    fn diffuse_equals_exit_transmission_contrast() {
        // A&H's formula is (T_p − T_s)/(T_p + T_s) for light leaving the medium (index 1/n)
        // at exterior angle θ; check against the Fresnel code at interior angle θ'.
        for n in INDICES {
            for deg in [5.0, 30.0, 60.0, 85.0_f64] {
                let t = deg.to_radians();
                let sin_in = t.sin() / n;
                let cos_in = (1.0 - sin_in * sin_in).sqrt();
                let f = fresnel_amplitudes(cos_in, Complex64::new(1.0 / n, 0.0));
                let (ts, tp) = (1.0 - f.r_s.norm_sqr(), 1.0 - f.r_p.norm_sqr());
                let expect = (tp - ts) / (tp + ts);
                assert!((diffuse_dolp(t, n) - expect).abs() < 1e-12, "{n} {deg}");
            }
        }
    }

    #[test]
    fn diffuse_zenith_round_trip() {
        for n in INDICES {
            let tb = brewster_angle(n);
            let angles = [
                0.0,
                1e-4,
                0.1,
                tb - 0.05,
                tb,
                tb + 0.05,
                1.4,
                1.55,
                FRAC_PI_2 - 1e-4,
            ];
            for t in angles {
                let back = diffuse_zenith(diffuse_dolp(t, n), n);
                // f64 closed form; near grazing dρ/dθ → small, so a looser bound there.
                let tol = if t > 1.5 { 1e-4 } else { 1e-9 };
                assert!((back - t).abs() < tol, "n {n} θ {t} -> {back}");
            }
        }
    }

    #[test]
    fn diffuse_zenith_clamps_above_the_maximum() {
        assert_eq!(diffuse_zenith(0.9, 1.5), FRAC_PI_2);
        assert_eq!(diffuse_zenith(diffuse_dolp_max(1.5), 1.5), FRAC_PI_2);
        assert_eq!(diffuse_zenith(-0.1, 1.5), 0.0);
        assert!(diffuse_zenith(f64::NAN, 1.5).is_nan());
        assert!(diffuse_zenith(0.1, 1.0).is_nan());
    }

    #[test]
    fn specular_closed_form_and_brewster() {
        // Classic closed form for real n:
        // ρ_s = 2 sin²θ cosθ √(n² − sin²θ) / (n² − sin²θ − n² sin²θ + 2 sin⁴θ).
        for n in INDICES {
            for deg in [1.0, 20.0, 45.0, 70.0, 89.0_f64] {
                let t = deg.to_radians();
                let s2 = t.sin().powi(2);
                let cf = 2.0 * s2 * t.cos() * (n * n - s2).sqrt()
                    / (n * n - s2 - n * n * s2 + 2.0 * s2 * s2);
                assert!((specular_dolp(t, n) - cf).abs() < 1e-12, "{n} {deg}");
            }
            assert!((specular_dolp(brewster_angle(n), n) - 1.0).abs() < 1e-12);
            assert!(specular_dolp(0.0, n).abs() < 1e-15);
            assert!(specular_dolp(FRAC_PI_2, n).abs() < 1e-12);
        }
    }

    #[test]
    fn specular_zenith_round_trip_on_both_branches() {
        for n in INDICES {
            let tb = brewster_angle(n);
            for t in [0.05, 0.3, tb - 0.1, tb - 1e-3] {
                let (lo, hi) = specular_zenith(specular_dolp(t, n), n);
                assert!((lo - t).abs() < 1e-9, "below: n {n} θ {t} -> {lo}");
                assert!(hi > tb && (specular_dolp(hi, n) - specular_dolp(t, n)).abs() < 1e-9);
            }
            for t in [tb + 1e-3, tb + 0.1, 1.4, 1.55] {
                let (_, hi) = specular_zenith(specular_dolp(t, n), n);
                assert!((hi - t).abs() < 1e-8, "above: n {n} θ {t} -> {hi}");
            }
            assert_eq!(specular_zenith(1.2, n), (tb, tb));
            assert_eq!(specular_zenith(0.0, n), (0.0, FRAC_PI_2));
        }
    }

    #[test]
    fn conductor_dolp_is_weaker_than_dielectric_and_zero_at_normal_incidence() {
        let gold = Complex64::new(0.47, 2.4);
        assert!(specular_dolp_complex(1.0, gold).abs() < 1e-12);
        let c45 = FRAC_PI_4.cos();
        let d = specular_dolp_complex(c45, gold);
        assert!(d > 0.0 && d < specular_dolp(FRAC_PI_4, 1.5), "{d}");
        // Real eta through the complex path equals the dielectric function.
        let e = specular_dolp_complex(c45, Complex64::new(1.5, 0.0));
        assert!((e - specular_dolp(FRAC_PI_4, 1.5)).abs() < 1e-15);
        assert_eq!(specular_dolp_complex(0.5, Complex64::new(1.0, 0.0)), 0.0);
    }
}
