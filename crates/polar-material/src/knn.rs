//! The learned classifier: k nearest neighbours (polar-learn) over per-pixel feature
//! vectors that training and inference both compute one way ([`pixel_features`]).
//!
//! Every feature is scale-free (S0 enters only divided by the frame's robust scale) and
//! computed with the cues of [`crate::prepare`]: from the normals and object mask of shape
//! from polarization where given, as `polar-vision train` gives them at training and `run`
//! at inference, else from the silhouettes. The features differ with the cues, so a model
//! holds only for the kind of cues it is trained with.

use polar_image::{Gray, NormalImage, par_map};
use polar_imgproc::{Border, box_filter};
use polar_learn::{Expect, Knn};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::features::Features;
use crate::fresnel_cues::FresnelTable;
use crate::{DIELECTRIC, METAL, MaterialError, Prepared, Regions};

/// The task name in model files.
pub const TASK: &str = "material";
/// Number of features.
pub const DIMS: usize = 10;
/// The ordered feature list, written into every model file:
/// - `dolp`: windowed DoLP;
/// - `s0_relative`: windowed S0 over the frame's 99th percentile (albedo, exposure-free);
/// - `phase_cos`, `phase_sin`: `cos 2δ`, `sin 2δ` with `δ` = AoLP − the cues' azimuth
///   (0 where unknown);
/// - `fresnel_excess`: DoLP minus the largest metal specular DoLP at the cues' zenith
///   (Wolff's cue; positive only a dielectric can reach);
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

/// A loaded material kNN classifier (load it with [`EXPECT`]).
pub type KnnClassifier = Knn<DIMS>;

/// Per-pixel feature vectors ([`FEATURES`]), row-major, one per pixel.
pub fn pixel_features(p: &Prepared) -> Result<Vec<[f32; DIMS]>, MaterialError> {
    let x = FrameFeatures::new(p)?;
    Ok(par_map(p.fg.len(), |k| x.at(k)))
}

/// What the feature vectors of one frame are read from: the frame-wide planes and the
/// per-region cues, so that a vector costs a few loads wherever it is needed.
struct FrameFeatures<'a> {
    p: &'a Prepared,
    table: FresnelTable,
    /// Mean and standard deviation of the windowed DoLP over [`LOCAL`]² windows.
    local: (Vec<f32>, Vec<f32>),
    /// [`crate::rule::region_cues`] per region id.
    region: Vec<[f32; 2]>,
}

impl<'a> FrameFeatures<'a> {
    fn new(p: &'a Prepared) -> Result<Self, MaterialError> {
        Ok(Self {
            p,
            table: FresnelTable::new(),
            local: local_stats(&p.features)?,
            region: crate::rule::region_cues(&p.features, &p.cues, &p.regions),
        })
    }

    /// The feature vector of pixel `k`.
    fn at(&self, k: usize) -> [f32; DIMS] {
        let (f, cues) = (&self.p.features, &self.p.cues);
        let or0 = |v: f32| if v.is_finite() { v } else { 0.0 };
        let z = cues.zenith[k];
        let envelope = if z.is_finite() {
            self.table.metal_max(z)
        } else {
            self.table.metal_ceiling()
        };
        let region = self.region[self.p.regions.labels[k] as usize];
        [
            f.dolp[k],
            f.s0[k],
            or0(cues.phase[k]),
            or0(cues.phase_sin[k]),
            f.dolp[k] - envelope,
            self.local.0[k],
            self.local.1[k],
            region[0],
            region[1],
            f.window_noise(),
        ]
    }
}

/// Mean and standard deviation of the windowed DoLP over [`LOCAL`]² windows.
fn local_stats(f: &Features) -> Result<(Vec<f32>, Vec<f32>), MaterialError> {
    let (w, h) = (f.width, f.height);
    let d = Gray::from_vec(w, h, f.dolp.clone()).expect("size of the features");
    let d2 = Gray::from_vec(w, h, par_map(w * h, |k| f.dolp[k] * f.dolp[k])).expect("size");
    let (mut m, mut m2) = (Gray::new(w, h), Gray::new(w, h));
    box_filter(&d, &mut m, LOCAL, LOCAL, Border::Reflect101)?;
    box_filter(&d2, &mut m2, LOCAL, LOCAL, Border::Reflect101)?;
    let (mean, m2) = (m.into_vec(), m2.as_slice());
    let sd = par_map(w * h, |k| (m2[k] - mean[k] * mean[k]).max(0.0).sqrt());
    Ok((mean, sd))
}

/// Most kNN queries per frame, about: beyond it the object pixels are queried on a grid
/// of stride `s`, one query per region in each grid cell, and the region's other pixels in
/// the cell take its answer (the features are windowed over
/// [`crate::features::WINDOW`]² pixels already, so neighbours differ little).
pub const MAX_QUERIES: usize = 1 << 12;

/// Marks a pixel that takes no kNN answer in [`representatives`].
const NONE: usize = usize::MAX;

/// For each pixel, the pixel whose kNN answer it takes ([`NONE`] where not `usable`): the
/// first usable pixel, in raster order, of its region in its `stride`² grid cell.
fn representatives(
    usable: impl Fn(usize) -> bool + Sync,
    regions: &Regions,
    w: usize,
    stride: usize,
) -> Vec<usize> {
    let mut rep = vec![NONE; regions.labels.len()];
    rep.par_chunks_mut(w * stride)
        .enumerate()
        .for_each(|(band, out)| {
            let k0 = band * w * stride;
            // Per grid cell of the band, the (region, representative) pairs met so far.
            let mut cells: Vec<Vec<(u32, usize)>> = vec![Vec::new(); w.div_ceil(stride)];
            for (i, r) in out.iter_mut().enumerate() {
                let k = k0 + i;
                if !usable(k) {
                    continue;
                }
                let l = regions.labels[k];
                let cell = &mut cells[i % w / stride];
                *r = match cell.iter().find(|c| c.0 == l) {
                    Some(&(_, first)) => first,
                    None => {
                        cell.push((l, k));
                        k
                    }
                };
            }
        });
    rep
}

/// Probability of metal per pixel (0.5 outside the object mask and on invalid pixels): the
/// fraction of metal among the `k` nearest training points. With `smooth`, each region
/// gets the mean over its valid pixels.
pub fn metal_probability(
    clf: &KnnClassifier,
    p: &Prepared,
    smooth: bool,
) -> Result<Vec<f32>, MaterialError> {
    let x = FrameFeatures::new(p)?;
    let (f, fg, lab) = (&p.features, &p.fg, &p.regions.labels);
    let usable = |k: usize| fg[k] && f.valid[k];
    let count = (0..fg.len()).filter(|&k| usable(k)).count();
    let stride = ((count as f64 / MAX_QUERIES as f64).sqrt().ceil() as usize).max(1);
    let rep = representatives(usable, &p.regions, f.width, stride);
    let queried: Vec<usize> = (0..rep.len()).filter(|&k| rep[k] == k).collect();
    let answers: Vec<f32> = queried
        .par_iter()
        .map(|&k| clf.fraction(&x.at(k), METAL - 1))
        .collect();
    let mut answer = vec![0.5f32; rep.len()];
    for (&k, &a) in queried.iter().zip(&answers) {
        answer[k] = a;
    }
    let per_pixel = par_map(
        rep.len(),
        |k| if rep[k] == NONE { 0.5 } else { answer[rep[k]] },
    );
    if !smooth {
        return Ok(per_pixel);
    }
    let mut sum = vec![(0.0f64, 0usize); p.regions.count + 1];
    for (k, &l) in lab.iter().enumerate() {
        if l != 0 && f.valid[k] {
            sum[l as usize].0 += f64::from(per_pixel[k]);
            sum[l as usize].1 += 1;
        }
    }
    Ok(par_map(lab.len(), |k| match sum[lab[k] as usize] {
        (s, n) if lab[k] != 0 && n > 0 => (s / n as f64) as f32,
        _ => 0.5,
    }))
}

/// Training points of one labelled frame: the feature vectors of the valid pixels that
/// [`crate::classify`] with this classifier and the same `normals` and `foreground` would
/// see as object and `labels` (as in `gt/material.png`) marks dielectric or metal, with
/// their class indices. Appends to `points` (row-major) and `classes`.
pub fn add_training_pixels(
    obs: &Observation,
    normals: Option<&NormalImage>,
    foreground: Option<&Gray<u8>>,
    labels: &Gray<u8>,
    points: &mut Vec<f32>,
    classes: &mut Vec<u8>,
) -> Result<(), MaterialError> {
    crate::check_size("labels", obs.size(), Some(labels.size()))?;
    let p = crate::prepare(obs, normals, foreground)?;
    let x = FrameFeatures::new(&p)?;
    for (k, &l) in labels.as_slice().iter().enumerate() {
        if p.fg[k] && p.features.valid[k] && (l == DIELECTRIC || l == METAL) {
            points.extend_from_slice(&x.at(k));
            classes.push(l - 1);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two regions meeting inside grid cells, with unusable pixels scattered over both:
    /// every usable pixel takes, by the definition, the first usable pixel in raster order
    /// of its own region in its own cell, and unusable pixels take none.
    #[test]
    fn representatives_stay_in_their_region_and_cell() {
        let (w, h, stride) = (11, 8, 3);
        let labels = (0..w * h)
            .map(|k| if k % w < 4 || k / w == 5 { 1 } else { 2 })
            .collect();
        let regions = Regions { labels, count: 2 };
        let usable = |k: usize| k % 7 != 3;
        let rep = representatives(usable, &regions, w, stride);
        let cell = |k: usize| (k % w / stride, k / w / stride);
        let key = |k: usize| (cell(k), regions.labels[k]);
        for (k, &r) in rep.iter().enumerate() {
            let first = (0..w * h).find(|&j| usable(j) && key(j) == key(k));
            let expected = if usable(k) { first.unwrap() } else { NONE };
            assert_eq!(r, expected, "pixel {k}");
        }
        // Both regions meet in cell column 1: it holds two representatives per cell row.
        let queried = (0..w * h).filter(|&k| rep[k] == k).count();
        assert!(
            queried > (w.div_ceil(stride)) * h.div_ceil(stride),
            "{queried}"
        );
    }
}
