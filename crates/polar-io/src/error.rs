//! The one error type of this crate. Every variant names the file it is about.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Errors from reading or writing images and sample directories.
#[derive(Debug, Error)]
pub enum Error {
    /// The file (or directory) does not exist.
    #[error("{path}: no such file or directory")]
    NotFound {
        /// The missing path.
        path: PathBuf,
    },
    /// An operating-system error other than "not found" (permissions, disk full, ...).
    #[error("{path}: {source}")]
    Io {
        /// The file being read or written.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// The file ends early or its bytes do not decode as the expected format.
    #[error("{path}: truncated or corrupt {format} file: {detail}")]
    Corrupt {
        /// The file.
        path: PathBuf,
        /// "PNG", "EXR" or "JSON".
        format: &'static str,
        /// What the decoder reported.
        detail: String,
    },
    /// The header claims more pixels than [`crate::MAX_PIXELS`]; refused before decoding.
    #[error("{path}: {width}x{height} is more than the {max} pixels this reader accepts")]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Width in the header.
        width: usize,
        /// Height in the header.
        height: usize,
        /// The limit.
        max: usize,
    },
    /// An EXR whose pixels times channels exceed [`crate::MAX_EXR_SAMPLES`]; refused before
    /// decoding.
    #[error(
        "{path}: {pixels} pixels of {channels} channels is more than the {max} samples this reader accepts"
    )]
    TooManySamples {
        /// The file.
        path: PathBuf,
        /// Pixels in the header.
        pixels: usize,
        /// Channels in the header.
        channels: usize,
        /// The limit.
        max: usize,
    },
    /// The image has a colour type this reader does not accept (e.g. an RGB PNG as a mosaic).
    #[error("{path}: colour type {found}, expected {expected}")]
    ColorType {
        /// The file.
        path: PathBuf,
        /// The colour type in the file, e.g. "Rgb8".
        found: String,
        /// What the reader accepts.
        expected: &'static str,
    },
    /// A PNG palette holds 1 to 256 colours; the one given does not.
    #[error("{path}: a palette of {entries} colours; a PNG palette holds 1 to 256")]
    Palette {
        /// The file.
        path: PathBuf,
        /// The colours given.
        entries: usize,
    },
    /// The image has a bit depth this reader does not accept.
    #[error("{path}: bit depth {found}, expected {expected}")]
    BitDepth {
        /// The file.
        path: PathBuf,
        /// Bits per sample in the file.
        found: u8,
        /// What the reader accepts.
        expected: &'static str,
    },
    /// A mosaic whose size cannot hold whole 2x2 super-pixels.
    #[error("{path}: mosaic is {width}x{height}; width and height must be even and at least 2")]
    MosaicSize {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// An image that no file format here can store (zero or more than `u32::MAX` pixels wide/high).
    #[error("{path}: cannot store a {width}x{height} image")]
    Dimensions {
        /// The file.
        path: PathBuf,
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// A value too large for the bit depth it is written at.
    #[error("{path}: value {value} at pixel ({x}, {y}) does not fit in {bits} bits")]
    ValueRange {
        /// The file.
        path: PathBuf,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// The offending value.
        value: u32,
        /// Bit depth of the file.
        bits: u8,
    },
    /// An EXR file lacks a channel the caller asked for.
    #[error("{path}: no channel {channel:?}; channels present: {present:?}")]
    MissingChannel {
        /// The file.
        path: PathBuf,
        /// The channel asked for.
        channel: String,
        /// The channels the file has.
        present: Vec<String>,
    },
    /// Channel names given for writing are empty or repeated.
    #[error("{path}: bad channel names {names:?}: {reason}")]
    ChannelNames {
        /// The file.
        path: PathBuf,
        /// The names given.
        names: Vec<String>,
        /// What is wrong with them.
        reason: &'static str,
    },
    /// An EXR file with other than one layer (this project writes single-layer files).
    #[error("{path}: {layers} layers, expected exactly one")]
    LayerCount {
        /// The file.
        path: PathBuf,
        /// Number of layers found.
        layers: usize,
    },
    /// A sample value breaks a rule of the format (NaN, Inf, negative S0, unknown label, ...).
    #[error("{path}: channel {channel} at pixel ({x}, {y}) is {value}, must be {requirement}")]
    InvalidValue {
        /// The file.
        path: PathBuf,
        /// Channel name.
        channel: String,
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// The offending value.
        value: f64,
        /// The rule it breaks.
        requirement: &'static str,
    },
    /// Two files of one sample have different sizes.
    #[error("{path}: size {found:?} differs from {expected:?} of {reference}")]
    SizeMismatch {
        /// The file with the unexpected size.
        path: PathBuf,
        /// Its `(width, height)`.
        found: (usize, usize),
        /// The `(width, height)` of the reference file.
        expected: (usize, usize),
        /// The file the size was taken from.
        reference: PathBuf,
    },
    /// An image that goes with a frame (an object mask) has another size, judged from its
    /// header before its pixels are decoded.
    #[error("{path}: it is {}x{}, the frame {}x{}", found.0, found.1, frame.0, frame.1)]
    FrameSize {
        /// The image.
        path: PathBuf,
        /// Its `(width, height)`.
        found: (usize, usize),
        /// The frame's `(width, height)`.
        frame: (usize, usize),
    },
    /// `meta.json` is valid JSON but not an object.
    #[error("{path}: meta.json must hold a JSON object, found {found}")]
    MetaNotObject {
        /// The file.
        path: PathBuf,
        /// The JSON type found ("array", "string", ...).
        found: &'static str,
    },
    /// Serializing a value to JSON failed (a map with non-string keys, ...).
    #[error("{path}: cannot write JSON: {source}")]
    JsonWrite {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: serde_json::Error,
    },
}

impl Error {
    /// Maps an `std::io::Error` on `path` to `NotFound`, `Corrupt` (unexpected end of file) or `Io`.
    pub(crate) fn io(path: &Path, format: &'static str, source: std::io::Error) -> Self {
        match source.kind() {
            std::io::ErrorKind::NotFound => Error::NotFound {
                path: path.to_owned(),
            },
            std::io::ErrorKind::UnexpectedEof => Error::Corrupt {
                path: path.to_owned(),
                format,
                detail: source.to_string(),
            },
            _ => Error::Io {
                path: path.to_owned(),
                source,
            },
        }
    }

    /// A `Corrupt` error for `path`.
    pub(crate) fn corrupt(path: &Path, format: &'static str, detail: impl ToString) -> Self {
        Error::Corrupt {
            path: path.to_owned(),
            format,
            detail: detail.to_string(),
        }
    }
}

/// Result with this crate's [`Error`](enum@Error).
pub type Result<T, E = Error> = std::result::Result<T, E>;
