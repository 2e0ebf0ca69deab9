//! Borrowed views: a `width × height` window of interleaved pixels whose rows start
//! `stride` pixels apart, so a whole image, a rectangle of one or a plane held in any
//! buffer can be read row by row without copying.

use crate::{Image, ImageError};

/// A borrowed `width × height` window of `C`-channel pixels of type `T`, rows `stride`
/// pixels apart. It carries no kind: it is the form in which the generic operations and
/// the demosaicers read any image ([`Image::view`]); [`ImageView::to_image`] copies it
/// back into an image of a chosen kind.
#[derive(Debug)]
pub struct ImageView<'a, T, const C: usize> {
    data: &'a [T],
    width: usize,
    height: usize,
    stride: usize,
}

// Not derived: a view is a pair of references and numbers, `Copy` whatever `T` is.
impl<T, const C: usize> Clone for ImageView<'_, T, C> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T, const C: usize> Copy for ImageView<'_, T, C> {}

impl<'a, T, const C: usize> ImageView<'a, T, C> {
    /// A view of the interleaved buffer `data`: pixel `(x, y)` starts at sample
    /// `(y * stride + x) * C`. Needs `stride >= width` and a buffer that holds the last
    /// row; longer buffers are fine (the view is then a part of them).
    pub fn new(
        data: &'a [T],
        width: usize,
        height: usize,
        stride: usize,
    ) -> Result<Self, ImageError> {
        match span::<C>(width, height, stride) {
            Some(n) if stride >= width && n <= data.len() => Ok(Self {
                data: &data[..n],
                width,
                height,
                stride,
            }),
            _ => Err(ImageError::ViewBounds {
                len: data.len(),
                width,
                height,
                stride,
                channels: C,
            }),
        }
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

    /// Pixels from the start of one row to the start of the next (`>= width`).
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The interleaved samples of row `y` (`width * C` of them).
    ///
    /// # Panics
    /// If `y >= height`, as slice indexing does.
    #[inline]
    pub fn row(&self, y: usize) -> &'a [T] {
        assert!(y < self.height, "row {y} of a view {} high", self.height);
        let start = y * self.stride * C;
        &self.data[start..start + self.width * C]
    }

    /// The rows, top to bottom.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = &'a [T]> + use<'a, T, C> {
        let view = *self;
        (0..self.height).map(move |y| view.row(y))
    }

    /// Pixel at column `x`, row `y`.
    ///
    /// # Panics
    /// If `(x, y)` is outside the view.
    #[inline]
    pub fn pixel(&self, x: usize, y: usize) -> &'a [T; C] {
        self.check_column(x);
        &self.data.as_chunks::<C>().0[y * self.stride + x]
    }

    /// Panics unless column `x` lies inside the view, where a position beyond the right edge
    /// may still be inside the buffer (the next row's or a crop's neighbour's). Rows need no
    /// check here: the buffer ends with the last row (see [`span`]), so a row below the
    /// view fails the slice's own bounds check.
    #[inline(always)]
    #[track_caller]
    fn check_column(&self, x: usize) {
        if x >= self.width {
            outside_column(x, self.width);
        }
    }

    /// The `width × height` rectangle whose top-left pixel is `(x, y)`, sharing this
    /// view's buffer and stride; an error if it does not lie inside the view.
    pub fn crop(
        &self,
        x: usize,
        y: usize,
        width: usize,
        height: usize,
    ) -> Result<Self, ImageError> {
        let inside =
            |at: usize, n: usize, limit: usize| at.checked_add(n).is_some_and(|e| e <= limit);
        if !(inside(x, width, self.width) && inside(y, height, self.height)) {
            return Err(ImageError::CropBounds {
                x,
                y,
                width,
                height,
                outer_width: self.width,
                outer_height: self.height,
            });
        }
        if width == 0 || height == 0 {
            return Ok(Self {
                data: &[],
                width,
                height,
                stride: width,
            });
        }
        let start = (y * self.stride + x) * C;
        let n = span::<C>(width, height, self.stride).expect("inside a view that fits");
        Ok(Self {
            data: &self.data[start..start + n],
            width,
            height,
            stride: self.stride,
        })
    }
}

impl<T: Copy> ImageView<'_, T, 1> {
    /// The sample at column `x`, row `y` of a single-channel view.
    ///
    /// # Panics
    /// If `(x, y)` is outside the view.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> T {
        self.check_column(x);
        self.data[y * self.stride + x]
    }
}

impl<T: Clone, const C: usize> ImageView<'_, T, C> {
    /// Copies the window into a new contiguous image of kind `K`.
    pub fn to_image<K>(&self) -> Image<T, C, K> {
        let mut data = Vec::with_capacity(self.width * self.height * C);
        for row in self.rows() {
            data.extend_from_slice(row);
        }
        Image::from_vec(self.width, self.height, data).expect("rows of the view fill the image")
    }
}

/// Samples from the first pixel of a view to the end of its last row, `None` on overflow.
fn span<const C: usize>(width: usize, height: usize, stride: usize) -> Option<usize> {
    match height {
        0 => Some(0),
        _ => (height - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(width))
            .and_then(|n| n.checked_mul(C)),
    }
}

/// The panic of an access right of a view, out of line so that the check stays small
/// enough to inline into per-pixel loops.
#[cold]
#[inline(never)]
#[track_caller]
fn outside_column(x: usize, width: usize) -> ! {
    panic!("column {x} outside a view {width} wide")
}
