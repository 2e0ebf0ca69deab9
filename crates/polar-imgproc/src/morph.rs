//! Grey-scale morphology on `f32` images: erosion (local minimum), dilation (local
//! maximum), opening and closing with rectangle, cross and ellipse structuring elements.
//!
//! Border: like `cv2.erode`/`cv2.dilate` with their default `BORDER_CONSTANT` and
//! `morphologyDefaultBorderValue()` (+inf for erosion, -inf for dilation), pixels outside
//! the image are simply left out of the minimum/maximum.

use polar_image::Gray;
use rayon::prelude::*;

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
struct Run {
    dy: usize,
    x0: usize,
    len: usize,
}

/// The non-empty rows of the structuring element, as `cv::getStructuringElement` builds it.
fn runs(shape: MorphShape, kw: usize, kh: usize) -> Vec<Run> {
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

/// Which extremum a morphological operation takes.
#[derive(Clone, Copy)]
enum Extremum {
    Min,
    Max,
}

impl Extremum {
    fn pick(self, a: f32, b: f32) -> f32 {
        match self {
            Extremum::Min => a.min(b),
            Extremum::Max => a.max(b),
        }
    }

    /// The border value that never wins.
    fn neutral(self) -> f32 {
        match self {
            Extremum::Min => f32::INFINITY,
            Extremum::Max => f32::NEG_INFINITY,
        }
    }
}

fn check_kernel(kw: usize, kh: usize) -> Result<(), Error> {
    match (kw, kh) {
        (0, _) | (_, 0) => Err(Error::KernelSize {
            ksize: 0,
            reason: "must be >= 1",
        }),
        _ => Ok(()),
    }
}

/// Extremum over the structuring element anchored at its centre; out-of-image pixels ignored.
fn morph(
    src: &Gray<f32>,
    dst: &mut Gray<f32>,
    shape: MorphShape,
    kw: usize,
    kh: usize,
    ext: Extremum,
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
    let neutral = ext.neutral();
    dst.as_mut_slice()
        .par_chunks_mut(w * rows)
        .enumerate()
        .for_each(|(b, out)| {
            let y0 = b * rows;
            let n_out = out.len() / w;
            let n_tmp = n_out + kh - 1;
            let mut pad = vec![neutral; w + kw - 1];
            // tmp[d][t]: horizontal extremum of run d over source row y0 + t - ay.
            let mut tmp = vec![neutral; distinct.len() * n_tmp * w];
            for t in 0..n_tmp {
                let Some(y) = (y0 + t).checked_sub(ay).filter(|&y| y < h) else {
                    continue;
                };
                pad[ax..ax + w].copy_from_slice(&s[y * w..(y + 1) * w]);
                for (d, &(x0, len)) in distinct.iter().enumerate() {
                    let o = &mut tmp[(d * n_tmp + t) * w..(d * n_tmp + t + 1) * w];
                    o.copy_from_slice(&pad[x0..x0 + w]);
                    for i in 1..len {
                        o.iter_mut()
                            .zip(&pad[x0 + i..x0 + i + w])
                            .for_each(|(a, &v)| *a = ext.pick(*a, v));
                    }
                }
            }
            for (r, orow) in out.chunks_exact_mut(w).enumerate() {
                orow.fill(neutral);
                for &(dy, d) in &rows_of {
                    let t = &tmp[(d * n_tmp + r + dy) * w..(d * n_tmp + r + dy + 1) * w];
                    orow.iter_mut()
                        .zip(t)
                        .for_each(|(a, &v)| *a = ext.pick(*a, v));
                }
            }
        });
    Ok(())
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
    morph(src, dst, shape, kw, kh, Extremum::Min)
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
    morph(src, dst, shape, kw, kh, Extremum::Max)
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
