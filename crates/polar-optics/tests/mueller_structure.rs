//! Validity checks, the Lu–Chipman decomposition, the 3×3 linear form and the
//! block-diagonal fast path.

use approx::assert_abs_diff_eq;
use nalgebra::{Matrix2, Vector4};
use num_complex::Complex64;
use polar_optics::mueller::{
    absorber, couples_circular, depolarizer, from_jones, linear_part, linear_polarizer,
    linear_rotator, partial_polarizer, retarder, rotator,
};
use polar_optics::stokes::{from_linear, linear, to_linear};
use polar_optics::validity::{coherency_eigenvalues, is_passive, is_realizable, max_transmittance};
use polar_optics::{BlockDiagonal, Mueller, OpticsError, Stokes, fresnel_amplitudes, lu_chipman};

/// Results of a few 4×4 products, inverses and a 3×3 symmetric eigen-solve: 1e-10
/// absolute leaves a wide margin over rounding (~1e-15) for well-conditioned inputs.
const EPS: f64 = 1e-10;

#[test]
fn passivity_uses_the_best_input() {
    // Partial polarizer at 30 degrees, t_max 0.9: best input is light along its axis, output 0.9.
    let m = partial_polarizer(0.5, 0.9, 50.0).unwrap();
    assert_abs_diff_eq!(max_transmittance(&m), 0.9, epsilon = 1e-12);
    assert!(is_passive(&m, 1e-12));
    assert!(!is_passive(&(m * 1.2), 1e-12));
    // An ideal polarizer: m00 = 0.5 but 1.0 for the aligned input.
    assert_abs_diff_eq!(
        max_transmittance(&linear_polarizer(0.2)),
        1.0,
        epsilon = 1e-12
    );
    assert!(!is_passive(&(Mueller::identity() * f64::NAN), 1e-12));
}

#[test]
fn cloude_eigenvalues_of_known_elements() {
    // Jones elements: rank one, eigenvalues (m00, 0, 0, 0).
    for m in [
        linear_polarizer(0.3),
        retarder(1.2, 0.4),
        rotator(0.7),
        fresnel_amplitudes(0.4, Complex64::new(0.2, 3.3)).reflection_mueller(),
    ] {
        let ev = coherency_eigenvalues(&m);
        assert_abs_diff_eq!(ev, Vector4::new(m[(0, 0)], 0.0, 0.0, 0.0), epsilon = EPS);
        assert!(is_realizable(&m, 1e-9));
    }
    // Ideal depolarizer: four equal eigenvalues 1/4.
    let ev = coherency_eigenvalues(&depolarizer(0.0, 0.0).unwrap());
    assert_abs_diff_eq!(ev, Vector4::repeat(0.25), epsilon = EPS);
    // diag(1, a, a, c): (1+2a+c)/4, (1-c)/4, (1-c)/4, (1-2a+c)/4.
    let (a, c) = (0.6, 0.3);
    let ev = coherency_eigenvalues(&depolarizer(a, c).unwrap());
    let expected = [
        (1.0 + 2.0 * a + c) / 4.0,
        (1.0 - c) / 4.0,
        (1.0 - c) / 4.0,
        (1.0 - 2.0 * a + c) / 4.0,
    ];
    assert_abs_diff_eq!(ev, Vector4::from(expected), epsilon = EPS);
    // Not realizable: S3 sign flip (a mirror image of the field, no linear optics does it)
    // and diag(1,1,1,0), which the depolarizer constructor therefore rejects.
    assert!(!is_realizable(
        &Mueller::from_diagonal(&Vector4::new(1.0, 1.0, 1.0, -1.0)),
        1e-9
    ));
    assert!(!is_realizable(
        &Mueller::from_diagonal(&Vector4::new(1.0, 1.0, 1.0, 0.0)),
        1e-9
    ));
    assert!(matches!(
        depolarizer(1.0, 0.0),
        Err(OpticsError::OutOfRange {
            name: "linear_kept",
            ..
        })
    ));
    // Passive yet not realizable, and realizable yet not passive: the two checks differ.
    assert!(is_passive(
        &Mueller::from_diagonal(&Vector4::new(1.0, 1.0, 1.0, -1.0)),
        1e-12
    ));
    assert!(
        is_realizable(&(Mueller::identity() * 2.0), 1e-9)
            && !is_passive(&(Mueller::identity() * 2.0), 1e-9)
    );
}

#[test]
fn from_jones_agrees_with_rotated_diagonal_forms() {
    // A retarder's Jones matrix rotated by theta: R(-t) diag(1, e^{i d}) R(t) with the
    // Jones rotation R(t) = [[c, s], [-s, c]] (frame rotation, as the Mueller rotator).
    let (d, t) = (0.8_f64, 0.35_f64);
    let (s, c) = t.sin_cos();
    let r = |s: f64| Matrix2::new(c, s, -s, c).map(|v| Complex64::new(v, 0.0));
    let diag = Matrix2::new(
        Complex64::new(1.0, 0.0),
        Complex64::new(0.0, 0.0),
        Complex64::new(0.0, 0.0),
        Complex64::from_polar(1.0, d),
    );
    let j = r(-s) * diag * r(s);
    assert_abs_diff_eq!(from_jones(&j), retarder(d, t), epsilon = EPS);
}

#[test]
fn lu_chipman_recovers_known_factors() {
    let m_delta = depolarizer(0.7, 0.5).unwrap();
    let m_r = retarder(0.9, 0.35);
    let m_d = partial_polarizer(0.6, 0.9, 9.0).unwrap(); // q = 0.9, r = 0.1: D = 0.8, T_u = 0.5
    let m = m_delta * m_r * m_d;
    let lc = lu_chipman(&m).unwrap();
    assert_abs_diff_eq!(lc.product(), m, epsilon = EPS);
    assert_abs_diff_eq!(lc.diattenuator, m_d, epsilon = EPS);
    assert_abs_diff_eq!(lc.retarder, m_r, epsilon = EPS);
    assert_abs_diff_eq!(lc.depolarizer, m_delta, epsilon = EPS);
    assert_abs_diff_eq!(lc.diattenuation(), 0.8, epsilon = EPS);
    assert_abs_diff_eq!(lc.retardance(), 0.9, epsilon = EPS);
    assert_abs_diff_eq!(
        lc.depolarization_power(),
        1.0 - (0.7 + 0.7 + 0.5) / 3.0,
        epsilon = EPS
    );
}

#[test]
fn lu_chipman_round_trip_general_matrix() {
    // A realizable depolarizing matrix with polarizance: convex sum of Jones elements,
    // times a metal reflection and rotations.
    let metal = fresnel_amplitudes(0.5, Complex64::new(0.2, 3.3)).reflection_mueller();
    let m = (retarder(2.0, 0.2) * partial_polarizer(1.1, 0.8, 4.0).unwrap() * 0.6
        + rotator(0.4) * metal * 0.4)
        * absorber(0.9).unwrap();
    assert!(is_realizable(&m, 1e-9) && is_passive(&m, 1e-12));
    let lc = lu_chipman(&m).unwrap();
    assert_abs_diff_eq!(lc.product(), m, epsilon = EPS);
    // Factors have their defining structure: M_R orthogonal with det 1, m_Delta symmetric.
    let r3 = lc.retarder.fixed_view::<3, 3>(1, 1).into_owned();
    assert_abs_diff_eq!(
        r3 * r3.transpose(),
        nalgebra::Matrix3::identity(),
        epsilon = EPS
    );
    assert_abs_diff_eq!(r3.determinant(), 1.0, epsilon = EPS);
    let d3 = lc.depolarizer.fixed_view::<3, 3>(1, 1).into_owned();
    assert_abs_diff_eq!(d3, d3.transpose(), epsilon = EPS);
}

#[test]
fn lu_chipman_rejects_singular_and_bad_input() {
    assert!(matches!(
        lu_chipman(&linear_polarizer(0.3)),
        Err(OpticsError::Singular { .. })
    ));
    assert!(matches!(
        lu_chipman(&depolarizer(0.0, 0.0).unwrap()),
        Err(OpticsError::Singular { .. })
    ));
    assert!(matches!(
        lu_chipman(&Mueller::zeros()),
        Err(OpticsError::OutOfRange { name: "m00", .. })
    ));
    let mut nan = Mueller::identity();
    nan[(2, 1)] = f64::NAN;
    assert!(matches!(
        lu_chipman(&nan),
        Err(OpticsError::NonFinite { .. })
    ));
}

#[test]
fn linear_form_matches_full_form_without_circular_coupling() {
    let chain = rotator(0.3)
        * partial_polarizer(0.2, 0.9, 20.0).unwrap()
        * fresnel_amplitudes(0.6, Complex64::new(1.5, 0.0)).reflection_mueller()
        * depolarizer(0.5, 0.5).unwrap();
    assert!(!couples_circular(&chain, 1e-15));
    let s = linear(1.0, 0.8) * 0.5 + Stokes::new(0.5, 0.0, 0.0, 0.0);
    let lin = linear_part(&rotator(0.3))
        * linear_part(&partial_polarizer(0.2, 0.9, 20.0).unwrap())
        * linear_part(&fresnel_amplitudes(0.6, Complex64::new(1.5, 0.0)).reflection_mueller())
        * linear_part(&depolarizer(0.5, 0.5).unwrap());
    assert_abs_diff_eq!(
        from_linear(&(lin * to_linear(&s))),
        chain * s,
        epsilon = 1e-14
    );
    assert_abs_diff_eq!(
        linear_rotator(0.3),
        linear_part(&rotator(0.3)),
        epsilon = 0.0
    );
    // A retarder and a metal reflection do couple S3: the 3x3 form would be wrong.
    assert!(couples_circular(&retarder(0.5, 0.2), 1e-12));
}

#[test]
fn block_diagonal_fast_path_equals_full_products() {
    let f = fresnel_amplitudes(0.6, Complex64::new(0.2, 3.3));
    let b1 = f.reflection_block();
    let b2 = fresnel_amplitudes(0.3, Complex64::new(1.5, 0.0)).transmission_block();
    let (m1, m2) = (b1.to_mueller(), b2.to_mueller());
    assert_eq!(m1, f.reflection_mueller());
    let general = rotator(0.3) * m1 * retarder(0.4, 0.9);
    let s = Stokes::new(1.0, 0.3, -0.2, 0.1);
    // Same operations in a different order: agree to rounding.
    assert_abs_diff_eq!((b1 * b2).to_mueller(), m1 * m2, epsilon = 1e-15);
    assert_abs_diff_eq!(b1 * s, m1 * s, epsilon = 1e-15);
    assert_abs_diff_eq!(b1 * general, m1 * general, epsilon = 1e-15);
    assert_abs_diff_eq!(general * b1, general * m1, epsilon = 1e-15);
    assert_eq!(BlockDiagonal::identity().to_mueller(), Mueller::identity());
    // Detection: block-diagonal forms are found, rotated elements are not.
    assert_eq!(BlockDiagonal::from_mueller(&m1, 0.0), Some(b1));
    assert!(BlockDiagonal::from_mueller(&depolarizer(0.5, 0.2).unwrap(), 0.0).is_some());
    assert!(BlockDiagonal::from_mueller(&linear_polarizer(0.3), 1e-12).is_none());
}

#[test]
fn rotated_block_equals_rotated_rows_and_columns() {
    use polar_optics::frame::{rotate_columns, rotate_rows};
    // A conductor's reflection (every block entry non-zero) between two rotations,
    // one of them past 90° (negative cos 2θ); the written-out form makes the same
    // products minus those with zeros, so the results are equal, not just close.
    let b = fresnel_amplitudes(0.6, Complex64::new(0.2, 3.3)).reflection_block();
    for (out, inp) in [(0.4_f64, -1.1_f64), (2.0, 0.3), (0.0, 0.0)] {
        let (out, inp) = ((2.0 * out).sin_cos(), (2.0 * inp).sin_cos());
        let (out, inp) = ((out.1, out.0), (inp.1, inp.0));
        let expected = rotate_columns(&rotate_rows(&b.to_mueller(), out), inp);
        assert_eq!((b.rotated(out, inp) - expected).amax(), 0.0);
    }
}
