//! One metrics function per task.

use std::collections::BTreeMap;

use polar_image::{Gray, NormalImage};
use polar_imgproc::{AngularErrorStats, ConfusionMatrix, angular_error, psnr, ssim_map};
use serde::{Deserialize, Serialize};

use crate::depth::{DepthFit, depth_fit};
use crate::{EvalError, check_size};

/// Normal-map accuracy: angles in degrees between estimated and true normals.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct NormalMetrics {
    /// Pixels scored.
    pub count: usize,
    /// Share of the object pixels with a true normal that have an estimate (the angles
    /// are over those only, so a method that leaves hard pixels out scores better).
    pub coverage: f64,
    /// Mean angle.
    pub mean_deg: f64,
    /// Median angle.
    pub median_deg: f64,
    /// Root mean square angle.
    pub rmse_deg: f64,
    /// Percentage of pixels below 11.25°.
    pub pct_below_11_25: f64,
    /// Percentage below 22.5°.
    pub pct_below_22_5: f64,
    /// Percentage below 30°.
    pub pct_below_30: f64,
    /// Mean angle per estimated reflection type (by name), where the estimate gives one.
    pub mean_deg_by_type: BTreeMap<String, f64>,
    /// Depth after the best scale-and-offset fit, where depth was estimated.
    pub depth: Option<DepthFit>,
}

impl NormalMetrics {
    fn from_stats(s: AngularErrorStats, objects: usize) -> Self {
        Self {
            count: s.count,
            coverage: s.count as f64 / objects.max(1) as f64,
            mean_deg: s.mean,
            median_deg: s.median,
            rmse_deg: s.rmse,
            pct_below_11_25: s.pct_below_11_25,
            pct_below_22_5: s.pct_below_22_5,
            pct_below_30: s.pct_below_30,
            mean_deg_by_type: BTreeMap::new(),
            depth: None,
        }
    }
}

/// Normal accuracy over `objects` (non-zero = scored); with `types` (a per-pixel class and
/// its names, index = value) also per class, and with depths the fitted depth error.
pub fn normal_metrics(
    est: &NormalImage,
    truth: &NormalImage,
    objects: &Gray<u8>,
    types: Option<(&Gray<u8>, &[&str])>,
    depth: Option<(&Gray<f32>, &Gray<f32>)>,
) -> Result<Option<NormalMetrics>, EvalError> {
    check_size("normals", est.size(), truth.size())?;
    check_size("object mask", objects.size(), truth.size())?;
    let Some(stats) = angular_error(est, truth, Some(objects))? else {
        return Ok(None);
    };
    let with_truth = (truth.pixels().iter().zip(objects.as_slice()))
        .filter(|(n, m)| **m != 0 && n.iter().any(|&c| c != 0.0))
        .count();
    let mut out = NormalMetrics::from_stats(stats, with_truth);
    if let Some((classes, names)) = types {
        check_size("reflection types", classes.size(), truth.size())?;
        for (value, name) in names.iter().enumerate() {
            let mask = select(objects, |k| usize::from(classes.as_slice()[k]) == value);
            if let Some(s) = angular_error(est, truth, Some(&mask))? {
                out.mean_deg_by_type.insert((*name).to_owned(), s.mean);
            }
        }
    }
    if let Some((est_depth, gt_depth)) = depth {
        out.depth = depth_fit(est_depth, gt_depth, objects)?;
    }
    Ok(Some(out))
}

/// `objects` restricted to the pixels where `keep(k)` holds.
fn select(objects: &Gray<u8>, keep: impl Fn(usize) -> bool) -> Gray<u8> {
    let mut m = objects.clone();
    for (k, v) in m.as_mut_slice().iter_mut().enumerate() {
        *v = u8::from(*v != 0 && keep(k));
    }
    m
}

/// Material labels (0 background, 1 dielectric, 2 metal, 3 transparent) against truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaterialMetrics {
    /// Pixels whose true label is 1 or 2 and whose prediction is 1 or 2.
    pub foreground_pixels: u64,
    /// Metal against dielectric: the fraction of those pixels labelled correctly.
    pub metal_vs_dielectric_accuracy: Option<f64>,
    /// Those pixels over all pixels whose true label is 1 or 2: the share of the opaque
    /// objects the accuracy speaks for (background or transparent predictions leave it).
    pub opaque_coverage: Option<f64>,
    /// Fraction of all pixels labelled correctly (four classes).
    pub pixel_accuracy: Option<f64>,
    /// IoU per class (index = label), `None` where the class is in neither image.
    pub class_iou: Vec<Option<f64>>,
    /// Rows = truth, columns = prediction, labels 0..=3.
    pub confusion: Vec<Vec<u64>>,
}

/// Scores a material map (labels 0..=3) against `gt/material.png`.
pub fn material_metrics(pred: &Gray<u8>, truth: &Gray<u8>) -> Result<MaterialMetrics, EvalError> {
    check_size("material labels", pred.size(), truth.size())?;
    let cm = ConfusionMatrix::from_labels(truth, pred, 4)?;
    let (right, fg) = [(1, 1), (2, 2), (1, 2), (2, 1)]
        .iter()
        .fold((0, 0), |(r, n), &(t, p)| {
            let c = cm.count(t, p);
            (r + if t == p { c } else { 0 }, n + c)
        });
    let opaque: u64 = (0..4).map(|p| cm.count(1, p) + cm.count(2, p)).sum();
    Ok(MaterialMetrics {
        foreground_pixels: fg,
        metal_vs_dielectric_accuracy: (fg > 0).then(|| right as f64 / fg as f64),
        opaque_coverage: (opaque > 0).then(|| fg as f64 / opaque as f64),
        pixel_accuracy: cm.accuracy(),
        class_iou: (0..4).map(|c| cm.class_iou(c)).collect(),
        confusion: (0..4)
            .map(|t| (0..4).map(|p| cm.count(t, p)).collect())
            .collect(),
    })
}

/// A binary mask (non-zero = inside) against its truth.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MaskMetrics {
    /// `|P ∩ T| / |P ∪ T|`; `None` when both are empty.
    pub iou: Option<f64>,
    /// `|P ∩ T| / |P|`; `None` when nothing is predicted.
    pub precision: Option<f64>,
    /// `|P ∩ T| / |T|`; `None` when the truth is empty.
    pub recall: Option<f64>,
    /// Fraction of the distractor pixels (e.g. opaque shiny objects) predicted inside.
    pub false_positive_on_distractors: Option<f64>,
}

/// Scores a mask; `distractors` (non-zero = a pixel that must stay outside, e.g. metal and
/// dielectric objects of `gt/material.png`) gives the false-positive fraction on them.
pub fn mask_metrics(
    pred: &Gray<u8>,
    truth: &Gray<u8>,
    distractors: Option<&Gray<u8>>,
) -> Result<MaskMetrics, EvalError> {
    check_size("mask", pred.size(), truth.size())?;
    let (p, t) = (pred.as_slice(), truth.as_slice());
    let count = |f: &dyn Fn(usize) -> bool| (0..p.len()).filter(|&k| f(k)).count() as f64;
    let inter = count(&|k| p[k] != 0 && t[k] != 0);
    let (np, nt) = (count(&|k| p[k] != 0), count(&|k| t[k] != 0));
    let union = np + nt - inter;
    let fp = match distractors {
        Some(d) => {
            check_size("distractor mask", d.size(), truth.size())?;
            let d = d.as_slice();
            let nd = count(&|k| d[k] != 0);
            (nd > 0.0).then(|| count(&|k| d[k] != 0 && p[k] != 0) / nd)
        }
        None => None,
    };
    let ratio = |a: f64, b: f64| (b > 0.0).then(|| a / b);
    Ok(MaskMetrics {
        iou: ratio(inter, union),
        precision: ratio(inter, np),
        recall: ratio(inter, nt),
        false_positive_on_distractors: fp,
    })
}

/// PSNR (dB) and SSIM of one image against a reference.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImageScore {
    /// Peak signal-to-noise ratio with the reference's maximum as the data range.
    pub psnr_db: f64,
    /// Mean SSIM with the same data range.
    pub ssim: f64,
}

/// Dehazing: the hazy input and the dehazed output, each against a clear reference, and
/// the estimated transmission against the true one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DehazeMetrics {
    /// Hazy S0 against the reference.
    pub hazy: ImageScore,
    /// Dehazed radiance against the reference.
    pub dehazed: ImageScore,
    /// Mean absolute transmission error, where the truth is known.
    pub transmission_mae: Option<f64>,
    /// Pearson correlation of estimated and true transmission.
    pub transmission_correlation: Option<f64>,
    /// PSNR over the pixels whose radiance the image still holds (true transmission at
    /// least [`REACHABLE_TRANSMISSION`]), where the truth is known and such pixels exist.
    pub reachable: Option<ReachableScore>,
    /// The scores over the object pixels, where the labels are known and hold any.
    pub objects: Option<ObjectScore>,
}

/// Pixels whose true transmission is below this are left out of [`ReachableScore`]: less
/// than a tenth of their radiance reaches the camera, so any inversion multiplies the
/// sensor's noise and quantization more than tenfold, and sky seen through a deep haze
/// (`t` near 0) holds no trace of the haze-free sky at all.
pub const REACHABLE_TRANSMISSION: f32 = 0.1;

/// PSNR of the hazy input and the dehazed output over the reachable pixels, with the
/// data range of the whole frame's score.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReachableScore {
    /// Share of the frame's pixels that are reachable.
    pub fraction: f64,
    /// Hazy S0 against the reference, dB.
    pub hazy_psnr_db: f64,
    /// Dehazed radiance against the reference, dB.
    pub dehazed_psnr_db: f64,
}

/// The hazy input and the dehazed output over the object pixels (`gt/material.png` label
/// not 0), what the scene holds in front of the haze whatever its sky does: PSNR with the
/// whole frame's data range, SSIM the mean of the frame's SSIM map over those pixels, and
/// the transmission's error there.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ObjectScore {
    /// Share of the frame's pixels that are object pixels.
    pub fraction: f64,
    /// Hazy S0 against the reference.
    pub hazy: ImageScore,
    /// Dehazed radiance against the reference.
    pub dehazed: ImageScore,
    /// Mean absolute transmission error, where the truth is known.
    pub transmission_mae: Option<f64>,
    /// Pearson correlation of estimated and true transmission.
    pub transmission_correlation: Option<f64>,
}

/// Scores a dehazing result over the whole frame, the reachable pixels (where the true
/// transmission is given) and the object pixels (where `labels` are given, 0 = none). The
/// data range of PSNR and SSIM is the reference's maximum (at least the smallest positive
/// float), so a scale-free score.
pub fn dehaze_metrics(
    hazy: &Gray<f32>,
    dehazed: &Gray<f32>,
    reference: &Gray<f32>,
    transmission: Option<(&Gray<f32>, &Gray<f32>)>,
    labels: Option<&Gray<u8>>,
) -> Result<DehazeMetrics, EvalError> {
    check_size("dehazed", dehazed.size(), reference.size())?;
    check_size("hazy", hazy.size(), reference.size())?;
    if let Some(l) = labels {
        check_size("labels", l.size(), reference.size())?;
    }
    if let Some((est, gt)) = transmission {
        check_size("transmission", est.size(), gt.size())?;
        check_size("true transmission", gt.size(), reference.size())?;
    }
    let range = reference
        .as_slice()
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f32::MIN_POSITIVE, f32::max) as f64;
    let pair = Pair { reference, range };
    let keep = labels
        .map(|l| pixels_where(l.as_slice(), |v| v != 0))
        .filter(|k| !k.is_empty());
    let (hazy_score, hazy_objects) = pair.scores(hazy, keep.as_deref())?;
    let (dehazed_score, dehazed_objects) = pair.scores(dehazed, keep.as_deref())?;
    let reachable = transmission.and_then(|(_, gt)| pair.reachable(hazy, dehazed, gt));
    let objects = keep
        .as_deref()
        .zip(hazy_objects.zip(dehazed_objects))
        .map(|(keep, scores)| object_score(keep, reference.as_slice().len(), scores, transmission));
    let error = transmission.map(|(est, gt)| transmission_error(est.as_slice(), gt.as_slice()));
    Ok(DehazeMetrics {
        hazy: hazy_score,
        dehazed: dehazed_score,
        transmission_mae: error.map(|e| e.0),
        transmission_correlation: error.and_then(|e| e.1),
        reachable,
        objects,
    })
}

/// [`ObjectScore`] over the object pixels `keep` of a frame of `len` pixels, from the
/// input's and the output's scores there and the transmission's error there.
fn object_score(
    keep: &[usize],
    len: usize,
    (hazy, dehazed): (ImageScore, ImageScore),
    transmission: Option<(&Gray<f32>, &Gray<f32>)>,
) -> ObjectScore {
    let error = transmission.map(|(est, gt)| {
        let (e, g): (Vec<f32>, Vec<f32>) = keep
            .iter()
            .map(|&k| (est.as_slice()[k], gt.as_slice()[k]))
            .unzip();
        transmission_error(&e, &g)
    });
    ObjectScore {
        fraction: keep.len() as f64 / len as f64,
        hazy,
        dehazed,
        transmission_mae: error.map(|e| e.0),
        transmission_correlation: error.and_then(|e| e.1),
    }
}

/// A frame's reference and the data range its scores use.
struct Pair<'a> {
    reference: &'a Gray<f32>,
    range: f64,
}

impl Pair<'_> {
    /// PSNR and SSIM of `img` over the whole frame and, where `objects` are given (not
    /// empty), over them: the mean of the same SSIM map there.
    fn scores(
        &self,
        img: &Gray<f32>,
        objects: Option<&[usize]>,
    ) -> Result<(ImageScore, Option<ImageScore>), EvalError> {
        let (w, h) = self.reference.size();
        let mut map = Gray::new(w, h);
        let whole = ImageScore {
            psnr_db: psnr(self.reference, img, self.range)?,
            ssim: ssim_map(self.reference, img, self.range, &mut map)?,
        };
        let m = map.as_slice();
        let over = objects.map(|keep| ImageScore {
            psnr_db: self.psnr_over(img, keep),
            ssim: keep.iter().map(|&k| f64::from(m[k])).sum::<f64>() / keep.len() as f64,
        });
        Ok((whole, over))
    }

    /// PSNR (dB) of `img` over the pixels `keep` (not empty).
    fn psnr_over(&self, img: &Gray<f32>, keep: &[usize]) -> f64 {
        let (r, x) = (self.reference.as_slice(), img.as_slice());
        let sse: f64 = keep.iter().map(|&k| f64::from(x[k] - r[k]).powi(2)).sum();
        10.0 * (self.range * self.range * keep.len() as f64 / sse).log10()
    }

    /// [`ReachableScore`] for the true transmission `t_true`; `None` where no pixel is
    /// reachable.
    fn reachable(
        &self,
        hazy: &Gray<f32>,
        dehazed: &Gray<f32>,
        t_true: &Gray<f32>,
    ) -> Option<ReachableScore> {
        let keep = pixels_where(t_true.as_slice(), |t| t >= REACHABLE_TRANSMISSION);
        (!keep.is_empty()).then(|| ReachableScore {
            fraction: keep.len() as f64 / t_true.as_slice().len() as f64,
            hazy_psnr_db: self.psnr_over(hazy, &keep),
            dehazed_psnr_db: self.psnr_over(dehazed, &keep),
        })
    }
}

/// Indices of the values for which `keep` holds.
fn pixels_where<T: Copy>(v: &[T], keep: impl Fn(T) -> bool) -> Vec<usize> {
    (0..v.len()).filter(|&k| keep(v[k])).collect()
}

/// Mean absolute error and Pearson correlation of estimated transmissions `est` against
/// the true ones `gt` (equally long).
fn transmission_error(est: &[f32], gt: &[f32]) -> (f64, Option<f64>) {
    let n = est.len().max(1) as f64;
    let mae = est
        .iter()
        .zip(gt)
        .map(|(a, b)| f64::from((a - b).abs()))
        .sum::<f64>()
        / n;
    (mae, pearson(est, gt))
}

/// The gain `k` minimising `Σ (k x − y)²` over the indices where `keep` holds and `y` is
/// finite: the factor from an observation's unit to the truth's (a camera frame in DN, the
/// truth in radiance) without the sensor's parameters. `None` where no pair counts or `x`
/// is 0 on all of them.
pub fn gain_to(x: &[f32], y: &[f32], keep: impl Fn(usize) -> bool) -> Option<f64> {
    let (xy, xx) = (x.iter().zip(y).enumerate())
        .filter(|&(k, (_, y))| keep(k) && y.is_finite())
        .fold((0.0, 0.0), |(xy, xx), (_, (&x, &y))| {
            (
                xy + f64::from(x) * f64::from(y),
                xx + f64::from(x) * f64::from(x),
            )
        });
    (xx > 0.0).then(|| xy / xx)
}

/// Pearson correlation of two equally long series over the pairs where both are finite;
/// `None` with fewer than 2 such pairs or a constant series.
pub fn pearson(a: &[f32], b: &[f32]) -> Option<f64> {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(&x, &y)| (f64::from(x), f64::from(y)))
        .collect();
    let n = pairs.len() as f64;
    if pairs.len() < 2 {
        return None;
    }
    let (sa, sb) = pairs
        .iter()
        .fold((0.0, 0.0), |(p, q), (x, y)| (p + x, q + y));
    let (ma, mb) = (sa / n, sb / n);
    let (sab, saa, sbb) = pairs.iter().fold((0.0, 0.0, 0.0), |(s, u, v), (x, y)| {
        let (dx, dy) = (x - ma, y - mb);
        (s + dx * dy, u + dx * dx, v + dy * dy)
    });
    (saa > 0.0 && sbb > 0.0).then(|| sab / (saa * sbb).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gain_to_fits_the_scale_over_the_kept_finite_pixels() {
        let x = [1.0f32, 2.0, 3.0, 4.0, 5.0];
        // y = 2.5 x but for a NaN, a pixel left out (index 1) and a zero x.
        let y = [2.5f32, 99.0, f32::NAN, 10.0, 12.5];
        let k = gain_to(&x, &y, |i| i != 1).unwrap();
        assert!((k - 2.5).abs() < 1e-12, "{k}");
        assert_eq!(gain_to(&[0.0, 0.0], &[1.0, 2.0], |_| true), None);
        assert_eq!(gain_to(&x, &y, |_| false), None);
    }

    fn gray<T>(w: usize, v: Vec<T>) -> Gray<T> {
        let h = v.len() / w;
        Gray::from_vec(w, h, v).unwrap()
    }

    #[test]
    fn material_accuracy_counts_only_metal_and_dielectric_pixels() {
        let truth = gray(6, vec![0u8, 1, 1, 2, 2, 3]);
        let pred = gray(6, vec![1u8, 1, 2, 2, 0, 3]);
        let m = material_metrics(&pred, &truth).unwrap();
        // Foreground pairs: (1,1) right, (1,2) wrong, (2,2) right; (2,0) is not counted.
        assert_eq!(m.foreground_pixels, 3);
        assert!((m.metal_vs_dielectric_accuracy.unwrap() - 2.0 / 3.0).abs() < 1e-12);
        // Four pixels are truly metal or dielectric; three of them are labelled so.
        assert!((m.opaque_coverage.unwrap() - 3.0 / 4.0).abs() < 1e-12);
        assert_eq!(m.confusion[2][0], 1);
        assert_eq!(m.class_iou[3], Some(1.0));
        assert!(material_metrics(&gray(3, vec![0u8, 1, 4]), &gray(3, vec![0u8; 3])).is_err());
    }

    #[test]
    fn mask_precision_recall_and_distractors() {
        let truth = gray(5, vec![255u8, 255, 0, 0, 0]);
        let pred = gray(5, vec![255u8, 0, 255, 255, 0]);
        let shiny = gray(5, vec![0u8, 0, 1, 0, 1]);
        let m = mask_metrics(&pred, &truth, Some(&shiny)).unwrap();
        assert_eq!((m.precision, m.recall), (Some(1.0 / 3.0), Some(0.5)));
        assert_eq!(m.iou, Some(0.25));
        assert_eq!(m.false_positive_on_distractors, Some(0.5));
        let empty = gray(5, vec![0u8; 5]);
        let m = mask_metrics(&empty, &empty, None).unwrap();
        assert_eq!((m.iou, m.precision, m.recall), (None, None, None));
    }

    #[test]
    fn reachable_score_leaves_out_pixels_the_haze_hid() {
        // 12x12 (SSIM's window needs 11x11): the reference is 1 everywhere; the output is
        // off by 1 at pixel 0, which the haze hid (t = 0.05), and by 0.1 at pixel 1 (t = 0.5).
        let n = 144;
        let reference = gray(12, vec![1.0f32; n]);
        let mut dehazed = vec![1.0f32; n];
        (dehazed[0], dehazed[1]) = (0.0, 0.9);
        let dehazed = gray(12, dehazed);
        let hazy = gray(12, vec![0.8f32; n]);
        let mut t = vec![1.0f32; n];
        (t[0], t[1]) = (0.05, 0.5);
        let t = gray(12, t);
        let m = dehaze_metrics(&hazy, &dehazed, &reference, Some((&t, &t)), None).unwrap();
        let r = m.reachable.unwrap();
        assert_eq!(r.fraction, 143.0 / 144.0);
        let want = |sse: f64| 10.0 * (143.0 / sse).log10();
        assert!((r.dehazed_psnr_db - want(0.01)).abs() < 1e-4, "{r:?}");
        assert!((r.hazy_psnr_db - want(143.0 * 0.04)).abs() < 1e-4, "{r:?}");
        assert!(m.dehazed.psnr_db < r.dehazed_psnr_db - 10.0);
        let hidden = gray(12, vec![0.0f32; n]);
        let m = dehaze_metrics(&hazy, &dehazed, &reference, Some((&t, &hidden)), None).unwrap();
        assert_eq!(m.reachable, None);
    }

    #[test]
    fn object_score_counts_only_labelled_pixels() {
        // 12x12: the output is off by 0.5 on the 4 object pixels (labels 1-3) and by 1 on
        // one background pixel, which must not count; no labelled pixel gives no score.
        let n = 144;
        let reference = gray(12, vec![1.0f32; n]);
        let hazy = gray(12, vec![0.8f32; n]);
        let mut dehazed = vec![1.0f32; n];
        let mut labels = vec![0u8; n];
        for (k, l) in [(30, 1u8), (31, 2), (42, 3), (43, 1)] {
            (dehazed[k], labels[k]) = (0.5, l);
        }
        dehazed[100] = 0.0;
        let (dehazed, labels) = (gray(12, dehazed), gray(12, labels));
        let t_true = gray(12, vec![0.5f32; n]);
        let mut t_est = vec![0.5f32; n];
        t_est[30] = 0.9;
        let t_est = gray(12, t_est);
        let m = dehaze_metrics(
            &hazy,
            &dehazed,
            &reference,
            Some((&t_est, &t_true)),
            Some(&labels),
        )
        .unwrap();
        let o = m.objects.unwrap();
        assert_eq!(o.fraction, 4.0 / 144.0);
        assert!(
            (o.dehazed.psnr_db - 10.0 * (1.0f64 / 0.25).log10()).abs() < 1e-9,
            "{o:?}"
        );
        assert!(
            (o.hazy.psnr_db - 10.0 * (1.0f64 / 0.04).log10()).abs() < 1e-4,
            "{o:?}"
        );
        assert!(
            o.dehazed.ssim < 1.0 && o.dehazed.ssim < m.dehazed.ssim,
            "{o:?}"
        );
        assert!((o.transmission_mae.unwrap() - 0.1).abs() < 1e-6, "{o:?}");
        let none = gray(12, vec![0u8; n]);
        let m = dehaze_metrics(&hazy, &dehazed, &reference, None, Some(&none)).unwrap();
        assert_eq!(m.objects, None);
    }

    #[test]
    fn pearson_of_affine_series_is_one_and_of_constant_is_none() {
        let a = [1.0f32, 2.0, 4.0, f32::NAN, 8.0];
        let b = [3.0f32, 5.0, 9.0, 1.0, 17.0];
        assert!((pearson(&a, &b).unwrap() - 1.0).abs() < 1e-12);
        let neg: Vec<f32> = b.iter().map(|v| -v).collect();
        assert!((pearson(&a, &neg).unwrap() + 1.0).abs() < 1e-12);
        assert_eq!(pearson(&a, &[2.0; 5]), None);
    }

    #[test]
    fn normals_are_scored_on_objects_and_by_type() {
        let n = |v: [f32; 3]| v;
        let truth = NormalImage::from_vec(3, 1, [n([0., 0., 1.]); 3].concat()).unwrap();
        let est = NormalImage::from_vec(
            3,
            1,
            [n([0., 0., 1.]), n([1., 0., 0.]), n([0., 1., 0.])].concat(),
        )
        .unwrap();
        let objects = gray(3, vec![1u8, 1, 0]);
        let types = gray(3, vec![1u8, 2, 2]);
        let m = normal_metrics(
            &est,
            &truth,
            &objects,
            Some((&types, &["none", "a", "b"])),
            None,
        )
        .unwrap()
        .unwrap();
        assert_eq!(m.count, 2);
        assert!((m.mean_deg - 45.0).abs() < 1e-9);
        assert_eq!(m.mean_deg_by_type.get("a"), Some(&0.0));
        assert!((m.mean_deg_by_type["b"] - 90.0).abs() < 1e-9);
        assert!(!m.mean_deg_by_type.contains_key("none"));
        assert_eq!(m.coverage, 1.0);
        // An object pixel left without an estimate lowers the coverage, not the mean.
        let missed = NormalImage::from_vec(
            3,
            1,
            [n([0., 0., 1.]), n([0., 0., 0.]), n([0., 1., 0.])].concat(),
        )
        .unwrap();
        let m = normal_metrics(&missed, &truth, &objects, None, None)
            .unwrap()
            .unwrap();
        assert_eq!((m.count, m.coverage, m.mean_deg), (1, 0.5, 0.0));
    }
}
