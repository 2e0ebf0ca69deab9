//! Edge-aware residual interpolation with the orthogonal-pair intensity guide.
//!
//! Residual interpolation for DoFP sensors (Ahmed, Zhao, Zhang, Zhou, Kong,
//! "Residual interpolation for division of focal plane polarization image sensors",
//! Opt. Express 25, 10651 (2017)) with the edge-aware residual interpolation of
//! Morimatsu, Monno, Tanaka, Okutomi (ICIP 2020, EARI), simplified:
//! 1. Guide `G = ½ (I_θ + Î_θ+90)`, an estimate of `S0/2`: every pixel's own sample
//!    plus the mean of its four diagonal neighbours, which carry the orthogonal
//!    polarizer (`I_θ + I_θ+90 = S0` for any linear Stokes vector; the intensity
//!    correlation of Zhang et al., Opt. Lett. 41, 3435 (2016)).
//!    The two pairs are balanced to the same mean over the frame (`pair_gains`):
//!    real sensors' pair sums differ by a few percent.
//! 2. Residuals `R = raw − G` at each sample hold only the polarization part
//!    `½ (S1 cos 2θ + S2 sin 2θ)`, which stays smooth where `S0` has fine texture.
//! 3. Each missing channel is `G` plus its residual interpolated from the nearest
//!    samples of that channel (2 on a row or column, 4 on the diagonals), each weighted by
//!    `1 / (1 DN + g)` with `g` the one-sided gradient toward that sample,
//!    `|I(p+2d) − I(p)| + |I(p+3d) − I(p+d)|` (same-polarizer differences, so
//!    polarization modulation does not read as an edge). Across an edge the weights
//!    favour the samples on the pixel's own side; in flat or linear regions opposite
//!    gradients are equal and the result is the bilinear interpolation of the residual.
//!
//! Exact for constant and linear fields (per channel) away from the border; the border
//! is handled by mirroring (reflect-101, which keeps every sample's polarizer).
//! Results are clamped at 0 (intensities cannot be negative).
//!
//! Measured (example `demosaic_error`): better than `bilinear` in every column
//! (PSNR of each channel, DoLP and AoLP error) on edges, on fine texture and on both.

use polar_image::{Border, Gray, ImageView, PolarizerStack};
use polar_optics::stokes::linear_stokes_from_quad;
use pulp::{Arch, Simd, WithSimd};
use rayon::prelude::*;

use crate::layout::{Mosaic, MosaicSample, offset_of};

/// How far the gradients reach: 3 samples.
const PAD: usize = 3;

/// Softening of the gradient weights, in DN: one quantisation step.
const WEIGHT_FLOOR: f32 = 1.0;

const DIAGONALS: [(isize, isize); 4] = [(1, 1), (-1, 1), (1, -1), (-1, -1)];

/// Reflect-101 index (`-1 → 1`, `n → n − 2`) for any offset; `n >= 2`.
fn mirror(i: isize, n: usize) -> usize {
    Border::Reflect101.index(i, n)
}

#[inline(always)]
fn f<T: MosaicSample>(v: T) -> f32 {
    v.into() as f32
}

/// The guide `½ raw + ⅛ Σ diagonal neighbours` at one pixel, from an accessor of the
/// mosaic at offsets `(dx, dy)`.
#[inline(always)]
fn guide_at(raw: impl Fn(isize, isize) -> f32) -> f32 {
    let diag: f32 = DIAGONALS.iter().map(|&(dx, dy)| raw(dx, dy)).sum();
    0.5 * raw(0, 0) + 0.125 * diag
}

/// The four values of one pixel by role, `[own, right, below, below-right]` (the
/// channels of `(x, y)`, `(x + 1, y)`, `(x, y + 1)`, `(x + 1, y + 1)`), from accessors of
/// the mosaic and of the residual at offsets `(dx, dy)` and the guide `g` there.
///
/// Each missing role is `g` plus the residual of its nearest samples weighted by
/// `1 / spread`, where `spread` is `1 + g` for the one-sided gradient `g` toward the
/// sample (one division per role: pairs as `(r₊ s₋ + r₋ s₊) / (s₋ + s₊)`, the diagonals
/// multiplied through by the product of the spreads); clamped at 0.
#[inline(always)]
fn roles(raw: impl Fn(isize, isize) -> f32, res: impl Fn(isize, isize) -> f32, g: f32) -> [f32; 4] {
    let spread = |(dx, dy): (isize, isize)| {
        WEIGHT_FLOOR
            + (raw(2 * dx, 2 * dy) - raw(0, 0)).abs()
            + (raw(3 * dx, 3 * dy) - raw(dx, dy)).abs()
    };
    let pair = |(dx, dy): (isize, isize)| {
        let (sp, sm) = (spread((dx, dy)), spread((-dx, -dy)));
        (res(dx, dy) * sm + res(-dx, -dy) * sp) / (sp + sm)
    };
    // Written out: `array::map` is not always inlined, and a call stops vectorisation.
    let s = [
        spread(DIAGONALS[0]),
        spread(DIAGONALS[1]),
        spread(DIAGONALS[2]),
        spread(DIAGONALS[3]),
    ];
    let others = [
        s[1] * s[2] * s[3],
        s[0] * s[2] * s[3],
        s[0] * s[1] * s[3],
        s[0] * s[1] * s[2],
    ];
    let num: f32 = (0..4)
        .map(|i| others[i] * res(DIAGONALS[i].0, DIAGONALS[i].1))
        .sum();
    let diag = num / others.iter().sum::<f32>();
    [
        raw(0, 0),
        (g + pair((1, 0))).max(0.0),
        (g + pair((0, 1))).max(0.0),
        (g + diag).max(0.0),
    ]
}

/// Channels `I0, I45, I90, I135` of the roles of [`roles`] at a pixel of column parity
/// `odd_col` on a row of parity `ODD_ROW` (selects, so that row loops vectorise).
#[inline(always)]
fn channels<const ODD_ROW: bool>(r: [f32; 4], odd_col: bool) -> [f32; 4] {
    std::array::from_fn(|c| {
        let (ox, oy) = offset_of(c);
        let dy = 2 * (oy ^ usize::from(ODD_ROW));
        let (even, odd) = (r[ox + dy], r[(ox ^ 1) + dy]);
        if odd_col { odd } else { even }
    })
}

/// Where one output row of the demosaicing goes: four channels per pixel, either as they
/// are or as Stokes. Implementations index a slice of the row's length (or the interior's).
pub(crate) trait RowSink {
    /// Stores the channels `I0, I45, I90, I135` of pixel `i`.
    fn put(&mut self, i: usize, q: [f32; 4]);
    /// The sub-row `start .. start + n`.
    fn slice(&mut self, start: usize, n: usize) -> Self;
}

impl RowSink for &mut [[f32; 4]] {
    #[inline(always)]
    fn put(&mut self, i: usize, q: [f32; 4]) {
        self[i] = q;
    }
    fn slice(&mut self, start: usize, n: usize) -> Self {
        // Reborrow the part: the sink is consumed per row, so this moves out of `self`.
        let all = std::mem::take(self);
        &mut all[start..start + n]
    }
}

/// `S0, S1, S2` rows: each pixel's channels go through `linear_stokes_from_quad`.
pub(crate) struct StokesRow<'a>(pub [&'a mut [f32]; 3]);

impl RowSink for StokesRow<'_> {
    #[inline(always)]
    fn put(&mut self, i: usize, q: [f32; 4]) {
        let [s0, s1, s2] = linear_stokes_from_quad(q[0], q[1], q[2], q[3]);
        let [a, b, c] = &mut self.0;
        (a[i], b[i], c[i]) = (s0, s1, s2);
    }
    fn slice(&mut self, start: usize, n: usize) -> Self {
        StokesRow(std::mem::take(&mut self.0).map(|s| &mut s[start..start + n]))
    }
}

/// The scaled guide `G` and the residual `raw − G` of a mosaic (size checked), written
/// into `guide` and `res` (each of the mosaic's size).
pub(crate) fn guide_and_residual<T: MosaicSample>(
    raw: ImageView<'_, T, 1>,
    guide: &mut Gray<f32>,
    res: &mut Gray<f32>,
) {
    let (w, h) = raw.size();
    debug_assert!(guide.size() == (w, h) && res.size() == (w, h));
    let guide_rows = guide.as_mut_slice().par_chunks_mut(w);
    guide_rows.enumerate().for_each(|(y, row)| {
        let rows = [mirror(y as isize - 1, h), y, mirror(y as isize + 1, h)].map(|r| raw.row(r));
        for x in [0, w - 1] {
            row[x] = guide_at(|dx, dy| f(rows[(dy + 1) as usize][mirror(x as isize + dx, w)]));
        }
        // Interior: `cut[dy + 1][dx + 1][i]` is the mosaic at (1 + i + dx, y + dy).
        let n = w - 2;
        let cut: [[&[T]; 3]; 3] = rows.map(|r| std::array::from_fn(|k| &r[k..k + n]));
        for (i, g) in row[1..w - 1].iter_mut().enumerate() {
            *g = guide_at(|dx, dy| f(cut[(dy + 1) as usize][(dx + 1) as usize][i]));
        }
    });
    let gains = pair_gains(guide.view(), raw);
    guide
        .as_mut_slice()
        .par_chunks_mut(w)
        .zip(res.as_mut_slice().par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (grow, rrow))| {
            let srow = raw.row(y);
            for (x, (g, r)) in grow.iter_mut().zip(rrow.iter_mut()).enumerate() {
                *g *= gains[(x + y) & 1];
                *r = f(srow[x]) - *g;
            }
        });
}

/// Gains `[even, odd]` for the guide at pixels with `x + y` even (the 90°/0° pair) and
/// odd (the 45°/135° pair) that give both pairs the same mean.
///
/// Compares each even pixel's guide with the mean of its four odd neighbours (the same
/// point, so exact for any linear field) over pixels at least 2 from the border (no
/// mirrored samples) whose 5x5 support holds no sample at the frame's maximum (clipped
/// samples carry no ratio, whatever the bit depth); `[1, 1]` when nothing is left.
/// The pair sums `I0 + I90` and `I45 + I135` are both `S0` in theory, but on the
/// bundled IMX250MZR frames the first is 2.0 % lower at every brightness; unbalanced,
/// that would be a ±1 % checkerboard in S0.
fn pair_gains<T: MosaicSample>(guide: ImageView<'_, f32, 1>, raw: ImageView<'_, T, 1>) -> [f32; 2] {
    let (w, h) = raw.size();
    let top = (0..h)
        .into_par_iter()
        .map(|y| raw.row(y).iter().map(|&v| v.into()).max().unwrap_or(0))
        .max()
        .unwrap_or(0);
    let (even, odd) = (2..h.saturating_sub(2))
        .into_par_iter()
        .map_init(
            || (vec![false; w], vec![false; w]),
            |(tall, short), y| {
                // A sample at the frame's maximum within the 5x5 disc without its corners
                // (dx² + dy² < 8): |dy| <= 2 in columns x - 1 ..= x + 1, |dy| <= 1 in x ± 2.
                let near: [&[T]; 5] = std::array::from_fn(|k| raw.row(y + k - 2));
                for (x, (t, s)) in tall.iter_mut().zip(short.iter_mut()).enumerate() {
                    let at_top = |k: usize| near[k][x].into() >= top;
                    *s = at_top(1) | at_top(2) | at_top(3);
                    *t = *s | at_top(0) | at_top(4);
                }
                let [up, mid, down] = [y - 1, y, y + 1].map(|r| guide.row(r));
                let (mut e, mut o) = (0.0f64, 0.0f64);
                for x in (2 + (y & 1)..w.saturating_sub(2)).step_by(2) {
                    if tall[x - 1] | tall[x] | tall[x + 1] | short[x - 2] | short[x + 2] {
                        continue;
                    }
                    e += f64::from(mid[x]);
                    o += 0.25 * f64::from(mid[x - 1] + mid[x + 1] + up[x] + down[x]);
                }
                (e, o)
            },
        )
        .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
    if even > 0.0 && odd > 0.0 {
        let g = (odd / even).sqrt();
        [g as f32, (1.0 / g) as f32]
    } else {
        [1.0, 1.0]
    }
}

/// One output row `y` of the residual interpolation into `sink` (the row's length),
/// from the mosaic `raw`, the scaled guide and the residual of [`guide_and_residual`]
/// (all of one size), as a `pulp` operation: `with_simd` is compiled per SIMD target.
/// The interior columns run in one uniform loop over pre-cut slices; the three columns
/// at each border mirror.
pub(crate) struct ResidualRow<'a, T, S> {
    pub raw: ImageView<'a, T, 1>,
    pub guide: ImageView<'a, f32, 1>,
    pub res: ImageView<'a, f32, 1>,
    pub y: usize,
    pub sink: S,
}

impl<T: MosaicSample, S: RowSink> WithSimd for ResidualRow<'_, T, S> {
    type Output = ();

    #[inline(always)]
    fn with_simd<V: Simd>(self, _: V) {
        if self.y & 1 == 1 {
            self.run::<true>();
        } else {
            self.run::<false>();
        }
    }
}

impl<T: MosaicSample, S: RowSink> ResidualRow<'_, T, S> {
    #[inline(always)]
    fn run<const ODD_ROW: bool>(mut self) {
        let ((w, h), y) = (self.raw.size(), self.y);
        debug_assert!(self.guide.size() == (w, h) && self.res.size() == (w, h));
        let row_of = |dy: isize| mirror(y as isize + dy, h);
        let raw: [&[T]; 2 * PAD + 1] =
            std::array::from_fn(|k| self.raw.row(row_of(k as isize - PAD as isize)));
        let res: [&[f32]; 3] = std::array::from_fn(|k| self.res.row(row_of(k as isize - 1)));
        let guide = self.guide.row(y);
        let n = w.saturating_sub(2 * PAD);
        // Border columns, mirrored.
        let (left, right) = if n == 0 {
            (0..w, w..w)
        } else {
            (0..PAD, w - PAD..w)
        };
        for x in left.chain(right) {
            let m = |dx: isize| mirror(x as isize + dx, w);
            let r = roles(
                |dx, dy| f(raw[(dy + PAD as isize) as usize][m(dx)]),
                |dx, dy| res[(dy + 1) as usize][m(dx)],
                guide[x],
            );
            self.sink.put(x, channels::<ODD_ROW>(r, x & 1 == 1));
        }
        if n == 0 {
            return;
        }
        // Interior: `raw_cut[dy + 3][dx + 3][i]` is the mosaic at (PAD + i + dx, y + dy).
        let raw_cut: [[&[T]; 2 * PAD + 1]; 2 * PAD + 1] =
            raw.map(|r| std::array::from_fn(|k| &r[k..k + n]));
        let res_cut: [[&[f32]; 3]; 3] =
            res.map(|r| std::array::from_fn(|k| &r[PAD - 1 + k..PAD - 1 + k + n]));
        let g = &guide[PAD..PAD + n];
        let mut out = self.sink.slice(PAD, n);
        for i in 0..n {
            let r = roles(
                |dx, dy| f(raw_cut[(dy + PAD as isize) as usize][(dx + PAD as isize) as usize][i]),
                |dx, dy| res_cut[(dy + 1) as usize][(dx + 1) as usize][i],
                g[i],
            );
            // Column PAD + i is odd when i is even (PAD is odd).
            out.put(i, channels::<ODD_ROW>(r, i & 1 == 0));
        }
    }
}

/// Edge-aware residual interpolation of the whole mosaic into the four polarizer images
/// (size already checked).
pub(crate) fn residual<T: MosaicSample>(raw: &Mosaic<T>) -> PolarizerStack {
    let (w, h) = raw.size();
    let (mut guide, mut res) = (Gray::new(w, h), Gray::new(w, h));
    guide_and_residual(raw.view(), &mut guide, &mut res);
    let (raw, guide, res) = (raw.view(), guide.view(), res.view());
    let mut out = PolarizerStack::new(w, h);
    let arch = Arch::new();
    out.pixels_mut()
        .par_chunks_mut(w)
        .enumerate()
        .for_each(|(y, row)| {
            arch.dispatch(ResidualRow {
                raw,
                guide,
                res,
                y,
                sink: row,
            })
        });
    out
}

#[cfg(test)]
/// The straightforward implementation the fused SIMD rows replace: mirrored full-size
/// planes of the mosaic, guide and residual, then per-pixel interpolation. The
/// production code must give the same bits.
mod reference {
    use polar_image::PolarizerStack;
    use rayon::prelude::*;

    use super::{DIAGONALS, PAD, WEIGHT_FLOOR, mirror};
    use crate::layout::{Mosaic, MosaicSample, channel_at};

    /// A plane mirrored by [`PAD`] on every side, indexed by image coordinates plus offsets.
    struct Padded {
        data: Vec<f32>,
        stride: usize,
    }

    impl Padded {
        /// Mirrors the `w x h` plane `f(x, y)`.
        fn new(w: usize, h: usize, f: impl Fn(usize, usize) -> f32 + Sync) -> Self {
            let stride = w + 2 * PAD;
            let xs: Vec<usize> = (0..stride)
                .map(|px| mirror(px as isize - PAD as isize, w))
                .collect();
            let mut data = vec![0.0; stride * (h + 2 * PAD)];
            data.par_chunks_mut(stride)
                .enumerate()
                .for_each(|(py, row)| {
                    let y = mirror(py as isize - PAD as isize, h);
                    for (v, &x) in row.iter_mut().zip(&xs) {
                        *v = f(x, y);
                    }
                });
            Self { data, stride }
        }

        /// Row `y + dy` (image coordinates, `|dy| <= PAD`) with its margins: image column
        /// `x` is at index `x + PAD`.
        #[inline]
        fn row(&self, y: usize, dy: isize) -> &[f32] {
            let start = (y + PAD).wrapping_add_signed(dy) * self.stride;
            &self.data[start..start + self.stride]
        }

        /// Value at `(x + dx, y + dy)`, `|dx|, |dy| <= PAD`.
        #[inline]
        fn at(&self, x: usize, y: usize, dx: isize, dy: isize) -> f32 {
            let (px, py) = (x + PAD, y + PAD);
            self.data[(py as isize + dy) as usize * self.stride + (px as isize + dx) as usize]
        }
    }

    /// Rows `y − 3 ..= y + 3` of a padded plane, indexed `[dy + 3][x + PAD + dx]`.
    type Window<'a> = [&'a [f32]; 2 * PAD + 1];

    fn window(plane: &Padded, y: usize) -> Window<'_> {
        std::array::from_fn(|k| plane.row(y, k as isize - PAD as isize))
    }

    /// Value of a window at `(x + dx, y + dy)`.
    #[inline]
    fn at(win: &Window<'_>, x: usize, dx: isize, dy: isize) -> f32 {
        win[(PAD as isize + dy) as usize][(x + PAD).wrapping_add_signed(dx)]
    }

    /// `1 + g` for the neighbour at `p + d`, with `g` the one-sided gradient of the mosaic
    /// from `p` toward `d`; its inverse is the neighbour's weight.
    #[inline]
    fn spread(raw: &Window<'_>, x: usize, (dx, dy): (isize, isize)) -> f32 {
        WEIGHT_FLOOR
            + (at(raw, x, 2 * dx, 2 * dy) - at(raw, x, 0, 0)).abs()
            + (at(raw, x, 3 * dx, 3 * dy) - at(raw, x, dx, dy)).abs()
    }

    /// Mean of the residual at `p ± d` with weights `1 / spread` (one division:
    /// `(r₊ s₋ + r₋ s₊) / (s₋ + s₊)`).
    #[inline]
    fn interpolate_pair(raw: &Window<'_>, res: &Window<'_>, x: usize, d: (isize, isize)) -> f32 {
        let (sp, sm) = (spread(raw, x, d), spread(raw, x, (-d.0, -d.1)));
        (at(res, x, d.0, d.1) * sm + at(res, x, -d.0, -d.1) * sp) / (sp + sm)
    }

    /// Mean of the residual at the four diagonal neighbours with weights `1 / spread`,
    /// multiplied through by the product of the spreads (one division).
    #[inline]
    fn interpolate_diagonal(raw: &Window<'_>, res: &Window<'_>, x: usize) -> f32 {
        let s = DIAGONALS.map(|d| spread(raw, x, d));
        let others = [
            s[1] * s[2] * s[3],
            s[0] * s[2] * s[3],
            s[0] * s[1] * s[3],
            s[0] * s[1] * s[2],
        ];
        let num: f32 = (0..4)
            .map(|i| others[i] * at(res, x, DIAGONALS[i].0, DIAGONALS[i].1))
            .sum();
        num / others.iter().sum::<f32>()
    }

    /// Gains `[even, odd]` for the guide at pixels with `x + y` even (the 90°/0° pair) and
    /// odd (the 45°/135° pair) that give both pairs the same mean.
    ///
    /// Compares each even pixel's guide with the mean of its four odd neighbours (the same
    /// point, so exact for any linear field) over pixels at least 2 from the border (no
    /// mirrored samples) whose 5x5 support holds no sample at the frame's maximum (clipped
    /// samples carry no ratio, whatever the bit depth); `[1, 1]` when nothing is left.
    /// The pair sums `I0 + I90` and `I45 + I135` are both `S0` in theory, but on the
    /// bundled IMX250MZR frames the first is 2.0 % lower at every brightness; unbalanced,
    /// that would be a ±1 % checkerboard in S0.
    fn pair_gains(guide: &[f32], raw: &Padded, w: usize, h: usize) -> [f32; 2] {
        let top = raw.data.par_iter().copied().reduce(|| 0.0, f32::max);
        let (even, odd) = (2..h.saturating_sub(2))
            .into_par_iter()
            .map(|y| {
                let rw = window(raw, y);
                let clipped = |x| {
                    (-2..=2isize).any(|dy| {
                        (-2..=2isize).any(|dx| dx * dx + dy * dy < 8 && at(&rw, x, dx, dy) >= top)
                    })
                };
                let (mut e, mut o) = (0.0f64, 0.0f64);
                for x in (2 + (y & 1)..w.saturating_sub(2)).step_by(2) {
                    if clipped(x) {
                        continue;
                    }
                    let k = y * w + x;
                    e += f64::from(guide[k]);
                    o +=
                        0.25 * f64::from(guide[k - 1] + guide[k + 1] + guide[k - w] + guide[k + w]);
                }
                (e, o)
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0 + b.0, a.1 + b.1));
        if even > 0.0 && odd > 0.0 {
            let g = (odd / even).sqrt();
            [g as f32, (1.0 / g) as f32]
        } else {
            [1.0, 1.0]
        }
    }

    /// Edge-aware residual interpolation of the whole mosaic (size already checked).
    pub(super) fn residual<T: MosaicSample>(raw: &Mosaic<T>) -> PolarizerStack {
        let (w, h) = raw.size();
        let src = raw.as_slice();
        let rawp = Padded::new(w, h, |x, y| src[y * w + x].into() as f32);
        let mut guide = vec![0.0; w * h];
        guide.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            let rw = window(&rawp, y);
            for (x, g) in row.iter_mut().enumerate() {
                let diag: f32 = DIAGONALS.iter().map(|&(dx, dy)| at(&rw, x, dx, dy)).sum();
                *g = 0.5 * at(&rw, x, 0, 0) + 0.125 * diag;
            }
        });
        let gains = pair_gains(&guide, &rawp, w, h);
        guide.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
            for (x, g) in row.iter_mut().enumerate() {
                *g *= gains[(x + y) & 1];
            }
        });
        let resp = Padded::new(w, h, |x, y| rawp.at(x, y, 0, 0) - guide[y * w + x]);

        let mut out = PolarizerStack::new(w, h);
        out.pixels_mut()
            .par_chunks_mut(w)
            .enumerate()
            .for_each(|(y, row)| {
                let (rw, sw) = (window(&rawp, y), window(&resp, y));
                for (x, (px, &g)) in row.iter_mut().zip(&guide[y * w..]).enumerate() {
                    px[channel_at(x, y)] = at(&rw, x, 0, 0);
                    for (c, r) in [
                        (channel_at(x + 1, y), interpolate_pair(&rw, &sw, x, (1, 0))),
                        (channel_at(x, y + 1), interpolate_pair(&rw, &sw, x, (0, 1))),
                        (channel_at(x + 1, y + 1), interpolate_diagonal(&rw, &sw, x)),
                    ] {
                        px[c] = (g + r).max(0.0);
                    }
                }
            });
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demosaic::{DemosaicMethod, demosaic};
    use crate::layout::channel_at;

    fn run(w: usize, h: usize, f: impl Fn(usize, usize) -> u16) -> PolarizerStack {
        let data = (0..w * h).map(|k| f(k % w, k / w)).collect();
        demosaic(
            &Mosaic::<u16>::from_vec(w, h, data).unwrap(),
            DemosaicMethod::Residual,
        )
        .unwrap()
    }

    #[test]
    fn mirror_keeps_the_polarizer_of_every_offset() {
        for n in [2, 4, 6] {
            for i in -7..(n as isize + 7) {
                let m = mirror(i, n);
                assert!(m < n, "n {n} i {i}");
                assert_eq!(m % 2, i.rem_euclid(2) as usize, "n {n} i {i}");
            }
        }
    }

    /// A linear field of a physical Stokes image (`I0 + I90 = I45 + I135`, all four
    /// channels linear in x and y): the guide and the residuals are linear per channel
    /// and opposite gradients are equal, so every pixel at least 3 from the border
    /// (where the mirror bends the ramp) is exact to f32 rounding (values < 700,
    /// rounding ~1e-4). Nearer the border the mirror turns the ramp into a "V"; the
    /// error there stays below one diagonal step of the steepest channel (7 DN).
    #[test]
    fn reproduces_linear_fields_exactly_in_the_interior() {
        let (w, h) = (24, 20);
        let truth = |c: usize, x: usize, y: usize| {
            let [a, gx, gy] = [[500, 4, 3], [450, 3, 1], [300, 2, 1], [350, 3, 3]][c];
            a + gx * x + gy * y
        };
        let out = run(w, h, |x, y| truth(channel_at(x, y), x, y) as u16);
        for y in 0..h {
            for x in 0..w {
                let margin = x.min(y).min(w - 1 - x).min(h - 1 - y);
                let tol = if margin >= 3 { 1e-3 } else { 7.0 };
                for c in 0..4 {
                    let (got, want) = (out.pixel(x, y)[c], truth(c, x, y) as f32);
                    assert!((got - want).abs() <= tol, "({x},{y}) c{c}: {got} vs {want}");
                }
            }
        }
    }

    /// A constant frame is reproduced exactly everywhere, borders and the smallest
    /// legal frames included (all arithmetic is on equal values: exact).
    #[test]
    fn constant_frames_exact_at_every_size() {
        for (w, h) in [(2, 2), (4, 4), (2, 6), (8, 4), (10, 12)] {
            let out = run(w, h, |_, _| 1234);
            assert!(
                out.pixels().iter().flatten().all(|&v| v == 1234.0),
                "{w}x{h}"
            );
        }
    }

    /// Smallest frames. A 2x2 frame of one physical Stokes vector (`10 + 50 = 20 + 40`)
    /// comes back exactly at all four pixels (the mirror maps every neighbour onto the
    /// one sample of its channel); arbitrary 2x2 and 4x4 frames are finite,
    /// non-negative and keep their own samples.
    #[test]
    fn smallest_frames() {
        let two = run(2, 2, |x, y| [[50, 20], [40, 10]][y][x]);
        assert!(
            two.pixels()
                .iter()
                .all(|px| *px == [10.0, 20.0, 50.0, 40.0])
        );
        for (w, h) in [(2, 2), (4, 4)] {
            let f = |x: usize, y: usize| (1000 + 700 * ((x * 7 + y * 3) % 5)) as u16;
            let out = run(w, h, f);
            for y in 0..h {
                for x in 0..w {
                    let px = out.pixel(x, y);
                    assert_eq!(px[channel_at(x, y)], f32::from(f(x, y)));
                    assert!(px.iter().all(|v| v.is_finite() && *v >= 0.0));
                }
            }
        }
    }

    #[test]
    fn all_zero_and_saturated_frames_are_nan_free() {
        let zero = demosaic(&Mosaic::<u8>::new(8, 6), DemosaicMethod::Residual).unwrap();
        assert!(zero.pixels().iter().flatten().all(|&v| v == 0.0));
        let full = run(8, 6, |_, _| u16::MAX);
        assert!(full.pixels().iter().flatten().all(|&v| v == 65535.0));
        // Half saturated, half black: a maximal edge; no NaN, nothing negative.
        let edge = run(8, 6, |x, _| if x < 4 { u16::MAX } else { 0 });
        assert!(
            edge.pixels()
                .iter()
                .flatten()
                .all(|v| v.is_finite() && *v >= 0.0)
        );
    }

    /// The bits of a demosaiced stack (NaN and signed zeros compared too).
    fn bits(stack: &PolarizerStack) -> Vec<u32> {
        stack
            .pixels()
            .iter()
            .flatten()
            .map(|v| v.to_bits())
            .collect()
    }

    /// Frames of every small size (mirror-only rows and columns, the interior loop
    /// empty or one pixel wide) and a textured 37x-period pattern: the production rows
    /// give the reference's bits. Tolerance 0: the same IEEE operations in the same order.
    #[test]
    fn equals_reference_on_small_frames() {
        for (w, h) in [
            (2, 2),
            (2, 6),
            (6, 2),
            (4, 4),
            (6, 6),
            (8, 6),
            (10, 12),
            (24, 20),
        ] {
            let data: Vec<u16> = (0..w * h)
                .map(|k| ((k * 7919 + k / w * 37) % 4093) as u16)
                .collect();
            let raw = Mosaic::<u16>::from_vec(w, h, data).unwrap();
            assert!(
                bits(&residual(&raw)) == bits(&reference::residual(&raw)),
                "{w}x{h}"
            );
        }
    }

    /// Both bundled real frames, as u16 and as u8 mosaics, on every SIMD target of this
    /// CPU: the demosaiced stack and the fused Stokes planes give the reference's bits
    /// (the fused planes against `StokesPlanes::from_stack` of the reference stack).
    #[test]
    fn equals_reference_on_real_frames_on_every_simd_target() {
        use crate::products::{StokesPlanes, stokes_planes};
        for name in ["carps_IMX250MZR.png", "camera_IMX250MZR.png"] {
            let path = format!(
                "{}/../../tests/data/real/{name}",
                env!("CARGO_MANIFEST_DIR")
            );
            let raw16 = polar_io::read_mosaic(&path).unwrap().image;
            let (w, h) = raw16.size();
            let raw8 = Mosaic::from_vec(w, h, raw16.as_slice().iter().map(|&v| v as u8).collect())
                .unwrap();
            let want16 = reference::residual(&raw16);
            assert!(bits(&residual(&raw16)) == bits(&want16), "{name} u16");
            assert!(
                bits(&residual(&raw8)) == bits(&reference::residual(&raw8)),
                "{name} u8"
            );
            let fused = stokes_planes(&raw16, DemosaicMethod::Residual).unwrap();
            let two_step = StokesPlanes::from_stack(&want16);
            for (a, b) in [
                (&fused.s0, &two_step.s0),
                (&fused.s1, &two_step.s1),
                (&fused.s2, &two_step.s2),
                (&fused.dolp, &two_step.dolp),
                (&fused.aolp, &two_step.aolp),
            ] {
                let eq = a
                    .as_slice()
                    .iter()
                    .zip(b.as_slice())
                    .all(|(x, y)| x.to_bits() == y.to_bits());
                assert!(eq, "{name} fused planes");
            }
            for arch in simd_targets() {
                let (mut guide, mut res) = (Gray::new(w, h), Gray::new(w, h));
                guide_and_residual(raw16.view(), &mut guide, &mut res);
                let mut out = PolarizerStack::new(w, h);
                for (y, row) in out.pixels_mut().chunks_mut(w).enumerate() {
                    arch.dispatch(ResidualRow {
                        raw: raw16.view(),
                        guide: guide.view(),
                        res: res.view(),
                        y,
                        sink: row,
                    });
                }
                assert!(bits(&out) == bits(&want16), "{name} {arch:?}");
            }
        }
    }

    /// Scalar, AVX2+FMA and AVX-512 where the CPU has them.
    fn simd_targets() -> Vec<Arch> {
        let mut archs = vec![Arch::Scalar];
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        {
            archs.extend(pulp::x86::V3::try_new().map(Arch::V3));
            archs.extend(pulp::x86::V4::try_new().map(Arch::V4));
        }
        archs
    }
}
