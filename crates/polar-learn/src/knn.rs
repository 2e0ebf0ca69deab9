//! k-nearest-neighbour voting over standardized features (Cover & Hart 1967), on an
//! immutable k-d tree of `kiddo`; and the balanced subsample that keeps models small.

use std::num::NonZeroUsize;
use std::path::Path;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::LearnError;
use crate::model::{Expect, KnnModel, Standardization};

/// A kNN classifier of `D` features, ready to query.
pub struct Knn<const D: usize> {
    tree: ImmutableKdTree<f32, D>,
    labels: Vec<u8>,
    k: NonZeroUsize,
    standardization: Standardization,
    model: KnnModel,
}

impl<const D: usize> std::fmt::Debug for Knn<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Knn")
            .field("features", &self.model.header.features)
            .field("points", &self.labels.len())
            .field("k", &self.k)
            .finish()
    }
}

impl<const D: usize> Knn<D> {
    /// Builds the k-d tree of a model with `D` features; `path` names the model in errors.
    pub fn new(model: KnnModel, path: &Path) -> Result<Self, LearnError> {
        let corrupt = |reason: String| LearnError::Corrupt {
            path: path.to_owned(),
            reason,
        };
        let h = &model.header;
        if h.features.len() != D {
            return Err(corrupt(format!(
                "{} features, {D} expected",
                h.features.len()
            )));
        }
        let k = NonZeroUsize::new(h.k).ok_or_else(|| corrupt("k = 0".into()))?;
        let points: Vec<[f32; D]> = model
            .points
            .chunks_exact(D)
            .map(|row| {
                let mut z: [f32; D] = row.try_into().expect("rows of D values");
                h.standardization.apply(&mut z);
                z
            })
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&points)
            .map_err(|e| corrupt(format!("cannot index the points: {e:?}")))?;
        Ok(Self {
            tree,
            labels: model.labels.clone(),
            k,
            standardization: h.standardization.clone(),
            model,
        })
    }

    /// Reads, checks and indexes a model file.
    pub fn load(path: &Path, expect: Expect<'_>) -> Result<Self, LearnError> {
        Self::new(KnnModel::load(path, expect)?, path)
    }

    /// Parses, checks and indexes model bytes (e.g. a model compiled into the program);
    /// `name` names them in errors.
    pub fn from_bytes(bytes: &[u8], name: &Path, expect: Expect<'_>) -> Result<Self, LearnError> {
        Self::new(KnnModel::from_bytes(bytes, name, expect)?, name)
    }

    /// The model it was built from.
    pub fn model(&self) -> &KnnModel {
        &self.model
    }

    /// Fraction of the `k` nearest training points (standardized Euclidean distance) that
    /// have label `class`; `x` holds raw feature values.
    pub fn fraction(&self, x: &[f32; D], class: u8) -> f32 {
        let mut z = *x;
        self.standardization.apply(&mut z);
        let found = self
            .tree
            .query(&z)
            .nearest_n::<SquaredEuclidean<f32>>(self.k)
            .unsorted()
            .execute();
        let hits = found
            .iter()
            .filter(|r| self.labels[r.item as usize] == class)
            .count();
        hits as f32 / found.len().max(1) as f32
    }
}

/// Indices of at most `per_class` points of each label in `0..classes`, drawn without
/// replacement in an order fixed by `seed` (a SplitMix64 hash of seed and index), returned
/// sorted: the same inputs always give the same subsample.
pub fn balanced_subsample(
    labels: &[u8],
    classes: usize,
    per_class: usize,
    seed: u64,
) -> Vec<usize> {
    let mut out = Vec::new();
    for c in 0..classes {
        let mut idx: Vec<usize> = (0..labels.len())
            .filter(|&i| usize::from(labels[i]) == c)
            .collect();
        idx.sort_by_key(|&i| splitmix64(seed ^ splitmix64(i as u64)));
        idx.truncate(per_class);
        out.extend(idx);
    }
    out.sort_unstable();
    out
}

/// SplitMix64 (Steele, Lea & Flood 2014): a fast, well-mixed 64-bit hash.
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}
