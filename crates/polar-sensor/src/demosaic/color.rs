//! Colour polarization mosaics (Sony IMX250MYR, polanalyser's `COLOR_PolarRGB`): colour
//! first, then polarization, as polanalyser does it.
//!
//! 1. [`split_colors`]: the samples of each polarizer angle (every other pixel in x and y)
//!    form an RGGB Bayer image at half resolution; OpenCV's bilinear Bayer demosaicing
//!    (`COLOR_BayerBG2BGR`) of each gives R, G and B at every pixel of that angle, so each
//!    colour becomes a full-resolution mosaic in the monochrome layout. Per sample, with
//!    the rounding of `mean2`/`mean4`: its own colour kept; at red and blue the other
//!    two from the four-neighbour cross (green) and the four diagonals; at green red and
//!    blue from the left/right or up/down pair. OpenCV's border rule applies on the
//!    half-resolution image: its outermost rows and columns copy their inner neighbours.
//!    Half-resolution images 2 wide or high have no interior (OpenCV and so polanalyser
//!    return zeros there); we take each 2x2 Bayer block's own R, B and mean G instead.
//! 2. Each colour's mosaic goes through the monochrome demosaicing of [`super::demosaic`]
//!    (or the fused chains of [`crate::products`]); with `bilinear` the whole chain is
//!    polanalyser's `COLOR_PolarRGB` bit for bit.

use polar_image::{ImageView, PolarizerStack};
use pulp::{Arch, Simd, WithSimd};
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
    let arch = Arch::new();
    r.zip(g)
        .zip(b)
        .enumerate()
        .for_each(|(y, ((r, g), b))| split_row(src, y, [r, g, b], arch));
    Ok(out)
}

/// Row `y` of each colour's mosaic of [`split_colors`] (`raw` of a valid colour size), the
/// row kernel on the SIMD target `arch` where the half-resolution images are at least 4x4.
pub(crate) fn split_row<T: MosaicSample>(
    raw: ImageView<'_, T, 1>,
    y: usize,
    [r, g, b]: [&mut [T]; 3],
    arch: Arch,
) {
    let (w, h) = raw.size();
    let mut set = |x: usize| {
        let [vr, vg, vb] = bayer_at(raw, x, y).map(T::from_dn);
        (r[x], g[x], b[x]) = (vr, vg, vb);
    };
    if w < 8 || h < 8 {
        return (0..w).for_each(set);
    }
    [0, 1, w - 2, w - 1].into_iter().for_each(&mut set);
    let out = [&mut r[2..w - 2], &mut g[2..w - 2], &mut b[2..w - 2]];
    arch.dispatch(SplitRow { raw, y, out });
}

/// [`split_row_interior`] as a `pulp` operation, so that its loop is compiled for each
/// SIMD target and the best one of the CPU runs (as the fused rows of [`crate::products`]).
struct SplitRow<'a, T> {
    raw: ImageView<'a, T, 1>,
    y: usize,
    out: [&'a mut [T]; 3],
}

impl<T: MosaicSample> WithSimd for SplitRow<'_, T> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        split_row_interior(self.raw, self.y, self.out);
    }
}

/// Columns `2..w-2` of output row `y` of [`split_colors`] (half-resolution images at least
/// 4x4; `out` holds just those columns), equal to [`bayer_at`] there: one uniform loop over
/// the row with per-column selects instead of per-pixel clamping, so that it vectorises.
#[inline(always)]
fn split_row_interior<T: MosaicSample>(
    raw: ImageView<'_, T, 1>,
    y: usize,
    [r, g, b]: [&mut [T]; 3],
) {
    let (w, h) = raw.size();
    let j = (y >> 1).clamp(1, h / 2 - 2);
    let [up, mid, dn] = [j - 1, j, j + 1].map(|jj| raw.row(2 * jj + (y & 1)));
    let n = w - 4;
    // Every slice re-cut to exactly `n` so that the loop has no bounds checks.
    fn cut<T>(s: &[T], start: usize, n: usize) -> &[T] {
        &s[start..start + n]
    }
    let at = |s, start| cut(s, start, n);
    let (o, l, rt, u, d) = (at(mid, 2), at(mid, 0), at(mid, 4), at(up, 2), at(dn, 2));
    let (ul, ur, dl, dr) = (at(up, 0), at(up, 4), at(dn, 0), at(dn, 4));
    let (r, g, b) = (&mut r[..n], &mut g[..n], &mut b[..n]);
    // Row parity j and the parity of the half-resolution column (k + 2) >> 1 give the
    // colour of the centre sample; the other two colours come from the means around it.
    let odd_j = j & 1 == 1;
    for k in 0..n {
        let v = |s: &[T]| -> u32 { s[k].into() };
        let own = v(o);
        let (hor, ver) = (mean2(v(l), v(rt)), mean2(v(u), v(d)));
        let cross = mean4(v(l), v(rt), v(u), v(d));
        let diag = mean4(v(ul), v(ur), v(dl), v(dr));
        let odd_i = k & 2 == 0;
        let rgb = if odd_j {
            // Green (even i) or blue (odd i) centre.
            [
                if odd_i { diag } else { ver },
                if odd_i { cross } else { own },
                if odd_i { own } else { hor },
            ]
        } else {
            // Red (even i) or green (odd i) centre.
            [
                if odd_i { hor } else { own },
                if odd_i { own } else { cross },
                if odd_i { ver } else { diag },
            ]
        };
        (r[k], g[k], b[k]) = (T::from_dn(rgb[0]), T::from_dn(rgb[1]), T::from_dn(rgb[2]));
    }
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

    /// The row kernel (interior columns, SIMD-dispatched) equals the per-pixel [`bayer_at`]
    /// at every pixel, on every row parity and at the clamped border rows, for u8 and u16.
    #[test]
    fn row_kernel_equals_per_pixel_rule() {
        fn check<T: MosaicSample>(w: usize, h: usize, value: impl Fn(usize) -> u32) {
            let data = (0..w * h).map(|k| T::from_dn(value(k))).collect();
            let raw = Mosaic::<T>::from_vec(w, h, data).unwrap();
            let planes = split_colors(&raw).unwrap();
            for y in 0..h {
                for x in 0..w {
                    let want = bayer_at(raw.view(), x, y);
                    let got = planes.each_ref().map(|p| p.as_slice()[y * w + x].into());
                    assert_eq!(got, want, "{w}x{h} ({x},{y})");
                }
            }
        }
        check::<u8>(24, 16, |k| ((k * 7919) % 251) as u32);
        check::<u16>(16, 12, |k| ((k * 104_729) % 65_521) as u32);
        check::<u8>(8, 8, |k| ((k * 31) % 256) as u32);
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
