//! The only crate that touches files: grayscale and RGB PNG, float EXR with named channels,
//! and the sample-directory format of `conventions.md`.
//!
//! Every reader returns a typed [`Error`] naming the file: missing, truncated or corrupt,
//! wrong colour type or bit depth, odd mosaic size, missing channel, NaN/Inf where not
//! allowed, sizes that disagree within a sample. Every writer is atomic (temporary sibling,
//! then rename), so a failed program never leaves a half-written file under the final name.
//! Small records ([`write_atomic`], [`write_json`]) are also synced to disk before the
//! rename; images are synced where their folder is committed ([`StagedDir::commit`]).

use std::sync::atomic::{AtomicUsize, Ordering};

mod atomic;
mod checksum;
mod error;
mod openexr;
mod png;
mod sample;
mod shard;
mod staged;
mod validate;

pub use atomic::write_atomic;
pub use checksum::{sha256_file, sha256_hex};
pub use error::{Error, Result};
pub use openexr::{
    ExrCompression, exr_channel_names, read_exr, read_exr_channel, read_exr_from, write_exr,
    write_exr_plane, write_exr_planes, write_exr_planes3, write_exr_with,
};
pub use png::{
    BitDepth, GrayPng, MosaicPng, check_mosaic_size, read_gray_png, read_gray_png_from,
    read_gray8_png, read_mask_png, read_mask_png_from, read_mosaic, read_mosaic_from,
    read_rgb8_png, write_gray_png, write_gray8_png, write_gray16_png, write_indexed8_png,
    write_indexed8_png_rows, write_rgb8_png, write_rgb8_png_rows,
};
pub use sample::{
    GroundTruth, MaterialLabel, Sample, TRANSPARENT_MASK_ON, files, parse_json, parse_meta,
    read_ground_truth, read_json, read_optional_meta, read_sample, read_sample_with, write_json,
    write_sample, write_sample_into,
};
pub use shard::{Shard, ShardError};
pub use staged::{StagedDir, check_replaceable};
pub use validate::{Rule, Validation, check_channels, check_stokes, check_u8};

/// The default of the most pixels an image may have to be read: 100 megapixels, 20 times
/// a 5-MP sensor. Checked from the file's header before any pixel buffer is allocated, so
/// a small file that claims a huge image is refused at once instead of exhausting memory.
pub const MAX_PIXELS: usize = 100_000_000;

static PIXEL_LIMIT: AtomicUsize = AtomicUsize::new(MAX_PIXELS);

/// Sets the pixel limit of every reader in this process (default [`MAX_PIXELS`]); a
/// program sets it once from its options (e.g. `polar-vision --max-pixels`).
pub fn set_max_pixels(limit: usize) {
    PIXEL_LIMIT.store(limit, Ordering::Relaxed);
}

/// The pixel limit of the readers ([`set_max_pixels`]).
pub fn max_pixels() -> usize {
    PIXEL_LIMIT.load(Ordering::Relaxed)
}

/// The most samples (pixels times channels, all channels of the file counted) an EXR may
/// have to be read at the default pixel limit: [`MAX_PIXELS`] pixels of 4 channels (a
/// Stokes image), 1.6 GB as `f32` (4 × [`max_pixels`] when the limit is set).
/// Every channel of a file is decoded, so without this a file of many channels could ask
/// for any amount of memory within the pixel limit.
pub const MAX_EXR_SAMPLES: usize = 4 * MAX_PIXELS;

/// Refuses a `width × height` image of more than [`max_pixels`].
pub(crate) fn check_pixels(path: &std::path::Path, width: usize, height: usize) -> Result<()> {
    let max = max_pixels();
    match width.checked_mul(height) {
        Some(n) if n <= max => Ok(()),
        _ => Err(Error::TooLarge {
            path: path.to_owned(),
            width,
            height,
            max,
        }),
    }
}

/// Channel names of a full Stokes EXR (`stokes.exr`).
pub const STOKES_CHANNELS: [&str; 4] = ["S0", "S1", "S2", "S3"];
/// Channel names of a linear Stokes EXR (the vision output when S3 is unknown).
pub const LINEAR_STOKES_CHANNELS: [&str; 3] = ["S0", "S1", "S2"];
/// Channel names of a colour linear Stokes EXR (`stokes.exr` of a colour sensor): each of
/// [`LINEAR_STOKES_CHANNELS`] per colour of [`RGB_CHANNELS`], `S0.R, S0.G, S0.B, S1.R, ...`,
/// the names Mitsuba 3's `stokes` integrator writes in RGB modes.
pub const RGB_LINEAR_STOKES_CHANNELS: [&str; 9] = [
    "S0.R", "S0.G", "S0.B", "S1.R", "S1.G", "S1.B", "S2.R", "S2.G", "S2.B",
];
/// Channel names of the four polarizer images (`polarizers.exr`), in the order of
/// `polar_image::PolarizerStack`.
pub const POLARIZER_CHANNELS: [&str; 4] = ["I0", "I45", "I90", "I135"];
/// Channel names of a 3-vector EXR such as `normal.exr`.
pub const RGB_CHANNELS: [&str; 3] = ["R", "G", "B"];
/// Channel name of a single-channel EXR (`depth.exr`, `dolp.exr`, `aolp.exr`, ...).
pub const Y_CHANNEL: [&str; 1] = ["Y"];

#[cfg(test)]
mod tests {
    use super::*;

    /// The colour Stokes names are `<Stokes name>.<colour name>`, Stokes-major.
    #[test]
    fn colour_stokes_names_combine_stokes_and_colour_names() {
        let want: Vec<String> = LINEAR_STOKES_CHANNELS
            .iter()
            .flat_map(|s| RGB_CHANNELS.iter().map(move |c| format!("{s}.{c}")))
            .collect();
        assert_eq!(RGB_LINEAR_STOKES_CHANNELS.to_vec(), want);
    }
}
