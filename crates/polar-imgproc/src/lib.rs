//! Classic image-processing primitives for the analysis crates, each validated
//! against the implementation users trust (OpenCV 5 / opencv-contrib, scikit-image 0.26)
//! by golden files written by `tools/imgproc_goldens.py` and replayed in `tests/golden.rs`.
//!
//! Conventions (as in kornia-rs): an operation takes `(&src, &mut dst)` and returns
//! `Result<_, Error>`; the caller allocates `dst` with the right size; nothing here does
//! I/O. Images are [`Gray<f32>`](polar_image::Gray) (`Gray<u8>` for masks and class maps,
//! `Gray<u32>` for label maps). Work is split over row bands with rayon.
//!
//! | function | matches | border |
//! |---|---|---|
//! | [`gaussian_blur`] | `cv2.GaussianBlur(src, (k, k), sigma)` | `BORDER_REFLECT_101` |
//! | [`box_filter`] | `cv2.boxFilter(src, -1, (kw, kh), normalize=True)` | chosen, default `REFLECT_101` |
//! | [`sobel`], [`scharr`] | `cv2.Sobel(src, CV_32F, dx, dy, k)`, `cv2.Scharr` | `BORDER_REFLECT_101` |
//! | [`sep_filter`] | `cv2.sepFilter2D(src, CV_32F, kx, ky)` | chosen |
//! | [`erode`], [`dilate`], [`open`], [`close`], [`min_filter`], [`max_filter`] | `cv2.erode`/`dilate`/`morphologyEx` with `getStructuringElement` | outside pixels ignored (OpenCV's default constant border) |
//! | [`median_blur`], [`median_blur_u8`] | `cv2.medianBlur` | `BORDER_REPLICATE` |
//! | [`guided_filter`] | `cv2.ximgproc.guidedFilter(guide, src, r, eps)` | `BORDER_REFLECT` (its box means) |
//! | [`threshold_otsu`], [`threshold_otsu_u8`] | `skimage.filters.threshold_otsu` | - |
//! | [`label`], [`component_stats`] | `skimage.measure.label`, `cv2.connectedComponentsWithStats` | - |
//! | [`psnr`], [`ssim`], [`ssim_map`] | `skimage.metrics.peak_signal_noise_ratio`, `structural_similarity` | SSIM: `BORDER_REFLECT` (scipy `reflect`) |
//! | [`angular_error`], [`iou`], [`ConfusionMatrix`] | numpy formulas in the golden script | - |
//! | [`distance_to_background`] | `cv2.distanceTransform(src, DIST_L2, DIST_MASK_PRECISE)` | chosen ([`Outside`]) |

mod distance;
mod filter;
mod guided;
mod label;
pub mod mask;
mod median;
mod metrics;
mod morph;
mod threshold;

pub use distance::{Outside, distance_to_background};
pub use filter::{
    box_filter, gaussian_blur, gaussian_kernel, scharr, sep_filter, sobel, sobel_kernels,
};
pub use guided::guided_filter;
pub use label::{ComponentStats, Connectivity, component_stats, label};
pub use median::{median_blur, median_blur_u8};
pub use metrics::{
    AngularErrorStats, ConfusionMatrix, angular_error, angular_error_map, iou, psnr, ssim, ssim_map,
};
pub use morph::{MorphShape, close, dilate, erode, max_filter, min_filter, open};
pub use polar_image::Border;
pub use threshold::{threshold_otsu, threshold_otsu_u8};

use thiserror::Error;

/// Errors of the image-processing primitives.
#[derive(Debug, Error, PartialEq)]
pub enum Error {
    /// Source and destination (or two inputs) differ in size.
    #[error("size mismatch: {0}x{1} vs {2}x{3}")]
    SizeMismatch(usize, usize, usize, usize),
    /// The image has no pixels.
    #[error("empty image ({0}x{1})")]
    Empty(usize, usize),
    /// A kernel size is not allowed (must be odd and in the supported set).
    #[error("kernel size {ksize} not supported: {reason}")]
    KernelSize {
        /// Requested kernel size.
        ksize: usize,
        /// What is allowed.
        reason: &'static str,
    },
    /// A parameter is out of its valid range.
    #[error("invalid parameter {name} = {value}: {reason}")]
    Parameter {
        /// Parameter name.
        name: &'static str,
        /// Given value.
        value: f64,
        /// What is allowed.
        reason: &'static str,
    },
    /// The input holds a NaN or infinite value where only finite values make sense.
    #[error("non-finite value in input")]
    NonFinite,
    /// A label or class value is outside `0..n_classes`.
    #[error("class value {value} outside 0..{n_classes}")]
    ClassOutOfRange {
        /// Offending value.
        value: u32,
        /// Number of classes.
        n_classes: usize,
    },
}

/// Checks that two images have the same size.
pub(crate) fn same_size<T, U, const C: usize, const D: usize, K, L>(
    a: &polar_image::Image<T, C, K>,
    b: &polar_image::Image<U, D, L>,
) -> Result<(), Error> {
    if a.size() != b.size() {
        return Err(Error::SizeMismatch(
            a.width(),
            a.height(),
            b.width(),
            b.height(),
        ));
    }
    if a.width() == 0 || a.height() == 0 {
        return Err(Error::Empty(a.width(), a.height()));
    }
    Ok(())
}

/// Runs `f(first_row, band, scratch)` over bands of `rows` image rows of `dst` (row
/// width `w`) in parallel. Scratch buffers are reused across the bands of one rayon job
/// instead of being allocated per band.
pub(crate) fn par_bands<T: Send, S: Default>(
    dst: &mut [T],
    w: usize,
    rows: usize,
    f: impl Fn(usize, &mut [T], &mut S) + Sync + Send,
) {
    use rayon::prelude::*;
    dst.par_chunks_mut(w * rows)
        .enumerate()
        .for_each_init(S::default, |s, (b, out)| f(b * rows, out, s));
}

/// The first `n` elements of `v`, growing it (with `fill`) if needed; old contents stay.
pub(crate) fn scratch<T: Clone>(v: &mut Vec<T>, n: usize, fill: T) -> &mut [T] {
    if v.len() < n {
        v.resize(n, fill);
    }
    &mut v[..n]
}

/// Rows per rayon task: big enough to amortise the halo rows a band recomputes,
/// small enough to keep a band's scratch in L2 and both cores busy.
pub(crate) const BAND_ROWS: usize = 32;
