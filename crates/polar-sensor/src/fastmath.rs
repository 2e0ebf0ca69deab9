//! DoLP and AoLP of `polar_optics::stokes` in branch-free form, so that row loops
//! vectorise (the library `hypot`/`atan2` calls do not).
//!
//! Same definitions: `DoLP = sqrt((S1/S0)² + (S2/S0)²)`, `AoLP = ½ atan2(S2, S1)` wrapped to
//! `[0, π)`, both NaN where `S0` is not positive or not finite, AoLP 0 where
//! `S1 = S2 = 0`. `atan2` is the Cephes single-precision arctangent (range reduction
//! to `|t| <= tan(π/8)` and a degree-9 odd polynomial, about 1 ulp); tests bound the
//! difference from `polar_optics::stokes::{dolp, aolp}` at 3e-7 rad and 2 ulp.

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// `atan2(y, x)` in `(−π, π]`; signed zeros count as `+0` (so `atan2(±0, ±0) = 0`).
#[inline(always)]
fn atan2(y: f32, x: f32) -> f32 {
    let (ax, ay) = (x.abs(), y.abs());
    let (mn, mx) = (ax.min(ay), ax.max(ay));
    // Range reduction: for t = mn/mx > tan(π/8), atan t = π/4 + atan((mn − mx) / (mn + mx)).
    // One division either way.
    let big = mn > (std::f32::consts::SQRT_2 - 1.0) * mx;
    let (num, den) = if big { (mn - mx, mn + mx) } else { (mn, mx) };
    let u = if mx > 0.0 { num / den } else { 0.0 };
    let z = u * u;
    let p =
        (((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * u
            + u;
    let r = if big { p + FRAC_PI_4 } else { p };
    let r = if ay > ax { FRAC_PI_2 - r } else { r };
    let r = if x < 0.0 { PI - r } else { r };
    if y < 0.0 { -r } else { r }
}

/// `(DoLP, AoLP)` of one pixel; NaN for both where `S0` is not positive or not finite.
#[inline(always)]
pub fn dolp_aolp(s0: f32, s1: f32, s2: f32) -> (f32, f32) {
    let defined = s0 > 0.0 && s0.is_finite();
    // Scaled by S0 before squaring: no overflow for Stokes values near f32::MAX.
    let (u, v) = (s1 / s0, s2 / s0);
    let d = (u * u + v * v).sqrt();
    let a = 0.5 * atan2(s2, s1);
    let a = if a < 0.0 { a + PI } else { a };
    let a = if a >= PI { 0.0 } else { a };
    if defined {
        (d, a)
    } else {
        (f32::NAN, f32::NAN)
    }
}

/// DoLP and AoLP of a row of Stokes values (`#[inline(always)]`: compiled for the
/// SIMD target of the caller's dispatch, see `products`).
#[inline(always)]
pub fn dolp_aolp_row(s0: &[f32], s1: &[f32], s2: &[f32], dolp: &mut [f32], aolp: &mut [f32]) {
    let n = s0.len();
    let (s1, s2, dolp, aolp) = (&s1[..n], &s2[..n], &mut dolp[..n], &mut aolp[..n]);
    for x in 0..n {
        (dolp[x], aolp[x]) = dolp_aolp(s0[x], s1[x], s2[x]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polar_optics::stokes::{aolp, dolp};

    /// Against the reference formulas on a polar grid of (S1, S2), magnitudes 1e-3..1e4,
    /// all four quadrants, axes and diagonals included.
    #[test]
    fn matches_polar_optics_within_tolerance() {
        let mut worst = (0.0f32, 0.0f32);
        for i in 0..=3600 {
            let phi = i as f32 * (2.0 * PI / 3600.0);
            for mag in [1e-3f32, 0.37, 1.0, 255.0, 1e4] {
                let (s1, s2) = (mag * phi.cos(), mag * phi.sin());
                let s0 = 2.0 * mag;
                let (d, a) = dolp_aolp(s0, s1, s2);
                let (dr, ar) = (dolp(s0, s1, s2), aolp(s0, s1, s2));
                let da = (a - ar).abs();
                worst.0 = worst.0.max(da.min(PI - da));
                worst.1 = worst.1.max((d - dr).abs() / dr);
                assert!((0.0..PI).contains(&a), "AoLP {a} out of [0, π)");
            }
        }
        assert!(worst.0 <= 3e-7, "AoLP max error {}", worst.0);
        assert!(
            worst.1 <= 2.0 * f32::EPSILON,
            "DoLP max relative error {}",
            worst.1
        );
    }

    #[test]
    fn special_values() {
        assert_eq!(dolp_aolp(1.0, 0.0, 0.0), (0.0, 0.0));
        assert_eq!(dolp_aolp(1.0, -0.0, -0.0), (0.0, 0.0));
        assert_eq!(dolp_aolp(1.0, -1.0, 0.0).1, FRAC_PI_2);
        assert_eq!(dolp_aolp(1.0, -1.0, -0.0).1, FRAC_PI_2);
        for s0 in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            let (d, a) = dolp_aolp(s0, 0.5, 0.5);
            assert!(d.is_nan() && a.is_nan(), "S0 = {s0}");
        }
    }

    /// Stokes values near `f32::MAX` (a float frame from elsewhere): squaring S1 and S2
    /// before dividing by S0 would overflow to an infinite DoLP.
    #[test]
    fn dolp_near_float_max_does_not_overflow() {
        let (d, a) = dolp_aolp(3e38, -3e38, -3e38);
        assert!((d - std::f32::consts::SQRT_2).abs() < 1e-6, "DoLP {d}");
        assert!((a - 5.0 * PI / 8.0).abs() < 1e-6, "AoLP {a}");
        let (d, _) = dolp_aolp(f32::MAX, f32::MAX, 0.0);
        assert_eq!(d, 1.0);
    }
}
