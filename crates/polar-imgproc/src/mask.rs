//! Binary masks as `bool` planes (row-major, `w x h`): closing and opening with the
//! grey-scale operators, hole filling and small-component removal with the labelling; the
//! clean-up the segmenting tasks (material regions, transparency masks) share.

use crate::{Connectivity, MorphShape, close, label, open};
use polar_image::Gray;

use crate::Error;

/// A `w x h` boolean plane as a 0/1 float image.
fn to_f32(m: &[bool], w: usize, h: usize) -> Gray<f32> {
    Gray::from_vec(w, h, m.iter().map(|&b| f32::from(u8::from(b))).collect()).expect("mask size")
}

/// Morphological closing then opening with an ellipse of diameter `k` (odd): bridges gaps
/// narrower than `k` and removes specks narrower than `k`.
pub fn close_open(m: &[bool], w: usize, h: usize, k: usize) -> Result<Vec<bool>, Error> {
    let src = to_f32(m, w, h);
    let mut a = Gray::new(w, h);
    let mut b = Gray::new(w, h);
    close(&src, &mut a, MorphShape::Ellipse, k, k)?;
    open(&a, &mut b, MorphShape::Ellipse, k, k)?;
    Ok(b.as_slice().iter().map(|&v| v > 0.5).collect())
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
