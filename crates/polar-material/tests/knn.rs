//! The kNN classifier on the analytic scenes of synthetic.rs (two spheres over an
//! unpolarized floor): its features' scale invariance, and training on one scene then
//! classifying another with other indices and the materials swapped.

use polar_image::{Gray, NormalImage};
use std::path::Path;
use std::sync::Arc;

use polar_learn::KnnModel;
use polar_material::knn::{self, KnnClassifier};
use polar_material::{Classifier, DIELECTRIC, METAL, MaterialOptions, classify, prepare};
use polar_optics::pixel_frame::CameraModel;
use polar_sensor::{Observation, StokesPlanes};

mod common;
use common::*;

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
        let p = prepare(o, None, None).unwrap();
        (knn::pixel_features(&p).unwrap(), p.fg)
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

/// A kNN (k = 5) trained on the spheres of `surfaces` labelled `labels`, with the scene's
/// true normals and mask where `with_normals`.
fn trained(surfaces: [Surface; 2], labels: [u8; 2], with_normals: bool) -> Classifier {
    let (train, normals, fg) = scene(surfaces);
    let (mut points, mut classes) = (Vec::new(), Vec::new());
    knn::add_training_pixels(
        &train,
        with_normals.then_some(&normals),
        with_normals.then_some(&fg),
        &truth(labels),
        &mut points,
        &mut classes,
    )
    .unwrap();
    assert!(classes.contains(&0) && classes.contains(&1));
    let model = KnnModel::fit_balanced(
        knn::EXPECT,
        5,
        &points,
        &classes,
        1000,
        1,
        Default::default(),
    )
    .unwrap();
    assert!(model.labels.len() <= 1000);
    Classifier::Knn(Arc::new(
        KnnClassifier::new(model, Path::new("mem")).unwrap(),
    ))
}

/// The training scene of the two tests below: a glass-like specular sphere (n = 1.5) and
/// a gold one.
const TRAIN: [Surface; 2] = [Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)];
/// The test scene: the materials swapped in place, other indices (silver, n = 1.6).
const TEST: [Surface; 2] = [Surface::Specular(0.06, 3.586), Surface::Specular(1.6, 0.0)];

/// Asserts sphere 0 reads metal and sphere 1 dielectric: region smoothing makes each
/// sphere one label, so the shares are 0 or 1; 0.95 leaves room for rim pixels the window
/// blurs.
fn assert_swapped_scene_right(labels: &Gray<u8>) {
    let (metal, dielectric) = (share(labels, 0, METAL), share(labels, 1, DIELECTRIC));
    assert!(metal > 0.95 && dielectric > 0.95, "{metal} {dielectric}");
}

/// Trained on one scene, the kNN labels the other right.
#[test]
fn knn_trained_on_one_scene_labels_another() {
    let clf = trained(TRAIN, [DIELECTRIC, METAL], false);
    let (test, _, _) = scene(TEST);
    let opts = MaterialOptions::default();
    let labels = classify(&test, None, None, None, &clf, &opts)
        .unwrap()
        .labels;
    assert_swapped_scene_right(&labels);
}

/// Trained and run with the normals and mask given (as shape from polarization gives them
/// in `polar-vision train` and `run`), the kNN labels the other scene right; and it reads
/// its cues from the normals: the shipped model's confidences with them differ from those
/// with the silhouette cues.
#[test]
fn knn_reads_the_given_normals() {
    let clf = trained(TRAIN, [DIELECTRIC, METAL], true);
    let (test, normals, fg) = scene(TEST);
    let opts = MaterialOptions::default();
    let given = classify(&test, Some(&normals), Some(&fg), None, &clf, &opts).unwrap();
    assert_swapped_scene_right(&given.labels);
    let builtin =
        KnnClassifier::from_bytes(knn::BUILTIN_MODEL, Path::new("builtin"), knn::EXPECT).unwrap();
    let builtin = Classifier::Knn(Arc::new(builtin));
    let confidence = |n: Option<&NormalImage>| {
        let m = classify(&test, n, Some(&fg), None, &builtin, &opts).unwrap();
        m.confidence.into_vec()
    };
    let (with, without) = (confidence(Some(&normals)), confidence(None));
    let differ = with.iter().zip(&without).filter(|(a, b)| a != b).count();
    assert!(differ > 100, "{differ} pixels differ");
}

/// The shipped default model loads, and its header names this program's task, feature
/// list and classes (a model left stale by a feature change fails here).
#[test]
fn builtin_model_matches_the_feature_list() {
    let clf =
        KnnClassifier::from_bytes(knn::BUILTIN_MODEL, Path::new("builtin"), knn::EXPECT).unwrap();
    let h = &clf.model().header;
    assert_eq!(h.task, knn::TASK);
    assert_eq!(h.features, knn::FEATURES);
    assert_eq!(h.classes, knn::CLASSES);
    assert!(h.points >= 1000 && h.summary.samples > 0, "{h:?}");
}

/// The scene tiled `n x n`: frames large enough for several rayon tasks per pass and for
/// the kNN's query grid (stride above 1).
fn tiled(obs: &Observation, n: usize) -> Observation {
    let s = obs.planes.linear_stokes();
    let (w, h) = s.size();
    let mut big = polar_image::LinearStokesImage::new(w * n, h * n);
    for y in 0..h * n {
        for x in 0..w * n {
            big.pixels_mut()[y * w * n + x] = s.pixels()[(y % h) * w + x % w];
        }
    }
    Observation::new(
        StokesPlanes::from_linear_stokes(&big),
        CameraModel::Orthographic,
    )
}

/// Both classifiers give bit-identical labels and confidences on 1 and 3 threads (the
/// parallel passes split work, never a sum), with and without region smoothing.
#[test]
fn results_do_not_depend_on_the_thread_count() {
    let (obs, _, _) = scene([Surface::Specular(1.5, 0.0), Surface::Specular(0.43, 2.455)]);
    let obs = tiled(&obs, 6);
    let knn =
        KnnClassifier::from_bytes(knn::BUILTIN_MODEL, Path::new("builtin"), knn::EXPECT).unwrap();
    let run = |threads: usize, clf: &Classifier, smooth_regions: bool| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let opts = MaterialOptions { smooth_regions };
        let m = pool.install(|| classify(&obs, None, None, None, clf, &opts).unwrap());
        let bits: Vec<u32> = m
            .confidence
            .as_slice()
            .iter()
            .map(|v| v.to_bits())
            .collect();
        (m.labels, bits)
    };
    for clf in [Classifier::Physics, Classifier::Knn(Arc::new(knn))] {
        for smooth in [true, false] {
            let one = run(1, &clf, smooth);
            assert_eq!(one, run(3, &clf, smooth), "{clf:?} smooth {smooth}");
            // Not a trivial frame: both spheres are object pixels.
            assert!(one.0.as_slice().iter().filter(|&&l| l != 0).count() > 20_000);
        }
    }
}
