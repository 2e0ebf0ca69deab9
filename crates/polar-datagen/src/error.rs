//! The one error type of the crate: every variant names the file, sample or argument at fault.

use std::path::PathBuf;

/// Everything that can go wrong while making, resuming or merging a dataset.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file or directory operation failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The suite file cannot be parsed or breaks a rule (caught before any rendering).
    #[error("suite {path}: {message}")]
    Suite {
        /// The suite file.
        path: PathBuf,
        /// What is wrong and where.
        message: String,
    },
    /// The output directory cannot be created or written.
    #[error("output directory {path} is not writable: {source}")]
    OutputNotWritable {
        /// The output directory.
        path: PathBuf,
        /// Why the probe write failed.
        source: std::io::Error,
    },
    /// A scene file cannot be read or breaks a rule (caught before any rendering); the
    /// renderer's error names the file and the key.
    #[error("scene {0}")]
    Scene(#[from] polar_render::Error),
    /// A command-line option has a value the program cannot use.
    #[error("{option}: {message}")]
    Option {
        /// The option as the user writes it, e.g. `--jobs`.
        option: &'static str,
        /// What is wrong with its value.
        message: String,
    },
    /// The output directory holds files that are not a dataset of this program.
    #[error(
        "output directory {path} is not empty and is not a polar-datagen dataset (no {} or {}; it holds {found}); refusing to write into it: use a new or empty directory",
        crate::store::RUN_RECORD,
        crate::store::MANIFEST
    )]
    NotADataset {
        /// The output directory.
        path: PathBuf,
        /// Some of the names found in it.
        found: String,
    },
    /// Another run holds the lock of the dataset directory.
    #[error(
        "output directory {path} is in use by another polar-datagen run (it holds the lock file {}); wait for that run to end or use another directory",
        path.join(crate::store::LOCK).display()
    )]
    Locked {
        /// The output directory.
        path: PathBuf,
    },
    /// The output directory already holds a run of another suite, size or shard.
    #[error("output directory {path} holds a different run ({reason}); use a new directory")]
    RunMismatch {
        /// The output directory.
        path: PathBuf,
        /// Which recorded setting differs.
        reason: String,
    },
    /// A file's SHA-256 differs from the one recorded in the manifest.
    #[error("{path}: checksum mismatch (manifest {expected}, file {actual})")]
    Checksum {
        /// The file whose content changed.
        path: PathBuf,
        /// The checksum in the manifest.
        expected: String,
        /// The checksum of the file now.
        actual: String,
    },
    /// Shards that cannot be joined into one dataset.
    #[error("merge: {0}")]
    Merge(String),
    /// The per-sample work (rendering, sensor, writing) failed for one sample.
    #[error("sample {id}: {message}")]
    Sample {
        /// The sample id.
        id: String,
        /// What failed.
        message: String,
    },
    /// A file of the dataset cannot be read or written (the message names it).
    #[error("{0}")]
    File(#[from] polar_io::Error),
    /// A manifest line cannot be read or written.
    #[error("{path}: {message}")]
    Json {
        /// The JSON file.
        path: PathBuf,
        /// The parser's message.
        message: String,
    },
}

impl Error {
    /// Wraps an I/O error with the path it concerns.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Error {
        let path = path.into();
        move |source| Error::Io { path, source }
    }
}
