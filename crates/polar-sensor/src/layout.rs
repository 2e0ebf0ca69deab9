//! The IMX250MZR mosaic layout: which polarizer angle sits on which pixel.
//!
//! ```text
//!        x even  x odd
//! y even   90°    45°
//! y odd   135°     0°
//! ```
//! This is the layout polanalyser calls `COLOR_PolarMono`. Channels of a
//! [`polar_image::PolarizerStack`] are ordered `I0, I45, I90, I135`.

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

/// An integer raw sample: `u8` or `u16` digital numbers.
pub trait MosaicSample: Copy + Send + Sync + Into<u32> + 'static {
    /// The largest representable value (the saturation level of a full-range sensor).
    const MAX: u32;
}

impl MosaicSample for u8 {
    const MAX: u32 = u8::MAX as u32;
}

impl MosaicSample for u16 {
    const MAX: u32 = u16::MAX as u32;
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
}
