//! The IMX250MZR mosaic layout: which polarizer angle sits on which pixel.
//!
//! ```text
//!        x even  x odd
//! y even   90°    45°
//! y odd   135°     0°
//! ```
//! This is the layout polanalyser calls `COLOR_PolarMono`. Channels of a
//! [`polar_image::PolarizerStack`] are ordered `I0, I45, I90, I135`.
//!
//! A colour sensor (Sony IMX250MYR, polanalyser's `COLOR_PolarRGB`) puts one colour filter
//! over each whole 2x2 polarizer block and arranges the blocks in an RGGB Bayer pattern, so
//! the pattern repeats every 4x4 pixels ([`MosaicPattern::Rgb`], [`color_at`]):
//! ```text
//!        x 0..1  x 2..3
//! y 0..1    R       G
//! y 2..3    G       B
//! ```
//! Inside each block the polarizers are as above. The samples of one polarizer angle
//! (every other pixel in x and y) thus form an ordinary RGGB Bayer image.

use std::fmt;
use std::str::FromStr;

use crate::SensorError;

/// A raw mosaic with samples of type `T` (`u8` or `u16`), in the layout above: its own
/// image kind, so it cannot be passed where a plain single-channel image is expected.
pub use polar_image::Mosaic;

/// Polarizer angles in degrees of the four stack channels, in channel order.
pub const CHANNEL_ANGLES_DEG: [f64; 4] = [0.0, 45.0, 90.0, 135.0];

/// Stack channel index (0 = I0, 1 = I45, 2 = I90, 3 = I135) of each super-pixel position, `[y & 1][x & 1]`.
pub const CHANNEL_AT: [[usize; 2]; 2] = [[2, 1], [3, 0]];

/// Stack channel index of the polarizer over pixel `(x, y)`.
#[inline]
pub fn channel_at(x: usize, y: usize) -> usize {
    CHANNEL_AT[y & 1][x & 1]
}

/// Position `(dx, dy)` of channel `c` inside its 2x2 super-pixel.
pub fn offset_of(c: usize) -> (usize, usize) {
    match c {
        0 => (1, 1),
        1 => (1, 0),
        2 => (0, 0),
        _ => (0, 1),
    }
}

/// Colour names of the colour channels, in channel order (0 = red, 1 = green, 2 = blue).
pub const COLOR_NAMES: [&str; 3] = ["R", "G", "B"];

/// Colour channel (0 R, 1 G, 2 B) of each 2x2 polarizer block of a colour mosaic,
/// `[(y >> 1) & 1][(x >> 1) & 1]`: RGGB blocks.
pub const COLOR_AT: [[usize; 2]; 2] = [[0, 1], [1, 2]];

/// Colour channel of the filter over pixel `(x, y)` of a colour mosaic.
#[inline]
pub fn color_at(x: usize, y: usize) -> usize {
    COLOR_AT[(y >> 1) & 1][(x >> 1) & 1]
}

/// The filters over a raw frame: polarizers only, or polarizers under colour filters.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum MosaicPattern {
    /// Sony IMX250MZR: 2x2 polarizer super-pixels (polanalyser's `COLOR_PolarMono`).
    #[default]
    Mono,
    /// Sony IMX250MYR: 2x2 polarizer blocks of one colour, the blocks in an RGGB Bayer
    /// pattern (polanalyser's `COLOR_PolarRGB`).
    Rgb,
}

impl MosaicPattern {
    /// Every pattern, in the order of help texts.
    pub const ALL: [Self; 2] = [Self::Mono, Self::Rgb];

    /// The name used on the command line and in `meta.json`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Mono => "mono",
            Self::Rgb => "rgb",
        }
    }

    /// All pattern names.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|p| p.name()).collect()
    }

    /// Pixels per side of the repeating tile: 2 (polarizers) or 4 (polarizers and colours).
    pub fn period(self) -> usize {
        match self {
            Self::Mono => 2,
            Self::Rgb => 4,
        }
    }

    /// Checks that a `width x height` frame holds whole tiles of the pattern.
    pub fn check_size(self, width: usize, height: usize) -> Result<(), SensorError> {
        crate::check_mosaic_size(width, height)?;
        let n = self.period();
        if width.is_multiple_of(n) && height.is_multiple_of(n) {
            Ok(())
        } else {
            Err(SensorError::ColorSize { width, height })
        }
    }
}

impl fmt::Display for MosaicPattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for MosaicPattern {
    type Err = SensorError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| SensorError::UnknownPattern(s.to_string()))
    }
}

/// An integer raw sample: `u8` or `u16` digital numbers.
pub trait MosaicSample: Copy + Default + Send + Sync + Into<u32> + 'static {
    /// The largest representable value (the saturation level of a full-range sensor).
    const MAX: u32;

    /// The sample of value `v <= Self::MAX` (e.g. a mean of samples).
    fn from_dn(v: u32) -> Self;
}

impl MosaicSample for u8 {
    const MAX: u32 = u8::MAX as u32;

    fn from_dn(v: u32) -> Self {
        debug_assert!(v <= <Self as MosaicSample>::MAX);
        v as u8
    }
}

impl MosaicSample for u16 {
    const MAX: u32 = u16::MAX as u32;

    fn from_dn(v: u32) -> Self {
        debug_assert!(v <= <Self as MosaicSample>::MAX);
        v as u16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_invert_channel_at() {
        for c in 0..4 {
            let (dx, dy) = offset_of(c);
            assert_eq!(channel_at(dx, dy), c);
            assert_eq!(channel_at(dx + 2, dy + 4), c);
        }
    }

    #[test]
    fn layout_matches_the_conventions() {
        let angle = |x, y| CHANNEL_ANGLES_DEG[channel_at(x, y)];
        assert_eq!(
            [angle(0, 0), angle(1, 0), angle(0, 1), angle(1, 1)],
            [90.0, 45.0, 135.0, 0.0]
        );
    }

    #[test]
    fn colour_blocks_are_rggb_of_whole_polarizer_blocks() {
        let names: Vec<&str> = (0..8).map(|x| COLOR_NAMES[color_at(x, 1)]).collect();
        assert_eq!(names, ["R", "R", "G", "G", "R", "R", "G", "G"]);
        let names: Vec<&str> = (0..8).map(|x| COLOR_NAMES[color_at(x, 2)]).collect();
        assert_eq!(names, ["G", "G", "B", "B", "G", "G", "B", "B"]);
        assert_eq!(color_at(5, 7), color_at(1, 3));
    }

    #[test]
    fn pattern_names_and_sizes() {
        for p in MosaicPattern::ALL {
            assert_eq!(p.name().parse::<MosaicPattern>().unwrap(), p);
        }
        assert_eq!(
            "bayer".parse::<MosaicPattern>().unwrap_err(),
            SensorError::UnknownPattern("bayer".into())
        );
        assert_eq!(MosaicPattern::Mono.check_size(6, 2), Ok(()));
        assert_eq!(MosaicPattern::Rgb.check_size(8, 4), Ok(()));
        assert_eq!(
            MosaicPattern::Rgb.check_size(6, 8).unwrap_err(),
            SensorError::ColorSize {
                width: 6,
                height: 8
            }
        );
        assert!(matches!(
            MosaicPattern::Rgb.check_size(5, 8).unwrap_err(),
            SensorError::OddSize { .. }
        ));
    }
}
