//! The model file: what a kNN classifier needs to run and what it was trained on.
//!
//! Layout (all integers and floats little-endian):
//! ```text
//! "POLARKNN"                      8 bytes, magic
//! header length H                 u32
//! header                          H bytes of JSON: ModelHeader
//! points                          N x D f32, raw (unstandardized) feature vectors
//! labels                          N u8, class indices into header.classes
//! ```
//! `N = header.points`, `D = header.features.len()`. The file must be exactly that long,
//! which is checked before anything is allocated from the header's counts, so a damaged or
//! hostile file cannot make the reader allocate more than its own size.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::LearnError;
use crate::knn::balanced_subsample;

/// Version of the layout above and of [`ModelHeader`]; bump on any change.
pub const FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"POLARKNN";
/// Largest header accepted (bytes): the JSON holds names and a summary, never data.
const MAX_HEADER: usize = 1 << 20;
/// Largest feature count accepted (a k-d tree is for low dimensions).
pub const MAX_FEATURES: usize = 32;
/// Largest class count accepted (labels are bytes).
const MAX_CLASSES: usize = 256;

/// Per-feature standardization `z = (x − mean) / scale`, fitted on the training points.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Standardization {
    /// Mean of each feature.
    pub mean: Vec<f32>,
    /// Standard deviation of each feature (1 where a feature is constant).
    pub scale: Vec<f32>,
}

impl Standardization {
    /// Mean and standard deviation of each of the `dims` features of the row-major `points`.
    pub fn fit(points: &[f32], dims: usize) -> Self {
        let n = (points.len() / dims.max(1)).max(1) as f64;
        let mut mean = vec![0.0f64; dims];
        let mut sq = vec![0.0f64; dims];
        for row in points.chunks_exact(dims) {
            for (j, &v) in row.iter().enumerate() {
                mean[j] += f64::from(v);
                sq[j] += f64::from(v) * f64::from(v);
            }
        }
        let mean: Vec<f64> = mean.iter().map(|m| m / n).collect();
        let scale = sq
            .iter()
            .zip(&mean)
            .map(|(s, m)| {
                let sd = (s / n - m * m).max(0.0).sqrt() as f32;
                if sd > 1e-6 { sd } else { 1.0 }
            })
            .collect();
        Self {
            mean: mean.iter().map(|&m| m as f32).collect(),
            scale,
        }
    }

    /// Standardizes `x` in place; a non-finite value becomes 0 (the training mean).
    pub fn apply(&self, x: &mut [f32]) {
        for ((v, m), s) in x.iter_mut().zip(&self.mean).zip(&self.scale) {
            let z = (*v - m) / s;
            *v = if z.is_finite() { z } else { 0.0 };
        }
    }
}

/// What the model was trained on, for people and for reproducing it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TrainingSummary {
    /// The dataset folder as given to the training command.
    pub dataset: String,
    /// Samples read.
    pub samples: usize,
    /// Sample families used (empty = all).
    pub families: Vec<String>,
    /// Labelled pixels available per class name, before subsampling.
    pub pixels_per_class: BTreeMap<String, u64>,
    /// Training points kept per class name.
    pub points_per_class: BTreeMap<String, u64>,
    /// The settings that made the model (input, demosaicing, k, point budget, seed...).
    pub settings: BTreeMap<String, String>,
}

/// The JSON header of a model file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelHeader {
    /// [`FORMAT_VERSION`] of the writer.
    pub format_version: u32,
    /// Kind of model, `knn`.
    pub kind: String,
    /// The task it classifies for (e.g. `material`).
    pub task: String,
    /// Ordered feature names: the meaning of each coordinate.
    pub features: Vec<String>,
    /// Class names; a label is an index into this list.
    pub classes: Vec<String>,
    /// Feature standardization.
    pub standardization: Standardization,
    /// Neighbours that vote.
    pub k: usize,
    /// Number of training points in the body.
    pub points: usize,
    /// The training set.
    pub summary: TrainingSummary,
}

/// What a reader requires of a model file.
#[derive(Clone, Copy, Debug)]
pub struct Expect<'a> {
    /// The task (`ModelHeader::task`).
    pub task: &'a str,
    /// The ordered feature list.
    pub features: &'a [&'a str],
    /// The class names.
    pub classes: &'a [&'a str],
}

/// A kNN model: header, training points (row-major, raw) and their labels.
#[derive(Clone, Debug, PartialEq)]
pub struct KnnModel {
    /// The header.
    pub header: ModelHeader,
    /// `header.points × header.features.len()` raw feature values.
    pub points: Vec<f32>,
    /// Class index of each point.
    pub labels: Vec<u8>,
}

/// The kind string of kNN models.
pub const KIND_KNN: &str = "knn";

impl KnnModel {
    /// Fits a model: standardization over `points` (row-major, `expect.features.len()`
    /// values each) with `labels` indexing `expect.classes`.
    pub fn fit(
        expect: Expect<'_>,
        k: usize,
        points: Vec<f32>,
        labels: Vec<u8>,
        summary: TrainingSummary,
    ) -> Result<Self, LearnError> {
        let dims = expect.features.len();
        let n = labels.len();
        if dims == 0 || dims > MAX_FEATURES || points.len() != n * dims {
            return Err(LearnError::Fit(format!(
                "{} values for {n} points of {dims} features",
                points.len()
            )));
        }
        if k == 0 || k > n {
            return Err(LearnError::Fit(format!("k = {k} with {n} training points")));
        }
        if let Some(c) = (0..expect.classes.len()).find(|&c| !labels.contains(&(c as u8))) {
            return Err(LearnError::Fit(format!(
                "no training point of class {}",
                expect.classes[c]
            )));
        }
        if points.iter().any(|v| !v.is_finite()) {
            return Err(LearnError::Fit("a feature value is not finite".into()));
        }
        let header = ModelHeader {
            format_version: FORMAT_VERSION,
            kind: KIND_KNN.into(),
            task: expect.task.into(),
            features: expect.features.iter().map(|s| s.to_string()).collect(),
            classes: expect.classes.iter().map(|s| s.to_string()).collect(),
            standardization: Standardization::fit(&points, dims),
            k,
            points: n,
            summary,
        };
        Ok(Self {
            header,
            points,
            labels,
        })
    }

    /// Fits a model on at most `max_points` of the training points (the same number per
    /// class, a subsample fixed by `seed`: [`balanced_subsample`]) and fills the summary's
    /// per-class counts of labelled pixels and kept points.
    pub fn fit_balanced(
        expect: Expect<'_>,
        k: usize,
        points: &[f32],
        labels: &[u8],
        max_points: usize,
        seed: u64,
        mut summary: TrainingSummary,
    ) -> Result<Self, LearnError> {
        let (dims, classes) = (expect.features.len(), expect.classes.len());
        if points.len() != labels.len() * dims {
            return Err(LearnError::Fit(format!(
                "{} values for {} points of {dims} features",
                points.len(),
                labels.len()
            )));
        }
        let keep = balanced_subsample(labels, classes, max_points / classes.max(1), seed);
        let mut kept_points = Vec::with_capacity(keep.len() * dims);
        let mut kept = Vec::with_capacity(keep.len());
        for &i in &keep {
            kept_points.extend_from_slice(&points[i * dims..(i + 1) * dims]);
            kept.push(labels[i]);
        }
        for (c, name) in expect.classes.iter().enumerate() {
            let count = |l: &[u8]| l.iter().filter(|&&v| usize::from(v) == c).count() as u64;
            summary
                .pixels_per_class
                .insert((*name).into(), count(labels));
            summary
                .points_per_class
                .insert((*name).into(), count(&kept));
        }
        Self::fit(expect, k, kept_points, kept, summary)
    }

    /// The file's bytes.
    pub fn to_bytes(&self) -> Vec<u8> {
        let header = serde_json::to_vec(&self.header).expect("a header always serializes");
        let mut out =
            Vec::with_capacity(12 + header.len() + self.points.len() * 4 + self.labels.len());
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&(header.len() as u32).to_le_bytes());
        out.extend_from_slice(&header);
        for v in &self.points {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.labels);
        out
    }

    /// Reads and checks a model file against what the caller computes.
    pub fn load(path: &Path, expect: Expect<'_>) -> Result<Self, LearnError> {
        let bytes = std::fs::read(path).map_err(|e| LearnError::Io {
            path: path.to_owned(),
            action: "cannot read",
            reason: e.to_string(),
        })?;
        Self::from_bytes(&bytes, path, expect)
    }

    /// Parses and checks model bytes; `path` names them in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path, expect: Expect<'_>) -> Result<Self, LearnError> {
        let corrupt = |reason: String| LearnError::Corrupt {
            path: path.to_owned(),
            reason,
        };
        if bytes.len() < 12 || &bytes[..8] != MAGIC {
            return Err(corrupt(
                "it does not start with the POLARKNN signature".into(),
            ));
        }
        let hlen = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize;
        if hlen > MAX_HEADER || hlen > bytes.len() - 12 {
            return Err(corrupt(format!(
                "header length {hlen} does not fit the {}-byte file",
                bytes.len()
            )));
        }
        let header = parse_header(&bytes[12..12 + hlen], path)?;
        check_header(&header, path, expect)?;
        let body = &bytes[12 + hlen..];
        let (points, labels) = parse_body(body, &header).map_err(corrupt)?;
        Ok(Self {
            header,
            points,
            labels,
        })
    }
}

/// The header, or the clearest error: a stale version is told before a JSON error.
fn parse_header(bytes: &[u8], path: &Path) -> Result<ModelHeader, LearnError> {
    let value: serde_json::Value =
        serde_json::from_slice(bytes).map_err(|e| LearnError::Corrupt {
            path: path.to_owned(),
            reason: format!("header: {e}"),
        })?;
    let version = value
        .get("format_version")
        .and_then(serde_json::Value::as_u64);
    if let Some(v) = version
        && v != u64::from(FORMAT_VERSION)
    {
        return Err(LearnError::Stale {
            path: path.to_owned(),
            found: u32::try_from(v).unwrap_or(u32::MAX),
            supported: FORMAT_VERSION,
        });
    }
    serde_json::from_value(value).map_err(|e| LearnError::Corrupt {
        path: path.to_owned(),
        reason: format!("header: {e}"),
    })
}

fn check_header(h: &ModelHeader, path: &Path, expect: Expect<'_>) -> Result<(), LearnError> {
    let p = || PathBuf::from(path);
    if h.kind != KIND_KNN || h.task != expect.task {
        return Err(LearnError::WrongTask {
            path: p(),
            expected: format!("{KIND_KNN} {}", expect.task),
            found: format!("{} {}", h.kind, h.task),
        });
    }
    if h.features != expect.features || h.classes != expect.classes {
        return Err(LearnError::WrongFeatures {
            path: p(),
            expected: format!(
                "{}; classes {}",
                expect.features.join(", "),
                expect.classes.join(", ")
            ),
            found: format!(
                "{}; classes {}",
                h.features.join(", "),
                h.classes.join(", ")
            ),
        });
    }
    let d = h.features.len();
    let s = &h.standardization;
    let scales_ok = s.scale.iter().all(|v| v.is_finite() && *v > 0.0);
    let means_ok = s.mean.iter().all(|v| v.is_finite());
    let problem = if d > MAX_FEATURES || h.classes.len() > MAX_CLASSES {
        Some(format!("{d} features, {} classes", h.classes.len()))
    } else if s.mean.len() != d || s.scale.len() != d || !scales_ok || !means_ok {
        Some("the standardization does not match the features".into())
    } else if h.k == 0 || h.k > h.points {
        Some(format!("k = {} with {} points", h.k, h.points))
    } else {
        None
    };
    match problem {
        Some(reason) => Err(LearnError::Corrupt { path: p(), reason }),
        None => Ok(()),
    }
}

/// Points and labels, after checking the body's length against the header's counts.
fn parse_body(body: &[u8], h: &ModelHeader) -> Result<(Vec<f32>, Vec<u8>), String> {
    let d = h.features.len();
    let expected = h
        .points
        .checked_mul(4 * d + 1)
        .filter(|&len| len == body.len());
    if expected.is_none() {
        return Err(format!(
            "the header promises {} points of {d} features, the body holds {} bytes (truncated or damaged)",
            h.points,
            body.len()
        ));
    }
    let (raw, labels) = body.split_at(h.points * 4 * d);
    let points: Vec<f32> = raw
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes")))
        .collect();
    if let Some(i) = points.iter().position(|v| !v.is_finite()) {
        return Err(format!("point {} has a non-finite feature", i / d));
    }
    if let Some(i) = labels
        .iter()
        .position(|&l| usize::from(l) >= h.classes.len())
    {
        return Err(format!(
            "point {i} has label {} of {} classes",
            labels[i],
            h.classes.len()
        ));
    }
    Ok((points, labels.to_vec()))
}
