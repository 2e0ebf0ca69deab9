//! Analytic scenes: spheres seen orthographically over an unpolarized floor, with the
//! DoLP and AoLP that Fresnel's equations give for specular reflection (dielectric,
//! metal) or diffuse emission (dielectric) of unpolarized light, and named hard cases.

use polar_image::{Gray, NormalImage};
use polar_material::{
    BACKGROUND, Classifier, DIELECTRIC, METAL, MaterialOptions, TRANSPARENT, classify,
};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

mod common;
use common::*;

fn run(obs: &Observation, normals: Option<&NormalImage>, fg: Option<&Gray<u8>>) -> Gray<u8> {
    classify(
        obs,
        normals,
        fg,
        None,
        &Classifier::Physics,
        &MaterialOptions::default(),
    )
    .expect("classify")
    .labels
}

/// Glass-like dielectric (n = 1.5) specular sphere next to a gold sphere: the
/// dielectric exceeds every metal's Fresnel DoLP near Brewster's angle, the gold never.
/// Region smoothing makes each sphere one label, so the shares are 1 or 0; 0.95 leaves
/// room for a rim pixel the window blurs.
#[test]
fn specular_dielectric_and_gold_spheres_are_told_apart() {
    let (obs, normals, fg) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    for (name, n, m) in [
        ("mask", None, Some(&fg)),
        ("mask + normals", Some(&normals), Some(&fg)),
        ("automatic mask", None, None),
    ] {
        let l = run(&obs, n, m);
        assert!(
            share(&l, 0, DIELECTRIC) > 0.95,
            "{name}: {}",
            share(&l, 0, DIELECTRIC)
        );
        assert!(
            share(&l, 1, METAL) > 0.95,
            "{name}: {}",
            share(&l, 1, METAL)
        );
    }
}

/// The shape task's zeniths are off by 10-25° on average. Measured 15° short of the truth
/// (toward the camera), a copper sphere's own DoLP (copper sets the top of the metal
/// envelope) is above the envelope at that zenith on its outer half; read with the margin
/// for measured zeniths it stays metal, and the dielectric's DoLP near Brewster's angle
/// still passes.
#[test]
fn copper_stays_metal_with_zeniths_measured_too_small() {
    copper_told_apart_with_zeniths(|z| (z - 15f64.to_radians()).max(0.0));
}

/// On a metal the shape task's dielectric model reads the weak polarization as near
/// normal incidence. With every measured zenith 5° (azimuths right), copper's DoLP toward
/// its rim is far above the metal envelope there even with the margin; the silhouette's
/// sphere prior, the floor of a measured zenith, keeps it metal, and the dielectric's
/// DoLP near Brewster's angle still passes at the prior's zenith.
#[test]
fn copper_stays_metal_with_zeniths_measured_near_zero() {
    copper_told_apart_with_zeniths(|_| 5f64.to_radians());
}

/// The dielectric (n = 1.5) and copper spheres, classified with the true normals' zeniths
/// replaced by `measured(zenith)` (azimuths kept), are each labelled as what they are.
fn copper_told_apart_with_zeniths(measured: impl Fn(f64) -> f64) {
    let (obs, mut normals, fg) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.9, 2.6)]);
    for n in normals.pixels_mut() {
        let r = f64::from(n[0].hypot(n[1]));
        if n[2] > 0.0 && r > 0.0 {
            let (s, c) = measured(r.asin()).sin_cos();
            let k = s / r;
            *n = [
                (f64::from(n[0]) * k) as f32,
                (f64::from(n[1]) * k) as f32,
                c as f32,
            ];
        }
    }
    let l = run(&obs, Some(&normals), Some(&fg));
    let (d, m) = (share(&l, 0, DIELECTRIC), share(&l, 1, METAL));
    assert!(d > 0.95 && m > 0.95, "{d} {m}");
}

/// An object mask that merges a gold sphere with a dielectric one (a bridge of floor
/// pixels between them): the dielectric's Fresnel evidence votes the whole region
/// dielectric, but split at the bridge the gold blob shows no Fresnel evidence and its
/// light is polarized across the azimuth, so it is metal. With the silhouette's cues and
/// with the true normals.
#[test]
fn gold_merged_with_a_dielectric_stays_metal() {
    let (obs, normals, mut fg) =
        scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    for y in 22..27 {
        for x in 40..57 {
            fg.as_mut_slice()[y * W + x] = 1;
        }
    }
    for n in [None, Some(&normals)] {
        let l = run(&obs, n, Some(&fg));
        let (d, m) = (share(&l, 0, DIELECTRIC), share(&l, 1, METAL));
        assert!(d > 0.95 && m > 0.95, "normals {}: {d} {m}", n.is_some());
    }
}

/// A diffuse dielectric is weakly polarized (below the metal envelope) but along the
/// azimuth: the silhouette phase cue must call it dielectric, the aluminium metal.
#[test]
fn diffuse_dielectric_is_told_from_aluminium_by_the_aolp_phase() {
    let (obs, normals, fg) = scene([Surface::Diffuse(1.5), Surface::Specular(1.0, 6.6)]);
    for n in [None, Some(&normals)] {
        let l = run(&obs, n, Some(&fg));
        assert!(
            share(&l, 0, DIELECTRIC) > 0.95,
            "{}",
            share(&l, 0, DIELECTRIC)
        );
        assert!(share(&l, 1, METAL) > 0.95, "{}", share(&l, 1, METAL));
    }
}

/// Scaling S0, S1, S2 by 37 (exposure) changes no label and no confidence beyond float
/// rounding of the normalised Stokes values.
#[test]
fn scale_invariance_times_37() {
    let (obs, _, _) = scene([Surface::Specular(1.5, 0.0), Surface::Diffuse(1.4)]);
    let mut scaled = obs.planes.linear_stokes();
    scaled.as_mut_slice().iter_mut().for_each(|v| *v *= 37.0);
    let obs37 = Observation::new(
        StokesPlanes::from_linear_stokes(&scaled),
        CameraModel::Orthographic,
    );
    let opts = MaterialOptions::default();
    let a = classify(&obs, None, None, None, &Classifier::Physics, &opts).unwrap();
    let b = classify(&obs37, None, None, None, &Classifier::Physics, &opts).unwrap();
    assert_eq!(a.labels, b.labels);
    for (x, y) in a.confidence.as_slice().iter().zip(b.confidence.as_slice()) {
        assert!((x - y).abs() < 1e-4, "{x} {y}");
    }
}

/// Transparent pixels take label 3 and leave the opaque classes.
#[test]
fn transparent_mask_wins() {
    let (obs, _, fg) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let mut t = Gray::<u8>::new(W, H);
    t.as_mut_slice()[24 * W + 24] = 255;
    let out = classify(
        &obs,
        None,
        Some(&fg),
        Some(&t),
        &Classifier::Physics,
        &MaterialOptions::default(),
    )
    .unwrap();
    assert_eq!(out.labels.as_slice()[24 * W + 24], TRANSPARENT);
    assert_eq!(out.labels.as_slice()[0], BACKGROUND);
}

/// A transparency mask over both a glass-like dielectric sphere and a gold one relabels
/// the dielectric only: glass is a dielectric, and the transparency cues also mark
/// mirror-like metals, whose reflections polarize coherently.
#[test]
fn transparent_mask_leaves_a_metal_object_metal() {
    let (obs, _, fg) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let t = Gray::from_vec(W, H, vec![255u8; W * H]).unwrap();
    let opts = MaterialOptions::default();
    let out = classify(&obs, None, Some(&fg), Some(&t), &Classifier::Physics, &opts).unwrap();
    assert!(share(&out.labels, 0, TRANSPARENT) > 0.95);
    assert!(share(&out.labels, 1, METAL) > 0.95);
    assert_eq!(out.labels.as_slice()[0], TRANSPARENT);
}

/// A transparency mask that cuts into an opaque object (a false positive of the
/// transparency task over the left half of the diffuse sphere) relabels those pixels and
/// changes nothing else: its edge is no occluding contour, so the rest of the sphere keeps
/// its silhouette and its region vote, label and confidence alike.
#[test]
fn transparent_mask_only_relabels() {
    let (obs, _, fg) = scene([Surface::Diffuse(1.5), Surface::Specular(1.0, 6.6)]);
    let mut t = Gray::<u8>::new(W, H);
    for y in 0..H {
        for x in 0..24 {
            t.as_mut_slice()[y * W + x] = 255;
        }
    }
    let opts = MaterialOptions::default();
    let with = classify(&obs, None, Some(&fg), Some(&t), &Classifier::Physics, &opts).unwrap();
    let without = classify(&obs, None, Some(&fg), None, &Classifier::Physics, &opts).unwrap();
    assert!(share(&without.labels, 0, DIELECTRIC) > 0.95);
    for k in 0..W * H {
        if t.as_slice()[k] != 0 {
            assert_eq!(with.labels.as_slice()[k], TRANSPARENT);
        } else {
            assert_eq!(
                with.labels.as_slice()[k],
                without.labels.as_slice()[k],
                "pixel {k}"
            );
            assert_eq!(
                with.confidence.as_slice()[k],
                without.confidence.as_slice()[k],
                "pixel {k}"
            );
        }
    }
}

fn uniform(w: usize, h: usize, s0: f32, s1: f32) -> Observation {
    let mut p = StokesPlanes::new(w, h);
    p.s0.as_mut_slice().fill(s0);
    p.s1.as_mut_slice().fill(s1);
    Observation::new(
        StokesPlanes::from_linear_stokes(&p.linear_stokes()),
        CameraModel::Orthographic,
    )
}

fn all_background(obs: &Observation) -> bool {
    let out = classify(
        obs,
        None,
        None,
        None,
        &Classifier::Physics,
        &MaterialOptions::default(),
    )
    .expect("a finite result");
    out.confidence
        .as_slice()
        .iter()
        .all(|c| c.is_finite() && (0.0..=1.0).contains(c))
        && out.labels.as_slice().iter().all(|&l| l == BACKGROUND)
}

#[test]
fn all_dark_frame_is_background() {
    assert!(all_background(&uniform(16, 16, 0.0, 0.0)));
}

#[test]
fn dolp_zero_everywhere_is_background() {
    assert!(all_background(&uniform(32, 32, 0.5, 0.0)));
}

#[test]
fn tiny_images_are_classified() {
    for (w, h) in [(1, 1), (2, 2), (1, 5)] {
        assert!(all_background(&uniform(w, h, 1.0, 0.0)), "{w}x{h}");
        let out = classify(
            &uniform(w, h, 1.0, 0.5),
            None,
            None,
            None,
            &Classifier::Physics,
            &MaterialOptions::default(),
        )
        .expect("tiny polarized image");
        assert_eq!(out.labels.size(), (w, h));
    }
}

#[test]
fn nan_s0_and_saturated_pixels_do_not_panic() {
    let (obs, normals, _) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let mut planes = obs.planes.clone();
    planes.s0.as_mut_slice()[24 * W + 20] = f32::NAN;
    planes.s1.as_mut_slice()[24 * W + 21] = f32::INFINITY;
    let mut flags = Gray::<u8>::new(W, H);
    flags.as_mut_slice()[24 * W + 72] = polar_sensor::mask::SATURATED;
    let mut nn = normals.clone();
    nn.pixels_mut()[5] = [f32::NAN, 0.0, 1.0];
    let bad = Observation::new(planes, CameraModel::Orthographic).with_flags(flags);
    let out = classify(
        &bad,
        Some(&nn),
        None,
        None,
        &Classifier::Physics,
        &MaterialOptions::default(),
    )
    .expect("finite result");
    assert!(out.confidence.as_slice().iter().all(|c| c.is_finite()));
    assert!(share(&out.labels, 0, DIELECTRIC) > 0.9);
}

#[test]
fn per_pixel_labels_without_region_smoothing() {
    let (obs, _, fg) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let opts = MaterialOptions {
        smooth_regions: false,
    };
    let l = classify(&obs, None, Some(&fg), None, &Classifier::Physics, &opts)
        .unwrap()
        .labels;
    // Per pixel the gold sphere has no dielectric evidence anywhere; the dielectric only
    // where its DoLP clears the envelope (a band around Brewster's angle).
    assert!(share(&l, 1, METAL) > 0.95, "{}", share(&l, 1, METAL));
    assert!(
        share(&l, 0, DIELECTRIC) > 0.3,
        "{}",
        share(&l, 0, DIELECTRIC)
    );
}

#[test]
fn size_mismatch_is_an_error() {
    let obs = uniform(8, 8, 1.0, 0.0);
    let fg = Gray::<u8>::new(4, 8);
    let n = NormalImage::new(8, 4);
    let opts = MaterialOptions::default();
    assert!(classify(&obs, None, Some(&fg), None, &Classifier::Physics, &opts).is_err());
    assert!(classify(&obs, Some(&n), None, None, &Classifier::Physics, &opts).is_err());
    assert!(
        classify(
            &uniform(0, 0, 1.0, 0.0),
            None,
            None,
            None,
            &Classifier::Physics,
            &opts
        )
        .is_err()
    );
}

/// An object mask that merges a diffuse dielectric with a larger metal into one region
/// (as a mask taking in touching objects does): the region-wide tallies vote metal, but
/// the dielectric's own windows show its diffuse phase on more than
/// `LOCAL_EVIDENCE_SHARE` of the region, so the region is dielectric. One region gets
/// one label, so the aluminium goes with it: the price of the merged mask.
#[test]
fn dielectric_merged_into_a_metal_region_is_not_voted_down() {
    let (obs, normals, mut fg) = scene([Surface::Diffuse(1.5), Surface::Specular(1.0, 6.6)]);
    // Keep the dielectric's outer band (zenith above 40°) on the side of the metal only,
    // a fifth of the region, and bridge the gap.
    for y in 0..H {
        for x in 0..W {
            let k = y * W + x;
            if let Some((0, ze, _)) = sphere_at(x, y) {
                fg.as_mut_slice()[k] = u8::from(x >= 30 && ze > 0.7);
            }
            if (44..52).contains(&x) && (22..26).contains(&y) {
                fg.as_mut_slice()[k] = 1;
            }
        }
    }
    let l = run(&obs, Some(&normals), Some(&fg));
    let dielectric: usize = (0..W * H)
        .filter(|&k| fg.as_slice()[k] != 0 && l.as_slice()[k] == DIELECTRIC)
        .count();
    let n = fg.as_slice().iter().filter(|&&v| v != 0).count();
    assert_eq!(
        dielectric, n,
        "{dielectric} of the region's {n} pixels dielectric"
    );
}
