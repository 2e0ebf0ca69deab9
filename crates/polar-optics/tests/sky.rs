//! The single-scattering Rayleigh sky: its polarization (DoLP, AoLP), symmetry about the
//! solar meridian, the layer integral against quadrature, and the hard cases (view at the
//! sun's zenith angle, the horizon, below it, toward the sun, bad parameters).

use nalgebra::Vector3;
use polar_optics::frame::basis_angle;
use polar_optics::sky::RayleighSky;
use polar_optics::stokes::{aolp, dolp};
use polar_optics::{OpticsError, Stokes, stokes_basis};
use std::f64::consts::PI;

type V3 = Vector3<f64>;

/// An orthonormal frame `(east, north, up)` for a given zenith: both `z`-up and a `y`-up
/// world (as a renderer's camera may use) are tested.
fn frames() -> [(V3, V3, V3); 2] {
    [(V3::x(), V3::y(), V3::z()), (V3::z(), V3::x(), V3::y())]
}

/// The unit direction at zenith angle `zen` and azimuth `az` (degrees) in a frame.
fn sky_dir((e, n, u): &(V3, V3, V3), zen: f64, az: f64) -> V3 {
    let (z, a) = (zen.to_radians(), az.to_radians());
    (e * a.cos() + n * a.sin()) * z.sin() + u * z.cos()
}

fn sky(frame: &(V3, V3, V3), sun_zen: f64, sun_az: f64, tau: f64) -> RayleighSky {
    RayleighSky::new(sky_dir(frame, sun_zen, sun_az), frame.2, tau, 1361.0).unwrap()
}

/// Stokes of the light that comes from the sky direction `v`.
fn from_dir(s: &RayleighSky, v: &V3) -> Stokes {
    s.radiance(&-v)
}

#[test]
fn dolp_is_sin2_over_1_plus_cos2_of_the_scattering_angle() {
    for frame in frames() {
        let s = sky(&frame, 40.0, 30.0, 0.1);
        for zen in [0.0, 15.0, 40.0, 60.0, 85.0, 89.9] {
            for az in [0.0, 45.0, 100.0, 210.0, 300.0] {
                let v = sky_dir(&frame, zen, az);
                let l = from_dir(&s, &v);
                let c = v.dot(&s.sun_direction);
                let want = (1.0 - c * c) / (1.0 + c * c);
                // Two frame rotations: a few ulps; 1e-12.
                assert!(
                    (dolp(l[0], l[1], l[2]) - want).abs() < 1e-12,
                    "zen {zen} az {az}"
                );
                assert!(l[0] > 0.0 && l[3] == 0.0);
            }
        }
    }
}

#[test]
fn dolp_is_1_at_90_degrees_from_the_sun() {
    let frame = frames()[0];
    let s = sky(&frame, 30.0, 0.0, 0.2);
    // Zenith angle 60° toward azimuth 180° is 90° from the sun.
    let l = from_dir(&s, &sky_dir(&frame, 60.0, 180.0));
    assert!((dolp(l[0], l[1], l[2]) - 1.0).abs() < 1e-12);
}

#[test]
fn aolp_is_perpendicular_to_the_sun_view_plane() {
    for frame in frames() {
        let s = sky(&frame, 55.0, -20.0, 0.3);
        for zen in [10.0, 35.0, 70.0, 88.0] {
            for az in [5.0, 90.0, 160.0, 250.0] {
                let v = sky_dir(&frame, zen, az);
                let k = -v;
                let l = s.radiance(&k);
                // The E-field vibrates along the normal of the plane holding sun, view and observer.
                let normal = s.sun_direction.cross(&v).normalize();
                let want = basis_angle(&k, &stokes_basis(&k), &normal).rem_euclid(PI);
                let got = aolp(l[0], l[1], l[2]);
                let gap = (got - want).rem_euclid(PI);
                // 1e-9 rad: AoLP = ½ atan2 of well-conditioned components (DoLP ≥ 0.02 here).
                assert!(
                    gap.min(PI - gap) < 1e-9,
                    "zen {zen} az {az}: {got} vs {want}"
                );
            }
        }
    }
}

#[test]
fn symmetric_about_the_solar_meridian() {
    for frame in frames() {
        let s = sky(&frame, 50.0, 0.0, 0.25);
        for zen in [20.0, 50.0, 80.0] {
            for az in [30.0, 90.0, 170.0] {
                let (a, b) = (
                    from_dir(&s, &sky_dir(&frame, zen, az)),
                    from_dir(&s, &sky_dir(&frame, zen, -az)),
                );
                // Mirror images: same intensity and DoLP (the AoLPs mirror).
                assert!((a[0] - b[0]).abs() <= 1e-12 * a[0], "zen {zen} az {az}");
                assert!((dolp(a[0], a[1], a[2]) - dolp(b[0], b[1], b[2])).abs() < 1e-12);
            }
        }
    }
}

/// `∫₀^τ e^{−(τ−t)/μ0} e^{−t/μ} dt/μ` by composite Simpson (1e5 intervals: relative error
/// `~(h/μ)⁴/180`, below 1e-13 even for τ = 3 at zenith angle 89°).
fn layer_integral(tau: f64, mu: f64, mu0: f64) -> f64 {
    let n = 100_000;
    let h = tau / n as f64;
    let f = |t: f64| (-(tau - t) / mu0 - t / mu).exp() / mu;
    let inner: f64 = (1..n)
        .map(|i| if i % 2 == 1 { 4.0 } else { 2.0 } * f(i as f64 * h))
        .sum();
    (f(0.0) + inner + f(tau)) * h / 3.0
}

#[test]
fn radiance_is_the_layer_integral_of_single_scattering() {
    let frame = frames()[0];
    for (sun_zen, tau) in [(30.0, 0.1), (60.0, 1.0), (80.0, 3.0)] {
        let s = sky(&frame, sun_zen, 0.0, tau);
        let mu0 = sun_zen.to_radians().cos();
        for zen in [0.0, 25.0, 59.0, 75.0, 89.0] {
            let v = sky_dir(&frame, zen, 120.0);
            let mu = zen.to_radians().cos();
            let c = v.dot(&s.sun_direction);
            let phase = 3.0 / (16.0 * PI) * (1.0 + c * c);
            let want = 1361.0 * phase * layer_integral(tau, mu, mu0);
            let got = from_dir(&s, &v)[0];
            assert!(
                (got - want).abs() <= 1e-10 * want,
                "τ {tau} sun {sun_zen} zen {zen}: {got} vs {want}"
            );
            // The closed form of the brief, away from μ = μ0.
            if (mu - mu0).abs() > 1e-3 {
                let closed =
                    1361.0 * phase * mu0 / (mu0 - mu) * ((-tau / mu0).exp() - (-tau / mu).exp());
                assert!((got - closed).abs() <= 1e-12 * closed);
            }
        }
    }
}

#[test]
fn view_at_the_sun_zenith_angle_is_finite_and_continuous() {
    let frame = frames()[0];
    let (tau, sun_zen) = (0.4, 48.0);
    let s = sky(&frame, sun_zen, 0.0, tau);
    let mu0 = s.sun_cosine();
    let v = sky_dir(&frame, sun_zen, 140.0);
    let l = from_dir(&s, &v);
    let c = v.dot(&s.sun_direction);
    // L'Hôpital: E p (τ/μ0) e^{−τ/μ0}; same zenith angle up to rounding of μ (1e-12).
    let want = 1361.0 * 3.0 / (16.0 * PI) * (1.0 + c * c) * tau / mu0 * (-tau / mu0).exp();
    assert!((l[0] - want).abs() <= 1e-12 * want, "{} vs {want}", l[0]);
    for d in [1e-12, 1e-9, 1e-6] {
        for zen in [sun_zen - d, sun_zen + d] {
            let near = from_dir(&s, &sky_dir(&frame, zen, 140.0))[0];
            // d degrees away: the relative slope of L is O(1) per radian, i.e. ≤ 0.1 per degree.
            assert!(
                (near - l[0]).abs() <= (0.1 * d + 1e-13) * l[0],
                "d {d}: {near}"
            );
        }
    }
}

#[test]
fn horizon_is_finite_and_below_it_is_dark() {
    let frame = frames()[0];
    let s = sky(&frame, 35.0, 0.0, 0.5);
    let mu0 = s.sun_cosine();
    // Exactly horizontal (sky_dir(90°) keeps cos 90° = 6e-17 above it).
    let v = V3::new(0.5, 0.75f64.sqrt(), 0.0);
    let c = v.dot(&s.sun_direction);
    let limit = 1361.0 * 3.0 / (16.0 * PI) * (1.0 + c * c) * (-0.5 / mu0).exp();
    for eps in [1e-3, 1e-9, 1e-15, 1e-300] {
        let w = (v + frame.2 * eps).normalize();
        let l = from_dir(&s, &w);
        assert!(l.iter().all(|x| x.is_finite()), "eps {eps}");
        // Approaching the horizon L → E p e^{−τ/μ0}, with a relative O(μ/τ) difference.
        assert!(
            (l[0] - limit).abs() <= (2.0 * eps / 0.5 + 1e-12) * limit,
            "eps {eps}: {} vs {limit}",
            l[0]
        );
    }
    assert_eq!(from_dir(&s, &v), Stokes::zeros());
    assert_eq!(from_dir(&s, &sky_dir(&frame, 120.0, 10.0)), Stokes::zeros());
}

#[test]
fn looking_at_the_sun_is_finite_and_unpolarized() {
    let frame = frames()[1];
    let s = sky(&frame, 20.0, 75.0, 0.1);
    let l = s.radiance(&-s.sun_direction);
    assert!(l.iter().all(|x| x.is_finite()));
    assert!(dolp(l[0], l[1], l[2]) < 1e-12);
}

#[test]
fn optically_thin_limit_and_zero_depth() {
    // τ → 0: L ≈ E p τ/μ (one scattering along the slant path), relative O(τ).
    let frame = frames()[0];
    let s = sky(&frame, 30.0, 0.0, 1e-6);
    let v = sky_dir(&frame, 60.0, 90.0);
    let c = v.dot(&s.sun_direction);
    let want = 1361.0 * 3.0 / (16.0 * PI) * (1.0 + c * c) * 1e-6 / 0.5;
    assert!((from_dir(&s, &v)[0] - want).abs() <= 1e-5 * want);
    let clear = sky(&frame, 30.0, 0.0, 0.0);
    assert_eq!(from_dir(&clear, &v), Stokes::zeros());
    assert_eq!(clear.sun_transmittance(), 1.0);
}

#[test]
fn invalid_skies_are_rejected() {
    let up = V3::z();
    let sun = V3::new(0.3, 0.0, 0.9);
    let cases: [(V3, V3, f64, f64, &str); 7] = [
        (V3::new(1.0, 0.0, 0.0), up, 0.1, 1.0, "sun_direction . up"),
        (V3::new(0.2, 0.0, -0.5), up, 0.1, 1.0, "sun_direction . up"),
        (sun, up, -0.1, 1.0, "optical_depth"),
        (sun, up, f64::NAN, 1.0, "optical_depth"),
        (sun, up, f64::INFINITY, 1.0, "optical_depth"),
        (sun, up, 0.1, -2.0, "sun_irradiance"),
        (V3::zeros(), up, 0.1, 1.0, "|sun_direction|"),
    ];
    for (sun, up, tau, e, name) in cases {
        match RayleighSky::new(sun, up, tau, e) {
            Err(OpticsError::OutOfRange { name: got, .. }) => assert_eq!(got, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    // Fields edited after construction are caught by validate.
    let mut s = RayleighSky::new(sun, up, 0.1, 1.0).unwrap();
    s.up = V3::new(0.0, 0.0, 2.0);
    assert!(s.validate().is_err());
}
