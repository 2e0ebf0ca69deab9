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
    /// Every pixel is zero: no light, nothing to compute (DoLP/AoLP undefined everywhere).
    #[error("{0}: every pixel is 0 (no light); DoLP and AoLP would be undefined everywhere")]
    AllZero(PathBuf),
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
}
