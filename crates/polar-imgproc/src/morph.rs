//! Grey-scale morphology on `f32` images: erosion (local minimum), dilation (local
//! maximum), opening and closing with rectangle, cross and ellipse structuring elements.
//!
//! Border: like `cv2.erode`/`cv2.dilate` with their default `BORDER_CONSTANT` and
//! `morphologyDefaultBorderValue()` (+inf for erosion, -inf for dilation), pixels outside
//! the image are simply left out of the minimum/maximum.

use polar_image::Gray;

use crate::{Error, filter::band_rows, same_size};

/// Structuring-element shape, as `cv2.getStructuringElement(shape, (kw, kh))` with the
/// anchor at the centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MorphShape {
    /// `MORPH_RECT`: the full `kw x kh` rectangle (separable, fastest).
    Rect,
    /// `MORPH_CROSS`: the centre row and the centre column.
    Cross,
    /// `MORPH_ELLIPSE`: the ellipse inscribed in the rectangle, rounded as OpenCV does.
    Ellipse,
}

/// One row of a structuring element: kernel row `dy` covers columns `x0 .. x0 + len`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Run {
    pub(crate) dy: usize,
    pub(crate) x0: usize,
    pub(crate) len: usize,
}

/// The non-empty rows of the structuring element, as `cv::getStructuringElement` builds it.
pub(crate) fn runs(shape: MorphShape, kw: usize, kh: usize) -> Vec<Run> {
    let (c, r) = (kw / 2, kh / 2);
    (0..kh)
        .filter_map(|i| {
            let (j1, j2) = match shape {
                MorphShape::Rect => (0, kw),
                MorphShape::Cross if i == r => (0, kw),
                MorphShape::Cross => (c, c + 1),
                MorphShape::Ellipse => {
                    let dy = i as f64 - r as f64;
                    let inv_r2 = if r > 0 { 1.0 / (r * r) as f64 } else { 0.0 };
                    let dx = (c as f64 * (((r * r) as f64 - dy * dy) * inv_r2).sqrt())
                        .round_ties_even() as usize;
                    (c.saturating_sub(dx), (c + dx + 1).min(kw))
                }
            };
            (j2 > j1).then_some(Run {
                dy: i,
                x0: j1,
                len: j2 - j1,
            })
        })
        .collect()
}

/// Which extremum a morphological operation takes (a type, so the hot loops are
/// compiled once per extremum without a branch inside).
trait Pick: Send + Sync {
    /// The border value that never wins.
    const NEUTRAL: f32;
    /// The winner of two values. Plain comparisons (not `f32::min`/`max`) compile to single
    /// SIMD min/max instructions; NaN inputs give unspecified results, as in OpenCV.
    fn pick(a: f32, b: f32) -> f32;
}

/// Erosion: minimum.
struct Min;
/// Dilation: maximum.
struct Max;

impl Pick for Min {
    const NEUTRAL: f32 = f32::INFINITY;
    #[inline(always)]
    fn pick(a: f32, b: f32) -> f32 {
        if b < a { b } else { a }
    }
}

impl Pick for Max {
    const NEUTRAL: f32 = f32::NEG_INFINITY;
    #[inline(always)]
    fn pick(a: f32, b: f32) -> f32 {
        if b > a { b } else { a }
    }
}

pub(crate) fn check_kernel(kw: usize, kh: usize) -> Result<(), Error> {
    match (kw, kh) {
        (0, _) | (_, 0) => Err(Error::KernelSize {
            ksize: 0,
            reason: "must be >= 1",
        }),
        _ => Ok(()),
    }
}

/// Extremum over the structuring element anchored at its centre; out-of-image pixels ignored.
fn morph<P: Pick>(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
) -> Result<(), Error> {
    same_size(src, dst)?;
    check_kernel(kw, kh)?;
    let (w, h) = src.size();
    let (ax, ay) = (kw / 2, kh / 2);
    let all = runs(shape, kw, kh);
    let mut distinct: Vec<(usize, usize)> = all.iter().map(|r| (r.x0, r.len)).collect();
    distinct.sort_unstable();
    distinct.dedup();
    // (kernel row, index into `distinct`) per non-empty kernel row.
    let rows_of: Vec<(usize, usize)> = all
        .iter()
        .map(|r| (r.dy, distinct.partition_point(|&d| d < (r.x0, r.len))))
        .collect();
    let rows = band_rows(ay.max(kh - 1 - ay));
    let s = src.as_slice();
    let neutral = P::NEUTRAL;
    let rect = all.len() == kh && distinct.len() == 1;
    let max_len = distinct.iter().map(|d| d.1).max().unwrap_or(1);
    crate::par_bands(
        dst.as_mut_slice(),
        w,
        rows,
        |y0, out, sc: &mut [Vec<f32>; 3]| {
            let n_out = out.len() / w;
            let n_tmp = n_out + kh - 1;
            let [sc_a, sc_b, sc_t] = sc;
            let (mut cur, mut nxt) = (
                crate::scratch(sc_a, w + kw - 1, neutral),
                crate::scratch(sc_b, w + kw - 1, neutral),
            );
            // tmp[d][t]: horizontal extremum of run d over source row y0 + t - ay.
            let tmp = crate::scratch(sc_t, distinct.len() * n_tmp * w, neutral);
            for t in 0..n_tmp {
                let Some(y) = (y0 + t).checked_sub(ay).filter(|&y| y < h) else {
                    for d in 0..distinct.len() {
                        tmp[(d * n_tmp + t) * w..(d * n_tmp + t + 1) * w].fill(neutral);
                    }
                    continue;
                };
                let row = &s[y * w..(y + 1) * w];
                if let [(x0, len)] = distinct[..]
                    && max_len <= DIRECT_MAX
                {
                    run_direct::<P>(
                        row,
                        x0 as isize - ax as isize,
                        len,
                        &mut tmp[t * w..(t + 1) * w],
                    );
                    continue;
                }
                cur[..ax].fill(neutral);
                cur[ax + w..].fill(neutral);
                cur[ax..ax + w].copy_from_slice(row);
                // Doubling: at level `span`, cur[x] = extremum of the `span` pixels from x; a
                // run of length len is two overlapping windows of the largest span <= len.
                let mut span = 1;
                loop {
                    for (d, &(x0, len)) in distinct.iter().enumerate() {
                        if prev_pow2(len) == span {
                            let o = &mut tmp[(d * n_tmp + t) * w..(d * n_tmp + t + 1) * w];
                            let (a, b) =
                                (&cur[x0..x0 + w], &cur[x0 + len - span..x0 + len - span + w]);
                            o.iter_mut()
                                .zip(a.iter().zip(b))
                                .for_each(|(o, (&a, &b))| *o = P::pick(a, b));
                        }
                    }
                    if 2 * span > max_len {
                        break;
                    }
                    let n = cur.len() - span;
                    nxt[..n]
                        .iter_mut()
                        .zip(cur[..n].iter().zip(&cur[span..]))
                        .for_each(|(o, (&a, &b))| *o = P::pick(a, b));
                    std::mem::swap(&mut cur, &mut nxt);
                    span *= 2;
                }
            }
            if rect && kh > DIRECT_MAX {
                vertical_doubling::<P>(tmp, w, n_tmp, kh, out);
                return;
            }
            let tmp: &[f32] = tmp;
            for (r, orow) in out.chunks_exact_mut(w).enumerate() {
                let taps: Vec<&[f32]> = rows_of
                    .iter()
                    .map(|&(dy, d)| &tmp[(d * n_tmp + r + dy) * w..(d * n_tmp + r + dy + 1) * w])
                    .collect();
                pick_into::<P>(orow, &taps);
            }
        },
    );
    Ok(())
}

/// A rectangle's rows (one run) up to this length, and its columns up to this height, are
/// reduced tap by tap (fused four at a time); longer runs, and shapes with several run
/// lengths (cross, ellipse, which share the doubling levels), use doubling, whose cost
/// is logarithmic in the length.
const DIRECT_MAX: usize = 8;

/// `out[x] = extremum of tap[x] over all taps` (at least one), reading up to four taps
/// per pass over `out` to keep memory traffic low.
fn pick_into<P: Pick>(out: &mut [f32], taps: &[&[f32]]) {
    let (first, rest) = taps.split_at(taps.len().min(4));
    let o = out.iter_mut();
    match first {
        [a] => o.zip(*a).for_each(|(o, &a)| *o = a),
        [a, b] => o
            .zip(a.iter().zip(*b))
            .for_each(|(o, (&a, &b))| *o = P::pick(a, b)),
        [a, b, c] => o
            .zip(a.iter().zip(b.iter().zip(*c)))
            .for_each(|(o, (&a, (&b, &c)))| *o = P::pick(P::pick(a, b), c)),
        [a, b, c, d] => o
            .zip(a.iter().zip(b.iter().zip(c.iter().zip(*d))))
            .for_each(|(o, (&a, (&b, (&c, &d))))| *o = P::pick(P::pick(a, b), P::pick(c, d))),
        _ => {}
    }
    for g in rest.chunks(3) {
        let o = out.iter_mut();
        match g {
            [a] => o.zip(*a).for_each(|(o, &a)| *o = P::pick(*o, a)),
            [a, b] => o
                .zip(a.iter().zip(*b))
                .for_each(|(o, (&a, &b))| *o = P::pick(*o, P::pick(a, b))),
            [a, b, c] => o
                .zip(a.iter().zip(b.iter().zip(*c)))
                .for_each(|(o, (&a, (&b, &c)))| *o = P::pick(P::pick(*o, a), P::pick(b, c))),
            _ => {}
        }
    }
}

/// `out[x] = extremum of row[x + off .. x + off + len]` (columns outside the row ignored),
/// straight from the source row: taps fused by [`pick_into`] inside, a scalar loop on the
/// few edge pixels.
fn run_direct<P: Pick>(row: &[f32], off: isize, len: usize, out: &mut [f32]) {
    let w = row.len() as isize;
    let lo = (-off).clamp(0, w);
    let hi = (w - off - len as isize + 1).clamp(lo, w);
    let (lo, hi) = (lo as usize, hi as usize);
    if hi > lo {
        let base = (lo as isize + off) as usize;
        let taps: Vec<&[f32]> = (0..len)
            .map(|i| &row[base + i..base + i + hi - lo])
            .collect();
        pick_into::<P>(&mut out[lo..hi], &taps);
    }
    for x in (0..lo).chain(hi..row.len()) {
        let first = (x as isize + off).max(0);
        let last = (x as isize + off + len as isize).min(w);
        out[x] = (first..last).fold(P::NEUTRAL, |m, c| P::pick(m, row[c as usize]));
    }
}

/// Largest power of two `<= n` (`n >= 1`).
fn prev_pow2(n: usize) -> usize {
    1 << (usize::BITS - 1 - n.leading_zeros())
}

/// Vertical extremum over `kh` consecutive rows of `tmp` (`n_tmp` rows of width `w`) into
/// `out`, by in-place doubling as for the rows.
#[inline(always)]
fn vertical_doubling<P: Pick>(tmp: &mut [f32], w: usize, n_tmp: usize, kh: usize, out: &mut [f32]) {
    let p = prev_pow2(kh);
    let mut span = 1;
    while span < p {
        for t in 0..n_tmp - span {
            let (head, tail) = tmp.split_at_mut((t + span) * w);
            let dst = &mut head[t * w..(t + 1) * w];
            dst.iter_mut()
                .zip(&tail[..w])
                .for_each(|(a, &b)| *a = P::pick(*a, b));
        }
        span *= 2;
    }
    for (r, orow) in out.chunks_exact_mut(w).enumerate() {
        let (a, b) = (
            &tmp[r * w..(r + 1) * w],
            &tmp[(r + kh - p) * w..(r + kh - p + 1) * w],
        );
        orow.iter_mut()
            .zip(a.iter().zip(b))
            .for_each(|(o, (&a, &b))| *o = P::pick(a, b));
    }
}

/// Erosion: minimum over the structuring element, matching `cv2.erode(src, kernel)` with
/// `kernel = cv2.getStructuringElement(shape, (kw, kh))` and default border (ignored).
pub fn erode(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
) -> Result<(), Error> {
    morph::<Min>(src, dst, shape, kw, kh)
}

/// Dilation: maximum over the structuring element, matching `cv2.dilate(src, kernel)`
/// (border ignored).
pub fn dilate(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
) -> Result<(), Error> {
    morph::<Max>(src, dst, shape, kw, kh)
}

/// Opening (erosion then dilation), matching `cv2.morphologyEx(src, MORPH_OPEN, kernel)`.
pub fn open(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
) -> Result<(), Error> {
    let mut tmp = Gray::new(src.width(), src.height());
    erode(src, &mut tmp, shape, kw, kh)?;
    dilate(&tmp, dst, shape, kw, kh)
}

/// Closing (dilation then erosion), matching `cv2.morphologyEx(src, MORPH_CLOSE, kernel)`.
pub fn close(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
) -> Result<(), Error> {
    let mut tmp = Gray::new(src.width(), src.height());
    dilate(src, &mut tmp, shape, kw, kh)?;
    erode(&tmp, dst, shape, kw, kh)
}

/// Minimum filter over a `kw x kh` rectangle (= rectangular erosion; out-of-image pixels
/// ignored, which equals scipy's `minimum_filter(mode='nearest')` too).
pub fn min_filter(src: &Gray<f32>, dst: &mut Gray<f32>, kw: usize, kh: usize) -> Result<(), Error> {
    erode(src, dst, MorphShape::Rect, kw, kh)
}

/// Maximum filter over a `kw x kh` rectangle (= rectangular dilation).
pub fn max_filter(src: &Gray<f32>, dst: &mut Gray<f32>, kw: usize, kh: usize) -> Result<(), Error> {
    dilate(src, dst, MorphShape::Rect, kw, kh)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mask(shape: MorphShape, kw: usize, kh: usize) -> Vec<String> {
        let mut rows = vec![vec!['.'; kw]; kh];
        for r in runs(shape, kw, kh) {
            rows[r.dy][r.x0..r.x0 + r.len]
                .iter_mut()
                .for_each(|c| *c = '#');
        }
        rows.into_iter().map(String::from_iter).collect()
    }

    #[test]
    fn structuring_elements_match_opencv() {
        // cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (5, 5)) and MORPH_CROSS (3, 3).
        assert_eq!(
            mask(MorphShape::Ellipse, 5, 5),
            ["..#..", "#####", "#####", "#####", "..#.."]
        );
        assert_eq!(mask(MorphShape::Cross, 3, 3), [".#.", "###", ".#."]);
    }

    #[test]
    fn erosion_ignores_the_border() {
        let src = Gray::from_vec(3, 1, vec![5.0f32, 1.0, 3.0]).unwrap();
        let mut dst = Gray::new(3, 1);
        erode(&src, &mut dst, MorphShape::Rect, 3, 3).unwrap();
        assert_eq!(dst.as_slice(), &[1.0, 1.0, 1.0]);
        dilate(&src, &mut dst, MorphShape::Rect, 3, 1).unwrap();
        assert_eq!(dst.as_slice(), &[5.0, 5.0, 3.0]);
    }
}
