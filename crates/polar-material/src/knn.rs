//! The learned classifier: k nearest neighbours (polar-learn) over per-pixel feature
//! vectors that training and inference both take from [`pixel_features`].
//!
//! Every feature is scale-free (S0 enters only divided by the frame's robust scale) and
//! computed with the silhouette cues (the same at training and inference: the zenith is
//! the sphere prior and the phase is measured against the silhouette's outward normal).

use std::path::Path;

use polar_image::Gray;
use polar_imgproc::mask::components;
use polar_imgproc::{Border, box_filter};
use polar_learn::{Expect, Knn, KnnModel, LearnError, TrainingSummary, balanced_subsample};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::cues::Cues;
use crate::features::Features;
use crate::fresnel_cues::FresnelTable;
use crate::{DIELECTRIC, METAL, MaterialError};

/// The task name in model files.
pub const TASK: &str = "material";
/// Number of features.
pub const DIMS: usize = 10;
/// The ordered feature list, written into every model file:
/// - `dolp`: windowed DoLP;
/// - `s0_relative`: windowed S0 over the frame's 99th percentile (albedo, exposure-free);
/// - `phase_cos`, `phase_sin`: `cos 2δ`, `sin 2δ` with `δ` = AoLP − silhouette azimuth
///   (0 where unknown, inside the objects);
/// - `fresnel_excess`: DoLP minus the largest metal specular DoLP at the sphere prior's
///   zenith (Wolff's cue; positive only a dielectric can reach);
/// - `dolp_local_mean`, `dolp_local_sd`: DoLP statistics over a [`LOCAL`]² window;
/// - `region_over`, `region_phase`: the physics rule's evidence over the pixel's connected
///   object region ([`crate::rule::region_cues`]);
/// - `noise`: the frame's windowed DoLP noise level (clean and noisy frames differ).
pub const FEATURES: [&str; DIMS] = [
    "dolp",
    "s0_relative",
    "phase_cos",
    "phase_sin",
    "fresnel_excess",
    "dolp_local_mean",
    "dolp_local_sd",
    "region_over",
    "region_phase",
    "noise",
];
/// Class names; class index `i` is label `i + 1` ([`DIELECTRIC`], [`METAL`]).
pub const CLASSES: [&str; 2] = ["dielectric", "metal"];
/// Side of the window of the local DoLP statistics (pixels, odd).
pub const LOCAL: usize = 15;
/// What a material model file must declare.
pub const EXPECT: Expect<'static> = Expect {
    task: TASK,
    features: &FEATURES,
    classes: &CLASSES,
};

/// The default model file shipped with the project, trained on
/// `datasets-synth/suites/material-train.toml` by `tools/train-default-models.sh`.
pub const BUILTIN_MODEL: &[u8] = include_bytes!("../models/material-knn.bin");

/// A loaded material kNN classifier.
#[derive(Debug)]
pub struct KnnClassifier {
    knn: Knn<DIMS>,
}

impl KnnClassifier {
    /// Reads and checks a model file.
    pub fn load(path: &Path) -> Result<Self, LearnError> {
        Self::new(KnnModel::load(path, EXPECT)?, path)
    }

    /// Parses and checks model bytes (e.g. a model compiled into the program); `name`
    /// names them in errors.
    pub fn from_bytes(bytes: &[u8], name: &Path) -> Result<Self, LearnError> {
        Self::new(KnnModel::from_bytes(bytes, name, EXPECT)?, name)
    }

    /// Indexes a model.
    pub fn new(model: KnnModel, name: &Path) -> Result<Self, LearnError> {
        Ok(Self {
            knn: Knn::new(model, name)?,
        })
    }

    /// The model.
    pub fn model(&self) -> &KnnModel {
        self.knn.model()
    }
}

/// Per-pixel feature vectors ([`FEATURES`]), row-major, one per pixel.
pub fn pixel_features(
    f: &Features,
    cues: &Cues,
    fg: &[bool],
) -> Result<Vec<[f32; DIMS]>, MaterialError> {
    let table = FresnelTable::new();
    let (mean, sd) = local_stats(f)?;
    let region = crate::rule::region_cues(f, cues, fg)?;
    let noise = f.window_noise();
    let or0 = |v: f32| if v.is_finite() { v } else { 0.0 };
    Ok((0..f.width * f.height)
        .map(|k| {
            let z = cues.zenith[k];
            let envelope = if z.is_finite() {
                table.metal_max(z)
            } else {
                table.metal_ceiling()
            };
            [
                f.dolp[k],
                f.s0[k],
                or0(cues.phase[k]),
                or0(cues.phase_sin[k]),
                f.dolp[k] - envelope,
                mean[k],
                sd[k],
                region[k][0],
                region[k][1],
                noise,
            ]
        })
        .collect())
}

/// Mean and standard deviation of the windowed DoLP over [`LOCAL`]² windows.
fn local_stats(f: &Features) -> Result<(Vec<f32>, Vec<f32>), MaterialError> {
    let (w, h) = (f.width, f.height);
    let d = Gray::from_vec(w, h, f.dolp.clone()).expect("size of the features");
    let d2 = Gray::from_vec(w, h, f.dolp.iter().map(|v| v * v).collect()).expect("size");
    let (mut m, mut m2) = (Gray::new(w, h), Gray::new(w, h));
    box_filter(&d, &mut m, LOCAL, LOCAL, Border::Reflect101)?;
    box_filter(&d2, &mut m2, LOCAL, LOCAL, Border::Reflect101)?;
    let mean = m.into_vec();
    let sd = m2
        .as_slice()
        .iter()
        .zip(&mean)
        .map(|(&s, &mu)| (s - mu * mu).max(0.0).sqrt())
        .collect();
    Ok((mean, sd))
}

/// Most kNN queries per frame: beyond it the object pixels are queried on a grid of
/// stride `s` and the others take their cell's anchor (the features are windowed over
/// [`crate::features::WINDOW`]² pixels already, so neighbours differ little).
pub const MAX_QUERIES: usize = 1 << 12;

/// Probability of metal per pixel (0.5 outside `fg` and on invalid pixels): the fraction
/// of metal among the `k` nearest training points. With `smooth`, each 8-connected region
/// of `fg` gets the mean over its valid pixels.
pub fn metal_probability(
    clf: &KnnClassifier,
    f: &Features,
    cues: &Cues,
    fg: &[bool],
    smooth: bool,
) -> Result<Vec<f32>, MaterialError> {
    let x = pixel_features(f, cues, fg)?;
    let w = f.width;
    let usable = |k: usize| fg[k] && f.valid[k];
    let count = (0..x.len()).filter(|&k| usable(k)).count();
    let stride = ((count as f64 / MAX_QUERIES as f64).sqrt().ceil() as usize).max(1);
    let anchor = |k: usize| {
        let (px, py) = (k % w, k / w);
        (py - py % stride) * w + (px - px % stride)
    };
    // A pixel is queried when it is its cell's anchor or its anchor is not usable.
    let own = |k: usize| anchor(k) == k || !usable(anchor(k));
    let metal = METAL - 1;
    let mut p: Vec<f32> = x
        .par_iter()
        .enumerate()
        .with_min_len(256)
        .map(|(k, v)| {
            if usable(k) && own(k) {
                clf.knn.fraction(v, metal)
            } else {
                0.5
            }
        })
        .collect();
    for k in 0..p.len() {
        if usable(k) && !own(k) {
            p[k] = p[anchor(k)];
        }
    }
    if !smooth {
        return Ok(p);
    }
    let (lab, count) = components(fg, f.width, f.height)?;
    let mut sum = vec![(0.0f64, 0usize); count + 1];
    for (k, &l) in lab.iter().enumerate() {
        if l != 0 && f.valid[k] {
            sum[l as usize].0 += f64::from(p[k]);
            sum[l as usize].1 += 1;
        }
    }
    Ok(lab
        .iter()
        .map(|&l| match sum[l as usize] {
            (s, n) if l != 0 && n > 0 => (s / n as f64) as f32,
            _ => 0.5,
        })
        .collect())
}

/// Training points of one labelled frame: the feature vectors of the valid pixels that
/// [`crate::classify`] with this classifier would see as object and `labels` (as in
/// `gt/material.png`) marks dielectric or metal, with their class indices. Appends to
/// `points` (row-major) and `classes`.
pub fn add_training_pixels(
    obs: &Observation,
    labels: &Gray<u8>,
    points: &mut Vec<f32>,
    classes: &mut Vec<u8>,
) -> Result<(), MaterialError> {
    crate::check_size("labels", obs.size(), Some(labels.size()))?;
    let p = crate::prepare(obs, None, None, None)?;
    let x = pixel_features(&p.features, &p.cues, &p.fg)?;
    for (k, &l) in labels.as_slice().iter().enumerate() {
        if p.fg[k] && p.features.valid[k] && (l == DIELECTRIC || l == METAL) {
            points.extend_from_slice(&x[k]);
            classes.push(l - 1);
        }
    }
    Ok(())
}

/// Fits a model on all training points, keeping at most `max_points` of them (half per
/// class, a subsample fixed by `seed`); fills the summary's per-class counts.
pub fn fit(
    points: &[f32],
    classes: &[u8],
    k: usize,
    max_points: usize,
    seed: u64,
    mut summary: TrainingSummary,
) -> Result<KnnModel, LearnError> {
    let keep = balanced_subsample(classes, CLASSES.len(), max_points / CLASSES.len(), seed);
    let mut kept_points = Vec::with_capacity(keep.len() * DIMS);
    let mut kept = Vec::with_capacity(keep.len());
    for &i in &keep {
        kept_points.extend_from_slice(&points[i * DIMS..(i + 1) * DIMS]);
        kept.push(classes[i]);
    }
    for (c, name) in CLASSES.iter().enumerate() {
        let count = |l: &[u8]| l.iter().filter(|&&v| usize::from(v) == c).count() as u64;
        summary
            .pixels_per_class
            .insert((*name).into(), count(classes));
        summary
            .points_per_class
            .insert((*name).into(), count(&kept));
    }
    KnnModel::fit(EXPECT, k, kept_points, kept, summary)
}
