//! Binary masks as `bool` planes (row-major, `w x h`): closing and opening (equal to the
//! grey-scale operators on 0/1 images), hole filling and small-component removal with the labelling; the
//! clean-up the segmenting tasks (material regions, transparency masks) share.

use crate::morph::{check_kernel, runs};
use crate::{Connectivity, MorphShape, close, label, open};
use polar_image::Gray;

use crate::Error;

/// Morphological closing then opening with an ellipse of diameter `k` (odd): bridges gaps
/// narrower than `k` and removes specks narrower than `k`. Equal to [`grey_close_open`];
/// computed on byte run distances (16 pixels per SIMD lane group) where the ellipse is
/// narrower than 509 pixels.
pub fn close_open(m: &[bool], w: usize, h: usize, k: usize) -> Result<Vec<bool>, Error> {
    check_kernel(k, k)?;
    if k / 2 >= usize::from(u8::MAX) {
        return grey_close_open(m, w, h, k);
    }
    let element: Vec<Offsets> = runs(MorphShape::Ellipse, k, k)
        .iter()
        .map(|r| Offsets {
            dy: r.dy as isize - (k / 2) as isize,
            left: (k / 2 - r.x0) as u8,
            right: (r.x0 + r.len - 1 - k / 2) as u8,
        })
        .collect();
    let closed = binary_morph(
        &binary_morph(m, w, h, &element, false),
        w,
        h,
        &element,
        true,
    );
    let opened = binary_morph(
        &binary_morph(&closed, w, h, &element, true),
        w,
        h,
        &element,
        false,
    );
    Ok(opened)
}

/// `close` then `open` with [`MorphShape::Ellipse`] of diameter `k` on the 0/1 image of
/// `m` (out-of-image pixels ignored), thresholded at 0.5.
pub fn grey_close_open(m: &[bool], w: usize, h: usize, k: usize) -> Result<Vec<bool>, Error> {
    let src = Gray::from_vec(w, h, m.iter().map(|&b| f32::from(u8::from(b))).collect())
        .expect("mask size");
    let (mut a, mut b) = (Gray::new(w, h), Gray::new(w, h));
    close(&src, &mut a, MorphShape::Ellipse, k, k)?;
    open(&a, &mut b, MorphShape::Ellipse, k, k)?;
    Ok(b.as_slice().iter().map(|&v| v > 0.5).collect())
}

/// One row of a structuring element that contains its centre column: row offset `dy`
/// from the anchor, reaching `left` columns to the left and `right` to the right.
struct Offsets {
    dy: isize,
    left: u8,
    right: u8,
}

/// Dilation of `m` by `element` (or, with `erode`, erosion: the dilation of the
/// complement, complemented), pixels outside the image ignored. A pixel is hit when, in
/// some element row, the nearest set pixel of that image row to its left lies within
/// `left` or the nearest to its right within `right`.
fn binary_morph(m: &[bool], w: usize, h: usize, element: &[Offsets], erode: bool) -> Vec<bool> {
    use rayon::prelude::*;
    let row = w.max(1);
    // Per pixel, the distance along its row to the nearest set pixel at or left of it and
    // at or right of it (saturated: the element reaches at most 254 columns).
    let (mut left, mut right) = (vec![0u8; w * h], vec![0u8; w * h]);
    left.par_chunks_mut(row)
        .zip(right.par_chunks_mut(row))
        .zip(m.par_chunks(row))
        .for_each(|((l, r), m)| row_distances(m, !erode, l, r));
    let mut out = vec![false; w * h];
    out.par_chunks_mut(row).enumerate().for_each(|(y, o)| {
        for e in element {
            let Some(sy) = y.checked_add_signed(e.dy).filter(|&sy| sy < h) else {
                continue;
            };
            let (l, r) = (&left[sy * w..(sy + 1) * w], &right[sy * w..(sy + 1) * w]);
            o.iter_mut()
                .zip(l.iter().zip(r))
                .for_each(|(o, (&l, &r))| *o |= (l <= e.left) | (r <= e.right));
        }
        if erode {
            o.iter_mut().for_each(|v| *v = !*v);
        }
    });
    out
}

/// Distances from each pixel of `row` to the nearest pixel equal to `set` at or left of
/// it (`left`) and at or right of it (`right`), saturated at [`u8::MAX`] (none within 254).
fn row_distances(row: &[bool], set: bool, left: &mut [u8], right: &mut [u8]) {
    let mut run = u8::MAX;
    for (d, &v) in left.iter_mut().zip(row) {
        run = if v == set { 0 } else { run.saturating_add(1) };
        *d = run;
    }
    run = u8::MAX;
    for (d, &v) in right.iter_mut().zip(row).rev() {
        run = if v == set { 0 } else { run.saturating_add(1) };
        *d = run;
    }
}

/// Connected-component labels of `m` (0 = outside `m`) and their count.
pub fn components(m: &[bool], w: usize, h: usize) -> Result<(Vec<u32>, usize), Error> {
    let src = Gray::from_vec(w, h, m.iter().map(|&b| u8::from(b)).collect()).expect("mask size");
    let mut lab = Gray::new(w, h);
    let n = label(&src, &mut lab, Connectivity::Eight)?;
    Ok((lab.into_vec(), n))
}

/// Fills holes: components of the complement (4-connected) that do not touch the border.
pub fn fill_holes(m: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    let inv: Vec<u8> = m.iter().map(|&b| u8::from(!b)).collect();
    let src = Gray::from_vec(w, h, inv).expect("mask size");
    let mut lab = Gray::new(w, h);
    let n = label(&src, &mut lab, Connectivity::Four)?;
    let lab = lab.into_vec();
    let mut touches = vec![false; n + 1];
    for x in 0..w {
        touches[lab[x] as usize] = true;
        touches[lab[(h - 1) * w + x] as usize] = true;
    }
    for y in 0..h {
        touches[lab[y * w] as usize] = true;
        touches[lab[y * w + w - 1] as usize] = true;
    }
    Ok(m.iter()
        .zip(&lab)
        .map(|(&b, &l)| b || !touches[l as usize])
        .collect())
}

/// Drops components of `m` smaller than `min_area` pixels.
pub fn remove_small(m: &[bool], w: usize, h: usize, min_area: usize) -> Result<Vec<bool>, Error> {
    let (lab, n) = components(m, w, h)?;
    let mut area = vec![0usize; n + 1];
    lab.iter().for_each(|&l| area[l as usize] += 1);
    Ok(lab
        .iter()
        .map(|&l| l != 0 && area[l as usize] >= min_area)
        .collect())
}

/// Structuring-element diameter: about 1/40 of the image's smaller side, odd, at least 3.
pub fn morph_size(w: usize, h: usize) -> usize {
    ((w.min(h) / 40) | 1).max(3)
}

/// The mask pipeline: close then open ([`morph_size`]), fill holes, drop components
/// under 1/2000 of the image (at least 4 pixels).
pub fn clean(seed: &[bool], w: usize, h: usize) -> Result<Vec<bool>, Error> {
    let m = close_open(seed, w, h, morph_size(w, h))?;
    let m = fill_holes(&m, w, h)?;
    remove_small(&m, w, h, (w * h / 2000).max(4))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ring_hole_is_filled_and_border_gap_is_not() {
        // 7x7: a ring around (3,3), and a notch open to the border at the top.
        let (w, h) = (7, 7);
        let mut m = vec![false; w * h];
        for y in 1..6 {
            for x in 1..6 {
                m[y * w + x] = x == 1 || x == 5 || y == 1 || y == 5;
            }
        }
        let f = fill_holes(&m, w, h).unwrap();
        assert!(f[3 * w + 3] && f[2 * w + 2]);
        assert!(!f[0] && !f[3 * w]);
    }

    /// The run-distance closing-opening equals the grey-scale one exactly, on
    /// pseudo-random masks of several densities, sizes below and above the element, odd
    /// and even diameters, up to the widest the byte distances take.
    #[test]
    fn close_open_equals_the_grey_scale_operators() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for (w, h, k) in [
            (1, 1, 3),
            (5, 3, 7),
            (40, 31, 5),
            (64, 48, 9),
            (33, 70, 8),
            (90, 20, 25),
        ] {
            for density in [5u64, 30, 50, 80] {
                let m: Vec<bool> = (0..w * h).map(|_| next() % 100 < density).collect();
                assert_eq!(
                    close_open(&m, w, h, k).unwrap(),
                    grey_close_open(&m, w, h, k).unwrap(),
                    "{w}x{h}, k = {k}, density {density}"
                );
            }
        }
    }

    #[test]
    fn small_components_go() {
        let (w, h) = (5, 1);
        let m = [true, false, true, true, true];
        assert_eq!(
            remove_small(&m, w, h, 2).unwrap(),
            [false, false, true, true, true]
        );
    }
}
