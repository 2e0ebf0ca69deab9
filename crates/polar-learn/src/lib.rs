//! Learned models of the vision tasks, in one place: a k-nearest-neighbour classifier over
//! standardized feature vectors ([`Knn`], on `kiddo`'s k-d tree) and its model file
//! ([`KnnModel`], see [`model`] for the format).
//!
//! The tasks own their features; this crate owns fitting (standardization, a balanced
//! deterministic subsample), storing, checking and querying. A model file says which task
//! and which ordered feature list it was trained for, so a model of another task, of an
//! older feature list or of an older format is refused with a clear error.

pub mod knn;
pub mod model;

pub use knn::{Knn, balanced_subsample};
pub use model::{Expect, FORMAT_VERSION, KnnModel, ModelHeader, Standardization, TrainingSummary};

use std::path::PathBuf;

use thiserror::Error;

/// Errors of model files and fitting.
#[derive(Debug, Error)]
pub enum LearnError {
    /// The file could not be read or written.
    #[error("{path}: {action}: {reason}")]
    Io {
        /// The model file.
        path: PathBuf,
        /// `cannot read` or `cannot write`.
        action: &'static str,
        /// The system's reason.
        reason: String,
    },
    /// The file is not a model file, or it is truncated or damaged.
    #[error("{path}: not a valid model file: {reason}")]
    Corrupt {
        /// The model file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file was written in another format version (retrain the model).
    #[error(
        "{path}: model file format version {found}, this program reads version {supported}; retrain the model"
    )]
    Stale {
        /// The model file.
        path: PathBuf,
        /// The file's version.
        found: u32,
        /// The version this program reads.
        supported: u32,
    },
    /// The model was trained for another task or kind of model.
    #[error("{path}: a {found} model, but a {expected} model is needed")]
    WrongTask {
        /// The model file.
        path: PathBuf,
        /// What is needed (`kind task`).
        expected: String,
        /// What the file holds.
        found: String,
    },
    /// The model's feature list is not the one this program computes (retrain the model).
    #[error(
        "{path}: the model's features [{found}] are not this program's [{expected}]; retrain the model"
    )]
    WrongFeatures {
        /// The model file.
        path: PathBuf,
        /// This program's feature list.
        expected: String,
        /// The file's feature list.
        found: String,
    },
    /// Fitting was asked for something impossible (no points, a class without points...).
    #[error("cannot fit the model: {0}")]
    Fit(String),
}
