//! The main chain raw mosaic -> `S0, S1, S2, DoLP, AoLP` (f32 planes).
//!
//! For `bilinear` the chain is fused: each rayon task takes one mosaic row,
//! interpolates, forms Stokes and DoLP/AoLP while the row is in cache, so the
//! four polarizer images are never written to memory. Other methods demosaic
//! first and then apply the same per-pixel formulas: `linear_stokes_from_quad` of
//! `polar_optics::stokes`, and its `dolp`/`aolp` in the vectorisable form of [`crate::fastmath`].

use polar_image::{Gray, LinearStokesImage, PolarizerStack};
use polar_optics::stokes::linear_stokes_from_quad;
use rayon::prelude::*;

use crate::demosaic::bilinear::bilinear_stokes_row;
use crate::demosaic::{DemosaicMethod, demosaic};
use crate::fastmath::dolp_aolp_row;
use crate::layout::{Mosaic, MosaicSample};
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

/// DoLP and AoLP of one row of Stokes values (NaN where `S0 <= 0` or not finite).
#[inline]
fn derived_row(s0: &[f32], s1: &[f32], s2: &[f32], d: &mut [f32], a: &mut [f32]) {
    dolp_aolp_row(s0, s1, s2, d, a);
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
    let (ow, oh) = method.output_size(w, h);
    if out.size() != (ow, oh) {
        let (got_width, got_height) = out.size();
        return Err(SensorError::OutputSize {
            width: ow,
            height: oh,
            got_width,
            got_height,
        });
    }
    if method != DemosaicMethod::Bilinear || w < 4 || h < 4 {
        *out = StokesPlanes::from_stack(&demosaic(raw, method)?);
        return Ok(());
    }
    let src = raw.as_slice();
    out.rows_mut()
        .enumerate()
        .for_each(|(y, [s0, s1, s2, d, a])| {
            bilinear_stokes_row(src, w, h, y, [&mut *s0, &mut *s1, &mut *s2]);
            derived_row(s0, s1, s2, d, a);
        });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
