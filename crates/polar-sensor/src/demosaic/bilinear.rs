//! Bilinear demosaicing, bit-identical to polanalyser's `COLOR_PolarMono`.
//!
//! polanalyser runs OpenCV's Bayer bilinear demosaicing twice (`COLOR_BayerBG2BGR`
//! for the 0°/90° lattice, `COLOR_BayerGR2BGR` for 45°/135°). Per pixel and channel
//! that is, with OpenCV's integer rounding:
//! - own sample: kept;
//! - channel on the left/right (or up/down) neighbours: `(a + b + 1) >> 1`;
//! - channel on the four diagonal neighbours: `(a + b + c + d + 2) >> 2`.
//!
//! Border (checked against OpenCV 5.0 in the goldens): OpenCV computes the
//! interior `1..w-1 x 1..h-1` and then copies column 1 to column 0, column `w-2` to
//! `w-1`, row 1 to row 0 and row `h-2` to `h-1` (so even measured samples on the
//! one-pixel frame are replaced). We do the same, which makes the whole image
//! identical to polanalyser's. For frames 2 pixels wide or high OpenCV has no
//! interior and polanalyser returns zeros; there we replicate each super-pixel
//! (nearest neighbour) instead.

use polar_image::PolarizerStack;
use polar_optics::stokes::linear_stokes_from_quad;
use rayon::prelude::*;

use crate::layout::{Mosaic, MosaicSample, channel_at, offset_of};

/// The four polarizer values at `(x, y)`, channel order `I0, I45, I90, I135`, in DN.
#[inline]
pub(crate) fn bilinear_at<T: MosaicSample>(
    src: &[T],
    w: usize,
    h: usize,
    x: usize,
    y: usize,
) -> [u32; 4] {
    if w < 4 || h < 4 {
        let (bx, by) = (x & !1, y & !1);
        return std::array::from_fn(|c| {
            let (dx, dy) = offset_of(c);
            src[(by + dy) * w + bx + dx].into()
        });
    }
    let (x, y) = (x.clamp(1, w - 2), y.clamp(1, h - 2));
    let at = |x: usize, y: usize| -> u32 { src[y * w + x].into() };
    let roles = [
        at(x, y),
        (at(x - 1, y) + at(x + 1, y) + 1) >> 1,
        (at(x, y - 1) + at(x, y + 1) + 1) >> 1,
        (at(x - 1, y - 1) + at(x + 1, y - 1) + at(x - 1, y + 1) + at(x + 1, y + 1) + 2) >> 2,
    ];
    let mut out = [0; 4];
    for (r, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
        out[channel_at(x + dx, y + dy)] = roles[r];
    }
    out
}

/// Bilinear demosaicing of the whole mosaic (size already checked).
pub(crate) fn bilinear<T: MosaicSample>(raw: &Mosaic<T>) -> PolarizerStack {
    let (w, h) = raw.size();
    let src = raw.as_slice();
    let mut out = PolarizerStack::new(w, h);
    out.pixels_mut()
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                *px = bilinear_at(src, w, h, x, y).map(|v| v as f32);
            }
        });
    out
}

/// Which role (0 own, 1 left/right, 2 up/down, 3 diagonal) carries each channel
/// `I0, I45, I90, I135`, for a pixel at row parity `py` and column parity `px`:
/// `ROLE_OF[py][px][c]`. Follows from the layout `[[90, 45], [135, 0]]`.
const ROLE_OF: [[[usize; 4]; 2]; 2] = [[[3, 1, 0, 2], [2, 0, 1, 3]], [[1, 3, 2, 0], [0, 2, 3, 1]]];

/// Linear Stokes `S0, S1, S2` of one mosaic row `y` after bilinear demosaicing,
/// without materialising the four images: the fused kernel of [`crate::products`].
///
/// Each output slice has the mosaic width; `w, h >= 4` (smaller frames use
/// [`bilinear_at`] per pixel).
pub(crate) fn bilinear_stokes_row<T: MosaicSample>(
    src: &[T],
    w: usize,
    h: usize,
    y: usize,
    [s0, s1, s2]: [&mut [f32]; 3],
) {
    let yc = y.clamp(1, h - 2);
    let rows = [
        &src[(yc - 1) * w..yc * w],
        &src[yc * w..(yc + 1) * w],
        &src[(yc + 1) * w..(yc + 2) * w],
    ];
    if yc & 1 == 0 {
        stokes_row_interior::<T, 0>(rows, s0, s1, s2);
    } else {
        stokes_row_interior::<T, 1>(rows, s0, s1, s2);
    }
    for s in [s0, s1, s2] {
        s[0] = s[1];
        s[w - 1] = s[w - 2];
    }
}

/// Interior columns `1..w-1` of [`bilinear_stokes_row`] for row parity `PY`,
/// two pixels (odd column, even column) per step so that roles are compile-time.
#[inline(always)]
fn stokes_row_interior<T: MosaicSample, const PY: usize>(
    [up, mid, dn]: [&[T]; 3],
    s0: &mut [f32],
    s1: &mut [f32],
    s2: &mut [f32],
) {
    let w = mid.len();
    let v = |r: &[T], i: usize| -> u32 { r[i].into() };
    for k in 0..(w - 2) / 2 {
        for (j, px) in [(0, 1), (1, 0)] {
            let x = 2 * k + 1 + j;
            let roles = [
                v(mid, x),
                (v(mid, x - 1) + v(mid, x + 1) + 1) >> 1,
                (v(up, x) + v(dn, x) + 1) >> 1,
                (v(up, x - 1) + v(up, x + 1) + v(dn, x - 1) + v(dn, x + 1) + 2) >> 2,
            ]
            .map(|r| r as f32);
            let q = ROLE_OF[PY][px];
            let [a, b, c] =
                linear_stokes_from_quad(roles[q[0]], roles[q[1]], roles[q[2]], roles[q[3]]);
            (s0[x], s1[x], s2[x]) = (a, b, c);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ROLE_OF` must agree with the layout: the role at offset (dx, dy) carries `channel_at(x+dx, y+dy)`.
    #[test]
    fn role_table_matches_layout() {
        for (py, px) in [(0, 0), (0, 1), (1, 0), (1, 1)] {
            for (r, (dx, dy)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                let c = channel_at(px + dx, py + dy);
                assert_eq!(ROLE_OF[py][px][c], r, "parity ({px},{py}) channel {c}");
            }
        }
    }

    #[test]
    fn fused_row_equals_stokes_of_demosaiced_pixels() {
        let (w, h) = (10, 8);
        let src: Vec<u16> = (0..w * h).map(|i| ((i * 7919) % 4093) as u16).collect();
        for y in 0..h {
            let (mut a, mut b, mut c) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
            bilinear_stokes_row(&src, w, h, y, [&mut a, &mut b, &mut c]);
            for x in 0..w {
                let i = bilinear_at(&src, w, h, x, y).map(|v| v as f32);
                assert_eq!(
                    [a[x], b[x], c[x]],
                    linear_stokes_from_quad(i[0], i[1], i[2], i[3]),
                    "({x},{y})"
                );
            }
        }
    }
}
