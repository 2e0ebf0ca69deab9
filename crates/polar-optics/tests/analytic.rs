//! Analytic values every polarization core must reproduce.

use approx::assert_abs_diff_eq;
use nalgebra::{Matrix2, Vector3};
use num_complex::Complex64;
use polar_optics::frame::{basis_angle, rotate_mueller_basis, rotate_stokes_basis, stokes_basis};
use polar_optics::mueller::{
    from_diagonal_jones, from_jones, linear_polarizer, partial_polarizer, retarder,
    rotated_element, rotator,
};
use polar_optics::stokes::{self, linear, linear_stokes_from_quad, linear_stokes_least_squares};
use polar_optics::{Stokes, fresnel_amplitudes};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Closed-form results computed in f64 with a handful of operations: 1e-12 leaves
/// ~4 orders of magnitude above rounding.
const EPS: f64 = 1e-12;

fn real(n: f64) -> Complex64 {
    Complex64::new(n, 0.0)
}

#[test]
fn f0_is_0_04_for_n_1_5() {
    let (rs, rp) = fresnel_amplitudes(1.0, real(1.5)).reflectance();
    // ((1.5 - 1) / (1.5 + 1))^2 = 0.04 exactly in real arithmetic.
    assert_abs_diff_eq!(rs, 0.04, epsilon = EPS);
    assert_abs_diff_eq!(rp, 0.04, epsilon = EPS);
    let m = fresnel_amplitudes(1.0, real(1.5)).reflection_mueller();
    assert_abs_diff_eq!(m[(0, 0)], 0.04, epsilon = EPS);
    // Normal incidence is isotropic: no diattenuation.
    assert_abs_diff_eq!(m[(0, 1)], 0.0, epsilon = EPS);
}

#[test]
fn rp_vanishes_at_brewster() {
    for n in [1.33, 1.5, 2.4] {
        let theta_b = f64::atan(n);
        let f = fresnel_amplitudes(theta_b.cos(), real(n));
        let (rs, rp) = f.reflectance();
        assert!(rp < 1e-28, "R_p = {rp} at Brewster for n = {n}");
        assert!(rs > 0.05, "R_s = {rs} should stay finite");
        // Reflected light is fully s-polarized: Stokes (1, 1, 0, 0) in the s/p frame (x = s).
        let out = f.reflection_mueller() * stokes::unpolarized(1.0);
        assert_abs_diff_eq!(out[1] / out[0], 1.0, epsilon = 1e-12);
    }
}

#[test]
fn malus_law() {
    // Two ideal polarizers at relative angle a: I = I0/2 * cos^2 a, through both
    // the Mueller product and the scalar formula.
    for k in 0..=12 {
        let a = k as f64 * PI / 12.0;
        let out = linear_polarizer(a + 0.3) * linear_polarizer(0.3) * stokes::unpolarized(2.0);
        assert_abs_diff_eq!(out[0], a.cos().powi(2), epsilon = EPS);
        let lin = linear(1.0, 0.3);
        let i = stokes::intensity_through_polarizer(lin[0], lin[1], lin[2], a + 0.3);
        assert_abs_diff_eq!(i, a.cos().powi(2), epsilon = EPS);
    }
}

#[test]
fn quarter_wave_plate_makes_circular() {
    // 45-degree linear light through a QWP with horizontal fast axis: the slow (y)
    // component lags by pi/2, E_y = i E_x, which turns counterclockwise for an observer
    // facing the source: left-handed, S3 = -1 under S3 = I_RCP - I_LCP.
    let out = retarder(FRAC_PI_2, 0.0) * linear(1.0, FRAC_PI_4);
    assert_abs_diff_eq!(out, Stokes::new(1.0, 0.0, 0.0, -1.0), epsilon = EPS);
    // Fast axis vertical (or -45 degree light) gives the opposite hand.
    let out = retarder(FRAC_PI_2, FRAC_PI_2) * linear(1.0, FRAC_PI_4);
    assert_abs_diff_eq!(out[3], 1.0, epsilon = EPS);
    // Same element from the Jones matrix diag(1, i) through both Jones -> Mueller paths.
    let (one, i) = (real(1.0), Complex64::new(0.0, 1.0));
    assert_abs_diff_eq!(
        retarder(FRAC_PI_2, 0.0),
        from_diagonal_jones(one, i),
        epsilon = EPS
    );
    let jones = Matrix2::new(one, real(0.0), real(0.0), i);
    assert_abs_diff_eq!(
        from_jones(&jones),
        from_diagonal_jones(one, i),
        epsilon = EPS
    );
    // Jones check of the handedness: E = (1, i)/sqrt2 has S3 = 2 Im(E_x E_y*) = -1.
    let ex = real(1.0 / 2f64.sqrt());
    let ey = i * ex;
    assert_abs_diff_eq!(2.0 * (ex * ey.conj()).im, -1.0, epsilon = EPS);
    // Half-wave plate at 22.5 degrees rotates 0-degree linear light to 45 degrees.
    let out = retarder(PI, PI / 8.0) * linear(1.0, 0.0);
    assert_abs_diff_eq!(out, linear(1.0, FRAC_PI_4), epsilon = EPS);
}

/// Born & Wolf (§14.2) reflectances of an absorbing medium written with real
/// arithmetic only, independent of the crate's complex formulas:
/// `2p² = sqrt((n²−k²−sin²θ)² + 4n²k²) + (n²−k²−sin²θ)`, `2q²` the same with `−`,
/// `R_s = ((cosθ−p)² + q²)/((cosθ+p)² + q²)`,
/// `R_p = R_s ((p − sinθ tanθ)² + q²)/((p + sinθ tanθ)² + q²)`.
fn born_wolf_reflectance(n: f64, k: f64, theta: f64) -> (f64, f64) {
    let (s, c) = theta.sin_cos();
    let a = n * n - k * k - s * s;
    let root = (a * a + 4.0 * n * n * k * k).sqrt();
    let p = (0.5 * (root + a)).sqrt();
    let q = (0.5 * (root - a)).sqrt();
    let rs = ((c - p).powi(2) + q * q) / ((c + p).powi(2) + q * q);
    let st = s * theta.tan();
    let rp = rs * ((p - st).powi(2) + q * q) / ((p + st).powi(2) + q * q);
    (rs, rp)
}

#[test]
fn metal_reflectance_gold_silver_aluminium() {
    // n, k at 616.8 nm (gold, silver: P. B. Johnson and R. W. Christy, "Optical constants
    // of the noble metals", Phys. Rev. B 6, 4370 (1972), tabulated point 0.6168 um) and
    // at 619.9 nm (aluminium: A. D. Rakic, Appl. Opt. 34, 4755 (1995), tabulated point
    // 0.61993 um), both as listed by refractiveindex.info (database files
    // main/Au/Johnson.yml, main/Ag/Johnson.yml, main/Al/Rakic.yml).
    let metals = [
        ("gold", 0.21, 3.272, 0.93),
        ("silver", 0.06, 4.152, 0.98),
        ("aluminium", 1.3660, 7.4052, 0.91),
    ];
    for (name, n, k, r_expected) in metals {
        let eta = Complex64::new(n, k);
        let r0 = ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
        let (rs, rp) = fresnel_amplitudes(1.0, eta).reflectance();
        assert_abs_diff_eq!(rs, r0, epsilon = EPS);
        assert_abs_diff_eq!(rp, r0, epsilon = EPS);
        // Plausibility against the well-known visible reflectances (two digits).
        assert!((r0 - r_expected).abs() < 0.01, "{name}: R0 = {r0}");
        for deg in [10.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0] {
            let theta = f64::to_radians(deg);
            let (bs, bp) = born_wolf_reflectance(n, k, theta);
            let (rs, rp) = fresnel_amplitudes(theta.cos(), eta).reflectance();
            // Both paths are well conditioned here (|eta| > 3); 1e-12 absolute.
            assert_abs_diff_eq!(rs, bs, epsilon = EPS);
            assert_abs_diff_eq!(rp, bp, epsilon = EPS);
        }
    }
}

#[test]
fn tir_phase_matches_analytic_formula() {
    // Glass to air, n = 1/1.5; Born & Wolf §1.5.4: tan(delta/2) = cos t sqrt(sin^2 t - n^2) / sin^2 t,
    // with delta = arg(r_s) - arg(r_p).
    let n: f64 = 1.0 / 1.5;
    let theta_c = n.asin();
    for k in 1..=20 {
        let theta = theta_c + (FRAC_PI_2 - theta_c) * k as f64 / 20.0;
        let (s, c) = theta.sin_cos();
        let expected = 2.0 * (c * (s * s - n * n).max(0.0).sqrt() / (s * s)).atan();
        let f = fresnel_amplitudes(c, real(n));
        assert_abs_diff_eq!(f.reflection_phase(), expected, epsilon = 1e-12);
        let (rs, rp) = f.reflectance();
        assert_abs_diff_eq!(rs, 1.0, epsilon = 1e-12);
        assert_abs_diff_eq!(rp, 1.0, epsilon = 1e-12);
    }
    // The maximum (Born & Wolf §1.5.4, the Fresnel rhomb): tan(delta_max/2) = (1 - n^2)/(2n)
    // at sin^2 t = 2n^2/(1 + n^2); 45.24 degrees at 51.67 degrees for n = 1/1.5.
    let sin2 = 2.0 * n * n / (1.0 + n * n);
    let f = fresnel_amplitudes((1.0 - sin2).sqrt(), real(n));
    let delta_max = 2.0 * ((1.0 - n * n) / (2.0 * n)).atan();
    assert_abs_diff_eq!(f.reflection_phase(), delta_max, epsilon = 1e-12);
    let near = fresnel_amplitudes((1.0 - sin2).sqrt() + 1e-3, real(n)).reflection_phase();
    assert!(near < delta_max);
}

#[test]
fn basis_rotation_by_45_degrees() {
    // Horizontal light seen from a frame rotated by +45 degrees is at -45 degrees: S2 = -1.
    let out = rotator(FRAC_PI_4) * linear(1.0, 0.0);
    assert_abs_diff_eq!(out, Stokes::new(1.0, 0.0, -1.0, 0.0), epsilon = EPS);
    // The same through the frame helper: light along +z, frame x axis turned from +x to (+x+y)/sqrt2.
    let k = Vector3::z();
    let target = Vector3::new(1.0, 1.0, 0.0).normalize();
    assert_abs_diff_eq!(
        basis_angle(&k, &Vector3::x(), &target),
        FRAC_PI_4,
        epsilon = EPS
    );
    let out = rotate_stokes_basis(&k, &Vector3::x(), &target) * linear(1.0, 0.0);
    assert_abs_diff_eq!(out, Stokes::new(1.0, 0.0, -1.0, 0.0), epsilon = EPS);
    // Circular light is unchanged by any basis rotation.
    let circ = Stokes::new(1.0, 0.0, 0.0, 1.0);
    assert_abs_diff_eq!(rotator(0.7) * circ, circ, epsilon = EPS);
}

#[test]
fn stokes_basis_rotation_round_trip() {
    let k = Vector3::new(0.3, -0.5, 0.8).normalize();
    let a = stokes_basis(&k);
    assert_abs_diff_eq!(a.dot(&k), 0.0, epsilon = EPS);
    let b = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(k), 1.1) * a;
    let s = Stokes::new(1.0, 0.2, -0.5, 0.3);
    let there = rotate_stokes_basis(&k, &a, &b) * s;
    let back = rotate_stokes_basis(&k, &b, &a) * there;
    assert_abs_diff_eq!(back, s, epsilon = EPS);
    // DoP and intensity are frame invariants; AoLP shifts by -1.1 rad.
    assert_abs_diff_eq!(there[1].hypot(there[2]), s[1].hypot(s[2]), epsilon = EPS);
    let shift = stokes::aolp(s[0], s[1], s[2]) - stokes::aolp(there[0], there[1], there[2]);
    assert_abs_diff_eq!(shift.rem_euclid(PI), 1.1, epsilon = 1e-12);
}

#[test]
fn rotate_mueller_basis_consistency() {
    // A polarizer transmitting along lab direction (1,1,0)/sqrt2, for light along +z.
    // Frame A: x = +x (polarizer at 45 degrees). Frame B: x = (1,1,0)/sqrt2 (polarizer at 0).
    let k = Vector3::z();
    let xa = Vector3::x();
    let xb = Vector3::new(1.0, 1.0, 0.0).normalize();
    let in_a = linear(1.0, 0.2) + stokes::unpolarized(0.5);
    let m_b = linear_polarizer(0.0);
    let m_a = rotate_mueller_basis(&m_b, &k, &xb, &xa, &k, &xb, &xa);
    assert_abs_diff_eq!(m_a, linear_polarizer(FRAC_PI_4), epsilon = EPS);
    // Physical output expressed in frame A either way.
    let via_b =
        rotate_stokes_basis(&k, &xb, &xa) * (m_b * (rotate_stokes_basis(&k, &xa, &xb) * in_a));
    assert_abs_diff_eq!(m_a * in_a, via_b, epsilon = EPS);
    // A rotated element equals the element expressed in the rotated frame.
    let ret = retarder(0.9, 0.0);
    let in_frame = rotate_mueller_basis(&ret, &k, &xb, &xa, &k, &xb, &xa);
    assert_abs_diff_eq!(in_frame, rotated_element(&ret, FRAC_PI_4), epsilon = EPS);
}

#[test]
fn partial_polarizer_has_its_extinction_ratio() {
    let m = partial_polarizer(0.4, 0.8, 100.0).unwrap();
    let along = (m * linear(1.0, 0.4))[0];
    let across = (m * linear(1.0, 0.4 + FRAC_PI_2))[0];
    assert_abs_diff_eq!(along, 0.8, epsilon = EPS);
    assert_abs_diff_eq!(along / across, 100.0, epsilon = 1e-9);
    let ideal = partial_polarizer(0.4, 1.0, f64::INFINITY).unwrap();
    assert_abs_diff_eq!(ideal, linear_polarizer(0.4), epsilon = EPS);
    assert!(partial_polarizer(0.0, 1.2, 10.0).is_err());
    assert!(partial_polarizer(0.0, 0.5, 0.5).is_err());
    assert!(partial_polarizer(0.0, f64::NAN, 10.0).is_err());
}

#[test]
fn least_squares_equals_quad_closed_form() {
    let s = linear(1.0, 0.37) * 0.6 + stokes::unpolarized(0.7);
    let angles = [0.0, FRAC_PI_4, FRAC_PI_2, 3.0 * FRAC_PI_4];
    let i: Vec<f64> = angles
        .iter()
        .map(|&a| stokes::intensity_through_polarizer(s[0], s[1], s[2], a))
        .collect();
    // Noisy intensities: the closed form must equal the LS solution for any data.
    let noisy = [i[0] + 0.01, i[1] - 0.02, i[2] + 0.005, i[3] + 0.03];
    let ls = linear_stokes_least_squares(&angles, &noisy).unwrap();
    let quad = linear_stokes_from_quad(noisy[0], noisy[1], noisy[2], noisy[3]);
    assert_abs_diff_eq!(ls, Vector3::from(quad), epsilon = EPS);
    let exact = linear_stokes_least_squares(&angles, &i).unwrap();
    assert_abs_diff_eq!(exact, s.fixed_rows::<3>(0).into_owned(), epsilon = EPS);
}

#[test]
fn least_squares_any_angles_recovers_stokes() {
    let s = Stokes::new(2.0, 0.3, -0.9, 0.0);
    // Irregular angles, including two that coincide modulo 180 degrees.
    let angles = [0.1, 0.9, 2.0, 0.1 + PI, 2.9];
    let i: Vec<f64> = angles
        .iter()
        .map(|&a| stokes::intensity_through_polarizer(s[0], s[1], s[2], a))
        .collect();
    let ls = linear_stokes_least_squares(&angles, &i).unwrap();
    assert_abs_diff_eq!(ls, s.fixed_rows::<3>(0).into_owned(), epsilon = EPS);
}
