//! Typed images. The channel count and the meaning of the channels are part of the type
//! (`Image<T, C, K>`, `K` a marker of [`kind`]), so a 4-channel Stokes image, a stack of
//! the four polarizer images and a 1-channel DoLP plane cannot be mixed up.
//! Pixels are stored row-major and interleaved; row 0 is the top row. [`ImageView`]
//! borrows any image (or a rectangle of one) without its kind, for generic code.

mod border;
pub mod kind;
mod par;
mod quantile;
mod view;

use std::marker::PhantomData;

pub use border::Border;
pub use kind::Plain;
pub use par::{PAR_BLOCK, par_fill, par_map};
pub use quantile::quantile;
use thiserror::Error;
pub use view::ImageView;

/// Errors from constructing or combining images.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ImageError {
    /// The buffer length does not equal `width * height * C`.
    #[error(
        "buffer of {len} values does not fit a {width}x{height} image with {channels} channel(s)"
    )]
    BufferSize {
        /// Buffer length given.
        len: usize,
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
        /// Channels per pixel.
        channels: usize,
    },
    /// Two images that must have the same size do not.
    #[error("size mismatch: {0}x{1} vs {2}x{3}")]
    SizeMismatch(usize, usize, usize, usize),
    /// A view's rows do not fit its buffer, or its stride is less than its width.
    #[error(
        "a {width}x{height} view with {channels} channel(s) and a row stride of {stride} pixels does not fit a buffer of {len} values"
    )]
    ViewBounds {
        /// Buffer length given.
        len: usize,
        /// View width.
        width: usize,
        /// View height.
        height: usize,
        /// Pixels from one row start to the next.
        stride: usize,
        /// Channels per pixel.
        channels: usize,
    },
    /// A crop rectangle reaches outside the view it is cut from.
    #[error(
        "a {width}x{height} crop at ({x}, {y}) reaches outside the {outer_width}x{outer_height} view"
    )]
    CropBounds {
        /// Left column of the crop.
        x: usize,
        /// Top row of the crop.
        y: usize,
        /// Crop width.
        width: usize,
        /// Crop height.
        height: usize,
        /// Width of the view cut from.
        outer_width: usize,
        /// Height of the view cut from.
        outer_height: usize,
    },
}

/// A `width × height` image with `C` interleaved channels of type `T` that mean `K`
/// (a marker of [`kind`]; [`Plain`] when the image has no particular meaning).
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T, const C: usize, K = Plain> {
    width: usize,
    height: usize,
    data: Vec<T>,
    kind: PhantomData<K>,
}

/// A single-channel image without a particular meaning (DoLP, AoLP, depth, mask, ...).
pub type Gray<T> = Image<T, 1>;
/// Linear Stokes `S0, S1, S2` per pixel.
pub type LinearStokesImage = Image<f32, 3, kind::LinearStokes>;
/// Full Stokes `S0, S1, S2, S3` per pixel.
pub type StokesImage = Image<f32, 4, kind::Stokes>;
/// The four polarizer images `I0, I45, I90, I135` per pixel.
pub type PolarizerStack = Image<f32, 4, kind::Polarizers>;
/// Unit camera-frame surface normals `x, y, z` per pixel (`0, 0, 0` where no surface).
pub type NormalImage = Image<f32, 3, kind::Normals>;
/// A raw division-of-focal-plane mosaic with samples of type `T` (`u8` or `u16` DN).
pub type Mosaic<T> = Image<T, 1, kind::RawMosaic>;

impl<T: Clone + Default, const C: usize, K> Image<T, C, K> {
    /// An image filled with `T::default()`.
    pub fn new(width: usize, height: usize) -> Self {
        Self::wrap(width, height, vec![T::default(); width * height * C])
    }
}

impl<T, const C: usize, K> Image<T, C, K> {
    /// The image of a buffer whose length is already known to fit.
    fn wrap(width: usize, height: usize, data: Vec<T>) -> Self {
        debug_assert_eq!(data.len(), width * height * C);
        Self {
            width,
            height,
            data,
            kind: PhantomData,
        }
    }

    /// Wraps an interleaved row-major buffer, checking its length.
    pub fn from_vec(width: usize, height: usize, data: Vec<T>) -> Result<Self, ImageError> {
        if data.len() != width * height * C {
            return Err(ImageError::BufferSize {
                len: data.len(),
                width,
                height,
                channels: C,
            });
        }
        Ok(Self::wrap(width, height, data))
    }

    /// The same pixels as an image of kind `K2`, without copying: the one explicit way
    /// to change what an image means (e.g. a plain 4-channel result into a Stokes image).
    pub fn into_kind<K2>(self) -> Image<T, C, K2> {
        Image::wrap(self.width, self.height, self.data)
    }

    /// The whole image as a borrowed view (no copy, no kind).
    pub fn view(&self) -> ImageView<'_, T, C> {
        ImageView::new(&self.data, self.width, self.height, self.width)
            .expect("an image's buffer fits its size")
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The interleaved samples.
    pub fn as_slice(&self) -> &[T] {
        &self.data
    }

    /// The interleaved samples, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.data
    }

    /// Consumes the image, returning its buffer.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }

    /// The pixels as `[T; C]` arrays, row-major.
    pub fn pixels(&self) -> &[[T; C]] {
        self.data.as_chunks::<C>().0
    }

    /// The pixels as mutable `[T; C]` arrays, row-major.
    pub fn pixels_mut(&mut self) -> &mut [[T; C]] {
        self.data.as_chunks_mut::<C>().0
    }

    /// Pixel at column `x`, row `y`.
    pub fn pixel(&self, x: usize, y: usize) -> &[T; C] {
        &self.pixels()[y * self.width + x]
    }

    /// Checks that `other` has the same size.
    pub fn check_same_size<U, const D: usize, L>(
        &self,
        other: &Image<U, D, L>,
    ) -> Result<(), ImageError> {
        if self.size() == other.size() {
            Ok(())
        } else {
            Err(ImageError::SizeMismatch(
                self.width,
                self.height,
                other.width,
                other.height,
            ))
        }
    }
}

impl<T: Copy, const C: usize, K> Image<T, C, K> {
    /// Channel `c` as a new single-channel image.
    pub fn channel(&self, c: usize) -> Gray<T> {
        assert!(c < C, "channel {c} out of range for a {C}-channel image");
        let data = self.pixels().iter().map(|p| p[c]).collect();
        Gray::wrap(self.width, self.height, data)
    }

    /// Builds a `C`-channel image from `C` single-channel images of equal size.
    pub fn from_channels(channels: [&Gray<T>; C]) -> Result<Self, ImageError> {
        let (w, h) = channels[0].size();
        for ch in &channels[1..] {
            channels[0].check_same_size(*ch)?;
        }
        let mut data = Vec::with_capacity(w * h * C);
        for i in 0..w * h {
            data.extend(channels.iter().map(|ch| ch.data[i]));
        }
        Ok(Self::wrap(w, h, data))
    }
}

/// Whether a `width × height` division-of-focal-plane mosaic is made of whole 2×2
/// super-pixels (at least one): the one size rule every mosaic reader and demosaicer checks.
pub fn is_mosaic_size(width: usize, height: usize) -> bool {
    let ok = |n: usize| n >= 2 && n.is_multiple_of(2);
    ok(width) && ok(height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_vec_rejects_wrong_length() {
        let err = Image::<f32, 3>::from_vec(2, 2, vec![0.0; 11]).unwrap_err();
        assert!(matches!(err, ImageError::BufferSize { len: 11, .. }));
    }

    #[test]
    fn channels_round_trip() {
        let img = Image::<u16, 2>::from_vec(2, 1, vec![1, 2, 3, 4]).unwrap();
        let (a, b) = (img.channel(0), img.channel(1));
        assert_eq!(a.as_slice(), &[1, 3]);
        assert_eq!(Image::from_channels([&a, &b]).unwrap(), img);
        assert_eq!(img.pixel(1, 0), &[3, 4]);
    }
}
