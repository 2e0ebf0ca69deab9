//! Analytic scenes: a glass disc over a textured, unpolarized checkerboard, with the
//! DoLP of Fresnel transmission through two interfaces and the AoLP along the azimuth
//! (rotated 90° from the reflection a shiny opaque object would send), and hard cases;
//! both segmenters (the learned one also: its model file and its training).

use std::path::Path;
use std::sync::Arc;

use polar_image::Gray;
use polar_learn::{Expect, KnnModel, LearnError};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};
use polar_transparency::knn::{self, BUILTIN_MODEL, EXPECT, KnnClassifier};
use polar_transparency::{
    MIN_THRESHOLD, MIN_WINDOWS, NOISE_FLOOR_CAP, ON, SEE_THROUGH, Segmenter, TransparencyOptions,
    cue_threshold, detect,
};
use std::f64::consts::FRAC_PI_2;

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
    disc_at(48.0, 48.0, 30.0, x, y)
}

/// Glass disc of `radius` px centred at `(cx, cy)`: `Some((zenith, azimuth))` inside.
fn disc_at(cx: f64, cy: f64, radius: f64, x: usize, y: usize) -> Option<(f64, f64)> {
    let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5 - cy));
    let r = dx.hypot(dy) / radius;
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
    observation_of_size(N, f)
}

/// An `n x n` observation whose pixel `(x, y)` has S0, DoLP and AoLP `f(x, y)`.
fn observation_of_size(n: usize, f: impl Fn(usize, usize) -> (f64, f64, f64)) -> Observation {
    let mut p = StokesPlanes::new(n, n);
    for y in 0..n {
        for x in 0..n {
            let k = y * n + x;
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

/// The window spreads the rim's polarization half a window onto the checkerboard; the
/// depolarized-rim trim takes it back: no mask pixel lies more than one pixel outside
/// the disc (its rim pixel straddles the outline).
#[test]
fn glass_mask_stays_on_the_glass() {
    for segmenter in [
        Segmenter::Cues,
        Segmenter::Knn(Arc::new(trained_on_one_scene())),
    ] {
        let out = detect(&glass_scene(), &segmenter, &TransparencyOptions::default()).unwrap();
        let outside: Vec<(usize, usize)> = (0..N * N)
            .map(|k| (k % N, k / N))
            .filter(|&(x, y)| out.mask.as_slice()[y * N + x] == ON)
            .filter(|&(x, y)| (x as f64 + 0.5 - 48.0).hypot(y as f64 + 0.5 - 48.0) > 31.0)
            .collect();
        assert!(outside.is_empty(), "{segmenter:?}: {outside:?}");
        assert!(iou_with_disc(&out.mask) > 0.85);
    }
}

/// The transmitted DoLP vanishes at the disc's centre (normal incidence) and is largest
/// at its rim; hole filling recovers the centre. IoU 0.85: the mask may lose or gain a
/// rim of about two pixels (the window and the morphology) on a 30-pixel radius.
#[test]
fn glass_disc_over_checkerboard_is_found() {
    let out = detect(
        &glass_scene(),
        &Segmenter::Cues,
        &TransparencyOptions::default(),
    )
    .unwrap();
    let iou = iou_with_disc(&out.mask);
    assert!(iou > 0.85, "IoU {iou}");
    assert!(out.score.as_slice().iter().all(|s| (0.0..=1.0).contains(s)));
}

/// A dark glossy opaque disc polarizes like glass (here its reflection is as polarized as
/// the glass's transmission, and stronger) but returns a tenth of the light around it:
/// no glass. The same disc at 0.9 of the backdrop's brightness stays glass.
#[test]
fn dark_glossy_opaque_disc_is_no_glass() {
    for (brightness, glass) in [(0.1, false), (0.9, true)] {
        let obs = observation(|x, y| match disc(x, y) {
            Some((ze, az)) => (
                brightness * 0.5,
                (2.0 * transmitted_dolp(ze, 1.5)).min(1.0),
                az + FRAC_PI_2,
            ),
            None => (checker(x, y), 0.0, 0.0),
        });
        let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
        let iou = iou_with_disc(&out.mask);
        assert_eq!(iou > 0.8, glass, "brightness {brightness}: IoU {iou}");
    }
}

/// The darkness test's bar, [`SEE_THROUGH`] of the surroundings' median brightness (a plain
/// backdrop, so that the median is one value): a glossy disc at 0.43 of it is no glass,
/// one at 0.55 is.
#[test]
fn disc_just_below_the_see_through_share_is_no_glass() {
    for (ratio, glass) in [(0.43, false), (0.55, true)] {
        let obs = observation(|x, y| match disc(x, y) {
            Some((ze, az)) => (ratio * 0.5, (2.0 * transmitted_dolp(ze, 1.5)).min(1.0), az),
            None => (0.5, 0.0, 0.0),
        });
        let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
        let iou = iou_with_disc(&out.mask);
        assert_eq!(iou > 0.8, glass, "ratio {ratio}: IoU {iou}");
    }
    const { assert!(SEE_THROUGH > 0.43 && SEE_THROUGH < 0.55) };
}

/// Glass lit so that only part of its rim is polarized: reflection of a bright window on
/// one side, the rest of the disc transmitting the depolarized checkerboard at DoLP 0.
/// The seed is an open arc (a C) that hole filling cannot close; the convex hull does, up
/// to the chord across the unpolarized third of the rim: the circular segment beyond it
/// (a fifth of the disc) is lost, so the IoU is at most 0.8. The arc alone: about 0.35.
#[test]
fn glass_polarized_along_an_open_arc_is_filled() {
    let obs = disc_polarized_where(|ze, az| ze > 0.7 && az.cos() > -0.5, FRAC_PI_2);
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let iou = iou_with_disc(&out.mask);
    assert!(iou > 0.7, "IoU {iou}");
}

/// The glass disc over the checkerboard polarized (twice its transmission's DoLP, the AoLP
/// `phase` from the azimuth) where `polarized(zenith, azimuth)`, depolarized elsewhere.
fn disc_polarized_where(polarized: impl Fn(f64, f64) -> bool, phase: f64) -> Observation {
    observation(|x, y| match disc(x, y) {
        Some((ze, az)) if polarized(ze, az) => (
            0.9 * checker(x, y),
            2.0 * transmitted_dolp(ze, 1.5),
            az + phase,
        ),
        Some(_) => (0.9 * checker(x, y), 0.0, 0.0),
        None => (checker(x, y), 0.0, 0.0),
    })
}

/// Glass whose rim is polarized in two arcs, top and bottom, the sides depolarized (where
/// reflection and transmission cancel) and so the face: each arc's own hull is the
/// circular segment beyond its chord; the two take one hull, the disc.
#[test]
fn glass_rim_polarized_in_two_arcs_takes_one_hull() {
    let obs = disc_polarized_where(|ze, az| ze > 0.7 && az.sin().abs() > 0.3, 0.0);
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let iou = iou_with_disc(&out.mask);
    assert!(iou > 0.85, "IoU {iou}");
}

/// Two glass discs 12 pixels apart (`ARC_GAP` of the frame) keep their own hulls: the
/// one over both would run over the checkerboard between them.
#[test]
fn glass_discs_side_by_side_stay_apart() {
    let obs = observation(|x, y| {
        match disc_at(25.0, 48.0, 17.0, x, y).or_else(|| disc_at(71.0, 48.0, 17.0, x, y)) {
            Some((ze, az)) => (0.9 * checker(x, y), transmitted_dolp(ze, 1.5), az),
            None => (checker(x, y), 0.0, 0.0),
        }
    });
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let on = |x: usize, y: usize| out.mask.as_slice()[y * N + x] == ON;
    assert!(on(25, 48) && on(71, 48), "both discs found");
    assert!((30..66).all(|y| !on(48, y)), "nothing between them");
}

/// The same two discs joined by a polarized strip three pixels high (a glint on the floor
/// between them): one component, whose single hull would take in the checkerboard above
/// and below the strip; cut at the strip, a neck far narrower than either disc, each disc
/// keeps its own hull.
#[test]
fn glass_discs_joined_by_a_polarized_strip_keep_their_own_hulls() {
    let obs = observation(|x, y| {
        match disc_at(25.0, 48.0, 17.0, x, y).or_else(|| disc_at(71.0, 48.0, 17.0, x, y)) {
            Some((ze, az)) => (0.9 * checker(x, y), 2.0 * transmitted_dolp(ze, 1.5), az),
            None if (47..50).contains(&y) && (38..59).contains(&x) => (checker(x, y), 0.3, 0.0),
            None => (checker(x, y), 0.0, 0.0),
        }
    });
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let on = |x: usize, y: usize| out.mask.as_slice()[y * N + x] == ON;
    assert!(on(25, 48) && on(71, 48), "both discs found");
    let between = (30..42).chain(56..66).filter(|&y| on(48, y)).count();
    assert_eq!(between, 0, "the checkerboard between the discs taken in");
}

/// A glass slab whose face, turned to the camera, returns no polarization (the backdrop
/// seen through it), polarized along its top edge in a band and along its three other edges
/// only in dashed lines three pixels wide (grazing reflection, broken where it cancels): at
/// 400² the cleaning's opening (11 pixels) drops the lines, and the top band's hull alone
/// covers a tenth of the slab; kept with the band, they give the hull the slab's outline.
#[test]
fn glass_slab_outlined_in_dashes_takes_its_whole_face() {
    let n = 400;
    let slab = |x: usize, y: usize| (100..300).contains(&x) && (120..280).contains(&y);
    let backdrop = |x: usize, y: usize| checker(x / 4, y / 4);
    let obs = observation_of_size(n, |x, y| {
        let edge = !(103..297).contains(&x) || y >= 277;
        let dashed = (x + y) % 20 < 16;
        match slab(x, y) {
            true if y < 136 || (edge && dashed) => (0.9 * backdrop(x, y), 0.3, 0.0),
            true => (0.9 * backdrop(x, y), 0.0, 0.0),
            false => (backdrop(x, y), 0.0, 0.0),
        }
    });
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let (mut inter, mut union) = (0, 0);
    for k in 0..n * n {
        let (p, t) = (out.mask.as_slice()[k] == ON, slab(k % n, k / n));
        inter += usize::from(p && t);
        union += usize::from(p || t);
    }
    let iou = inter as f64 / union as f64;
    assert!(iou > 0.9, "IoU {iou}");
}

/// Score maps with three levels: a background over most of the frame, weakly polarized
/// glass, and more strongly polarized glass covering more pixels than the weak one, so that
/// Otsu's threshold falls between the two glasses. On a clean background the threshold is
/// capped down to its floor, below the weak glass; on a background that sensor noise lifts
/// the cap does not bind and Otsu's threshold stands.
#[test]
fn threshold_keeps_weak_glass_beside_strong_glass_on_a_clean_background() {
    let map = |background: f32| {
        let v = (0..10_000)
            .map(|k| match k % 20 {
                0 => 0.35,
                1 | 2 => 0.95,
                _ => background,
            })
            .collect();
        Gray::from_vec(100, 100, v).unwrap()
    };
    let clean = map(0.0);
    let otsu = polar_imgproc::threshold_otsu(&clean).unwrap();
    assert!(otsu > 0.35, "Otsu {otsu} keeps the weak glass by itself");
    assert_eq!(cue_threshold(&clean).unwrap().value, MIN_THRESHOLD);
    let noisy = map(0.15);
    let otsu = polar_imgproc::threshold_otsu(&noisy).unwrap();
    assert_eq!(cue_threshold(&noisy).unwrap().value, otsu);
}

/// A standard normal sample per `(k, salt)`, deterministic (splitmix64, Box-Muller).
fn gaussian(k: usize, salt: u64) -> f64 {
    let uniform = |i: u64| {
        let mut z = (k as u64)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(salt.wrapping_mul(0xBF58_476D_1CE4_E5B9))
            .wrapping_add(i);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    let (a, b) = (uniform(1).max(1e-300), uniform(2));
    (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
}

/// `obs` with independent Gaussian noise of `sigma` times S0 added to S1 and S2 of every
/// pixel: a dim frame's shot noise, through the Stokes products.
fn with_stokes_noise(obs: &Observation, sigma: f64) -> Observation {
    let mut p = obs.planes.clone();
    let s0 = p.s0.as_slice().to_vec();
    for (k, v) in p.s1.as_mut_slice().iter_mut().enumerate() {
        *v += (sigma * f64::from(s0[k]) * gaussian(k, 1)) as f32;
    }
    for (k, v) in p.s2.as_mut_slice().iter_mut().enumerate() {
        *v += (sigma * f64::from(s0[k]) * gaussian(k, 2)) as f32;
    }
    Observation::new(p, CameraModel::Orthographic)
}

/// A depolarizing checkerboard seen through heavy noise (DoLP of the noise alone about
/// 0.2 per pixel): the windows' chance coherence puts much of the frame above
/// [`MIN_THRESHOLD`], and the noise floor must keep it all out. Glass on the same noisy
/// backdrop is still found (the bound: the noise frays the mask's outline by a pixel or
/// two on the 30-pixel radius).
#[test]
fn heavy_noise_on_a_depolarizing_frame_is_no_glass() {
    let backdrop = with_stokes_noise(&observation(|x, y| (checker(x, y), 0.0, 0.0)), 0.15);
    let out = detect(&backdrop, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let above_floor = out.score.as_slice().iter().filter(|&&s| s > MIN_THRESHOLD);
    assert!(
        above_floor.count() > N * N / 20,
        "the noise is too weak to test anything"
    );
    assert!(out.mask.as_slice().iter().all(|&v| v == 0));
    assert!(out.noise_floor.is_some());
    // The learned segmenter's seeds pass the same cue bar, and it reports that bar.
    let knn = Segmenter::Knn(Arc::new(trained_on_one_scene()));
    let learned = detect(&backdrop, &knn, &TransparencyOptions::default()).unwrap();
    assert_eq!(learned.noise_floor, out.noise_floor);
    assert!(learned.mask.as_slice().iter().all(|&v| v == 0));
    let glass = with_stokes_noise(&glass_scene(), 0.15);
    let out = detect(&glass, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    let iou = iou_with_disc(&out.mask);
    assert!(iou > 0.8, "IoU {iou}");
}

/// A frame polarized coherently everywhere (a water surface filling the view) has no
/// depolarizing background: the noise floor stops at [`NOISE_FLOOR_CAP`] and the surface
/// is marked, rather than taken for noise.
#[test]
fn frame_polarized_everywhere_is_one_transparent_surface() {
    let dolp = 3.0 * f64::from(NOISE_FLOOR_CAP);
    let obs = with_stokes_noise(&observation(|x, y| (checker(x, y), dolp, 0.4)), 0.02);
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    // Otsu's threshold splits the one-level score in the middle, so the seeds are ragged
    // and the hull fills most, not all, of the frame; without the cap nothing is marked.
    let marked = out.mask.as_slice().iter().filter(|&&v| v == ON).count();
    assert!(marked > N * N * 3 / 4, "{marked} of {} pixels", N * N);
}

/// Coherently polarized specks smaller than [`MIN_WINDOWS`] averaging windows are noise,
/// not glass: dropped, and not spread by the hull.
#[test]
fn polarized_specks_are_no_glass() {
    let obs = observation(|x, y| {
        let speck = (x % 32) < 5 && (y % 32) < 5 && x > 8 && y > 8;
        (checker(x, y), if speck { 0.4 } else { 0.0 }, 0.3)
    });
    // A 5x5 speck, spread by the window, stays under the minimum area.
    let window = polar_transparency::cues::WINDOW;
    assert!((5 + window - 1).pow(2) < MIN_WINDOWS * window.pow(2));
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    assert!(out.mask.as_slice().iter().all(|&v| v == 0));
    assert!(
        out.score.as_slice().iter().any(|&s| s > 0.5),
        "the specks do score"
    );
}

/// A textured, depolarizing scene has no transparent object: the floored Otsu threshold
/// must not split its noise-free score in two.
#[test]
fn unpolarized_checkerboard_has_no_glass() {
    let obs = observation(|x, y| (checker(x, y), 0.0, 0.0));
    let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    assert!(out.mask.as_slice().iter().all(|&v| v == 0));
}

/// The demosaicing polarizes an intensity edge falsely (a super-pixel's polarizers sample
/// either side of it), with the same angle all along it; inside the frame the window
/// also sees the edge's other side, where the false polarization turns the other way,
/// but along the frame's edge it sees the mirror image. An unpolarized checkerboard whose
/// edges run two pixels inside the top and right borders (one row of half tone between
/// the squares along the top), mosaicked and demosaicked by the default method and
/// bilinear, has no glass (without the border rule, 298 pixels of bilinear's). Not
/// `newton`: its false polarization at such a soft edge is coherent anywhere in the frame.
#[test]
fn demosaicked_edges_along_the_border_are_no_glass() {
    let edge = 2;
    let sharp = |x: usize, y: usize| checker(x + 12 - (N - edge) % 12, y + 12 - edge);
    // One row of half tone, as a lens and pixel area blur the edge.
    let s0 = |x: usize, y: usize| {
        if y + 1 == edge {
            0.5 * (sharp(x, y) + sharp(x, y + 1))
        } else {
            sharp(x, y)
        }
    };
    let raw: Vec<u16> = (0..N * N)
        .map(|k| (2000.0 * s0(k % N, k / N)) as u16)
        .collect();
    let raw = polar_image::Mosaic::from_vec(N, N, raw).unwrap();
    for method in [
        polar_sensor::DemosaicMethod::Bilinear,
        polar_sensor::DemosaicMethod::Residual,
    ] {
        let planes = polar_sensor::stokes_planes(&raw, method).unwrap();
        let obs = Observation::new(planes, CameraModel::Orthographic);
        let out = detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
        let marked = out.mask.as_slice().iter().filter(|&&v| v == ON).count();
        assert_eq!(marked, 0, "{method:?}");
    }
}

/// `obs` with S0, S1, S2 multiplied by `k` (another exposure).
fn scaled(obs: &Observation, k: f32) -> Observation {
    let mut s = obs.planes.linear_stokes();
    s.as_mut_slice().iter_mut().for_each(|v| *v *= k);
    Observation::new(
        StokesPlanes::from_linear_stokes(&s),
        CameraModel::Orthographic,
    )
}

#[test]
fn scale_invariance_times_37() {
    let obs = glass_scene();
    let obs37 = scaled(&obs, 37.0);
    let (a, b) = (
        detect(&obs, &Segmenter::Cues, &TransparencyOptions::default()).unwrap(),
        detect(&obs37, &Segmenter::Cues, &TransparencyOptions::default()).unwrap(),
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
        &Segmenter::Cues,
        &TransparencyOptions {
            threshold: Some(0.0),
        },
    )
    .unwrap();
    let none = detect(
        &obs,
        &Segmenter::Cues,
        &TransparencyOptions {
            threshold: Some(1.0),
        },
    )
    .unwrap();
    // Every pixel whose window reaches the disc (2 px beyond its rim), and the convex hull
    // of that digitised disc a little more: IoU about 0.84.
    assert!(iou_with_disc(&low.mask) > 0.8);
    assert!(none.mask.as_slice().iter().all(|&v| v == 0));
    for bad in [-0.1, 1.5, f32::NAN] {
        assert!(
            detect(
                &obs,
                &Segmenter::Cues,
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
    let out =
        detect(obs, &Segmenter::Cues, &TransparencyOptions::default()).expect("a finite result");
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
    assert!(
        detect(
            &uniform(0, 0, 1.0),
            &Segmenter::Cues,
            &TransparencyOptions::default()
        )
        .is_err()
    );
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
    let out = detect(&bad, &Segmenter::Cues, &TransparencyOptions::default()).unwrap();
    assert!(out.score.as_slice().iter().all(|s| s.is_finite()));
    assert!(iou_with_disc(&out.mask) > 0.85);
}

// The learned segmenter.

/// A glass disc of `radius` px centred at `(cx, cy)` over a checkerboard whose pixels
/// carry a small polarization of random angle (a depolarizing surface seen by a noisy
/// sensor: DoLP up to 0.03 per pixel, incoherent from one pixel to the next).
fn noisy_glass_scene(cx: f64, cy: f64, radius: f64) -> (Observation, Gray<u8>) {
    let inside = |x: usize, y: usize| disc_at(cx, cy, radius, x, y);
    let hash = |k: usize| {
        (
            (k as f64 * 0.754_877_666).fract(),
            (k as f64 * 0.569_840_29).fract(),
        )
    };
    let obs = observation(|x, y| match inside(x, y) {
        Some((ze, az)) => (0.9 * checker(x, y), transmitted_dolp(ze, 1.5), az),
        None => {
            let (a, b) = hash(y * N + x);
            (checker(x, y), 0.03 * a, std::f64::consts::PI * b)
        }
    });
    let truth = (0..N * N)
        .map(|k| {
            if inside(k % N, k / N).is_some() {
                ON
            } else {
                0
            }
        })
        .collect();
    (obs, Gray::from_vec(N, N, truth).unwrap())
}

fn iou(mask: &Gray<u8>, truth: &Gray<u8>) -> f64 {
    let pairs = mask.as_slice().iter().zip(truth.as_slice());
    let inter = pairs
        .clone()
        .filter(|(p, t)| **p == ON && **t == ON)
        .count();
    let union = pairs.filter(|(p, t)| **p == ON || **t == ON).count();
    inter as f64 / union.max(1) as f64
}

/// A kNN model trained on one noisy scene (disc at the centre, radius 30).
fn trained_on_one_scene() -> KnnClassifier {
    let (obs, truth) = noisy_glass_scene(48.0, 48.0, 30.0);
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    knn::add_training_pixels(&obs, &truth, &mut points, &mut classes).unwrap();
    let model =
        KnnModel::fit_balanced(EXPECT, 7, &points, &classes, 2000, 1, Default::default()).unwrap();
    KnnClassifier::new(model, Path::new("mem")).unwrap()
}

/// Trained on a disc at the centre, the kNN finds a disc elsewhere and of another size
/// (IoU 0.8: the context windows and the clean-up may move the edge by about three pixels
/// on a 24-pixel radius), and calls nothing transparent in a scene of depolarized texture
/// alone.
#[test]
fn learned_separates_coherent_glass_from_a_depolarized_background() {
    let knn = Segmenter::Knn(Arc::new(trained_on_one_scene()));
    let opts = TransparencyOptions::default();
    let (test, truth) = noisy_glass_scene(40.0, 56.0, 24.0);
    let found = iou(&detect(&test, &knn, &opts).unwrap().mask, &truth);
    assert!(found > 0.8, "IoU {found}");
    let (background, _) = noisy_glass_scene(-100.0, -100.0, 1.0);
    let out = detect(&background, &knn, &opts).unwrap();
    let on = out.mask.as_slice().iter().filter(|&&v| v == ON).count();
    assert_eq!(on, 0, "{on} pixels called transparent");
}

/// The vote counts only where the cue score passes its threshold: a model trained with the
/// labels swapped (the depolarized backdrop as glass) votes transparent over a backdrop
/// of texture alone, and still nothing is marked there.
#[test]
fn learned_votes_only_among_polarized_pixels() {
    let (obs, truth) = noisy_glass_scene(48.0, 48.0, 30.0);
    let swapped = Gray::from_vec(
        N,
        N,
        truth
            .as_slice()
            .iter()
            .map(|&v| if v == ON { 0 } else { ON })
            .collect(),
    )
    .unwrap();
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    knn::add_training_pixels(&obs, &swapped, &mut points, &mut classes).unwrap();
    let model =
        KnnModel::fit_balanced(EXPECT, 7, &points, &classes, 2000, 1, Default::default()).unwrap();
    let knn = Segmenter::Knn(Arc::new(
        KnnClassifier::new(model, Path::new("mem")).unwrap(),
    ));
    let (background, _) = noisy_glass_scene(-100.0, -100.0, 1.0);
    let out = detect(&background, &knn, &TransparencyOptions::default()).unwrap();
    let votes = out.score.as_slice().iter().filter(|&&p| p > 0.7).count();
    assert!(
        votes > N * N / 2,
        "the swapped model votes for the backdrop: {votes}"
    );
    assert!(out.mask.as_slice().iter().all(|&v| v == 0));
}

/// Scaling S0, S1, S2 by 37 changes no feature beyond float rounding (every feature is a
/// ratio) and gives the builtin model's identical mask.
#[test]
fn learned_scale_invariance_times_37() {
    let (obs, _) = noisy_glass_scene(48.0, 48.0, 30.0);
    let obs37 = scaled(&obs, 37.0);
    let (a, b) = (
        knn::pixel_features(&obs).unwrap(),
        knn::pixel_features(&obs37).unwrap(),
    );
    for (x, y) in a.iter().flatten().zip(b.iter().flatten()) {
        assert!((x - y).abs() <= 1e-5 + 1e-4 * x.abs(), "{x} {y}");
    }
    let builtin = KnnClassifier::from_bytes(BUILTIN_MODEL, Path::new("builtin"), EXPECT).unwrap();
    let seg = Segmenter::Knn(Arc::new(builtin));
    let opts = TransparencyOptions::default();
    let (m, m37) = (
        detect(&obs, &seg, &opts).unwrap(),
        detect(&obs37, &seg, &opts).unwrap(),
    );
    assert_eq!(m.mask, m37.mask);
}

/// The shipped model loads and names this program's task, features and classes (a model
/// left stale by a feature change fails here).
#[test]
fn builtin_model_matches_the_feature_list() {
    let clf = KnnClassifier::from_bytes(BUILTIN_MODEL, Path::new("builtin"), EXPECT).unwrap();
    let h = &clf.model().header;
    assert_eq!(
        (h.task.as_str(), &h.features, &h.classes),
        (
            knn::TASK,
            &knn::FEATURES.map(String::from).to_vec(),
            &knn::CLASSES.map(String::from).to_vec()
        )
    );
    assert!(h.points >= 1000 && h.summary.samples > 0, "{h:?}");
    assert!(
        BUILTIN_MODEL.len() < 300_000,
        "{} bytes",
        BUILTIN_MODEL.len()
    );
}

/// A transparent model file reads back equal; a truncated one and one of another task are
/// refused with errors naming the file.
#[test]
fn model_file_round_trip_and_errors() {
    let dir = tempfile::tempdir().unwrap();
    let model = trained_on_one_scene().model().clone();
    let path = dir.path().join("t.knn");
    std::fs::write(&path, model.to_bytes()).unwrap();
    let back = KnnClassifier::load(&path, EXPECT).unwrap();
    assert_eq!(back.model(), &model);
    let bytes = model.to_bytes();
    std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
    let err = KnnClassifier::load(&path, EXPECT).unwrap_err();
    assert!(matches!(err, LearnError::Corrupt { .. }), "{err}");
    assert!(err.to_string().contains("t.knn"), "{err}");
    let other = Expect {
        task: "material",
        ..EXPECT
    };
    let mut m = model.clone();
    m.header.task = other.task.into();
    std::fs::write(&path, m.to_bytes()).unwrap();
    let err = KnnClassifier::load(&path, EXPECT).unwrap_err();
    assert!(matches!(err, LearnError::WrongTask { .. }), "{err}");
}
