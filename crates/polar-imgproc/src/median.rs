//! Median filter matching `cv2.medianBlur` (border `BORDER_REPLICATE`): `f32` images with
//! `ksize` 3 or 5 (all OpenCV accepts for float), `u8` images with any odd `ksize`.
//!
//! Small windows first sort each column of the window (shared by the neighbouring outputs),
//! then select the median from the sorted columns: for 3x3 with the classic
//! `med3(max(lows), med3(mids), min(highs))`, for 5x5 with a comparator network derived from
//! Batcher's odd-even merge sort by dropping every comparator that never swaps when columns
//! are sorted (checked on all 0/1 inputs, enough by the 0-1 principle) and every one the
//! middle output does not depend on (85 steps instead of Batcher's 191 or the classic 99).
//! Everything is vectorised over a row of pixels. Large `u8` windows use a sliding
//! histogram (Huang et al. 1979).

use polar_image::Gray;
use rayon::prelude::*;

use crate::{Border, Error, filter::band_rows, same_size};

/// A pixel type the median network can order.
trait Lane: Copy + Default + Send + Sync + PartialOrd {}
impl Lane for f32 {}
impl Lane for u8 {}

#[inline(always)]
fn lo<T: Lane>(a: T, b: T) -> T {
    if b < a { b } else { a }
}

#[inline(always)]
fn hi<T: Lane>(a: T, b: T) -> T {
    if b < a { a } else { b }
}

/// Writes a comparator network out as straight-line code (so that the compiler keeps the
/// values in registers and vectorises over pixels) plus, for the tests, the steps as data.
macro_rules! straight_network {
    ($name:ident, $steps:ident, $n:literal; $($k:ident $a:literal $b:literal),* $(,)?) => {
        #[inline(always)]
        fn $name<T: Lane>(v: &mut [T; $n]) {
            $(straight_network!(@ $k v $a $b);)*
        }
        #[cfg(test)]
        const $steps: &[(&str, usize, usize)] = &[$((stringify!($k), $a, $b)),*];
    };
    (@ x $v:ident $a:literal $b:literal) => {
        let (l, h) = (lo($v[$a], $v[$b]), hi($v[$a], $v[$b]));
        $v[$a] = l;
        $v[$b] = h;
    };
    (@ lo $v:ident $a:literal $b:literal) => {
        $v[$a] = lo($v[$a], $v[$b]);
    };
    (@ hi $v:ident $a:literal $b:literal) => {
        $v[$b] = hi($v[$a], $v[$b]);
    };
}

// The tests' `sorted_columns_median_network(5)` (slot `5 c + rank`, median in slot 12), written out;
// the test `written_out_network_is_the_generated_one` keeps the two identical.
straight_network!(median25_sorted_columns, MEDIAN25_STEPS, 25;
    x 4 5, x 14 15, x 5 7, x 8 10, x 9 11, x 12 14, x 5 6, x 9 10, x 13 14, x 0 4, x 1 5,
    x 2 6, x 8 12, x 10 14, x 11 15, x 16 20, x 17 21, x 18 22, x 19 23, x 2 4, x 3 5,
    x 10 12, x 11 13, x 18 20, x 19 21, x 1 2, x 3 4, x 5 6, x 9 10, x 11 12, x 13 14,
    x 17 18, x 19 20, x 21 22, x 0 8, x 1 9, x 2 10, x 3 11, x 4 12, x 5 13, x 6 14,
    lo 7 15, x 4 8, x 5 9, x 6 10, x 7 11, x 20 24, x 2 4, x 3 5, x 6 8, x 7 9, x 10 12,
    x 11 13, x 22 24, x 1 2, x 3 4, x 5 6, x 7 8, x 9 10, x 11 12, lo 13 14, x 21 22,
    x 23 24, hi 0 16, hi 1 17, hi 2 18, hi 3 19, hi 4 20, hi 5 21, lo 6 22, lo 7 23,
    lo 8 24, hi 8 16, hi 9 17, lo 10 18, lo 11 19, lo 12 20, lo 13 21, hi 6 10, hi 7 11,
    lo 12 16, lo 13 17, hi 10 12, lo 11 13, hi 11 12
);

// Batcher's network sorting 5 values (the tests' `batcher(5)`, ranks end in slot order).
straight_network!(sort5, SORT5_STEPS, 5; x 0 1, x 2 3, x 0 2, x 1 3, x 1 2, x 0 4, x 2 4, x 1 2, x 3 4);

/// Sorts the columns of five consecutive rows (`rows`, back to back) into `cols`, rank by
/// rank, in one pass.
fn sort5_columns<T: Lane>(rows: &[T], cols: &mut [T]) {
    let pw = rows.len() / 5;
    let r: [&[T]; 5] = std::array::from_fn(|j| &rows[j * pw..(j + 1) * pw]);
    let (c0, rest) = cols.split_at_mut(pw);
    let (c1, rest) = rest.split_at_mut(pw);
    let (c2, rest) = rest.split_at_mut(pw);
    let (c3, c4) = rest.split_at_mut(pw);
    for x in 0..pw {
        let mut v = [r[0][x], r[1][x], r[2][x], r[3][x], r[4][x]];
        sort5(&mut v);
        (c0[x], c1[x], c2[x], c3[x], c4[x]) = (v[0], v[1], v[2], v[3], v[4]);
    }
}

/// Median for `ksize` 3 or 5, replicate border: each output row first sorts every column
/// of its `ksize` source rows (each used by `ksize` outputs), then selects per pixel.
fn median_small<T: Lane>(src: &Gray<T>, dst: &mut Gray<T>, ksize: usize) {
    let (w, h) = src.size();
    let r = ksize / 2;
    let rows = band_rows(r);
    let s = src.as_slice();
    let pw = w + 2 * r;
    crate::par_bands(
        dst.as_mut_slice(),
        w,
        rows,
        |y0, out, sc: &mut [Vec<T>; 2]| {
            let n_out = out.len() / w;
            let [sp, sc_cols] = sc;
            let padded = crate::scratch(sp, (n_out + 2 * r) * pw, T::default());
            for (t, prow) in padded.chunks_exact_mut(pw).enumerate() {
                let y = Border::Replicate.index((y0 + t) as isize - r as isize, h);
                Border::Replicate.pad_row(&s[y * w..(y + 1) * w], r, prow);
            }
            let cols = crate::scratch(sc_cols, ksize * pw, T::default());
            for (row, orow) in out.chunks_exact_mut(w).enumerate() {
                if ksize == 3 {
                    sort3_columns(&padded[row * pw..(row + 3) * pw], cols);
                    median3_of_sorted_columns(cols, pw, orow);
                    continue;
                }
                sort5_columns(&padded[row * pw..(row + 5) * pw], cols);
                let taps: [&[T]; 25] = std::array::from_fn(|i| {
                    let start = (i % 5) * pw + i / 5;
                    &cols[start..start + w]
                });
                for (x, o) in orow.iter_mut().enumerate() {
                    let mut v: [T; 25] = std::array::from_fn(|i| taps[i][x]);
                    median25_sorted_columns(&mut v);
                    *o = v[12];
                }
            }
        },
    );
}

/// 3x3 median from sorted columns (`lo <= mid <= hi` per column):
/// `med3(max(lo), med3(mid), min(hi))` over three neighbouring columns, a classic
/// identity (e.g. Paeth, Graphics Gems 1990) that needs no copies.
#[inline(always)]
fn median3_of_sorted_columns<T: Lane>(cols: &[T], pw: usize, out: &mut [T]) {
    let w = out.len();
    let row = |rank: usize, dx: usize| &cols[rank * pw + dx..rank * pw + dx + w];
    let med3 = |a: T, b: T, c: T| hi(lo(a, b), lo(hi(a, b), c));
    let (l0, l1, l2) = (row(0, 0), row(0, 1), row(0, 2));
    let (m0, m1, m2) = (row(1, 0), row(1, 1), row(1, 2));
    let (h0, h1, h2) = (row(2, 0), row(2, 1), row(2, 2));
    for x in 0..w {
        let a = hi(hi(l0[x], l1[x]), l2[x]);
        let b = med3(m0[x], m1[x], m2[x]);
        let c = lo(lo(h0[x], h1[x]), h2[x]);
        out[x] = med3(a, b, c);
    }
}

/// Sorts the columns of three consecutive rows (`rows`, three rows back to back) into
/// `cols` (lowest row, middle row, highest row) in one pass.
fn sort3_columns<T: Lane>(rows: &[T], cols: &mut [T]) {
    let pw = rows.len() / 3;
    let (a, rest) = rows.split_at(pw);
    let (b, c) = rest.split_at(pw);
    let (l, rest) = cols.split_at_mut(pw);
    let (m, h) = rest.split_at_mut(pw);
    for x in 0..pw {
        let (p, q) = (lo(a[x], b[x]), hi(a[x], b[x]));
        l[x] = lo(p, c[x]);
        m[x] = hi(p, lo(q, c[x]));
        h[x] = hi(q, c[x]);
    }
}

/// Median by sliding 256-bin histogram for `u8` images, replicate border.
fn median_histogram(src: &Gray<u8>, dst: &mut Gray<u8>, ksize: usize) {
    let (w, h) = src.size();
    let r = ksize / 2;
    let half = (ksize * ksize / 2) as u32;
    let s = src.as_slice();
    dst.as_mut_slice()
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, orow)| {
            let rows: Vec<&[u8]> = (0..ksize)
                .map(|j| {
                    let yy = Border::Replicate.index((y + j) as isize - r as isize, h);
                    &s[yy * w..(yy + 1) * w]
                })
                .collect();
            let col = |x: isize| Border::Replicate.index(x, w);
            let mut hist = Histogram {
                fine: [0; 256],
                coarse: [0; 16],
            };
            for dx in 0..ksize {
                hist.update(&rows, col(dx as isize - r as isize), 1);
            }
            for (x, o) in orow.iter_mut().enumerate() {
                if x > 0 {
                    hist.update(&rows, col(x as isize - r as isize - 1), -1);
                    hist.update(&rows, col((x + r) as isize), 1);
                }
                *o = hist.select(half);
            }
        });
}

/// A two-level (16 x 16 bins) histogram of a sliding window.
struct Histogram {
    fine: [u32; 256],
    coarse: [u32; 16],
}

impl Histogram {
    /// Adds (`delta = 1`) or removes (`-1`) column `x` of the window rows.
    fn update(&mut self, rows: &[&[u8]], x: usize, delta: i32) {
        for row in rows {
            let v = usize::from(row[x]);
            self.fine[v] = self.fine[v].wrapping_add_signed(delta);
            self.coarse[v >> 4] = self.coarse[v >> 4].wrapping_add_signed(delta);
        }
    }

    /// The value of rank `k` (0-based).
    fn select(&self, mut k: u32) -> u8 {
        let mut bucket = 0;
        while k >= self.coarse[bucket] {
            k -= self.coarse[bucket];
            bucket += 1;
        }
        let mut v = bucket * 16;
        while k >= self.fine[v] {
            k -= self.fine[v];
            v += 1;
        }
        v as u8
    }
}

/// Median filter on `f32`, matching `cv2.medianBlur(src, ksize)` for `ksize` 3 or 5
/// (border `BORDER_REPLICATE`). NaN inputs give unspecified results.
pub fn median_blur(src: &Gray<f32>, dst: &mut Gray<f32>, ksize: usize) -> Result<(), Error> {
    same_size(src, dst)?;
    if !matches!(ksize, 3 | 5) {
        return Err(Error::KernelSize {
            ksize,
            reason: "float median supports 3 and 5 (as OpenCV)",
        });
    }
    median_small(src, dst, ksize);
    Ok(())
}

/// Median filter on `u8`, matching `cv2.medianBlur(src, ksize)` for any odd `ksize >= 3`
/// (border `BORDER_REPLICATE`).
pub fn median_blur_u8(src: &Gray<u8>, dst: &mut Gray<u8>, ksize: usize) -> Result<(), Error> {
    same_size(src, dst)?;
    match ksize {
        3 | 5 => median_small(src, dst, ksize),
        k if k >= 7 && k % 2 == 1 => median_histogram(src, dst, k),
        _ => {
            return Err(Error::KernelSize {
                ksize,
                reason: "must be odd and >= 3",
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two distinct slots of length `len` of a flat buffer, mutably.
    #[inline(always)]
    fn two_slots<T>(buf: &mut [T], len: usize, a: usize, b: usize) -> (&mut [T], &mut [T]) {
        if a < b {
            let (x, y) = buf.split_at_mut(b * len);
            (&mut x[a * len..(a + 1) * len], &mut y[..len])
        } else {
            let (x, y) = buf.split_at_mut(a * len);
            (&mut y[..len], &mut x[b * len..(b + 1) * len])
        }
    }

    /// Batcher's odd-even merge sort for `n` values, with the wires beyond `n` (padding to a
    /// power of two) holding +inf folded away: comparators as slot pairs, and the slot that
    /// ends at each sorted position.
    fn batcher(n: usize) -> (Vec<(usize, usize)>, Vec<usize>) {
        let size = n.next_power_of_two();
        let mut wire: Vec<Option<usize>> = (0..size).map(|i| (i < n).then_some(i)).collect();
        let mut ops = Vec::new();
        let mut p = 1;
        while p < size {
            let mut k = p;
            while k >= 1 {
                let mut j = k % p;
                while j + k < size {
                    for i in (0..k.min(size - j - k))
                        .filter(|i| (i + j) / (2 * p) == (i + j + k) / (2 * p))
                    {
                        let (a, b) = (i + j, i + j + k);
                        match (wire[a], wire[b]) {
                            (Some(sa), Some(sb)) => ops.push((sa, sb)),
                            (None, Some(_)) => wire.swap(a, b),
                            _ => {}
                        }
                    }
                    j += 2 * k;
                }
                k /= 2;
            }
            p *= 2;
        }
        (ops, wire.into_iter().flatten().collect())
    }

    /// One step of a comparator network on value slots (`a` gets the smaller value).
    #[derive(Clone, Copy, Debug)]
    enum Step {
        /// `a, b = min(a, b), max(a, b)`.
        Exchange(usize, usize),
        /// `a = min(a, b)` (the maximum is never used).
        Min(usize, usize),
        /// `b = max(a, b)` (the minimum is never used).
        Max(usize, usize),
    }

    /// The median of a `k x k` window whose `k` columns (slots `c * k .. c * k + k`) are
    /// already sorted: Batcher's network minus every comparator that never swaps under that
    /// precondition (checked on all 0/1 inputs with sorted columns, which suffices by the
    /// 0-1 principle) and minus everything the middle output does not depend on.
    fn sorted_columns_median_network(k: usize) -> (Vec<Step>, usize) {
        let n = k * k;
        let (ops, sorted) = batcher(n);
        // Bit i of slot s's bitset = value of slot s in 0/1 input number i; input i sets the
        // top (k - digit_c) entries of column c to 1, digit_c = c-th base-(k+1) digit of i.
        let inputs = (k + 1).pow(k as u32);
        let words = inputs.div_ceil(64);
        let mut bits = vec![vec![0u64; words]; n];
        for i in 0..inputs {
            let mut rest = i;
            for c in 0..k {
                let zeros = rest % (k + 1);
                rest /= k + 1;
                for r in zeros..k {
                    bits[c * k + r][i / 64] |= 1 << (i % 64);
                }
            }
        }
        let mut live = Vec::new();
        for (a, b) in ops {
            if bits[a].iter().zip(&bits[b]).any(|(x, y)| x & !y != 0) {
                let (sa, sb) = two_slots(&mut bits, 1, a, b);
                for (x, y) in sa[0].iter_mut().zip(sb[0].iter_mut()) {
                    (*x, *y) = (*x & *y, *x | *y);
                }
                live.push((a, b));
            }
        }
        let out = sorted[n / 2];
        let mut needed = vec![false; n];
        needed[out] = true;
        let mut steps = Vec::new();
        for &(a, b) in live.iter().rev() {
            let step = match (needed[a], needed[b]) {
                (true, true) => Step::Exchange(a, b),
                (true, false) => Step::Min(a, b),
                (false, true) => Step::Max(a, b),
                (false, false) => continue,
            };
            needed[a] = true;
            needed[b] = true;
            steps.push(step);
        }
        steps.reverse();
        (steps, out)
    }

    /// Runs the network over slots of length `len` stored back to back in `buf`.
    #[inline(always)]
    fn apply<T: Lane>(steps: &[Step], buf: &mut [T], len: usize) {
        for &s in steps {
            match s {
                Step::Exchange(a, b) => {
                    let (sa, sb) = two_slots(buf, len, a, b);
                    sa.iter_mut().zip(sb.iter_mut()).for_each(|(x, y)| {
                        let (l, h) = (lo(*x, *y), hi(*x, *y));
                        *x = l;
                        *y = h;
                    });
                }
                Step::Min(a, b) => {
                    let (sa, sb) = two_slots(buf, len, a, b);
                    sa.iter_mut()
                        .zip(sb.iter())
                        .for_each(|(x, &y)| *x = lo(*x, y));
                }
                Step::Max(a, b) => {
                    let (sa, sb) = two_slots(buf, len, a, b);
                    sb.iter_mut()
                        .zip(sa.iter())
                        .for_each(|(y, &x)| *y = hi(x, *y));
                }
            }
        }
    }

    /// Median of random windows (columns sorted first, as `median_small` does), 3x3 and 5x5,
    /// with many ties (values 0..16).
    #[test]
    fn sorted_columns_network_selects_the_median() {
        let mut state = 12345u64;
        for k in [3, 5] {
            let (steps, out) = sorted_columns_median_network(k);
            eprintln!("{k}x{k} median network: {} steps", steps.len());
            for _ in 0..3000 {
                let mut vals: Vec<u8> = (0..k * k)
                    .map(|_| {
                        state = state
                            .wrapping_mul(6364136223846793005)
                            .wrapping_add(1442695040888963407);
                        (state >> 60) as u8
                    })
                    .collect();
                vals.chunks_mut(k).for_each(|c| c.sort_unstable());
                let mut buf = vals.clone();
                apply(&steps, &mut buf, 1);
                vals.sort_unstable();
                assert_eq!(buf[out], vals[k * k / 2]);
            }
        }
    }

    #[test]
    fn written_out_network_is_the_generated_one() {
        let (steps, out) = sorted_columns_median_network(5);
        let generated: Vec<(&str, usize, usize)> = steps
            .iter()
            .map(|s| match *s {
                Step::Exchange(a, b) => ("x", a, b),
                Step::Min(a, b) => ("lo", a, b),
                Step::Max(a, b) => ("hi", a, b),
            })
            .collect();
        assert_eq!(generated, MEDIAN25_STEPS);
        assert_eq!(out, 12);
        let (sort, order) = batcher(5);
        let sort: Vec<(&str, usize, usize)> = sort.into_iter().map(|(a, b)| ("x", a, b)).collect();
        assert_eq!((sort.as_slice(), order), (SORT5_STEPS, vec![0, 1, 2, 3, 4]));
    }

    #[test]
    fn histogram_and_network_agree_on_u8() {
        let data: Vec<u8> = (0..40 * 30).map(|i| ((i * 7919) % 251) as u8).collect();
        let src = Gray::from_vec(40, 30, data).unwrap();
        let (mut a, mut b) = (Gray::new(40, 30), Gray::new(40, 30));
        median_small(&src, &mut a, 5);
        median_histogram(&src, &mut b, 5);
        assert_eq!(a, b);
        assert!(median_blur(&Gray::new(4, 4), &mut Gray::new(4, 4), 7).is_err());
    }
}
