//! Property tests (proptest, 256 random cases each by default).

use approx::assert_abs_diff_eq;
use nalgebra::{Rotation3, Unit, Vector3};
use num_complex::Complex64;
use polar_optics::frame::rotate_stokes_basis;
use polar_optics::mueller::{
    absorber, depolarizer, linear_polarizer, partial_polarizer, retarder, rotator,
};
use polar_optics::stokes::{intensity_through_polarizer, is_physical, linear_stokes_least_squares};
use polar_optics::validity::{is_passive, is_realizable};
use polar_optics::{Mueller, Stokes, fresnel_amplitudes, lu_chipman};
use proptest::prelude::*;
use std::f64::consts::PI;

/// One physical Mueller element of any kind the crate builds.
fn element() -> impl Strategy<Value = Mueller> {
    prop_oneof![
        (-PI..PI).prop_map(rotator),
        (-PI..PI).prop_map(linear_polarizer),
        (-PI..PI, 0.0..=1.0, 1.0..1e4).prop_map(|(t, q, er)| partial_polarizer(t, q, er).unwrap()),
        (-10.0..10.0, -PI..PI).prop_map(|(d, t)| retarder(d, t)),
        (0.0..=1.0, 0.0..=1.0).prop_map(|(c, a)| depolarizer(a * 0.5 * (1.0 + c), c).unwrap()),
        (0.0..=1.0).prop_map(|t| absorber(t).unwrap()),
        (0.0..=1.0, 0.05..4.0, 0.0..10.0).prop_map(|(c, n, k)| {
            fresnel_amplitudes(c, Complex64::new(n, k)).reflection_mueller()
        }),
        (0.0..=1.0, 0.2..4.0).prop_map(|(c, n)| fresnel_amplitudes(c, Complex64::new(n, 0.0)).transmission_mueller()),
    ]
}

/// Physical Stokes vectors: intensity in (0, 10], degree of polarization in [0, 1],
/// any direction on the Poincaré sphere.
fn physical_stokes() -> impl Strategy<Value = Stokes> {
    (1e-3..10.0, 0.0..=1.0, -1.0..=1.0f64, -PI..PI).prop_map(|(s0, p, z, phi)| {
        let r = (1.0 - z * z).sqrt();
        Stokes::new(
            s0,
            s0 * p * r * phi.cos(),
            s0 * p * r * phi.sin(),
            s0 * p * z,
        )
    })
}

proptest! {
    #[test]
    fn product_of_physical_muellers_maps_physical_stokes_to_physical(
        chain in prop::collection::vec(element(), 1..6),
        s in physical_stokes(),
    ) {
        let m = chain.iter().fold(Mueller::identity(), |acc, e| e * acc);
        // Relative 1e-9: a few chained products, each exact to ~1e-15.
        prop_assert!(is_passive(&m, 1e-9), "max transmittance above 1: {m}");
        prop_assert!(is_realizable(&m, 1e-9), "not realizable: {m}");
        let out = m * s;
        prop_assert!(is_physical(&out, 1e-9), "{out} from {s}");
        prop_assert!(out[0] <= s[0] * (1.0 + 1e-9));
    }

    #[test]
    fn rotation_by_phi_then_minus_phi_is_identity(phi in -10.0..10.0f64, s in physical_stokes()) {
        assert_abs_diff_eq!(rotator(-phi) * rotator(phi), Mueller::identity(), epsilon = 1e-14);
        assert_abs_diff_eq!(rotator(-phi) * (rotator(phi) * s), s, epsilon = 1e-13 * s[0].max(1.0));
    }

    #[test]
    fn basis_rotation_there_and_back_is_identity(
        kx in -1.0..1.0f64, ky in -1.0..1.0f64, kz in -1.0..1.0f64, phi in -PI..PI, s in physical_stokes(),
    ) {
        let k = Vector3::new(kx, ky, kz);
        prop_assume!(k.norm() > 1e-3);
        let k = k.normalize();
        let a = polar_optics::stokes_basis(&k);
        let b = Rotation3::from_axis_angle(&Unit::new_unchecked(k), phi) * a;
        let back = rotate_stokes_basis(&k, &b, &a) * (rotate_stokes_basis(&k, &a, &b) * s);
        assert_abs_diff_eq!(back, s, epsilon = 1e-12 * s[0].max(1.0));
    }

    #[test]
    fn fresnel_r_plus_t_is_1_for_lossless_dielectrics(cos_i in 0.0..=1.0f64, n in 0.2..4.0f64) {
        let f = fresnel_amplitudes(cos_i, Complex64::new(n, 0.0));
        let (rs, rp) = f.reflectance();
        let (ts, tp) = f.transmittance();
        // Energy conservation holds exactly in real arithmetic; 1e-12 for rounding.
        prop_assert!((rs + ts - 1.0).abs() < 1e-12, "s: {rs} + {ts}");
        prop_assert!((rp + tp - 1.0).abs() < 1e-12, "p: {rp} + {tp}");
        // The same for the Mueller matrices and any input: intensities add up.
        let sum = f.reflection_mueller() + f.transmission_mueller();
        prop_assert!((sum[(0, 0)] - 1.0).abs() < 1e-12 && sum[(0, 1)].abs() < 1e-12);
    }

    #[test]
    fn least_squares_recovers_linear_stokes(
        s in physical_stokes(),
        angles in prop::collection::vec(0.0..PI, 3..10),
    ) {
        // Keep the three leading angles well apart so the fit is well conditioned.
        let mut angles = angles;
        angles[1] = angles[0] + PI / 3.0;
        angles[2] = angles[0] + 2.0 * PI / 3.0;
        let i: Vec<f64> = angles.iter().map(|&a| intensity_through_polarizer(s[0], s[1], s[2], a)).collect();
        let fit = linear_stokes_least_squares(&angles, &i).unwrap();
        assert_abs_diff_eq!(fit, s.fixed_rows::<3>(0).into_owned(), epsilon = 1e-12 * s[0].max(1.0));
    }

    #[test]
    fn lu_chipman_round_trip(
        d in -PI..PI, t in -PI..PI, p in -PI..PI, q in 0.1..1.0f64, er in 1.0..100.0f64,
        a in 0.05..0.5f64, c in 0.05..1.0f64,
    ) {
        let m = depolarizer(a, c).unwrap() * retarder(d, t) * partial_polarizer(p, q, er).unwrap();
        let lc = lu_chipman(&m).unwrap();
        // Inverses of well-conditioned 4x4 matrices (m_Delta entries >= 0.05): 1e-9.
        assert_abs_diff_eq!(lc.product(), m, epsilon = 1e-9);
        assert_abs_diff_eq!(lc.diattenuation(), (er - 1.0) / (er + 1.0), epsilon = 1e-9);
    }
}
