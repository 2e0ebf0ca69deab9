//! Analytic scenes: a glass disc over a textured, unpolarized checkerboard, with the
//! DoLP of Fresnel transmission through two interfaces and the AoLP along the azimuth
//! (rotated 90° from the reflection a shiny opaque object would send), and hard cases.

use polar_image::Gray;
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};
use polar_transparency::{ON, TransparencyOptions, detect};

const N: usize = 96;

/// DoLP of unpolarized light transmitted in and out of glass of index `n` at zenith `t`:
/// `(T_p² − T_s²)/(T_p² + T_s²)` with the Fresnel transmittances of one interface.
fn transmitted_dolp(t: f64, n: f64) -> f64 {
    let (c, s) = (t.cos(), t.sin());
    let ct = (1.0 - (s / n).powi(2)).sqrt();
    let rs = ((c - n * ct) / (c + n * ct)).powi(2);
    let rp = ((n * c - ct) / (n * c + ct)).powi(2);
    let (ts, tp) = ((1.0 - rs).powi(2), (1.0 - rp).powi(2));
    (tp - ts) / (tp + ts)
}

/// Glass disc of radius 30 px at the centre: `Some((zenith, azimuth))` inside.
fn disc(x: usize, y: usize) -> Option<(f64, f64)> {
    let (dx, dy) = (x as f64 + 0.5 - 48.0, -(y as f64 + 0.5 - 48.0));
    let r = dx.hypot(dy) / 30.0;
    (r < 1.0).then(|| ((0.98 * r).asin(), dy.atan2(dx)))
}

fn checker(x: usize, y: usize) -> f64 {
    if (x / 12 + y / 12).is_multiple_of(2) {
        0.2
    } else {
        0.8
    }
}

fn observation(f: impl Fn(usize, usize) -> (f64, f64, f64)) -> Observation {
    let mut p = StokesPlanes::new(N, N);
    for y in 0..N {
        for x in 0..N {
            let k = y * N + x;
            let (s0, d, a) = f(x, y);
            p.s0.as_mut_slice()[k] = s0 as f32;
            p.s1.as_mut_slice()[k] = (s0 * d * (2.0 * a).cos()) as f32;
            p.s2.as_mut_slice()[k] = (s0 * d * (2.0 * a).sin()) as f32;
        }
    }
    Observation::new(
        StokesPlanes::from_linear_stokes(&p.linear_stokes()),
        CameraModel::Orthographic,
    )
}

fn glass_scene() -> Observation {
    observation(|x, y| match disc(x, y) {
        Some((ze, az)) => (0.9 * checker(x, y), transmitted_dolp(ze, 1.5), az),
        None => (checker(x, y), 0.0, 0.0),
    })
}

fn iou_with_disc(mask: &Gray<u8>) -> f64 {
    let (mut inter, mut union) = (0, 0);
    for y in 0..N {
        for x in 0..N {
            let (p, t) = (mask.as_slice()[y * N + x] == ON, disc(x, y).is_some());
            inter += usize::from(p && t);
            union += usize::from(p || t);
        }
    }
    inter as f64 / union as f64
}

/// The transmitted DoLP vanishes at the disc's centre (normal incidence) and is largest
/// at its rim; hole filling recovers the centre. IoU 0.85: the mask may lose or gain a
/// rim of about two pixels (the window and the morphology) on a 30-pixel radius.
#[test]
fn glass_disc_over_checkerboard_is_found() {
    let out = detect(&glass_scene(), &TransparencyOptions::default()).unwrap();
    let iou = iou_with_disc(&out.mask);
    assert!(iou > 0.85, "IoU {iou}");
    assert!(out.score.as_slice().iter().all(|s| (0.0..=1.0).contains(s)));
}

/// A textured, depolarizing scene has no transparent object: the floored Otsu threshold
/// must not split its noise-free score in two.
#[test]
fn unpolarized_checkerboard_has_no_glass() {
    let obs = observation(|x, y| (checker(x, y), 0.0, 0.0));
    let out = detect(&obs, &TransparencyOptions::default()).unwrap();
    assert!(out.mask.as_slice().iter().all(|&v| v == 0));
}

#[test]
fn scale_invariance_times_37() {
    let obs = glass_scene();
    let mut s = obs.planes.linear_stokes();
    s.as_mut_slice().iter_mut().for_each(|v| *v *= 37.0);
    let obs37 = Observation::new(
        StokesPlanes::from_linear_stokes(&s),
        CameraModel::Orthographic,
    );
    let (a, b) = (
        detect(&obs, &TransparencyOptions::default()).unwrap(),
        detect(&obs37, &TransparencyOptions::default()).unwrap(),
    );
    assert_eq!(a.mask, b.mask);
    for (x, y) in a.score.as_slice().iter().zip(b.score.as_slice()) {
        assert!((x - y).abs() < 1e-5, "{x} {y}");
    }
}

#[test]
fn explicit_threshold_is_used_and_checked() {
    let obs = glass_scene();
    // Threshold 0: every pixel with any coherent polarization, i.e. the whole disc.
    let low = detect(
        &obs,
        &TransparencyOptions {
            threshold: Some(0.0),
        },
    )
    .unwrap();
    let none = detect(
        &obs,
        &TransparencyOptions {
            threshold: Some(1.0),
        },
    )
    .unwrap();
    assert!(iou_with_disc(&low.mask) > 0.85);
    assert!(none.mask.as_slice().iter().all(|&v| v == 0));
    for bad in [-0.1, 1.5, f32::NAN] {
        assert!(
            detect(
                &obs,
                &TransparencyOptions {
                    threshold: Some(bad)
                }
            )
            .is_err()
        );
    }
}

fn uniform(w: usize, h: usize, s0: f32) -> Observation {
    let mut p = StokesPlanes::new(w, h);
    p.s0.as_mut_slice().fill(s0);
    Observation::new(
        StokesPlanes::from_linear_stokes(&p.linear_stokes()),
        CameraModel::Orthographic,
    )
}

fn empty_and_finite(obs: &Observation) -> bool {
    let out = detect(obs, &TransparencyOptions::default()).expect("a finite result");
    out.score.as_slice().iter().all(|s| s.is_finite())
        && out.mask.as_slice().iter().all(|&v| v == 0)
}

#[test]
fn all_dark_frame_has_no_glass() {
    assert!(empty_and_finite(&uniform(16, 16, 0.0)));
}

#[test]
fn tiny_images() {
    for (w, h) in [(1, 1), (2, 2), (3, 1)] {
        assert!(empty_and_finite(&uniform(w, h, 1.0)), "{w}x{h}");
    }
    assert!(detect(&uniform(0, 0, 1.0), &TransparencyOptions::default()).is_err());
}

#[test]
fn nan_s0_and_saturation_do_not_panic() {
    let obs = glass_scene();
    let mut planes = obs.planes.clone();
    planes.s0.as_mut_slice()[48 * N + 30] = f32::NAN;
    planes.s2.as_mut_slice()[48 * N + 31] = f32::INFINITY;
    let mut flags = Gray::<u8>::new(N, N);
    flags.as_mut_slice()[10] = polar_sensor::mask::SATURATED;
    let bad = Observation::new(planes, CameraModel::Orthographic).with_flags(flags);
    let out = detect(&bad, &TransparencyOptions::default()).unwrap();
    assert!(out.score.as_slice().iter().all(|s| s.is_finite()));
    assert!(iou_with_disc(&out.mask) > 0.85);
}
