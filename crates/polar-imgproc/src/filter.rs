//! Separable linear filters: Gaussian blur, normalised box filter, Sobel and Scharr.
//!
//! `imageproc` was considered and not used: its Gaussian builds the kernel differently
//! from `cv::getGaussianKernel` and it clamps (replicates) at the border, so it cannot
//! match `cv2.GaussianBlur`/`cv2.Sobel`, which reflect (`BORDER_REFLECT_101`).

use polar_image::Gray;

use crate::{BAND_ROWS, Border, Error, same_size};

/// Rows per band for a filter of vertical radius `ry`: the halo rows a band recomputes
/// stay at or below a fifth of its work.
pub(crate) fn band_rows(ry: usize) -> usize {
    BAND_ROWS.max(8 * ry)
}

/// The kernel of `cv::getGaussianKernel(ksize, sigma)` as OpenCV 5 builds it: for
/// `sigma <= 0` and `ksize` 1, 3, 5, 7 or 9 its fixed tables (the 9-tap one is
/// `[4, 13, 30, 51, 60, 51, 30, 13, 4] / 256`, new in OpenCV 5); otherwise `exp(-x^2 / (2 sigma^2))` with
/// `x = i - (ksize-1)/2` and `sigma = 0.3 ((ksize-1)/2 - 1) + 0.8` when `sigma <= 0`,
/// normalised to sum 1 in double precision and rounded to `f32`.
pub fn gaussian_kernel(ksize: usize, sigma: f64) -> Result<Vec<f32>, Error> {
    if ksize == 0 || ksize.is_multiple_of(2) {
        return Err(Error::KernelSize {
            ksize,
            reason: "must be odd and positive",
        });
    }
    const FIXED: [&[f64]; 5] = [
        &[1.0],
        &[0.25, 0.5, 0.25],
        &[0.0625, 0.25, 0.375, 0.25, 0.0625],
        &[
            0.03125, 0.109375, 0.21875, 0.28125, 0.21875, 0.109375, 0.03125,
        ],
        &[4.0, 13.0, 30.0, 51.0, 60.0, 51.0, 30.0, 13.0, 4.0],
    ];
    let half = (ksize as f64 - 1.0) * 0.5;
    let raw: Vec<f64> = if sigma <= 0.0 && ksize <= 9 {
        FIXED[ksize / 2].to_vec()
    } else {
        let s = if sigma > 0.0 {
            sigma
        } else {
            (half - 1.0) * 0.3 + 0.8
        };
        let scale2 = -0.5 / (s * s);
        (0..ksize)
            .map(|i| (scale2 * (i as f64 - half).powi(2)).exp())
            .collect()
    };
    let sum: f64 = raw.iter().sum();
    Ok(raw.iter().map(|v| (v / sum) as f32).collect())
}

/// `ksize` that `cv2.GaussianBlur` derives for float images when given `ksize = 0`:
/// `round(sigma * 4 * 2 + 1) | 1`.
fn auto_ksize(sigma: f64) -> usize {
    (sigma * 8.0 + 1.0).round() as usize | 1
}

/// Gaussian blur matching `cv2.GaussianBlur(src, (ksize, ksize), sigma)` on `float32`
/// with the default border `BORDER_REFLECT_101`. `ksize = 0` derives the size from
/// `sigma` as OpenCV does; `sigma <= 0` derives sigma from `ksize`.
pub fn gaussian_blur(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    ksize: usize,
    sigma: f64,
) -> Result<(), Error> {
    let ksize = match (ksize, sigma > 0.0) {
        (0, true) => auto_ksize(sigma),
        (0, false) => {
            return Err(Error::KernelSize {
                ksize,
                reason: "0 needs sigma > 0",
            });
        }
        (k, _) => k,
    };
    let k = gaussian_kernel(ksize, sigma)?;
    sep_filter(src, dst, &k, &k, Border::Reflect101)
}

/// Separable correlation `dst(x, y) = sum_j ky[j] sum_i kx[i] src(x + i - ax, y + j - ay)`
/// with the anchor at the kernel centre (`ax = kx.len() / 2`), as `cv2.sepFilter2D` with
/// `float32` output; `border` chooses the extrapolation. Kernel lengths must be odd.
pub fn sep_filter(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    kx: &[f32],
    ky: &[f32],
    border: Border,
) -> Result<(), Error> {
    same_size(src, dst)?;
    for k in [kx, ky] {
        if k.len() % 2 == 0 {
            return Err(Error::KernelSize {
                ksize: k.len(),
                reason: "must be odd",
            });
        }
    }
    let (w, h) = src.size();
    let (rx, ry) = (kx.len() / 2, ky.len() / 2);
    let rows = band_rows(ry);
    let s = src.as_slice();
    crate::par_bands(
        dst.as_mut_slice(),
        w,
        rows,
        |y0, out, sc: &mut (Vec<f32>, Vec<f32>)| {
            let n_out = out.len() / w;
            let pad = crate::scratch(&mut sc.0, w + 2 * rx, 0.0);
            let tmp = crate::scratch(&mut sc.1, (n_out + 2 * ry) * w, 0.0);
            for (t, trow) in tmp.chunks_exact_mut(w).enumerate() {
                let y = border.index((y0 + t) as isize - ry as isize, h);
                border.pad_row(&s[y * w..(y + 1) * w], rx, pad);
                let pad: &[f32] = pad;
                correlate(kx, |i| &pad[i..i + w], trow);
            }
            let tmp: &[f32] = tmp;
            for (r, orow) in out.chunks_exact_mut(w).enumerate() {
                correlate(ky, |j| &tmp[(r + j) * w..(r + j + 1) * w], orow);
            }
        },
    );
    Ok(())
}

/// `out = sum_i k[i] tap(i)` over equal-length slices, tap-major so the inner loops
/// vectorise. Symmetric kernels (Gaussian, smoothers) and antisymmetric ones (first
/// derivatives) fold pairs of taps first, halving the multiplications.
#[inline(always)]
pub(crate) fn correlate<'a>(k: &[f32], tap: impl Fn(usize) -> &'a [f32], out: &mut [f32]) {
    let n = k.len();
    let r = n / 2;
    let symmetric = (0..r).all(|i| k[i] == k[n - 1 - i]);
    let antisymmetric = k[r] == 0.0 && (0..r).all(|i| k[i] == -k[n - 1 - i]);
    if symmetric || antisymmetric {
        // b enters as sgn * b (exact for sgn = +-1); two tap pairs per pass over `out`.
        let sgn = if symmetric { 1.0f32 } else { -1.0 };
        let kr = k[r];
        let pair = |i: usize| (k[i], tap(i), tap(n - 1 - i));
        match r {
            0 => out.iter_mut().zip(tap(0)).for_each(|(o, &v)| *o = kr * v),
            _ => {
                let (k0, a0, b0) = pair(0);
                out.iter_mut()
                    .zip(tap(r).iter().zip(a0.iter().zip(b0)))
                    .for_each(|(o, (&c, (&a, &b)))| *o = kr * c + k0 * (a + sgn * b));
            }
        }
        let mut i = 1;
        while i + 1 < r {
            let ((ki, ai, bi), (kj, aj, bj)) = (pair(i), pair(i + 1));
            out.iter_mut()
                .zip(ai.iter().zip(bi).zip(aj.iter().zip(bj)))
                .for_each(|(o, ((&a, &b), (&c, &d)))| {
                    *o += ki * (a + sgn * b) + kj * (c + sgn * d)
                });
            i += 2;
        }
        if i < r {
            let (ki, ai, bi) = pair(i);
            out.iter_mut()
                .zip(ai.iter().zip(bi))
                .for_each(|(o, (&a, &b))| *o += ki * (a + sgn * b));
        }
        return;
    }
    out.fill(0.0);
    for (i, &ki) in k.iter().enumerate() {
        out.iter_mut().zip(tap(i)).for_each(|(o, &v)| *o += ki * v);
    }
}

/// Normalised box filter (mean over a `kw x kh` window centred on the pixel), matching
/// `cv2.boxFilter(src, -1, (kw, kh), normalize=True, borderType=border)` on `float32`.
/// Like OpenCV it keeps running sums in `f64`, so the cost does not grow with the window
/// and the result is the correctly rounded mean to within one `f32` ulp.
/// `cv2.blur`/`cv2.boxFilter` default to `Border::Reflect101`.
pub fn box_filter(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    kw: usize,
    kh: usize,
    border: Border,
) -> Result<(), Error> {
    same_size(src, dst)?;
    for k in [kw, kh] {
        if k % 2 == 0 {
            return Err(Error::KernelSize {
                ksize: k,
                reason: "must be odd and positive",
            });
        }
    }
    let (w, h) = src.size();
    let (rx, ry) = (kw / 2, kh / 2);
    let scale = 1.0 / (kw * kh) as f64;
    let rows = band_rows(ry);
    let s = src.as_slice();
    crate::par_bands(
        dst.as_mut_slice(),
        w,
        rows,
        |y0, out, sc: &mut (Vec<f32>, Vec<f64>, Vec<f64>)| {
            let n_out = out.len() / w;
            let pad = crate::scratch(&mut sc.0, w + 2 * rx, 0.0);
            let tmp = crate::scratch(&mut sc.1, (n_out + 2 * ry) * w, 0.0);
            for (t, trow) in tmp.chunks_exact_mut(w).enumerate() {
                let y = border.index((y0 + t) as isize - ry as isize, h);
                border.pad_row(&s[y * w..(y + 1) * w], rx, pad);
                row_box_sum(pad, kw, trow);
            }
            let col = crate::scratch(&mut sc.2, w, 0.0);
            col.copy_from_slice(&tmp[..w]);
            for j in 1..kh {
                col.iter_mut()
                    .zip(&tmp[j * w..(j + 1) * w])
                    .for_each(|(c, v)| *c += v);
            }
            for (r, orow) in out.chunks_exact_mut(w).enumerate() {
                orow.iter_mut()
                    .zip(col.iter())
                    .for_each(|(o, c)| *o = (c * scale) as f32);
                if r + 1 < n_out {
                    let (add, sub) = (
                        &tmp[(r + kh) * w..(r + kh + 1) * w],
                        &tmp[r * w..(r + 1) * w],
                    );
                    for ((c, a), s) in col.iter_mut().zip(add).zip(sub) {
                        *c += a - s;
                    }
                }
            }
        },
    );
    Ok(())
}

/// Sums of `kw` consecutive values of `pad` in `f64`: `out[x] = sum(pad[x .. x + kw])`.
/// Short windows add the taps directly (vectorised); long ones keep running sums in four
/// interleaved segments so that the add/subtract chains overlap in the pipeline.
#[inline(always)]
fn row_box_sum(pad: &[f32], kw: usize, out: &mut [f64]) {
    let w = out.len();
    if kw <= 9 && kw % 2 == 1 {
        // Three taps in the first pass, two in each further one (fewer stores).
        let t = |i: usize| &pad[i..i + w];
        let f = f64::from;
        match kw {
            1 => out.iter_mut().zip(t(0)).for_each(|(o, &a)| *o = f(a)),
            _ => out
                .iter_mut()
                .zip(t(0).iter().zip(t(1).iter().zip(t(2))))
                .for_each(|(o, (&a, (&b, &c)))| *o = f(a) + f(b) + f(c)),
        }
        for i in (3..kw).step_by(2) {
            out.iter_mut()
                .zip(t(i).iter().zip(t(i + 1)))
                .for_each(|(o, (&a, &b))| *o += f(a) + f(b));
        }
        return;
    }
    const SEG: usize = 4;
    let seg = w.div_ceil(SEG);
    let start = |j: usize| (j * seg).min(w);
    let mut acc = [0.0f64; SEG];
    // Segments past the row's end are empty (narrow rows): nothing to start there.
    for (j, a) in acc.iter_mut().enumerate().filter(|&(j, _)| start(j) < w) {
        *a = pad[start(j)..start(j) + kw]
            .iter()
            .map(|&v| f64::from(v))
            .sum();
    }
    for i in 0..seg {
        for (j, a) in acc.iter_mut().enumerate() {
            let x = start(j) + i;
            if x >= start(j + 1) {
                continue;
            }
            if i > 0 {
                *a += f64::from(pad[x + kw - 1]) - f64::from(pad[x - 1]);
            }
            out[x] = *a;
        }
    }
}

/// The derivative / smoothing kernel pair of `cv::getDerivKernels(dx, dy, ksize)`
/// (unnormalised): a binomial smoother of length `ksize - order` convolved `order` times
/// with the difference `[-1, 1]`. `ksize = 1` means 3 taps for a derivative and 1 tap
/// for no derivative, as in OpenCV. Returns `(kx, ky)`.
pub fn sobel_kernels(dx: usize, dy: usize, ksize: usize) -> Result<(Vec<f32>, Vec<f32>), Error> {
    if !matches!(ksize, 1 | 3 | 5 | 7) {
        return Err(Error::KernelSize {
            ksize,
            reason: "Sobel supports 1, 3, 5, 7",
        });
    }
    if dx + dy == 0 || dx >= ksize.max(3) || dy >= ksize.max(3) {
        return Err(Error::Parameter {
            name: "dx+dy",
            value: (dx + dy) as f64,
            reason: "need dx + dy >= 1 and each order < ksize",
        });
    }
    let one = |order: usize| -> Vec<f32> {
        let n = if ksize == 1 && order > 0 { 3 } else { ksize };
        let mut k = vec![1.0f64];
        for _ in 0..n - 1 - order {
            k = convolve(&k, &[1.0, 1.0]);
        }
        for _ in 0..order {
            k = convolve(&k, &[-1.0, 1.0]);
        }
        k.iter().map(|&v| v as f32).collect()
    };
    Ok((one(dx), one(dy)))
}

/// Full discrete convolution of two short kernels.
fn convolve(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Sobel derivative matching `cv2.Sobel(src, cv2.CV_32F, dx, dy, ksize=ksize)` (scale 1,
/// delta 0, `BORDER_REFLECT_101`). Positive `dx` response where intensity grows to the
/// right, positive `dy` where it grows downward (image rows).
pub fn sobel(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    dx: usize,
    dy: usize,
    ksize: usize,
) -> Result<(), Error> {
    let (kx, ky) = sobel_kernels(dx, dy, ksize)?;
    sep_filter(src, dst, &kx, &ky, Border::Reflect101)
}

/// Scharr derivative matching `cv2.Scharr(src, cv2.CV_32F, dx, dy)` (`dx + dy == 1`,
/// kernel `[-1, 0, 1] x [3, 10, 3]`, `BORDER_REFLECT_101`).
pub fn scharr(src: &Gray<f32>, dst: &mut Gray<f32>, dx: usize, dy: usize) -> Result<(), Error> {
    if dx + dy != 1 {
        return Err(Error::Parameter {
            name: "dx+dy",
            value: (dx + dy) as f64,
            reason: "Scharr needs exactly one of dx, dy = 1",
        });
    }
    let (d, s) = ([-1.0f32, 0.0, 1.0], [3.0f32, 10.0, 3.0]);
    let (kx, ky) = if dx == 1 { (d, s) } else { (s, d) };
    sep_filter(src, dst, &kx, &ky, Border::Reflect101)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide_box_on_narrow_images_matches_the_direct_sum() {
        // Regression: windows wider than 9 on rows of 1, 2, 3, 5, 6 or 9 pixels indexed
        // past the padded row (an empty fourth segment).
        for w in 1..12 {
            let src = Gray::from_vec(w, 3, (0..3 * w).map(|i| i as f32).collect()).unwrap();
            let mut dst = Gray::new(w, 3);
            box_filter(&src, &mut dst, 11, 1, Border::Reflect101).unwrap();
            for y in 0..3 {
                for x in 0..w {
                    let sum: f32 = (-5..=5)
                        .map(|d| {
                            src.as_slice()[y * w + Border::Reflect101.index(x as isize + d, w)]
                        })
                        .sum();
                    let got = dst.as_slice()[y * w + x];
                    assert!(
                        (got - sum / 11.0).abs() < 1e-4,
                        "w {w} ({x},{y}): {got} vs {}",
                        sum / 11.0
                    );
                }
            }
        }
    }

    #[test]
    fn gaussian_kernel_fixed_tables_and_formula() {
        assert_eq!(gaussian_kernel(3, 0.0).unwrap(), [0.25, 0.5, 0.25]);
        assert_eq!(gaussian_kernel(9, 0.0).unwrap()[4], 60.0 / 256.0);
        let k = gaussian_kernel(11, 0.0).unwrap();
        // sigma = 0.3 * (5 - 1) + 0.8 = 2.0; the centre tap of a normalised Gaussian.
        let s = 2.0f64;
        let norm: f64 = (-5..=5)
            .map(|x| (-(x * x) as f64 / (2.0 * s * s)).exp())
            .sum();
        assert!((f64::from(k[5]) - 1.0 / norm).abs() < 1e-7);
        assert!(gaussian_kernel(4, 1.0).is_err());
    }

    #[test]
    fn sobel_kernels_match_opencv_tables() {
        let (kx, ky) = sobel_kernels(1, 0, 3).unwrap();
        assert_eq!(
            (kx.as_slice(), ky.as_slice()),
            (&[-1.0, 0.0, 1.0][..], &[1.0, 2.0, 1.0][..])
        );
        let (kx, ky) = sobel_kernels(2, 0, 5).unwrap();
        assert_eq!(kx, [1.0, 0.0, -2.0, 0.0, 1.0]);
        assert_eq!(ky, [1.0, 4.0, 6.0, 4.0, 1.0]);
        let (kx, ky) = sobel_kernels(0, 1, 1).unwrap();
        assert_eq!(
            (kx.as_slice(), ky.as_slice()),
            (&[1.0][..], &[-1.0, 0.0, 1.0][..])
        );
    }

    #[test]
    fn box_filter_of_constant_is_constant_and_sobel_of_ramp_is_8() {
        let src = Gray::from_vec(7, 5, vec![0.25f32; 35]).unwrap();
        let mut dst = Gray::new(7, 5);
        box_filter(&src, &mut dst, 5, 3, Border::Reflect101).unwrap();
        assert!(dst.as_slice().iter().all(|&v| v == 0.25));
        let ramp = Gray::from_vec(7, 5, (0..35).map(|i| (i % 7) as f32).collect()).unwrap();
        sobel(&ramp, &mut dst, 1, 0, 3).unwrap();
        // Interior: (x+1) - (x-1) = 2, times the smoother sum 4. Reflect101 edges give 0.
        assert_eq!(dst.pixel(3, 2)[0], 8.0);
        assert_eq!(dst.pixel(0, 2)[0], 0.0);
    }

    #[test]
    fn size_mismatch_is_an_error() {
        let src = Gray::<f32>::new(4, 4);
        let mut dst = Gray::new(4, 3);
        assert!(matches!(
            gaussian_blur(&src, &mut dst, 3, 0.0),
            Err(Error::SizeMismatch(4, 4, 4, 3))
        ));
    }
}
