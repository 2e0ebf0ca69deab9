//! The errors every subcommand can report.

use std::path::PathBuf;

use thiserror::Error;

/// A failure of a `polar-vision` subcommand, with enough context to act on it.
#[derive(Debug, Error)]
pub enum CliError {
    /// Reading or writing a file failed.
    #[error(transparent)]
    Io(#[from] polar_io::Error),
    /// The sensor front end rejected the data.
    #[error(transparent)]
    Sensor(#[from] polar_sensor::SensorError),
    /// The input path is neither a PNG file nor a sample directory with raw.png or stokes.exr.
    #[error("{0}: not a PNG file nor a sample directory with raw.png or stokes.exr")]
    Input(PathBuf),
    /// The output directory cannot be used.
    #[error("{path}: cannot use as output directory: {reason}")]
    OutDir {
        /// The directory given.
        path: PathBuf,
        /// Why not.
        reason: String,
    },
    /// `--bit-depth` exceeds what the file stores.
    #[error("{path}: --bit-depth {bits} is more than the {container}-bit samples the PNG stores")]
    BitDepthTooLarge {
        /// The file.
        path: PathBuf,
        /// Requested significant bits.
        bits: u8,
        /// Bits per sample in the file.
        container: u8,
    },
    /// `--black-level` leaves no signal below the saturation level.
    #[error(
        "{path}: --black-level {black} DN is at or above the saturation level ({level} DN): no signal is left"
    )]
    BlackLevel {
        /// The file.
        path: PathBuf,
        /// The black level given.
        black: u16,
        /// The saturation level of the data.
        level: u32,
    },
    /// Data does not fit the declared alignment.
    #[error(
        "{path}: pixel ({x}, {y}) = {value} is not {bits}-bit {align}-aligned data in a {container}-bit PNG{hint}"
    )]
    Alignment {
        /// The file.
        path: PathBuf,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// Offending value.
        value: u16,
        /// Declared significant bits.
        bits: u8,
        /// Bits per sample in the file.
        container: u8,
        /// `left` or `right`.
        align: &'static str,
        /// Suggestion.
        hint: &'static str,
    },
    /// A raw mosaic whose size does not fit its filter pattern.
    #[error(
        "{path}: does not fit the {pattern} pattern (--pattern, or sensor.pattern of meta.json): {source}"
    )]
    Pattern {
        /// The file.
        path: PathBuf,
        /// The pattern it was read as.
        pattern: polar_sensor::MosaicPattern,
        /// What is wrong.
        source: polar_sensor::SensorError,
    },
    /// A key of a JSON file holds a value that cannot be used.
    #[error("{path}: `{key}` is {value}; expected {expected}")]
    MetaValue {
        /// The file.
        path: PathBuf,
        /// The key, dotted (`sensor.pattern`).
        key: &'static str,
        /// The value found, as JSON.
        value: String,
        /// What is accepted.
        expected: String,
    },
    /// Every pixel is zero: no light, nothing to compute (DoLP/AoLP undefined everywhere).
    #[error("{0}: every pixel is 0 (no light); DoLP and AoLP would be undefined everywhere")]
    AllZero(PathBuf),
    /// No pixel of a Stokes image has a positive finite S0 (all zero, negative or NaN).
    #[error(
        "{0}: no pixel has a positive, finite S0 (no light); DoLP and AoLP would be undefined everywhere"
    )]
    NoLight(PathBuf),
    /// Every pixel is at the saturation level: the intensities are unknown.
    #[error(
        "{path}: every pixel is saturated (at {level} DN for {bits}-bit data); Stokes images would be meaningless"
    )]
    AllSaturated {
        /// The file.
        path: PathBuf,
        /// Saturation level in DN.
        level: u32,
        /// Significant bits.
        bits: u8,
    },
    /// `--input` names a file the sample directory does not have.
    #[error("{dir}: has no {file} (asked for by --input)")]
    MissingSource {
        /// The sample directory.
        dir: PathBuf,
        /// The missing file.
        file: &'static str,
    },
    /// The object mask of `--objects` cannot be used.
    #[error("{path}: cannot use as the object mask (--objects): {reason}")]
    Objects {
        /// The mask file.
        path: PathBuf,
        /// Why not.
        reason: String,
    },
    /// Ground truth of another size than the input.
    #[error("{sample}: the input is {}x{} but its ground truth is {}x{} (a half-resolution demosaicing such as superpixel cannot be scored)", input.0, input.1, gt.0, gt.1)]
    GtSize {
        /// The sample.
        sample: PathBuf,
        /// Input size.
        input: (usize, usize),
        /// Ground-truth size.
        gt: (usize, usize),
    },
    /// A folder holds no sample directories.
    #[error("{0}: no sample directories (sub-folders with raw.png or stokes.exr) found")]
    NoSamples(PathBuf),
    /// Shards evaluated with different options cannot be merged.
    #[error("{0}: evaluated with other options than the first shard; cannot merge")]
    MergeOptions(PathBuf),
    /// Shards of different selections of samples cannot be merged.
    #[error("{}: evaluated over another selection of samples (dataset, --family or number of shards) than the first shard; cannot merge", .0.display())]
    MergeSelection(PathBuf),
    /// The shards given miss samples of their selection.
    #[error(
        "the shards given hold {found} of the {expected} samples their evaluation selected (shard(s) {seen} of {shards} given): a shard is missing or did not finish"
    )]
    MergeIncomplete {
        /// Samples recorded in the shards given.
        found: usize,
        /// Samples of the selection.
        expected: usize,
        /// The shards given, e.g. `1, 3`.
        seen: String,
        /// Number of shards.
        shards: u32,
    },
    /// One sample recorded in two shard folders: which record counts is not known.
    #[error("{name}: recorded in two shard folders, {} and {}; give each shard's folder once", first.display(), second.display())]
    MergeDuplicate {
        /// The sample.
        name: String,
        /// Its record folder in the first shard given.
        first: PathBuf,
        /// Its record folder in the other.
        second: PathBuf,
    },
    /// A file or folder could not be read or written.
    #[error("{path}: {action}: {reason}")]
    File {
        /// The path.
        path: PathBuf,
        /// `cannot read` or `cannot write`.
        action: &'static str,
        /// The system's reason.
        reason: String,
    },
    /// A model file cannot be used (says which file and what is wrong).
    #[error("{0}")]
    Model(String),
    /// The command line does not parse (or asks for help).
    #[error("{0}")]
    Usage(String),
    /// The worker thread pool could not be made.
    #[error("cannot start worker threads: {0}")]
    Threads(String),
    /// Metrics could not be serialized.
    #[error("cannot serialize metrics: {0}")]
    Json(String),
    /// A task's library reported an error on valid input (a bug to report).
    #[error("{task}: {message}")]
    Task {
        /// The task.
        task: &'static str,
        /// Its error.
        message: String,
    },
}

impl CliError {
    /// A read failure of `path`.
    pub fn read(path: impl Into<PathBuf>, e: std::io::Error) -> Self {
        CliError::File {
            path: path.into(),
            action: "cannot read",
            reason: e.to_string(),
        }
    }

    /// A write failure of `path`.
    pub fn write(path: impl Into<PathBuf>, e: std::io::Error) -> Self {
        CliError::File {
            path: path.into(),
            action: "cannot write",
            reason: e.to_string(),
        }
    }
}
