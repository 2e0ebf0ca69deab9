//! The main chain raw mosaic -> `S0, S1, S2, DoLP, AoLP` (f32 planes).
//!
//! For `bilinear` the chain is fused: each rayon task takes one mosaic row,
//! interpolates, forms Stokes and DoLP/AoLP while the row is in cache, so the
//! four polarizer images are never written to memory. Other methods demosaic
//! first and then apply the same per-pixel formulas: `linear_stokes_from_quad` of
//! `polar_optics::stokes`, and its `dolp`/`aolp` in the vectorisable form of [`crate::fastmath`].
//!
//! The row kernels are generic scalar code that the compiler vectorises; `pulp`
//! compiles them once per SIMD target (x86-64 baseline, AVX2+FMA, AVX-512) and picks
//! the best one the CPU has at run time ([`simd_target`] names it). The results are
//! the same bit for bit on every target: the kernels use only `+ − × ÷ √` and
//! selects, which IEEE 754 rounds identically at any vector width, and Rust never
//! contracts `a * b + c` into an FMA on its own (a test compares the targets).

use polar_image::{Gray, Image, ImageView, LinearStokesImage, PolarizerStack};
use polar_optics::LinearStokesFit;
use polar_optics::stokes::{imax, imin, linear_stokes_from_quad};
use pulp::{Arch, Simd, WithSimd};
use rayon::prelude::*;

use crate::demosaic::bilinear::{bilinear_stokes_rows, rows_around};
use crate::demosaic::color::{split_colors, split_row};
use crate::demosaic::residual::{ResidualRow, StokesRow, guide_and_residual};
use crate::demosaic::{DemosaicMethod, demosaic};
use crate::fastmath::dolp_aolp_row;
use crate::layout::{Mosaic, MosaicPattern, MosaicSample};
use crate::{SensorError, check_mosaic_size};

/// Linear Stokes parameters and the derived DoLP and AoLP, one plane each.
///
/// DoLP and AoLP are NaN where `S0` is not positive (undefined; see the conventions).
#[derive(Clone, Debug, PartialEq)]
pub struct StokesPlanes {
    /// Total intensity `S0 = (I0 + I45 + I90 + I135) / 2`.
    pub s0: Gray<f32>,
    /// `S1 = I0 − I90`.
    pub s1: Gray<f32>,
    /// `S2 = I45 − I135`.
    pub s2: Gray<f32>,
    /// Degree of linear polarization `sqrt(S1² + S2²) / S0`.
    pub dolp: Gray<f32>,
    /// Angle of linear polarization `½ atan2(S2, S1)` in `[0, π)`.
    pub aolp: Gray<f32>,
}

impl StokesPlanes {
    /// Zero-filled planes of `width x height`.
    pub fn new(width: usize, height: usize) -> Self {
        let z = || Gray::new(width, height);
        Self {
            s0: z(),
            s1: z(),
            s2: z(),
            dolp: z(),
            aolp: z(),
        }
    }

    /// `(width, height)` of the planes.
    pub fn size(&self) -> (usize, usize) {
        self.s0.size()
    }

    /// Maximum intensity behind a rotating ideal polarizer, `(S0 + sqrt(S1² + S2²)) / 2`, per pixel.
    pub fn imax(&self) -> Gray<f32> {
        self.map3(imax)
    }

    /// Minimum intensity behind a rotating ideal polarizer, `(S0 − sqrt(S1² + S2²)) / 2`, per pixel.
    pub fn imin(&self) -> Gray<f32> {
        self.map3(imin)
    }

    /// `f(S0, S1, S2)` per pixel.
    fn map3(&self, f: impl Fn(f32, f32, f32) -> f32 + Sync) -> Gray<f32> {
        let mut out = Gray::new(self.s0.width(), self.s0.height());
        let (a, b, c) = (self.s0.as_slice(), self.s1.as_slice(), self.s2.as_slice());
        out.as_mut_slice()
            .par_iter_mut()
            .enumerate()
            .for_each(|(k, v)| *v = f(a[k], b[k], c[k]));
        out
    }

    /// `S0, S1, S2` as one interleaved 3-channel image.
    pub fn linear_stokes(&self) -> LinearStokesImage {
        LinearStokesImage::from_channels([&self.s0, &self.s1, &self.s2])
            .expect("planes share one size")
    }

    /// Stokes, DoLP and AoLP of a stack of the four polarizer images.
    pub fn from_stack(stack: &PolarizerStack) -> Self {
        let (w, h) = stack.size();
        let mut out = Self::new(w, h);
        let src = stack.pixels();
        out.rows_mut()
            .enumerate()
            .for_each(|(y, [s0, s1, s2, d, a])| {
                for x in 0..w {
                    let [i0, i45, i90, i135] = src[y * w + x];
                    [s0[x], s1[x], s2[x]] = linear_stokes_from_quad(i0, i45, i90, i135);
                }
                derived_row(s0, s1, s2, d, a);
            });
        out
    }

    /// DoLP and AoLP of an existing linear Stokes image (e.g. read from `stokes.exr`).
    pub fn from_linear_stokes(stokes: &LinearStokesImage) -> Self {
        let (w, h) = stokes.size();
        let mut out = Self::new(w, h);
        let src = stokes.pixels();
        out.rows_mut()
            .enumerate()
            .for_each(|(y, [s0, s1, s2, d, a])| {
                for x in 0..w {
                    [s0[x], s1[x], s2[x]] = src[y * w + x];
                }
                derived_row(s0, s1, s2, d, a);
            });
        out
    }

    /// The five planes as parallel iterators over rows `[s0, s1, s2, dolp, aolp]`.
    fn rows_mut(&mut self) -> impl IndexedParallelIterator<Item = [&mut [f32]; 5]> {
        let w = self.s0.width().max(1);
        let planes = [
            &mut self.s0,
            &mut self.s1,
            &mut self.s2,
            &mut self.dolp,
            &mut self.aolp,
        ];
        let [a, b, c, d, e] = planes.map(|p| p.as_mut_slice().par_chunks_mut(w));
        a.zip(b)
            .zip(c)
            .zip(d)
            .zip(e)
            .map(|((((a, b), c), d), e)| [a, b, c, d, e])
    }
}

/// Rec. 709 weights of linear R, G, B in the luminance `Y` (ITU-R BT.709, as sRGB).
pub const LUMA_REC709: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Stokes, DoLP and AoLP of each colour of a colour polarization mosaic, `[R, G, B]`
/// (names in [`crate::layout::COLOR_NAMES`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorStokesPlanes {
    /// The planes of red, green and blue.
    pub colors: [StokesPlanes; 3],
}

impl ColorStokesPlanes {
    /// Zero-filled planes of `width x height` for each colour.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            colors: std::array::from_fn(|_| StokesPlanes::new(width, height)),
        }
    }

    /// `(width, height)` of the planes.
    pub fn size(&self) -> (usize, usize) {
        self.colors[0].size()
    }

    /// DoLP and AoLP of each colour of a colour Stokes image with the channels
    /// `S0.R, S0.G, S0.B, S1.R, ... S2.B` (e.g. read from a colour `stokes.exr`).
    pub fn from_rgb_linear_stokes(stokes: &Image<f32, 9>) -> Self {
        let (w, h) = stokes.size();
        let colors = std::array::from_fn(|c| {
            let data = stokes
                .pixels()
                .iter()
                .flat_map(|p| [p[c], p[3 + c], p[6 + c]]);
            let one = LinearStokesImage::from_vec(w, h, data.collect())
                .expect("as many pixels as the colour image");
            StokesPlanes::from_linear_stokes(&one)
        });
        Self { colors }
    }

    /// Stokes of the luminance `Y = Σ LUMA_REC709[c] · colour c` with its DoLP and AoLP:
    /// Stokes parameters of incoherent light add, so this is what a sensor of Rec. 709
    /// luminance response would measure.
    pub fn luminance(&self) -> StokesPlanes {
        let (w, h) = self.size();
        let mut out = StokesPlanes::new(w, h);
        let src = self
            .colors
            .each_ref()
            .map(|p| [&p.s0, &p.s1, &p.s2].map(|g| g.as_slice()));
        out.rows_mut()
            .enumerate()
            .for_each(|(y, [s0, s1, s2, d, a])| {
                for (k, dst) in [s0.iter_mut(), s1.iter_mut(), s2.iter_mut()]
                    .into_iter()
                    .enumerate()
                {
                    for (x, v) in dst.enumerate() {
                        let i = y * w + x;
                        *v = (0..3).map(|c| LUMA_REC709[c] * src[c][k][i]).sum();
                    }
                }
                derived_row(s0, s1, s2, d, a);
            });
        out
    }
}

/// Colour mosaic (width and height multiples of 4) -> per colour `S0, S1, S2, DoLP, AoLP`:
/// [`crate::demosaic::color::split_colors`], then [`stokes_planes`] of each colour's
/// mosaic, so each colour runs the monochrome chain of `method` (fused where it is).
pub fn stokes_planes_rgb<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
) -> Result<ColorStokesPlanes, SensorError> {
    MosaicPattern::Rgb.check_size(raw.width(), raw.height())?;
    let (w, h) = method.output_size(raw.width(), raw.height());
    let mut out = ColorStokesPlanes::new(w, h);
    stokes_planes_rgb_into(raw, method, &mut out)?;
    Ok(out)
}

/// [`stokes_planes_rgb`] into caller-allocated planes of `method.output_size(..)` (only
/// the three colour mosaics are allocated).
pub fn stokes_planes_rgb_into<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
    out: &mut ColorStokesPlanes,
) -> Result<(), SensorError> {
    let (w, h) = raw.size();
    MosaicPattern::Rgb.check_size(w, h)?;
    check_output_size(method.output_size(w, h), out.size())?;
    if method == DemosaicMethod::Bilinear {
        fused_rgb_bilinear(raw.view(), out, Arch::new());
        return Ok(());
    }
    let mosaics = split_colors(raw)?;
    for (m, planes) in mosaics.iter().zip(&mut out.colors) {
        stokes_planes_into(m, method, planes)?;
    }
    Ok(())
}

/// DoLP and AoLP of one row of Stokes values (NaN where `S0 <= 0` or not finite),
/// on the best SIMD target of the CPU.
#[inline]
fn derived_row(s0: &[f32], s1: &[f32], s2: &[f32], d: &mut [f32], a: &mut [f32]) {
    Arch::new().dispatch(DerivedRow {
        stokes: [s0, s1, s2],
        dolp: d,
        aolp: a,
    });
}

/// The work of [`derived_row`], as a `pulp` operation: `with_simd` is monomorphised
/// per SIMD target and `#[inline(always)]`, so the row loop is compiled for each
/// (a closure is not reliably inlined there and would stay baseline code).
struct DerivedRow<'a> {
    stokes: [&'a [f32]; 3],
    dolp: &'a mut [f32],
    aolp: &'a mut [f32],
}

impl WithSimd for DerivedRow<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let [s0, s1, s2] = self.stokes;
        dolp_aolp_row(s0, s1, s2, self.dolp, self.aolp);
    }
}

/// Name of the SIMD target the row kernels run on, detected at run time on this CPU
/// (the build itself targets the x86-64 baseline unless `-C target-cpu` says otherwise).
pub fn simd_target() -> &'static str {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    match Arch::new() {
        Arch::V4(_) => return "x86-64-v4 (AVX-512)",
        Arch::V3(_) => return "x86-64-v3 (AVX2+FMA)",
        _ => {}
    }
    "baseline (no runtime SIMD dispatch)"
}

/// Least-squares `S0, S1, S2, DoLP, AoLP` from images behind ideal polarizers at any
/// `angles` (radians; at least three distinct modulo π), e.g. a rotating-polarizer
/// sequence. The fit is `polar_optics::LinearStokesFit` (pseudo-inverse computed once,
/// applied per pixel in f32); for 0/45/90/135° it equals the four-image formula.
pub fn stokes_planes_from_angles(
    images: &[&Gray<f32>],
    angles: &[f64],
) -> Result<StokesPlanes, SensorError> {
    let fit = LinearStokesFit::new(angles)?;
    let sizes: Vec<(usize, usize)> = images.iter().map(|i| i.size()).collect();
    if images.len() != angles.len() || sizes.windows(2).any(|p| p[0] != p[1]) {
        return Err(SensorError::StackShape {
            images: images.len(),
            sizes,
            angles: angles.len(),
        });
    }
    let pinv = fit.pseudo_inverse();
    let weights: Vec<[f32; 3]> = (0..angles.len())
        .map(|i| std::array::from_fn(|j| pinv[(j, i)] as f32))
        .collect();
    let (w, h) = sizes[0];
    let mut out = StokesPlanes::new(w, h);
    out.rows_mut()
        .enumerate()
        .for_each(|(y, [s0, s1, s2, d, a])| {
            for x in 0..w {
                let mut s = [0.0f32; 3];
                for (img, wt) in images.iter().zip(&weights) {
                    let v = img.as_slice()[y * w + x];
                    s.iter_mut().zip(wt).for_each(|(s, wt)| *s += wt * v);
                }
                [s0[x], s1[x], s2[x]] = s;
            }
            derived_row(s0, s1, s2, d, a);
        });
    Ok(out)
}

/// [`SensorError::OutputSize`] unless the caller's planes have the size `method` gives.
fn check_output_size(
    (width, height): (usize, usize),
    (got_width, got_height): (usize, usize),
) -> Result<(), SensorError> {
    if (got_width, got_height) == (width, height) {
        return Ok(());
    }
    Err(SensorError::OutputSize {
        width,
        height,
        got_width,
        got_height,
    })
}

/// Raw mosaic -> `S0, S1, S2, DoLP, AoLP`, allocating the output.
pub fn stokes_planes<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
) -> Result<StokesPlanes, SensorError> {
    check_mosaic_size(raw.width(), raw.height())?;
    let (w, h) = method.output_size(raw.width(), raw.height());
    let mut out = StokesPlanes::new(w, h);
    stokes_planes_into(raw, method, &mut out)?;
    Ok(out)
}

/// Raw mosaic -> `S0, S1, S2, DoLP, AoLP` into caller-allocated planes of
/// `method.output_size(..)` (the form for repeated frames: no allocation).
pub fn stokes_planes_into<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
    out: &mut StokesPlanes,
) -> Result<(), SensorError> {
    let (w, h) = raw.size();
    check_mosaic_size(w, h)?;
    check_output_size(method.output_size(w, h), out.size())?;
    match method {
        DemosaicMethod::Bilinear if w >= 4 && h >= 4 => {
            fused_bilinear(raw.view(), out, Arch::new())
        }
        DemosaicMethod::Residual => fused_residual(raw.view(), out, Arch::new()),
        _ => *out = StokesPlanes::from_stack(&demosaic(raw, method)?),
    }
    Ok(())
}

/// The fused residual chain: the guide and the residual go into the DoLP and AoLP planes
/// (scratch until the last pass), then each row is interpolated straight into `S0, S1,
/// S2`, then DoLP and AoLP are derived; so no full-size temporary is allocated.
fn fused_residual<T: MosaicSample>(raw: ImageView<'_, T, 1>, out: &mut StokesPlanes, arch: Arch) {
    let w = raw.width();
    guide_and_residual(raw, &mut out.dolp, &mut out.aolp);
    let (guide, res) = (out.dolp.view(), out.aolp.view());
    let [s0, s1, s2] = [&mut out.s0, &mut out.s1, &mut out.s2].map(|p| p.as_mut_slice());
    s0.par_chunks_mut(w)
        .zip(s1.par_chunks_mut(w))
        .zip(s2.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((a, b), c))| {
            arch.dispatch(ResidualRow {
                raw,
                guide,
                res,
                y,
                sink: StokesRow([a, b, c]),
            })
        });
    out.rows_mut()
        .for_each(|[s0, s1, s2, d, a]| derived_row(s0, s1, s2, d, a));
}

/// The fused bilinear chain on planes of the mosaic size (width and height `>= 4`), one
/// rayon task and one SIMD dispatch per row, each row's kernels compiled for `arch`.
fn fused_bilinear<T: MosaicSample>(raw: ImageView<'_, T, 1>, out: &mut StokesPlanes, arch: Arch) {
    out.rows_mut().enumerate().for_each(|(y, planes)| {
        let (rows, odd_row) = rows_around(raw, y);
        arch.dispatch(FusedRow {
            rows,
            odd_row,
            planes,
        })
    });
}

/// Mosaic rows per rayon task of [`fused_rgb_bilinear`]: its colour rows (two more than
/// the band) stay in cache between the split and the Stokes rows.
const RGB_BAND: usize = 16;

/// The fused colour chain for `bilinear` (a valid colour size): per band of rows, the
/// colour split of the rows the band reads into a small buffer, then per colour and row
/// the mono fused row of [`fused_bilinear`] on the buffered rows; so the colour mosaics
/// are never written to memory whole. Equal to split-then-[`fused_bilinear`] bit for bit.
fn fused_rgb_bilinear<T: MosaicSample>(
    raw: ImageView<'_, T, 1>,
    out: &mut ColorStokesPlanes,
    arch: Arch,
) {
    let (w, h) = raw.size();
    let mut bands: Vec<Vec<&mut [f32]>> = (0..h.div_ceil(RGB_BAND)).map(|_| vec![]).collect();
    for p in &mut out.colors {
        for plane in [&mut p.s0, &mut p.s1, &mut p.s2, &mut p.dolp, &mut p.aolp] {
            for (band, rows) in bands
                .iter_mut()
                .zip(plane.as_mut_slice().chunks_mut(w * RGB_BAND))
            {
                band.push(rows);
            }
        }
    }
    bands
        .into_par_iter()
        .enumerate()
        .for_each(|(b, mut planes)| {
            let (y0, y1) = (b * RGB_BAND, ((b + 1) * RGB_BAND).min(h));
            // Colour rows read by the band: around the clamped centre rows.
            let r0 = y0.clamp(1, h - 2) - 1;
            let n = (y1 - 1).clamp(1, h - 2) + 2 - r0;
            let mut buf = vec![T::default(); 3 * n * w];
            let (br, rest) = buf.split_at_mut(n * w);
            let (bg, bb) = rest.split_at_mut(n * w);
            for (i, ((r, g), b)) in br
                .chunks_mut(w)
                .zip(bg.chunks_mut(w))
                .zip(bb.chunks_mut(w))
                .enumerate()
            {
                split_row(raw, r0 + i, [r, g, b], arch);
            }
            for y in y0..y1 {
                let yc = y.clamp(1, h - 2);
                let k = (y - y0) * w..(y - y0 + 1) * w;
                for (c, colour) in planes.chunks_mut(5).enumerate() {
                    let row = |r: usize| &buf[(c * n + r - r0) * w..][..w];
                    let [s0, s1, s2, d, a] = colour else {
                        unreachable!("five planes per colour")
                    };
                    arch.dispatch(FusedRow {
                        rows: [row(yc - 1), row(yc), row(yc + 1)],
                        odd_row: yc & 1 == 1,
                        planes: [s0, s1, s2, d, a].map(|p| &mut p[k.clone()]),
                    });
                }
            }
        });
}

/// One output row of [`fused_bilinear`] as a `pulp` operation (see [`DerivedRow`]):
/// `rows` are the mosaic rows around the clamped centre row, `odd_row` its parity, and
/// `planes` the rows of `S0, S1, S2, DoLP, AoLP`.
struct FusedRow<'a, 'b, T> {
    rows: [&'a [T]; 3],
    odd_row: bool,
    planes: [&'b mut [f32]; 5],
}

impl<T: MosaicSample> WithSimd for FusedRow<'_, '_, T> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        let [s0, s1, s2, d, a] = self.planes;
        bilinear_stokes_rows(self.rows, self.odd_row, [s0, s1, s2]);
        dolp_aolp_row(s0, s1, s2, d, a);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use polar_optics::stokes::intensity_through_polarizer;

    fn test_mosaic(w: usize, h: usize) -> Mosaic<u8> {
        Mosaic::from_vec(
            w,
            h,
            (0..w * h)
                .map(|i| ((i * 37 + i / w * 11) % 251) as u8)
                .collect(),
        )
        .unwrap()
    }

    /// The fused bilinear path must equal demosaic-then-Stokes exactly (same integer
    /// demosaic values, same f32 formulas), on a frame with borders and a 4x4 one.
    #[test]
    fn fused_bilinear_equals_two_step() {
        for (w, h) in [(16, 12), (4, 4), (2, 6)] {
            let raw = test_mosaic(w, h);
            let fused = stokes_planes(&raw, DemosaicMethod::Bilinear).unwrap();
            let two_step =
                StokesPlanes::from_stack(&demosaic(&raw, DemosaicMethod::Bilinear).unwrap());
            assert_eq!(fused.s0, two_step.s0, "{w}x{h}");
            assert_eq!(fused.s1, two_step.s1);
            assert_eq!(fused.s2, two_step.s2);
            assert_eq!(fused.dolp, two_step.dolp);
            assert_eq!(fused.aolp, two_step.aolp);
        }
    }

    /// The banded colour chain equals the colour split followed by the mono fused chain
    /// per colour, bit for bit (NaN too), at sizes of one band, several bands with a
    /// partial last one, and the smallest colour mosaics, on every SIMD target.
    #[test]
    fn fused_rgb_equals_split_then_mono_chain() {
        let bits = |p: &StokesPlanes| -> Vec<u32> {
            [&p.s0, &p.s1, &p.s2, &p.dolp, &p.aolp]
                .iter()
                .flat_map(|g| g.as_slice().iter().map(|v| v.to_bits()))
                .collect()
        };
        let mut archs = vec![Arch::Scalar, Arch::new()];
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        archs.extend(pulp::x86::V3::try_new().map(Arch::V3));
        for (w, h) in [(4, 4), (8, 8), (12, 16), (24, 36), (40, 52)] {
            let mut raw = test_mosaic(w, h);
            raw.as_mut_slice()[..8].fill(0);
            let split = split_colors(&raw).unwrap();
            for &arch in &archs {
                let mut out = ColorStokesPlanes::new(w, h);
                fused_rgb_bilinear(raw.view(), &mut out, arch);
                for (m, got) in split.iter().zip(&out.colors) {
                    let want = stokes_planes(m, DemosaicMethod::Bilinear).unwrap();
                    assert!(bits(got) == bits(&want), "{w}x{h} {arch:?}");
                }
            }
        }
    }

    /// Every SIMD target this CPU has (baseline, AVX2+FMA, AVX-512) gives the same bits
    /// as the baseline code on both bundled real frames, as u8 and as u16 mosaics.
    /// Tolerance 0 (NaN compared by bits too): the kernels use only correctly rounded
    /// IEEE operations and selects (see the module doc). On a CPU without AVX2 there is
    /// nothing to compare.
    #[test]
    fn dispatch_targets_agree_bit_for_bit_on_real_frames() {
        let mut archs = vec![Arch::Scalar];
        #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
        {
            archs.extend(pulp::x86::V3::try_new().map(Arch::V3));
            archs.extend(pulp::x86::V4::try_new().map(Arch::V4));
        }
        let bits = |p: &StokesPlanes| -> Vec<u32> {
            [&p.s0, &p.s1, &p.s2, &p.dolp, &p.aolp]
                .iter()
                .flat_map(|g| g.as_slice().iter().map(|v| v.to_bits()))
                .collect()
        };
        fn run<T: MosaicSample>(raw: &Mosaic<T>, arch: Arch) -> StokesPlanes {
            let (w, h) = raw.size();
            let mut out = StokesPlanes::new(w, h);
            fused_bilinear(raw.view(), &mut out, arch);
            out
        }
        for name in ["carps_IMX250MZR.png", "camera_IMX250MZR.png"] {
            let path = format!(
                "{}/../../tests/data/real/{name}",
                env!("CARGO_MANIFEST_DIR")
            );
            let raw16 = polar_io::read_mosaic(&path).unwrap().image;
            let (w, h) = raw16.size();
            let raw8 = Mosaic::from_vec(w, h, raw16.as_slice().iter().map(|&v| v as u8).collect())
                .unwrap();
            let (base8, base16) = (run(&raw8, Arch::Scalar), run(&raw16, Arch::Scalar));
            for &arch in &archs[1..] {
                assert!(
                    bits(&run(&raw8, arch)) == bits(&base8),
                    "{name} u8 {arch:?}"
                );
                assert!(
                    bits(&run(&raw16, arch)) == bits(&base16),
                    "{name} u16 {arch:?}"
                );
            }
        }
    }

    /// Five angles, 0..144° in 36° steps, images made by Malus's law: the fit recovers
    /// the Stokes vector to f32 rounding (1e-4 relative), and a 3-angle set is enough.
    #[test]
    fn least_squares_from_arbitrary_angles() {
        let truth = [10.0f32, 3.0, -4.0];
        for angles_deg in [vec![0.0, 36.0, 72.0, 108.0, 144.0], vec![10.0, 70.0, 130.0]] {
            let angles: Vec<f64> = angles_deg.iter().map(|a: &f64| a.to_radians()).collect();
            let images: Vec<Gray<f32>> = angles
                .iter()
                .map(|&t| {
                    let v = intensity_through_polarizer(truth[0], truth[1], truth[2], t as f32);
                    Gray::from_vec(3, 2, vec![v; 6]).unwrap()
                })
                .collect();
            let refs: Vec<&Gray<f32>> = images.iter().collect();
            let p = stokes_planes_from_angles(&refs, &angles).unwrap();
            for (plane, want) in [(&p.s0, truth[0]), (&p.s1, truth[1]), (&p.s2, truth[2])] {
                assert!(
                    plane
                        .as_slice()
                        .iter()
                        .all(|v| (v - want).abs() < 1e-4 * 10.0),
                    "{angles_deg:?}"
                );
            }
            assert!((p.dolp.as_slice()[0] - 0.5).abs() < 1e-5);
        }
        let one = Gray::<f32>::new(2, 2);
        let err = stokes_planes_from_angles(&[&one, &one], &[0.0, 1.0]).unwrap_err();
        assert!(matches!(err, SensorError::Fit(_)), "{err}");
        let other = Gray::<f32>::new(4, 2);
        let err = stokes_planes_from_angles(&[&one, &one, &other], &[0.0, 1.0, 2.0]).unwrap_err();
        assert!(
            matches!(err, SensorError::StackShape { images: 3, .. }),
            "{err}"
        );
    }

    #[test]
    fn imax_imin_bracket_the_polarizer_images() {
        let raw = test_mosaic(8, 8);
        let stack = demosaic(&raw, DemosaicMethod::Superpixel).unwrap();
        let p = StokesPlanes::from_stack(&stack);
        let (hi, lo) = (p.imax(), p.imin());
        for (k, px) in stack.pixels().iter().enumerate() {
            // Four-image Stokes fits I(θ) exactly only if I0 + I90 = I45 + I135; allow that residual.
            let slack = 0.5 * ((px[0] + px[2]) - (px[1] + px[3])).abs() + 1e-3;
            assert!(
                px.iter()
                    .all(|&i| i <= hi.as_slice()[k] + slack && i >= lo.as_slice()[k] - slack),
                "{k}"
            );
            assert!((hi.as_slice()[k] + lo.as_slice()[k] - p.s0.as_slice()[k]).abs() < 1e-3);
        }
    }

    #[test]
    fn zero_intensity_gives_nan_dolp_and_aolp() {
        let raw = Mosaic::<u16>::new(4, 4);
        let p = stokes_planes(&raw, DemosaicMethod::Superpixel).unwrap();
        assert!(
            p.dolp
                .as_slice()
                .iter()
                .chain(p.aolp.as_slice())
                .all(|v| v.is_nan())
        );
    }

    #[test]
    fn wrong_output_size_is_an_error() {
        let raw = test_mosaic(8, 8);
        let mut out = StokesPlanes::new(8, 8);
        let err = stokes_planes_into(&raw, DemosaicMethod::Superpixel, &mut out).unwrap_err();
        assert!(matches!(
            err,
            SensorError::OutputSize {
                width: 4,
                height: 4,
                ..
            }
        ));
    }
}
