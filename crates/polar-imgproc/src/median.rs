//! Median filter matching `cv2.medianBlur` (border `BORDER_REPLICATE`): `f32` images with
//! `ksize` 3 or 5 (all OpenCV accepts for float), `u8` images with any odd `ksize`.
//!
//! Small windows use a selection network evaluated on whole runs of pixels at once (so the
//! compiler vectorises every compare-exchange); it is Batcher's odd-even merge sort,
//! padded with `+inf`, pruned to the comparators the middle output depends on.
//! Large `u8` windows use a sliding histogram (Huang et al. 1979).

use std::sync::OnceLock;

use polar_image::Gray;
use rayon::prelude::*;

use crate::{Border, Error, filter::band_rows, same_size};

/// One step of a selection network on value slots `a < b` (in sorted order, `a` gets
/// the smaller value).
#[derive(Clone, Copy, Debug)]
enum Step {
    /// `a, b = min(a, b), max(a, b)`.
    Exchange(usize, usize),
    /// `a = min(a, b)` (the maximum is never used).
    Min(usize, usize),
    /// `b = max(a, b)` (the minimum is never used).
    Max(usize, usize),
}

/// A pruned network selecting the median of `n` values, and the slot that ends up holding it.
fn median_network(n: usize) -> (Vec<Step>, usize) {
    let size = n.next_power_of_two();
    let mut comparators = Vec::new();
    let mut p = 1;
    while p < size {
        let mut k = p;
        while k >= 1 {
            let mut j = k % p;
            while j + k < size {
                for i in 0..k.min(size - j - k) {
                    if (i + j) / (2 * p) == (i + j + k) / (2 * p) {
                        comparators.push((i + j, i + j + k));
                    }
                }
                j += 2 * k;
            }
            k /= 2;
        }
        p *= 2;
    }
    // Wires beyond n carry +inf: fold them away, keeping only real slot exchanges.
    let mut wire: Vec<Option<usize>> = (0..size).map(|i| (i < n).then_some(i)).collect();
    let mut ops = Vec::new();
    for (a, b) in comparators {
        match (wire[a], wire[b]) {
            (Some(sa), Some(sb)) => ops.push((sa, sb)),
            (None, Some(_)) => wire.swap(a, b),
            _ => {}
        }
    }
    let out = wire[n / 2].unwrap_or(0);
    // Backward pass: keep only what the output depends on.
    let mut needed = vec![false; n];
    needed[out] = true;
    let mut steps = Vec::new();
    for &(a, b) in ops.iter().rev() {
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

/// A pixel type the median network can order.
trait Lane: Copy + Default + Send + Sync + PartialOrd {}
impl Lane for f32 {}
impl Lane for u8 {}

/// Pixels processed per network evaluation (all slots stay in L1).
const CHUNK: usize = 64;

fn lo<T: Lane>(a: T, b: T) -> T {
    if b < a { b } else { a }
}

fn hi<T: Lane>(a: T, b: T) -> T {
    if b < a { a } else { b }
}

fn apply<T: Lane>(steps: &[Step], slots: &mut [[T; CHUNK]]) {
    for &s in steps {
        let (a, b) = match s {
            Step::Exchange(a, b) | Step::Min(a, b) | Step::Max(a, b) => (a, b),
        };
        let Ok([sa, sb]) = slots.get_disjoint_mut([a, b]) else {
            continue;
        };
        match s {
            Step::Exchange(..) => sa.iter_mut().zip(sb.iter_mut()).for_each(|(x, y)| {
                let (l, h) = (lo(*x, *y), hi(*x, *y));
                *x = l;
                *y = h;
            }),
            Step::Min(..) => sa
                .iter_mut()
                .zip(sb.iter())
                .for_each(|(x, &y)| *x = lo(*x, y)),
            Step::Max(..) => sb
                .iter_mut()
                .zip(sa.iter())
                .for_each(|(y, &x)| *y = hi(x, *y)),
        }
    }
}

fn network(ksize: usize) -> &'static (Vec<Step>, usize) {
    static N3: OnceLock<(Vec<Step>, usize)> = OnceLock::new();
    static N5: OnceLock<(Vec<Step>, usize)> = OnceLock::new();
    if ksize == 3 {
        N3.get_or_init(|| median_network(9))
    } else {
        N5.get_or_init(|| median_network(25))
    }
}

/// Median by selection network for `ksize` 3 or 5, replicate border.
fn median_small<T: Lane>(src: &Gray<T>, dst: &mut Gray<T>, ksize: usize) {
    let (w, h) = src.size();
    let r = ksize / 2;
    let (steps, out_slot) = network(ksize);
    let rows = band_rows(r);
    let s = src.as_slice();
    dst.as_mut_slice()
        .par_chunks_mut(w * rows)
        .enumerate()
        .for_each(|(b, out)| {
            let y0 = b * rows;
            let n_out = out.len() / w;
            let pw = w + 2 * r;
            let mut padded = vec![T::default(); (n_out + 2 * r) * pw];
            for (t, prow) in padded.chunks_exact_mut(pw).enumerate() {
                let y = Border::Replicate.index((y0 + t) as isize - r as isize, h);
                Border::Replicate.pad_row(&s[y * w..(y + 1) * w], r, prow);
            }
            let mut slots = vec![[T::default(); CHUNK]; ksize * ksize];
            for (row, orow) in out.chunks_exact_mut(w).enumerate() {
                for x0 in (0..w).step_by(CHUNK) {
                    let m = CHUNK.min(w - x0);
                    for (k, slot) in slots.iter_mut().enumerate() {
                        let (dy, dx) = (k / ksize, k % ksize);
                        let start = (row + dy) * pw + x0 + dx;
                        slot[..m].copy_from_slice(&padded[start..start + m]);
                    }
                    apply(steps, &mut slots);
                    orow[x0..x0 + m].copy_from_slice(&slots[*out_slot][..m]);
                }
            }
        });
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

    /// Exhaustive 0-1 principle: a comparator network selects the median of every input
    /// iff it does so for every 0/1 input; 2^9 cases for 3x3, and random ones for 5x5.
    #[test]
    fn network_selects_the_median() {
        let (steps, out) = median_network(9);
        for bits in 0u32..512 {
            let mut slots = vec![[0u8; CHUNK]; 9];
            for (i, s) in slots.iter_mut().enumerate() {
                s[0] = ((bits >> i) & 1) as u8;
            }
            apply(&steps, &mut slots);
            assert_eq!(
                u32::from(slots[out][0]),
                u32::from(bits.count_ones() >= 5),
                "{bits:09b}"
            );
        }
        let (steps, out) = median_network(25);
        let mut state = 12345u64;
        for _ in 0..2000 {
            let mut vals: Vec<u8> = (0..25)
                .map(|_| {
                    state = state
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (state >> 56) as u8
                })
                .collect();
            let mut slots: Vec<[u8; CHUNK]> = vals.iter().map(|&v| [v; CHUNK]).collect();
            apply(&steps, &mut slots);
            vals.sort_unstable();
            assert_eq!(slots[out][0], vals[12]);
        }
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
