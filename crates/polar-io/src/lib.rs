//! The only crate that touches files: grayscale and RGB PNG, float EXR with named channels,
//! and the sample-directory format of `conventions.md`.
//!
//! Every reader returns a typed [`Error`] naming the file: missing, truncated or corrupt,
//! wrong colour type or bit depth, odd mosaic size, missing channel, NaN/Inf where not
//! allowed, sizes that disagree within a sample. Every writer is atomic (temporary sibling,
//! then rename), so a crash never leaves a half-written file under the final name.

mod atomic;
mod error;
mod openexr;
mod png;
mod sample;
mod shard;
mod validate;

pub use error::{Error, Result};
pub use openexr::{
    ExrCompression, exr_channel_names, read_exr, read_exr_channel, write_exr, write_exr_with,
};
pub use png::{
    BitDepth, GrayPng, check_mosaic_size, read_gray_png, read_gray8_png, read_mosaic,
    read_rgb8_png, write_gray_png, write_gray8_png, write_gray16_png, write_rgb8_png,
};
pub use sample::{
    GroundTruth, MaterialLabel, Sample, TRANSPARENT_MASK_ON, files, read_ground_truth, read_json,
    read_optional_meta, read_sample, read_sample_with, write_json, write_sample,
};
pub use shard::{Shard, ShardError};
pub use validate::{Rule, Validation, check_channels, check_stokes, check_u8};

/// The most pixels an image may have to be read: 100 megapixels, 40 times a 5-MP sensor.
/// Checked from the file's header before any pixel buffer is allocated, so a small file
/// that claims a huge image is refused at once instead of exhausting memory.
pub const MAX_PIXELS: usize = 100_000_000;

/// Refuses a `width × height` image of more than [`MAX_PIXELS`].
pub(crate) fn check_pixels(path: &std::path::Path, width: usize, height: usize) -> Result<()> {
    match width.checked_mul(height) {
        Some(n) if n <= MAX_PIXELS => Ok(()),
        _ => Err(Error::TooLarge {
            path: path.to_owned(),
            width,
            height,
            max: MAX_PIXELS,
        }),
    }
}

/// Channel names of a full Stokes EXR (`stokes.exr`).
pub const STOKES_CHANNELS: [&str; 4] = ["S0", "S1", "S2", "S3"];
/// Channel names of a linear Stokes EXR (the vision output when S3 is unknown).
pub const LINEAR_STOKES_CHANNELS: [&str; 3] = ["S0", "S1", "S2"];
/// Channel names of the four polarizer images (`polarizers.exr`), in the order of
/// `polar_image::PolarizerStack`.
pub const POLARIZER_CHANNELS: [&str; 4] = ["I0", "I45", "I90", "I135"];
/// Channel names of a 3-vector EXR such as `normal.exr`.
pub const RGB_CHANNELS: [&str; 3] = ["R", "G", "B"];
/// Channel name of a single-channel EXR (`depth.exr`, `dolp.exr`, `aolp.exr`, ...).
pub const Y_CHANNEL: [&str; 1] = ["Y"];
