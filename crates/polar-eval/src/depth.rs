//! Relative depth against ground truth: shape-from-polarization depth is defined up to
//! scale and offset, so it is compared after the least-squares fit `a·est + b ≈ gt`.

use polar_image::Gray;
use serde::{Deserialize, Serialize};

use crate::{EvalError, check_size};

/// The best affine fit of an estimated depth to the truth and its residual.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DepthFit {
    /// Pixels used (mask non-zero, both depths finite).
    pub count: usize,
    /// Scale `a` of `a·est + b`.
    pub scale: f64,
    /// Offset `b`.
    pub offset: f64,
    /// RMSE of the fitted depth, divided by the truth's range (max − min) over the pixels.
    pub relative_rmse: f64,
}

/// Fits `a·est + b` to `gt` by least squares over pixels where `mask` is non-zero and both
/// values are finite; `None` with fewer than 2 pixels or a constant truth. A constant
/// estimate gets `a = 0`, `b = mean(gt)`.
pub fn depth_fit(
    est: &Gray<f32>,
    gt: &Gray<f32>,
    mask: &Gray<u8>,
) -> Result<Option<DepthFit>, EvalError> {
    check_size("depth", est.size(), gt.size())?;
    check_size("depth mask", mask.size(), gt.size())?;
    let pairs: Vec<(f64, f64)> = est
        .as_slice()
        .iter()
        .zip(gt.as_slice())
        .zip(mask.as_slice())
        .filter(|&((e, g), &m)| m != 0 && e.is_finite() && g.is_finite())
        .map(|((&e, &g), _)| (f64::from(e), f64::from(g)))
        .collect();
    let n = pairs.len() as f64;
    if pairs.len() < 2 {
        return Ok(None);
    }
    let (se, sg) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (e, g)| (a + e, b + g));
    let (me, mg) = (se / n, sg / n);
    let (see, seg) = pairs.iter().fold((0.0, 0.0), |(a, b), (e, g)| {
        (a + (e - me) * (e - me), b + (e - me) * (g - mg))
    });
    let scale = if see > 0.0 { seg / see } else { 0.0 };
    let offset = mg - scale * me;
    let (lo, hi) = pairs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &(_, g)| {
            (l.min(g), h.max(g))
        });
    if hi <= lo {
        return Ok(None);
    }
    let sse: f64 = pairs
        .iter()
        .map(|(e, g)| (scale * e + offset - g).powi(2))
        .sum();
    Ok(Some(DepthFit {
        count: pairs.len(),
        scale,
        offset,
        relative_rmse: (sse / n).sqrt() / (hi - lo),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_copy_fits_exactly_and_noise_does_not() {
        let gt: Vec<f32> = (0..20).map(|i| 1.0 + (i as f32 * 0.37).sin()).collect();
        let est: Vec<f32> = gt.iter().map(|g| -2.0 * g + 5.0).collect();
        let gt = Gray::from_vec(5, 4, gt).unwrap();
        let mask = Gray::from_vec(5, 4, vec![1u8; 20]).unwrap();
        let fit = depth_fit(&Gray::from_vec(5, 4, est).unwrap(), &gt, &mask)
            .unwrap()
            .unwrap();
        assert!(
            (fit.scale + 0.5).abs() < 1e-6 && fit.relative_rmse < 1e-6,
            "{fit:?}"
        );
        let flat = Gray::from_vec(5, 4, vec![3.0f32; 20]).unwrap();
        let fit = depth_fit(&flat, &gt, &mask).unwrap().unwrap();
        assert_eq!(fit.scale, 0.0);
        assert!(fit.relative_rmse > 0.1);
    }

    #[test]
    fn too_few_pixels_or_flat_truth_give_none_and_sizes_are_checked() {
        let one = Gray::from_vec(1, 1, vec![1.0f32]).unwrap();
        let m = Gray::from_vec(1, 1, vec![1u8]).unwrap();
        assert!(depth_fit(&one, &one, &m).unwrap().is_none());
        let two = Gray::from_vec(2, 1, vec![1.0f32, 1.0]).unwrap();
        let m2 = Gray::from_vec(2, 1, vec![1u8, 1]).unwrap();
        assert!(depth_fit(&two, &two, &m2).unwrap().is_none());
        assert!(depth_fit(&one, &two, &m2).is_err());
    }
}
