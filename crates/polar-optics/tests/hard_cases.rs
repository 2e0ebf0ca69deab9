//! Hard cases: exact and limiting angles, limiting indices, zero and non-finite inputs.
//!
//! Documented behaviour: where a quantity is defined the result is finite (no NaN);
//! where it is undefined (S0 = 0, NaN or infinite angle, NaN index) it is NaN or an error.

use approx::assert_abs_diff_eq;
use num_complex::Complex64;
use polar_optics::fresnel::{FresnelAmplitudes, fresnel_amplitudes};
use polar_optics::stokes::{self, LinearStokesFit, linear_stokes_least_squares};
use polar_optics::{OpticsError, Stokes};
use std::f64::consts::FRAC_PI_2;

fn real(n: f64) -> Complex64 {
    Complex64::new(n, 0.0)
}

fn all_finite(f: &FresnelAmplitudes) -> bool {
    [f.r_s, f.r_p, f.t_s, f.t_p].iter().all(|z| z.is_finite())
        && f.reflection_mueller().iter().all(|v| v.is_finite())
        && f.transmission_mueller().iter().all(|v| v.is_finite())
}

const INDICES: [(f64, f64); 6] = [
    (1.5, 0.0),
    (1.0 / 1.5, 0.0),
    (0.2, 3.3),
    (1.37, 7.6),
    (4.0, 0.0),
    (0.25, 0.0),
];

#[test]
fn fresnel_theta_exactly_0() {
    for (n, k) in INDICES {
        let f = fresnel_amplitudes(1.0, Complex64::new(n, k));
        assert!(all_finite(&f));
        let r0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let (rs, rp) = f.reflectance();
        // Closed form in a few operations: 1e-14.
        assert_abs_diff_eq!(rs, r0, epsilon = 1e-14);
        assert_abs_diff_eq!(rp, r0, epsilon = 1e-14);
        // Isotropic at normal incidence: r_p = -r_s in these frames, no diattenuation.
        assert_abs_diff_eq!((f.r_p + f.r_s).norm(), 0.0, epsilon = 1e-14);
    }
}

#[test]
fn fresnel_grazing_theta_to_90_gives_r_1() {
    for (n, k) in INDICES {
        let eta = Complex64::new(n, k);
        let f = fresnel_amplitudes(0.0, eta);
        assert!(all_finite(&f));
        assert_eq!(f.reflectance(), (1.0, 1.0));
        assert_eq!(f.transmittance(), (0.0, 0.0));
        // Approaching grazing, R -> 1 continuously (R_s deficit ~ 4 cos t Re(1/w), linear in cos t).
        let (rs, rp) = fresnel_amplitudes(1e-9, eta).reflectance();
        assert!(
            (1.0 - rs) < 1e-7 && (1.0 - rp) < 1e-7,
            "{n}+{k}i: {rs} {rp}"
        );
        // Slightly negative cosines (rounding from a dot product) clamp to grazing.
        assert_eq!(fresnel_amplitudes(-1e-17, eta).reflectance(), (1.0, 1.0));
    }
}

#[test]
fn fresnel_index_matched_n_1() {
    for cos_i in [1.0, 0.5, 1e-6, 0.0] {
        let f = fresnel_amplitudes(cos_i, real(1.0));
        assert_eq!(f.reflectance(), (0.0, 0.0));
        assert!(all_finite(&f));
        let t = f.transmission_mueller();
        let expected = if cos_i > 0.0 {
            polar_optics::Mueller::identity()
        } else {
            polar_optics::Mueller::zeros()
        };
        // Grazing light carries no flux across the interface.
        assert_abs_diff_eq!(t, expected, epsilon = 1e-15);
    }
    // Nearly matched: r_s ~ (1 - eta^2)/(4 cos^2 t) ~ 1e-9, so R ~ 1e-18, continuous with
    // the exact case; the bound leaves a factor 10.
    let (rs, rp) = fresnel_amplitudes(0.7, real(1.0 + 1e-9)).reflectance();
    assert!(rs < 1e-17 && rp < 1e-17, "{rs} {rp}");
}

#[test]
fn fresnel_k_to_0_matches_dielectric() {
    for cos_i in [1.0, 0.8, 0.3, 0.01] {
        let d = fresnel_amplitudes(cos_i, real(1.5));
        let m = fresnel_amplitudes(cos_i, Complex64::new(1.5, 1e-12));
        // First order in k: differences of order 1e-12.
        assert_abs_diff_eq!((d.r_s - m.r_s).norm(), 0.0, epsilon = 1e-10);
        assert_abs_diff_eq!((d.r_p - m.r_p).norm(), 0.0, epsilon = 1e-10);
        // Also below the critical angle of n < 1 and inside TIR (branch continuity).
        let d = fresnel_amplitudes(cos_i, real(0.7));
        let m = fresnel_amplitudes(cos_i, Complex64::new(0.7, 1e-12));
        assert_abs_diff_eq!((d.r_s - m.r_s).norm(), 0.0, epsilon = 1e-5);
        assert_abs_diff_eq!((d.r_p - m.r_p).norm(), 0.0, epsilon = 1e-5);
    }
}

#[test]
fn fresnel_k_large_gives_r_1() {
    for cos_i in [1.0, 0.5, 0.0] {
        for k in [1e3, 1e6, 1e100, 1e200, f64::MAX, f64::INFINITY] {
            let f = fresnel_amplitudes(cos_i, Complex64::new(0.5, k));
            assert!(all_finite(&f), "k = {k}");
            let (rs, rp) = f.reflectance();
            // 1 - R ~ 4 n cos t / k^2 for large k.
            assert!(
                (1.0 - rs).abs() < 1e-5 && (1.0 - rp).abs() < 5e-3,
                "k = {k}: {rs} {rp}"
            );
        }
    }
}

#[test]
fn fresnel_critical_angle_plus_minus_1e_6() {
    let n: f64 = 1.0 / 1.5;
    let theta_c = n.asin();
    let below = fresnel_amplitudes((theta_c - 1e-6).cos(), real(n));
    let at = fresnel_amplitudes(theta_c.cos(), real(n));
    let above = fresnel_amplitudes((theta_c + 1e-6).cos(), real(n));
    for f in [&below, &at, &above] {
        assert!(all_finite(f));
        let (rs, rp) = f.reflectance();
        let (ts, tp) = f.transmittance();
        // Energy conservation for a lossless interface, in and out of TIR.
        assert_abs_diff_eq!(rs + ts, 1.0, epsilon = 1e-12);
        assert_abs_diff_eq!(rp + tp, 1.0, epsilon = 1e-12);
    }
    assert_abs_diff_eq!(above.reflectance().0, 1.0, epsilon = 1e-12);
    assert_abs_diff_eq!(above.reflectance().1, 1.0, epsilon = 1e-12);
    // Continuity: R changes like sqrt(delta theta) near theta_c, so ~1e-2 over 1e-6 rad.
    assert!((below.reflectance().0 - above.reflectance().0).abs() < 0.05);
    assert!((below.r_s - above.r_s).norm() < 0.05);
    // R = 1 everywhere beyond.
    for k in 1..100 {
        let theta = theta_c + (FRAC_PI_2 - theta_c) * k as f64 / 100.0;
        let f = fresnel_amplitudes(theta.cos(), real(n));
        assert_abs_diff_eq!(f.reflectance().0, 1.0, epsilon = 1e-12);
        assert_eq!(f.transmittance(), (0.0, 0.0));
    }
}

#[test]
fn fresnel_nan_and_inf_inputs() {
    // Undefined: NaN or infinite angle cosine, NaN index -> NaN amplitudes (documented).
    for cos_i in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let f = fresnel_amplitudes(cos_i, real(1.5));
        assert!(f.r_s.is_nan() && f.r_p.is_nan() && f.t_s.is_nan() && f.t_p.is_nan());
    }
    for eta in [Complex64::new(f64::NAN, 0.0), Complex64::new(1.5, f64::NAN)] {
        assert!(fresnel_amplitudes(0.5, eta).r_s.is_nan());
    }
    // Defined: an infinite index is the perfect conductor, R = 1, T = 0, no NaN.
    for eta in [
        Complex64::new(f64::INFINITY, 0.0),
        Complex64::new(0.0, f64::INFINITY),
    ] {
        let f = fresnel_amplitudes(0.5, eta);
        assert!(all_finite(&f));
        assert_eq!(f.reflectance(), (1.0, 1.0));
        assert_eq!(f.transmittance(), (0.0, 0.0));
    }
}

#[test]
fn stokes_s0_zero_is_nan() {
    // S0 = 0: no light, so DoLP/DoP/DoCP/AoLP/ellipticity are undefined -> NaN.
    assert!(stokes::dolp(0.0f64, 0.0, 0.0).is_nan());
    assert!(stokes::dop(0.0f64, 0.0, 0.0, 0.0).is_nan());
    assert!(stokes::docp(0.0f64, 0.0).is_nan());
    assert!(stokes::aolp(0.0f32, 0.0, 0.0).is_nan());
    assert!(stokes::ellipticity_angle(0.0f64, 0.0, 0.0, 0.0).is_nan());
    // Imax/Imin stay defined (0).
    assert_eq!(stokes::imax(0.0f64, 0.0, 0.0), 0.0);
    assert_eq!(stokes::imin(0.0f64, 0.0, 0.0), 0.0);
    // S0 = 0 with zero polarization is physical (darkness); with nonzero S1 it is not.
    assert!(stokes::is_physical(&Stokes::zeros(), 1e-12));
    assert!(!stokes::is_physical(
        &Stokes::new(0.0, 1e-3, 0.0, 0.0),
        1e-12
    ));
    // Tiny but positive S0 stays defined.
    assert_abs_diff_eq!(stokes::dolp(1e-300, 5e-301, 0.0), 0.5, epsilon = 1e-12);
}

#[test]
fn stokes_nan_and_inf_inputs() {
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        assert!(stokes::dolp(bad, 0.1, 0.1).is_nan());
        assert!(stokes::aolp(bad, 0.1, 0.1).is_nan());
        assert!(stokes::dop(bad, 0.1, 0.1, 0.0).is_nan());
        assert!(!stokes::is_physical(
            &Stokes::new(bad, 0.0, 0.0, 0.0),
            1e-12
        ));
        assert!(!stokes::is_physical(
            &Stokes::new(1.0, bad, 0.0, 0.0),
            1e-12
        ));
    }
    // NaN in S1 with a good S0 propagates (DoLP of an unknown vector is unknown).
    assert!(stokes::dolp(1.0, f64::NAN, 0.0).is_nan());
    // Unpolarized light: DoLP 0, AoLP falls back to 0 (documented), no NaN.
    assert_eq!(stokes::dolp(1.0, 0.0, 0.0), 0.0);
    assert_eq!(stokes::aolp(1.0, 0.0, 0.0), 0.0);
    assert_eq!(stokes::ellipticity_angle(1.0, 0.0, 0.0, 0.0), 0.0);
}

/// Stokes values near the float maximum (an f32 frame from another tool): forming
/// `hypot(S1, S2)` before dividing by S0 overflows to an infinite DoLP.
#[test]
fn stokes_dolp_near_float_max_is_finite() {
    let d = stokes::dolp(3e38f32, -3e38, -3e38);
    assert!((d - std::f32::consts::SQRT_2).abs() < 1e-6, "DoLP {d}");
    assert_eq!(stokes::dolp(f32::MAX, f32::MAX, 0.0), 1.0);
    let p = stokes::dop(f64::MAX, f64::MAX, f64::MAX, f64::MAX);
    assert!((p - 3f64.sqrt()).abs() < 1e-12, "DoP {p}");
}

#[test]
fn least_squares_fewer_than_3_distinct_angles_is_an_error() {
    let e = LinearStokesFit::new(&[0.0, 1.0]).unwrap_err();
    assert_eq!(e, OpticsError::TooFewAngles { distinct: 2 });
    // 0 and 180 degrees are the same polarizer.
    let e = LinearStokesFit::new(&[0.0, FRAC_PI_2, std::f64::consts::PI]).unwrap_err();
    assert_eq!(e, OpticsError::TooFewAngles { distinct: 2 });
    assert!(matches!(
        LinearStokesFit::new(&[0.0, f64::NAN, 1.0, 2.0]),
        Err(OpticsError::NonFinite { index: 1, .. })
    ));
    assert!(matches!(
        linear_stokes_least_squares(&[0.0, 1.0, 2.0], &[1.0, 2.0]),
        Err(OpticsError::LengthMismatch {
            angles: 3,
            intensities: 2
        })
    ));
    // Exactly three distinct angles is enough.
    assert!(LinearStokesFit::new(&[0.0, 1.0, 2.0]).is_ok());
}
