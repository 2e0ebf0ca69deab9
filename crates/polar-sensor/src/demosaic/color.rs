//! Colour polarization mosaics (Sony IMX250MYR, polanalyser's `COLOR_PolarRGB`): colour
//! first, then polarization, as polanalyser does it.
//!
//! 1. [`split_colors`]: the samples of each polarizer angle (every other pixel in x and y)
//!    form an RGGB Bayer image at half resolution; OpenCV's bilinear Bayer demosaicing
//!    (`COLOR_BayerBG2BGR`) of each gives R, G and B at every pixel of that angle, so each
//!    colour becomes a full-resolution mosaic in the monochrome layout. Per sample, with
//!    the rounding of [`mean2`]/[`mean4`]: its own colour kept; at red and blue the other
//!    two from the four-neighbour cross (green) and the four diagonals; at green red and
//!    blue from the left/right or up/down pair. OpenCV's border rule applies on the
//!    half-resolution image: its outermost rows and columns copy their inner neighbours.
//!    Half-resolution images 2 wide or high have no interior (OpenCV and so polanalyser
//!    return zeros there); we take each 2x2 Bayer block's own R, B and mean G instead.
//! 2. Each colour's mosaic goes through the monochrome demosaicing of [`super::demosaic`]
//!    (or the fused chains of [`crate::products`]); with `bilinear` the whole chain is
//!    polanalyser's `COLOR_PolarRGB` bit for bit.

use polar_image::{ImageView, PolarizerStack};
use rayon::prelude::*;

use super::DemosaicMethod;
use super::bilinear::{mean2, mean4};
use crate::SensorError;
use crate::layout::{COLOR_AT, Mosaic, MosaicPattern, MosaicSample};

/// Splits a colour mosaic (width and height multiples of 4) into one monochrome-layout
/// mosaic per colour, `[R, G, B]`, by OpenCV's bilinear Bayer interpolation on each
/// polarizer angle's samples (step 1 of the module doc).
pub fn split_colors<T: MosaicSample>(raw: &Mosaic<T>) -> Result<[Mosaic<T>; 3], SensorError> {
    let (w, h) = raw.size();
    MosaicPattern::Rgb.check_size(w, h)?;
    let src = raw.view();
    let mut out = [(); 3].map(|_| Mosaic::<T>::new(w, h));
    let [r, g, b] = out.each_mut().map(|m| m.as_mut_slice().par_chunks_mut(w));
    r.zip(g).zip(b).enumerate().for_each(|(y, ((r, g), b))| {
        for x in 0..w {
            let rgb = bayer_at(src, x, y);
            (r[x], g[x], b[x]) = (T::from_dn(rgb[0]), T::from_dn(rgb[1]), T::from_dn(rgb[2]));
        }
    });
    Ok(out)
}

/// Demosaics a colour mosaic into the four polarizer images of each colour, `[R, G, B]`
/// (channels `I0, I45, I90, I135`, in DN; size `method.output_size(..)`).
pub fn demosaic_rgb<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
) -> Result<[PolarizerStack; 3], SensorError> {
    let [r, g, b] = split_colors(raw)?;
    Ok([
        super::demosaic(&r, method)?,
        super::demosaic(&g, method)?,
        super::demosaic(&b, method)?,
    ])
}

/// `[R, G, B]` at pixel `(x, y)` of the colour mosaic `raw`: the bilinear Bayer values of
/// the half-resolution image of the polarizer under `(x, y)`.
#[inline]
fn bayer_at<T: MosaicSample>(raw: ImageView<'_, T, 1>, x: usize, y: usize) -> [u32; 3] {
    let (w, h) = raw.size();
    let (px, py, qw, qh) = (x & 1, y & 1, w / 2, h / 2);
    // Sample (i, j) of this polarizer's half-resolution Bayer image.
    let q = |i: usize, j: usize| -> u32 { raw.at(2 * i + px, 2 * j + py).into() };
    let (qx, qy) = (x >> 1, y >> 1);
    if qw < 4 || qh < 4 {
        let (bx, by) = (qx & !1, qy & !1);
        return [
            q(bx, by),
            mean2(q(bx + 1, by), q(bx, by + 1)),
            q(bx + 1, by + 1),
        ];
    }
    let (i, j) = (qx.clamp(1, qw - 2), qy.clamp(1, qh - 2));
    let own = q(i, j);
    let hor = || mean2(q(i - 1, j), q(i + 1, j));
    let ver = || mean2(q(i, j - 1), q(i, j + 1));
    let cross = || mean4(q(i - 1, j), q(i + 1, j), q(i, j - 1), q(i, j + 1));
    let diag = || {
        mean4(
            q(i - 1, j - 1),
            q(i + 1, j - 1),
            q(i - 1, j + 1),
            q(i + 1, j + 1),
        )
    };
    match (COLOR_AT[j & 1][i & 1], j & 1) {
        (0, _) => [own, cross(), diag()],
        (2, _) => [diag(), cross(), own],
        // Green on a red row: red left and right, blue above and below.
        (_, 0) => [hor(), own, ver()],
        _ => [ver(), own, hor()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::layout::color_at;

    /// A mosaic whose every sample is its colour's value: each split plane is that value.
    #[test]
    fn flat_colours_split_into_flat_planes() {
        for (w, h) in [(16, 12), (8, 8), (4, 8), (4, 4)] {
            let data = (0..w * h)
                .map(|k| [10u16, 200, 3000][color_at(k % w, k / w)])
                .collect();
            let raw = Mosaic::from_vec(w, h, data).unwrap();
            let planes = split_colors(&raw).unwrap();
            for (c, want) in [10u16, 200, 3000].into_iter().enumerate() {
                assert!(
                    planes[c].as_slice().iter().all(|&v| v == want),
                    "{w}x{h} colour {c}"
                );
            }
        }
    }

    /// Own colour kept in the interior; each sample only mixes samples of its own polarizer.
    #[test]
    fn own_samples_are_kept_and_polarizers_do_not_mix() {
        let (w, h) = (16, 16);
        // Value = 1000 * polarizer position + colour-dependent noise.
        let data: Vec<u16> = (0..w * h)
            .map(|k| {
                let (x, y) = (k % w, k / w);
                (1000 * ((y & 1) * 2 + (x & 1)) + (k * 37) % 300) as u16
            })
            .collect();
        let raw = Mosaic::from_vec(w, h, data.clone()).unwrap();
        let planes = split_colors(&raw).unwrap();
        for y in 2..h - 2 {
            for x in 2..w - 2 {
                let k = y * w + x;
                assert_eq!(planes[color_at(x, y)].as_slice()[k], data[k], "({x},{y})");
                for plane in &planes {
                    assert_eq!(
                        plane.as_slice()[k] / 1000,
                        data[k] / 1000,
                        "({x},{y}) took another polarizer's sample"
                    );
                }
            }
        }
    }

    #[test]
    fn sizes_not_multiple_of_four_are_rejected() {
        let err = split_colors(&Mosaic::<u8>::new(6, 8)).unwrap_err();
        assert_eq!(
            err,
            SensorError::ColorSize {
                width: 6,
                height: 8
            }
        );
        assert!(demosaic_rgb(&Mosaic::<u8>::new(8, 10), DemosaicMethod::Bilinear).is_err());
    }
}
