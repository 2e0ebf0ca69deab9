//! Guided filter (He, Sun, Tang, "Guided Image Filtering", ECCV 2010 / TPAMI 2013) with a
//! single-channel guide, matching `cv2.ximgproc.guidedFilter(guide, src, radius, eps)`.

use polar_image::Gray;
use rayon::prelude::*;

use crate::{Border, Error, box_filter, same_size};

/// Pixels per rayon task in the element-wise steps.
const CHUNK: usize = 1 << 14;

/// Guided filter `q = mean(a) I + mean(b)` with `a = cov(I, p) / (var(I) + eps)` and
/// `b = mean(p) - a mean(I)`, all means over `(2 radius + 1)^2` boxes.
///
/// Matches opencv-contrib's implementation step for step in `f32`: its box means use
/// `BORDER_REFLECT` (not the usual `REFLECT_101`; checked against OpenCV output), `eps`
/// is added unscaled to the variance (so it is in squared guide units: for a guide in
/// `[0, 1]` pass `eps` as is; OpenCV does not rescale 8-bit guides either), and the
/// evaluation order of every product and difference is the same. One difference is
/// deliberate: OpenCV takes `1 / (var + eps)` with the SSE approximate reciprocal
/// `_mm_rcp_ps` (relative error up to 1.5 * 2^-12, CPU-dependent), we divide exactly.
pub fn guided_filter(
    guide: &Gray<f32>,
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    radius: usize,
    eps: f64,
) -> Result<(), Error> {
    same_size(guide, src)?;
    same_size(src, dst)?;
    if !(eps >= 0.0 && eps.is_finite()) {
        return Err(Error::Parameter {
            name: "eps",
            value: eps,
            reason: "must be finite and >= 0",
        });
    }
    let (w, h) = src.size();
    let k = 2 * radius + 1;
    let mean = |img: &Gray<f32>| -> Result<Gray<f32>, Error> {
        let mut out = Gray::new(w, h);
        box_filter(img, &mut out, k, k, Border::Reflect)?;
        Ok(out)
    };
    let product = |a: &[f32], b: &[f32]| -> Result<Gray<f32>, Error> {
        let v = a.par_iter().zip(b).map(|(x, y)| x * y).collect();
        Gray::from_vec(w, h, v).map_err(|_| Error::SizeMismatch(w, h, w, h))
    };
    let (gi, p) = (guide.as_slice(), src.as_slice());
    let eps = eps as f32;
    let mean_i = mean(guide)?;
    let mean_p = mean(src)?;
    let corr_ii = mean(&product(gi, gi)?)?;
    let corr_ip = mean(&product(p, gi)?)?;
    let (mut alpha, mut beta) = (Gray::new(w, h), Gray::new(w, h));
    alpha
        .as_mut_slice()
        .par_chunks_mut(CHUNK)
        .zip(beta.as_mut_slice().par_chunks_mut(CHUNK))
        .enumerate()
        .for_each(|(c, (a, b))| {
            let o = c * CHUNK;
            for (j, (a, b)) in a.iter_mut().zip(b.iter_mut()).enumerate() {
                let (mi, mp) = (mean_i.as_slice()[o + j], mean_p.as_slice()[o + j]);
                let var = (corr_ii.as_slice()[o + j] + eps) - mi * mi;
                let cov = corr_ip.as_slice()[o + j] - mp * mi;
                *a = (1.0 / var) * cov;
                *b = mp - *a * mi;
            }
        });
    let (mean_a, mean_b) = (mean(&alpha)?, mean(&beta)?);
    dst.as_mut_slice()
        .par_iter_mut()
        .zip(
            mean_b
                .as_slice()
                .par_iter()
                .zip(mean_a.as_slice().par_iter().zip(gi)),
        )
        .for_each(|(q, (&mb, (&ma, &g)))| *q = mb + ma * g);
    Ok(())
}
