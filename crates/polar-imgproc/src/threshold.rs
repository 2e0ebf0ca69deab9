//! Otsu's threshold (N. Otsu, "A threshold selection method from gray-level histograms",
//! IEEE SMC 1979), bit-for-bit as `skimage.filters.threshold_otsu(image, nbins=256)`.

use polar_image::Gray;
use rayon::prelude::*;

use crate::Error;

/// Number of histogram bins for float images (scikit-image's default `nbins`).
const NBINS: usize = 256;

/// Index of the bin whose centre maximises the between-class variance
/// `w1 w2 (mu1 - mu2)^2`, evaluated in `f64` in the same order as scikit-image (first
/// maximum wins).
fn otsu_index(counts: &[u64], centers: &[f64]) -> usize {
    let n = counts.len();
    let weighted: Vec<f64> = counts
        .iter()
        .zip(centers)
        .map(|(&c, &x)| c as f64 * x)
        .collect();
    let (mut w1, mut m1) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut cw, mut cs) = (0u64, 0.0f64);
    for (c, s) in counts.iter().zip(&weighted) {
        cw += c;
        cs += s;
        w1.push(cw);
        m1.push(cs / cw as f64);
    }
    let (mut w2, mut m2) = (vec![0u64; n], vec![0.0f64; n]);
    let (mut cw, mut cs) = (0u64, 0.0f64);
    for i in (0..n).rev() {
        cw += counts[i];
        cs += weighted[i];
        w2[i] = cw;
        m2[i] = cs / cw as f64;
    }
    let mut best = (0, f64::NEG_INFINITY);
    for i in 0..n - 1 {
        let d = m1[i] - m2[i + 1];
        let v = (w1[i] * w2[i + 1]) as f64 * (d * d);
        if v > best.1 {
            best = (i, v);
        }
    }
    best.0
}

/// Otsu threshold of a float image, equal to `skimage.filters.threshold_otsu(image)`:
/// a 256-bin histogram over `[min, max]` built exactly as `numpy.histogram` does for
/// `float32` (edges `min + i * ((max - min) / 256)` in `f32`, last edge = max, last bin
/// closed), and the centre of the winning bin is returned. A constant image returns its
/// value. Pixels `> threshold` are foreground.
pub fn threshold_otsu(src: &Gray<f32>) -> Result<f32, Error> {
    let s = src.as_slice();
    let first = *s.first().ok_or(Error::Empty(src.width(), src.height()))?;
    let (lo, hi) = s
        .par_iter()
        .fold(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |(a, b), &v| (a.min(v), b.max(v)),
        )
        .reduce(
            || (f32::INFINITY, f32::NEG_INFINITY),
            |(a, b), (c, d)| (a.min(c), b.max(d)),
        );
    if s.iter().any(|v| !v.is_finite()) {
        return Err(Error::NonFinite);
    }
    if lo == hi {
        return Ok(first);
    }
    let delta = hi - lo;
    let step = delta / NBINS as f32;
    let mut edges: Vec<f32> = (0..=NBINS).map(|i| i as f32 * step + lo).collect();
    edges[NBINS] = hi;
    let bin = |v: f32| -> usize {
        let mut i = (((v - lo) / delta) * NBINS as f32) as usize;
        i = i.min(NBINS - 1);
        if v < edges[i] {
            i -= 1;
        }
        if i != NBINS - 1 && v >= edges[i + 1] {
            i += 1;
        }
        i
    };
    let counts = s
        .par_chunks(1 << 16)
        .map(|c| {
            let mut h = vec![0u64; NBINS];
            c.iter().for_each(|&v| h[bin(v)] += 1);
            h
        })
        .reduce(
            || vec![0u64; NBINS],
            |mut a, b| {
                a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                a
            },
        );
    let centers: Vec<f32> = edges.windows(2).map(|e| (e[0] + e[1]) / 2.0).collect();
    let c64: Vec<f64> = centers.iter().map(|&c| f64::from(c)).collect();
    Ok(centers[otsu_index(&counts, &c64)])
}

/// Otsu threshold of an 8-bit image, equal to `skimage.filters.threshold_otsu(image)` for
/// `uint8`: one bin per integer value from min to max (scikit-image does not rebin
/// integer images). Pixels `> threshold` are foreground.
pub fn threshold_otsu_u8(src: &Gray<u8>) -> Result<u8, Error> {
    let s = src.as_slice();
    let first = *s.first().ok_or(Error::Empty(src.width(), src.height()))?;
    let mut hist = [0u64; 256];
    s.iter().for_each(|&v| hist[usize::from(v)] += 1);
    let lo = hist.iter().position(|&c| c > 0).unwrap_or(0);
    let hi = hist.iter().rposition(|&c| c > 0).unwrap_or(0);
    if lo == hi {
        return Ok(first);
    }
    let centers: Vec<f64> = (lo..=hi).map(|v| v as f64).collect();
    Ok((lo + otsu_index(&hist[lo..=hi], &centers)) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bimodal_image_splits_between_modes() {
        let v: Vec<f32> = (0..100).map(|i| if i < 60 { 0.2 } else { 0.8 }).collect();
        let t = threshold_otsu(&Gray::from_vec(10, 10, v).unwrap()).unwrap();
        // Between the modes, and the lowest bin centre that separates them (first maximum).
        assert!(t > 0.2 && t < 0.21, "{t}");
        assert_eq!(
            threshold_otsu(&Gray::from_vec(2, 1, vec![0.5, 0.5]).unwrap()).unwrap(),
            0.5
        );
        let u = Gray::from_vec(4, 1, vec![10u8, 10, 200, 200]).unwrap();
        assert_eq!(threshold_otsu_u8(&u).unwrap(), 10);
    }

    #[test]
    fn non_finite_input_is_rejected() {
        let img = Gray::from_vec(2, 1, vec![0.5, f32::NAN]).unwrap();
        assert_eq!(threshold_otsu(&img), Err(Error::NonFinite));
    }
}
