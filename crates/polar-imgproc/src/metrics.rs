//! Image-quality and task metrics: PSNR, SSIM (as scikit-image computes them), angular
//! error of normal maps, IoU and confusion matrices.

use polar_image::{Gray, NormalImage};
use rayon::prelude::*;

use crate::{BAND_ROWS, Border, Error, same_size};

/// Peak signal-to-noise ratio `10 log10(R^2 / MSE)` in dB, as
/// `skimage.metrics.peak_signal_noise_ratio(reference, test, data_range=R)` on `float32`:
/// squared differences in `f32`, their mean in `f64`. Identical images give `+inf`.
pub fn psnr(reference: &Gray<f32>, test: &Gray<f32>, data_range: f64) -> Result<f64, Error> {
    same_size(reference, test)?;
    check_range(data_range)?;
    let chunk_sums: Vec<f64> = reference
        .as_slice()
        .par_chunks(1 << 14)
        .zip(test.as_slice().par_chunks(1 << 14))
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(x, y)| f64::from((x - y) * (x - y)))
                .sum::<f64>()
        })
        .collect();
    let sum = in_order(&chunk_sums);
    let mse = sum / reference.as_slice().len() as f64;
    Ok(10.0 * (data_range * data_range / mse).log10())
}

/// The sum of per-chunk partial sums, added in order: rayon's own `sum` associates them as
/// its threads happen to split the work, so the last bits would vary from run to run.
fn in_order(partial: &[f64]) -> f64 {
    partial.iter().sum()
}

fn check_range(data_range: f64) -> Result<(), Error> {
    if data_range > 0.0 && data_range.is_finite() {
        Ok(())
    } else {
        Err(Error::Parameter {
            name: "data_range",
            value: data_range,
            reason: "must be finite and > 0",
        })
    }
}

/// SSIM Gaussian window: sigma 1.5 truncated at 3.5 sigma (radius 5), as scikit-image's
/// `structural_similarity(gaussian_weights=True)` passes to `scipy.ndimage.gaussian_filter`.
const SSIM_SIGMA: f64 = 1.5;
const SSIM_RADIUS: usize = 5;

fn ssim_kernel() -> Vec<f32> {
    let r = SSIM_RADIUS as f64;
    let raw: Vec<f64> = (0..=2 * SSIM_RADIUS)
        .map(|i| (-0.5 / (SSIM_SIGMA * SSIM_SIGMA) * (i as f64 - r).powi(2)).exp())
        .collect();
    let sum: f64 = raw.iter().sum();
    raw.iter().map(|v| (v / sum) as f32).collect()
}

/// Mean structural similarity (Wang et al., IEEE TIP 2004), equal to
/// `skimage.metrics.structural_similarity(a, b, data_range=R, gaussian_weights=True,
/// sigma=1.5, use_sample_covariance=False)`: local means/variances with an 11x11 Gaussian
/// window (border `BORDER_REFLECT` = scipy `mode='reflect'`), `K1 = 0.01`, `K2 = 0.03`,
/// and the mean taken over the map without its 5-pixel border (where the window leaves
/// the image), as scikit-image crops it. Images must be at least 11x11.
pub fn ssim(a: &Gray<f32>, b: &Gray<f32>, data_range: f64) -> Result<f64, Error> {
    ssim_impl(a, b, data_range, None)
}

/// [`ssim`] that also writes the full SSIM map (scikit-image's `full=True` output `S`,
/// border included) into `map`; returns the same mean.
pub fn ssim_map(
    a: &Gray<f32>,
    b: &Gray<f32>,
    data_range: f64,
    map: &mut Gray<f32>,
) -> Result<f64, Error> {
    same_size(a, map)?;
    ssim_impl(a, b, data_range, Some(map))
}

fn ssim_impl(
    a: &Gray<f32>,
    b: &Gray<f32>,
    data_range: f64,
    map: Option<&mut Gray<f32>>,
) -> Result<f64, Error> {
    same_size(a, b)?;
    check_range(data_range)?;
    let (w, h) = a.size();
    let win = 2 * SSIM_RADIUS + 1;
    if w < win || h < win {
        return Err(Error::KernelSize {
            ksize: win,
            reason: "SSIM window exceeds the image",
        });
    }
    let k = ssim_kernel();
    let c1 = ((0.01 * data_range).powi(2)) as f32;
    let c2 = ((0.03 * data_range).powi(2)) as f32;
    let (sa, sb) = (a.as_slice(), b.as_slice());
    let r = SSIM_RADIUS;
    type Scratch = (Vec<f32>, Vec<f32>, Vec<f32>);
    let band = |sc: &mut Scratch, y0: usize, out: Option<&mut [f32]>, n_out: usize| -> f64 {
        // Horizontal pass of x, y, xx, yy, xy for rows y0 - r .. y0 + n_out + r.
        let n_tmp = n_out + 2 * r;
        let tmp = crate::scratch(&mut sc.0, 5 * n_tmp * w, 0.0);
        let pads = crate::scratch(&mut sc.1, 5 * (w + 2 * r), 0.0);
        let pw = w + 2 * r;
        for t in 0..n_tmp {
            let y = Border::Reflect.index((y0 + t) as isize - r as isize, h);
            let (ra, rb) = (&sa[y * w..(y + 1) * w], &sb[y * w..(y + 1) * w]);
            let (pa, rest) = pads.split_at_mut(pw);
            let (pb, rest) = rest.split_at_mut(pw);
            let (paa, rest) = rest.split_at_mut(pw);
            let (pbb, pab) = rest.split_at_mut(pw);
            Border::Reflect.pad_row(ra, r, pa);
            Border::Reflect.pad_row(rb, r, pb);
            for i in 0..pw {
                paa[i] = pa[i] * pa[i];
                pbb[i] = pb[i] * pb[i];
                pab[i] = pa[i] * pb[i];
            }
            for q in 0..5 {
                let dst = &mut tmp[(q * n_tmp + t) * w..(q * n_tmp + t + 1) * w];
                let src = &pads[q * pw..(q + 1) * pw];
                crate::filter::correlate(&k, |i| &src[i..i + w], dst);
            }
        }
        let mu = crate::scratch(&mut sc.2, 5 * w, 0.0);
        let mut out = out;
        let mut sum = 0.0f64;
        for row in 0..n_out {
            for q in 0..5 {
                let m = &mut mu[q * w..(q + 1) * w];
                let tmp: &[f32] = tmp;
                crate::filter::correlate(
                    &k,
                    |j| &tmp[(q * n_tmp + row + j) * w..(q * n_tmp + row + j + 1) * w],
                    m,
                );
            }
            let (ux, rest) = mu.split_at(w);
            let (uy, rest) = rest.split_at(w);
            let (uxx, rest) = rest.split_at(w);
            let (uyy, uxy) = rest.split_at(w);
            let y = y0 + row;
            let inside = y >= r && y < h - r;
            let mut row_sum = 0.0f64;
            for x in 0..w {
                let (vx, vy, vxy) = (
                    uxx[x] - ux[x] * ux[x],
                    uyy[x] - uy[x] * uy[x],
                    uxy[x] - ux[x] * uy[x],
                );
                let a1 = 2.0 * ux[x] * uy[x] + c1;
                let a2 = 2.0 * vxy + c2;
                let b1 = ux[x] * ux[x] + uy[x] * uy[x] + c1;
                let b2 = vx + vy + c2;
                let s = (a1 * a2) / (b1 * b2);
                if let Some(o) = out.as_deref_mut() {
                    o[row * w + x] = s;
                }
                if inside && x >= r && x < w - r {
                    row_sum += f64::from(s);
                }
            }
            sum += row_sum;
        }
        sum
    };
    let band_sums: Vec<f64> = match map {
        Some(m) => m
            .as_mut_slice()
            .par_chunks_mut(w * BAND_ROWS)
            .enumerate()
            .map_init(Scratch::default, |sc, (i, o)| {
                let n = o.len() / w;
                band(sc, i * BAND_ROWS, Some(o), n)
            })
            .collect(),
        None => (0..h.div_ceil(BAND_ROWS))
            .into_par_iter()
            .map_init(Scratch::default, |sc, i| {
                band(sc, i * BAND_ROWS, None, BAND_ROWS.min(h - i * BAND_ROWS))
            })
            .collect(),
    };
    Ok(in_order(&band_sums) / ((w - 2 * r) * (h - 2 * r)) as f64)
}

/// Summary of per-pixel angles between estimated and true normals, in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AngularErrorStats {
    /// Pixels evaluated.
    pub count: usize,
    /// Mean angle.
    pub mean: f64,
    /// Median angle (mean of the two middle values for an even count, as `numpy.median`).
    pub median: f64,
    /// Root mean square angle.
    pub rmse: f64,
    /// Percentage (0-100) of pixels with angle `< 11.25`.
    pub pct_below_11_25: f64,
    /// Percentage of pixels with angle `< 22.5`.
    pub pct_below_22_5: f64,
    /// Percentage of pixels with angle `< 30`.
    pub pct_below_30: f64,
}

/// Angular error between normal maps, the usual shape-from-polarization score:
/// `angle = atan2(|n1 x n2|, n1 . n2)` in degrees (same as `arccos` of the normalised dot
/// product, without its loss of precision near 0), over pixels where `mask` (if given) is
/// non-zero and both normals have non-zero length (the sample format writes `0,0,0` where
/// there is no surface). Returns `None` if no pixel qualifies.
pub fn angular_error(
    est: &NormalImage,
    truth: &NormalImage,
    mask: Option<&Gray<u8>>,
) -> Result<Option<AngularErrorStats>, Error> {
    same_size(est, truth)?;
    if let Some(m) = mask {
        same_size(est, m)?;
    }
    let mut angles: Vec<f64> = est
        .pixels()
        .par_iter()
        .zip(truth.pixels().par_iter())
        .enumerate()
        .filter(|(i, _)| mask.is_none_or(|m| m.as_slice()[*i] != 0))
        .filter_map(|(_, (a, b))| normal_angle_deg(a, b))
        .collect();
    let n = angles.len();
    if n == 0 {
        return Ok(None);
    }
    angles.par_sort_unstable_by(f64::total_cmp);
    let median = if n % 2 == 1 {
        angles[n / 2]
    } else {
        0.5 * (angles[n / 2 - 1] + angles[n / 2])
    };
    let pct = |t: f64| 100.0 * angles.partition_point(|&a| a < t) as f64 / n as f64;
    Ok(Some(AngularErrorStats {
        count: n,
        mean: angles.iter().sum::<f64>() / n as f64,
        median,
        rmse: (angles.iter().map(|a| a * a).sum::<f64>() / n as f64).sqrt(),
        pct_below_11_25: pct(11.25),
        pct_below_22_5: pct(22.5),
        pct_below_30: pct(30.0),
    }))
}

/// The angle (degrees) between two normals, `atan2(|a × b|, a · b)`; `None` where either
/// has zero length (no surface).
fn normal_angle_deg(a: &[f32; 3], b: &[f32; 3]) -> Option<f64> {
    let a = a.map(f64::from);
    let b = b.map(f64::from);
    let dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let (na, nb) = (
        a.iter().map(|v| v * v).sum::<f64>(),
        b.iter().map(|v| v * v).sum::<f64>(),
    );
    (na > 0.0 && nb > 0.0).then(|| {
        cross
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
            .atan2(dot)
            .to_degrees()
    })
}

/// Per-pixel angle (degrees) between estimated and true normals, as [`angular_error`]
/// scores them; NaN where `mask` (if given) is zero or either normal has zero length.
pub fn angular_error_map(
    est: &NormalImage,
    truth: &NormalImage,
    mask: Option<&Gray<u8>>,
) -> Result<Gray<f32>, Error> {
    same_size(est, truth)?;
    if let Some(m) = mask {
        same_size(est, m)?;
    }
    let data = est
        .pixels()
        .par_iter()
        .zip(truth.pixels().par_iter())
        .enumerate()
        .map(|(i, (a, b))| {
            let inside = mask.is_none_or(|m| m.as_slice()[i] != 0);
            inside
                .then(|| normal_angle_deg(a, b))
                .flatten()
                .map_or(f32::NAN, |v| v as f32)
        })
        .collect();
    let (w, h) = est.size();
    Ok(Gray::from_vec(w, h, data).expect("one angle per pixel"))
}

/// Intersection over union of two binary masks (non-zero = inside):
/// `|A and B| / |A or B|`; `None` when both are empty.
pub fn iou(pred: &Gray<u8>, truth: &Gray<u8>) -> Result<Option<f64>, Error> {
    same_size(pred, truth)?;
    let (inter, union) = pred
        .as_slice()
        .par_iter()
        .zip(truth.as_slice())
        .map(|(&p, &t)| (u64::from(p != 0 && t != 0), u64::from(p != 0 || t != 0)))
        .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    Ok((union > 0).then(|| inter as f64 / union as f64))
}

/// A confusion matrix over `n` classes: `count(truth, pred)` pixels of true class `truth`
/// predicted as `pred` (rows = truth, columns = prediction, as scikit-learn's
/// `confusion_matrix(y_true, y_pred)`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ConfusionMatrix {
    n: usize,
    counts: Vec<u64>,
}

impl ConfusionMatrix {
    /// Counts class pairs of two label images; every value must be `< n_classes`.
    pub fn from_labels(truth: &Gray<u8>, pred: &Gray<u8>, n_classes: usize) -> Result<Self, Error> {
        same_size(truth, pred)?;
        let counts = truth
            .as_slice()
            .par_chunks(1 << 16)
            .zip(pred.as_slice().par_chunks(1 << 16))
            .map(|(t, p)| {
                let mut c = vec![0u64; n_classes * n_classes];
                for (&t, &p) in t.iter().zip(p) {
                    let (t, p) = (usize::from(t), usize::from(p));
                    let bad = t.max(p);
                    if bad >= n_classes {
                        return Err(Error::ClassOutOfRange {
                            value: bad as u32,
                            n_classes,
                        });
                    }
                    c[t * n_classes + p] += 1;
                }
                Ok(c)
            })
            .try_reduce(
                || vec![0u64; n_classes * n_classes],
                |mut a, b| {
                    a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                    Ok(a)
                },
            )?;
        Ok(Self {
            n: n_classes,
            counts,
        })
    }

    /// Number of classes.
    pub fn n_classes(&self) -> usize {
        self.n
    }

    /// Pixels of true class `truth` predicted as `pred`.
    pub fn count(&self, truth: usize, pred: usize) -> u64 {
        self.counts[truth * self.n + pred]
    }

    /// IoU of class `c`: `TP / (TP + FP + FN)`; `None` if the class appears in neither image.
    pub fn class_iou(&self, c: usize) -> Option<f64> {
        let tp = self.count(c, c);
        let row: u64 = (0..self.n).map(|p| self.count(c, p)).sum();
        let col: u64 = (0..self.n).map(|t| self.count(t, c)).sum();
        let union = row + col - tp;
        (union > 0).then(|| tp as f64 / union as f64)
    }

    /// Mean of [`class_iou`](Self::class_iou) over the classes that appear.
    pub fn mean_iou(&self) -> Option<f64> {
        let ious: Vec<f64> = (0..self.n).filter_map(|c| self.class_iou(c)).collect();
        (!ious.is_empty()).then(|| ious.iter().sum::<f64>() / ious.len() as f64)
    }

    /// Fraction of pixels on the diagonal.
    pub fn accuracy(&self) -> Option<f64> {
        let total: u64 = self.counts.iter().sum();
        let diag: u64 = (0..self.n).map(|c| self.count(c, c)).sum();
        (total > 0).then(|| diag as f64 / total as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_have_ssim_1_and_infinite_psnr() {
        let v: Vec<f32> = (0..16 * 12)
            .map(|i| ((i * 37) % 101) as f32 / 100.0)
            .collect();
        let a = Gray::from_vec(16, 12, v).unwrap();
        assert!((ssim(&a, &a, 1.0).unwrap() - 1.0).abs() < 1e-6);
        assert_eq!(psnr(&a, &a, 1.0).unwrap(), f64::INFINITY);
        assert!(ssim(&Gray::new(10, 20), &Gray::new(10, 20), 1.0).is_err());
    }

    /// The sums behind PSNR and SSIM are bit-identical whatever the threads (the issue's
    /// determinism across `--threads`): 40 runs in pools of 1 to 4 threads.
    #[test]
    fn psnr_and_ssim_do_not_depend_on_the_threads() {
        let (w, h) = (640, 480);
        let wave = |f: f32| -> Gray<f32> {
            let v = (0..w * h)
                .map(|i| (i as f32 * f).sin() * 0.5 + 0.5)
                .collect();
            Gray::from_vec(w, h, v).unwrap()
        };
        let (a, b) = (wave(0.0137), wave(0.0139));
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| (psnr(&a, &b, 1.0).unwrap(), ssim(&a, &b, 1.0).unwrap()))
        };
        let first = run(1);
        for k in 0..40 {
            let (p, s) = run(1 + k % 4);
            assert_eq!(
                (p.to_bits(), s.to_bits()),
                (first.0.to_bits(), first.1.to_bits()),
                "run {k}"
            );
        }
    }

    #[test]
    fn right_angle_normals_and_confusion() {
        let est = NormalImage::from_vec(2, 1, vec![1.0, 0.0, 0.0, 0.0, 0.0, 2.0]).unwrap();
        let gt = NormalImage::from_vec(2, 1, vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0]).unwrap();
        let s = angular_error(&est, &gt, None).unwrap().unwrap();
        assert!((s.mean - 45.0).abs() < 1e-12 && (s.median - 45.0).abs() < 1e-12);
        assert_eq!((s.pct_below_11_25, s.pct_below_30), (50.0, 50.0));
        let t = Gray::from_vec(4, 1, vec![0u8, 1, 1, 2]).unwrap();
        let p = Gray::from_vec(4, 1, vec![0u8, 1, 2, 2]).unwrap();
        let cm = ConfusionMatrix::from_labels(&t, &p, 3).unwrap();
        assert_eq!(
            (cm.count(1, 2), cm.class_iou(1), cm.class_iou(2)),
            (1, Some(0.5), Some(0.5))
        );
        assert_eq!(iou(&t, &p).unwrap(), Some(1.0));
        assert!(ConfusionMatrix::from_labels(&t, &p, 2).is_err());
    }

    /// The map holds the angles the statistics average: 90° and 0° here (1e-6 for the
    /// f32 output), NaN outside the mask and where a normal is missing.
    #[test]
    fn angular_error_map_matches_the_statistics() {
        let est =
            NormalImage::from_vec(3, 1, vec![1.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0]).unwrap();
        let gt =
            NormalImage::from_vec(3, 1, vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0]).unwrap();
        let m = angular_error_map(&est, &gt, None).unwrap();
        let v = m.as_slice();
        assert!((v[0] - 90.0).abs() < 1e-6 && v[1].abs() < 1e-6 && v[2].is_nan());
        let mean = angular_error(&est, &gt, None).unwrap().unwrap().mean;
        assert!((f64::from(v[0] + v[1]) / 2.0 - mean).abs() < 1e-5);
        let mask = Gray::from_vec(3, 1, vec![0u8, 1, 1]).unwrap();
        assert!(
            angular_error_map(&est, &gt, Some(&mask))
                .unwrap()
                .as_slice()[0]
                .is_nan()
        );
        assert!(angular_error_map(&est, &gt, Some(&Gray::new(2, 1))).is_err());
    }
}
