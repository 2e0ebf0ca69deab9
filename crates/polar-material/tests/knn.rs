//! The kNN classifier on the analytic scenes of synthetic.rs (two spheres over an
//! unpolarized floor): its features' scale invariance, and training on one scene then
//! classifying another with other indices and the materials swapped.

use polar_image::{Gray, Image};
use polar_material::fresnel_cues::specular_dolp;
use std::path::Path;
use std::sync::Arc;

use polar_material::knn::{self, KnnClassifier};
use polar_material::{Classifier, DIELECTRIC, METAL, MaterialOptions, classify, prepare};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

const W: usize = 96;
const H: usize = 48;

/// How a sphere sends light: specular reflection with index `n + ik`, or diffuse.
#[derive(Clone, Copy)]
enum Surface {
    Specular(f64, f64),
    Diffuse(f64),
}

/// DoLP of light leaving a dielectric of index `n` after subsurface scattering, at
/// emission zenith `t` (Atkinson & Hancock 2006).
fn diffuse_dolp(t: f64, n: f64) -> f64 {
    let s2 = t.sin().powi(2);
    let num = (n - 1.0 / n).powi(2) * s2;
    let den = 2.0 + 2.0 * n * n - (n + 1.0 / n).powi(2) * s2 + 4.0 * t.cos() * (n * n - s2).sqrt();
    num / den
}

/// Two spheres of radius 20 px centred at x = 24 and x = 72, and the pixel's
/// `(sphere index, zenith, azimuth)`; azimuth measured counterclockwise from image +x.
fn sphere_at(x: usize, y: usize) -> Option<(usize, f64, f64)> {
    for (i, cx) in [24.0, 72.0].into_iter().enumerate() {
        let (dx, dy) = (x as f64 + 0.5 - cx, -(y as f64 + 0.5 - 24.0));
        let r = dx.hypot(dy) / 20.0;
        if r < 1.0 {
            return Some((i, r.asin(), dy.atan2(dx)));
        }
    }
    None
}

/// The observation of the two spheres (`surfaces[i]`) over a floor of S0 0.4.
fn scene(surfaces: [Surface; 2]) -> (Observation, Image<f32, 3>, Gray<u8>) {
    let mut p = StokesPlanes::new(W, H);
    let mut normals = Image::<f32, 3>::new(W, H);
    let mut fg = Gray::<u8>::new(W, H);
    for y in 0..H {
        for x in 0..W {
            let k = y * W + x;
            let (s0, dolp, aolp) = match sphere_at(x, y) {
                None => (0.4, 0.0, 0.0),
                Some((i, ze, az)) => {
                    normals.pixels_mut()[k] = [
                        (ze.sin() * az.cos()) as f32,
                        (ze.sin() * az.sin()) as f32,
                        ze.cos() as f32,
                    ];
                    fg.as_mut_slice()[k] = 1;
                    match surfaces[i] {
                        Surface::Specular(n, kk) => (
                            0.6,
                            specular_dolp(ze, n, kk),
                            az + std::f64::consts::FRAC_PI_2,
                        ),
                        Surface::Diffuse(n) => (0.7, diffuse_dolp(ze, n), az),
                    }
                }
            };
            p.s0.as_mut_slice()[k] = s0 as f32;
            p.s1.as_mut_slice()[k] = (s0 * dolp * (2.0 * aolp).cos()) as f32;
            p.s2.as_mut_slice()[k] = (s0 * dolp * (2.0 * aolp).sin()) as f32;
        }
    }
    let planes = StokesPlanes::from_linear_stokes(&p.linear_stokes());
    (
        Observation::new(planes, CameraModel::Orthographic),
        normals,
        fg,
    )
}

/// Share of sphere `i`'s pixels labelled `label`.
fn share(labels: &Gray<u8>, i: usize, label: u8) -> f64 {
    let (mut n, mut hit) = (0, 0);
    for y in 0..H {
        for x in 0..W {
            if let Some((j, _, _)) = sphere_at(x, y)
                && j == i
            {
                n += 1;
                hit += usize::from(labels.as_slice()[y * W + x] == label);
            }
        }
    }
    hit as f64 / n as f64
}

/// Ground-truth labels of a scene: sphere `i` gets `labels[i]`.
fn truth(labels: [u8; 2]) -> Gray<u8> {
    let mut g = Gray::<u8>::new(W, H);
    for y in 0..H {
        for x in 0..W {
            if let Some((i, _, _)) = sphere_at(x, y) {
                g.as_mut_slice()[y * W + x] = labels[i];
            }
        }
    }
    g
}

fn scaled(obs: &Observation, factor: f32) -> Observation {
    let mut s = obs.planes.linear_stokes();
    s.as_mut_slice().iter_mut().for_each(|v| *v *= factor);
    Observation::new(
        StokesPlanes::from_linear_stokes(&s),
        CameraModel::Orthographic,
    )
}

/// S0, S1, S2 times 7 (exposure) leave every feature equal up to float rounding of the
/// normalisation by the frame's scale (a few ulps of values of order 1: 1e-5).
#[test]
fn features_are_scale_invariant_times_7() {
    let (obs, _, _) = scene([Surface::Specular(1.5, 0.0), Surface::Diffuse(1.4)]);
    let features = |o: &Observation| {
        let p = prepare(o, None, None, None).unwrap();
        (
            knn::pixel_features(&p.features, &p.cues, &p.fg).unwrap(),
            p.fg,
        )
    };
    let (a, fa) = features(&obs);
    let (b, fb) = features(&scaled(&obs, 7.0));
    assert_eq!(fa, fb);
    let mut informative = 0;
    for (x, y) in a.iter().zip(&b) {
        for (u, v) in x.iter().zip(y) {
            assert!((u - v).abs() < 1e-5, "{x:?} {y:?}");
        }
        informative += usize::from(x[0] > 0.05);
    }
    // The spheres are polarized: the comparison is not over an empty frame.
    assert!(informative > 500, "{informative}");
}

/// Trained on a glass-like specular sphere (n = 1.5) and a gold one, the kNN labels a
/// scene with the materials swapped in place and other indices (n = 1.6, silver) right:
/// region smoothing makes each sphere one label, so the shares are 0 or 1; 0.95 leaves
/// room for rim pixels the window blurs.
#[test]
fn knn_trained_on_one_scene_labels_another() {
    let (train, _, _) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    knn::add_training_pixels(
        &train,
        &truth([DIELECTRIC, METAL]),
        &mut points,
        &mut classes,
    )
    .unwrap();
    assert!(classes.contains(&0) && classes.contains(&1));
    let model = knn::fit(&points, &classes, 5, 1000, 1, Default::default()).unwrap();
    assert!(model.labels.len() <= 1000);
    let clf = Classifier::Knn(Arc::new(
        KnnClassifier::new(model, Path::new("mem")).unwrap(),
    ));
    let (test, _, _) = scene([Surface::Specular(0.06, 3.586), Surface::Specular(1.6, 0.0)]);
    let labels = classify(&test, None, None, None, &clf, &MaterialOptions::default())
        .unwrap()
        .labels;
    assert!(
        share(&labels, 0, METAL) > 0.95,
        "{}",
        share(&labels, 0, METAL)
    );
    assert!(
        share(&labels, 1, DIELECTRIC) > 0.95,
        "{}",
        share(&labels, 1, DIELECTRIC)
    );
}

/// The shipped default model loads, and its header names this program's task, feature
/// list and classes (a model left stale by a feature change fails here).
#[test]
fn builtin_model_matches_the_feature_list() {
    let clf = KnnClassifier::from_bytes(knn::BUILTIN_MODEL, Path::new("builtin")).unwrap();
    let h = &clf.model().header;
    assert_eq!(h.task, knn::TASK);
    assert_eq!(h.features, knn::FEATURES);
    assert_eq!(h.classes, knn::CLASSES);
    assert!(h.points >= 1000 && h.summary.samples > 0, "{h:?}");
}
