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

use polar_image::{ImageView, PolarizerStack};
use rayon::prelude::*;

use crate::layout::{Mosaic, MosaicSample, channel_at, offset_of};

/// OpenCV's rounded mean of two samples (Bayer bilinear), `(a + b + 1) >> 1`.
#[inline(always)]
pub(crate) fn mean2(a: u32, b: u32) -> u32 {
    (a + b + 1) >> 1
}

/// OpenCV's rounded mean of four samples (Bayer bilinear), `(a + b + c + d + 2) >> 2`.
#[inline(always)]
pub(crate) fn mean4(a: u32, b: u32, c: u32, d: u32) -> u32 {
    (a + b + c + d + 2) >> 2
}

/// The four polarizer values at `(x, y)` of the mosaic `raw`, channel order
/// `I0, I45, I90, I135`, in DN.
#[inline]
pub(crate) fn bilinear_at<T: MosaicSample>(
    raw: ImageView<'_, T, 1>,
    x: usize,
    y: usize,
) -> [u32; 4] {
    let (w, h) = raw.size();
    if w < 4 || h < 4 {
        let (bx, by) = (x & !1, y & !1);
        return std::array::from_fn(|c| {
            let (dx, dy) = offset_of(c);
            raw.at(bx + dx, by + dy).into()
        });
    }
    let (x, y) = (x.clamp(1, w - 2), y.clamp(1, h - 2));
    let [up, mid, dn] = [y - 1, y, y + 1].map(|r| raw.row(r));
    let at = |row: &[T], x: usize| -> u32 { row[x].into() };
    let roles = [
        at(mid, x),
        mean2(at(mid, x - 1), at(mid, x + 1)),
        mean2(at(up, x), at(dn, x)),
        mean4(at(up, x - 1), at(up, x + 1), at(dn, x - 1), at(dn, x + 1)),
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
    let src = raw.view();
    let mut out = PolarizerStack::new(w, h);
    out.pixels_mut()
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, px) in row.iter_mut().enumerate() {
                *px = bilinear_at(src, x, y).map(|v| v as f32);
            }
        });
    out
}

/// The three mosaic rows output row `y` of [`bilinear_stokes_rows`] reads (around the
/// centre row clamped to `1..h-1`, OpenCV's border rule) and whether that centre is odd.
#[inline(always)]
pub(crate) fn rows_around<T>(raw: ImageView<'_, T, 1>, y: usize) -> ([&[T]; 3], bool) {
    let yc = y.clamp(1, raw.height() - 2);
    ([raw.row(yc - 1), raw.row(yc), raw.row(yc + 1)], yc & 1 == 1)
}

/// Linear Stokes `S0, S1, S2` of one mosaic row after bilinear demosaicing, from the
/// rows `[up, mid, dn]` around its (clamped) centre row and that row's parity
/// ([`rows_around`]), without materialising the four images: the fused kernel of
/// [`crate::products`] (the rows may also come from elsewhere, e.g. the colour chain's
/// per-band buffer).
///
/// Per pixel, with the roles of [`bilinear_at`] (own sample `o`, left/right mean `h`,
/// up/down mean `v`, diagonal mean `d`): `S0 = (o + h + v + d) / 2` and, from the
/// layout `[[90, 45], [135, 0]]`, with `P = d − o` and `Q = h − v`:
/// `(S1, S2) = (P, Q)` at (even row, even column), `(−Q, −P)` at (even, odd),
/// `(Q, P)` at (odd, even), `(−P, −Q)` at (odd, odd) — i.e. `S1 = I0 − I90`,
/// `S2 = I45 − I135` of `linear_stokes_from_quad`, bit for bit (a test checks it;
/// negation swaps the operands, so an exact zero stays `+0`). One uniform loop
/// over the row with per-column selects, so that it vectorises; `#[inline(always)]`
/// so that it is compiled for the SIMD target chosen by the caller's dispatch.
///
/// Each row and output slice has the mosaic width; width and height `>= 4` (smaller
/// frames use [`bilinear_at`] per pixel).
#[inline(always)]
pub(crate) fn bilinear_stokes_rows<T: MosaicSample>(
    [up, mid, dn]: [&[T]; 3],
    odd_row: bool,
    [s0, s1, s2]: [&mut [f32]; 3],
) {
    let w = mid.len();
    let n = w - 2;
    // Every slice re-cut to exactly `n` so that the loop has no bounds checks.
    fn cut<T>(s: &[T], start: usize, n: usize) -> &[T] {
        &s[start..start + n]
    }
    let at = |s, start| cut(s, start, n);
    let (o, ml, mr, uc, dc) = (at(mid, 1), at(mid, 0), at(mid, 2), at(up, 1), at(dn, 1));
    let (ul, ur, dl, dr) = (at(up, 0), at(up, 2), at(dn, 0), at(dn, 2));
    let (s0i, s1i, s2i) = (&mut s0[1..=n], &mut s1[1..=n], &mut s2[1..=n]);
    let u = |s: &[T], i: usize| -> i32 { Into::<u32>::into(s[i]) as i32 };
    for i in 0..n {
        // Sums of at most four 16-bit samples fit in i32; i32 -> f32 is one instruction.
        let own = u(o, i);
        let hor = (u(ml, i) + u(mr, i) + 1) >> 1;
        let ver = (u(uc, i) + u(dc, i) + 1) >> 1;
        let dia = (u(ul, i) + u(ur, i) + u(dl, i) + u(dr, i) + 2) >> 2;
        let [o, h, v, d] = [own, hor, ver, dia].map(|r| r as f32);
        s0i[i] = 0.5 * (o + h + v + d);
        // Interior column x = i + 1.
        let odd_col = i & 1 == 0;
        let (p, q) = if odd_col {
            (o - d, v - h)
        } else {
            (d - o, h - v)
        };
        (s1i[i], s2i[i]) = if odd_col != odd_row { (q, p) } else { (p, q) };
    }
    for s in [s0, s1, s2] {
        s[0] = s[1];
        s[w - 1] = s[w - 2];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polar_optics::stokes::linear_stokes_from_quad;

    #[test]
    fn fused_row_equals_stokes_of_demosaiced_pixels() {
        let (w, h) = (10, 8);
        let data: Vec<u16> = (0..w * h).map(|i| ((i * 7919) % 4093) as u16).collect();
        let raw = Mosaic::from_vec(w, h, data).unwrap();
        for y in 0..h {
            // Every parity of row and column is covered (all four super-pixel positions).
            let (mut a, mut b, mut c) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
            let (rows, odd_row) = rows_around(raw.view(), y);
            bilinear_stokes_rows(rows, odd_row, [&mut a, &mut b, &mut c]);
            for x in 0..w {
                let i = bilinear_at(raw.view(), x, y).map(|v| v as f32);
                let want = linear_stokes_from_quad(i[0], i[1], i[2], i[3]);
                // Bit for bit: also the sign of zero.
                assert_eq!(
                    [a[x], b[x], c[x]].map(f32::to_bits),
                    want.map(f32::to_bits),
                    "({x},{y})"
                );
            }
        }
    }
}
