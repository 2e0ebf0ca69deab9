//! The working scale: shape from polarization works in an image of [`WORKING_SIZE`] to
//! twice as many pixels on its long side (`ShapeOptions::working_size`), whatever the
//! camera's resolution, and interpolates its results to the camera's pixels.
//!
//! The methods' windows (edge smoothing, AoLP coherence, the smoothness field) are a few pixels
//! wide. In a much finer image an object's edges spread over many pixels, sensor noise
//! breaks its polarization field into fragments, and smoothness carries the contour's
//! evidence only a few pixels inward. So a finer image is binned as a camera with larger
//! pixels would see it (`Observation::binned`: the mean Stokes vector, `f` times less
//! noise), and the normals, depth, confidence and reflection types found there are
//! brought back to the camera's pixels ([`Grid::upsample`]), as they are: letting each
//! fine pixel choose its own candidate against the interpolated normals adds the fine
//! pixels' noise rather than shape (docs/benchmarks.md).

use nalgebra::Vector3;
use polar_image::{Gray, Image};
use polar_sensor::Observation;
use rayon::prelude::*;

use crate::cues::usable;
use crate::foreground::with_enclosed_invalid;
use crate::{Shape, ShapeError};

/// Default long side (pixels) of the image the steps work in.
pub const WORKING_SIZE: usize = 256;

/// The binning factor of a `w × h` image: the largest that keeps its long side at least
/// `working_size` (1 for smaller images; 0 means never binned).
pub fn working_factor(w: usize, h: usize, working_size: usize) -> usize {
    match working_size {
        0 => 1,
        n => (w.max(h) / n).max(1),
    }
}

/// A fine image of `w × h` pixels binned by `f`.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    /// Fine width.
    pub w: usize,
    /// Fine height.
    pub h: usize,
    /// Binning factor.
    pub f: usize,
}

impl Grid {
    /// Coarse `(width, height)`.
    fn coarse(&self) -> (usize, usize) {
        (self.w.div_ceil(self.f), self.h.div_ceil(self.f))
    }

    /// The shape of the fine observation `obs` from `coarse`, the shape of `obs` binned:
    /// the foreground (a given object mask's own pixels, else each pixel's block's),
    /// reflection types and confidence of each pixel's block, normals and
    /// depth interpolated bilinearly between block centres (depth in fine pixels). The
    /// fine pixels that are not [`usable`] are foreground where the fine foreground
    /// encloses them, as at the working scale (`foreground::with_enclosed_invalid`), with
    /// normals and depth but neither a reflection type nor a confidence.
    pub fn upsample(
        &self,
        coarse: Shape,
        obs: &Observation,
        objects: Option<&[bool]>,
    ) -> Result<Shape, ShapeError> {
        let (w, h) = (self.w, self.h);
        let valid: Vec<bool> = (0..w * h).into_par_iter().map(|k| usable(obs, k)).collect();
        // The foreground's measured pixels (a given object mask's own, else the block's);
        // as at the working scale, the unmeasured ones it encloses join it without a
        // confidence or a type.
        let measured: Vec<bool> = (0..w * h)
            .into_par_iter()
            .map(|k| {
                valid[k]
                    && match objects {
                        Some(m) => m[k],
                        None => coarse.foreground.as_slice()[self.block(k)] != 0,
                    }
            })
            .collect();
        let fg = with_enclosed_invalid(&valid, w, h, measured.clone())?;
        let cn = coarse.normal.pixels();
        let normals: Vec<f32> = (0..w * h)
            .into_par_iter()
            .flat_map_iter(|k| {
                let v = self.interpolate(k, |b| {
                    let n = Vector3::from(cn[b]).cast::<f64>();
                    (n != Vector3::zeros()).then_some(n)
                });
                let n = v.and_then(|v| v.try_normalize(1e-12)).filter(|_| fg[k]);
                let n = n.map_or([0.0; 3], |n| [n.x as f32, n.y as f32, n.z as f32]);
                n.into_iter()
            })
            .collect();
        let cd = coarse.depth.as_slice();
        let depth = (0..w * h)
            .into_par_iter()
            .map(|k| {
                let d = self.interpolate(k, |b| cd[b].is_finite().then(|| f64::from(cd[b])));
                d.filter(|_| fg[k])
                    .map_or(f32::NAN, |d| (d * self.f as f64) as f32)
            })
            .collect();
        Ok(Shape {
            normal: Image::from_vec(w, h, normals).expect("sized"),
            depth: Gray::from_vec(w, h, depth).expect("sized"),
            confidence: self.nearest(&coarse.confidence, &measured),
            reflection: self.nearest(&coarse.reflection, &measured),
            foreground: Gray::from_vec(w, h, fg.iter().map(|&f| 255 * u8::from(f)).collect())
                .expect("sized"),
            ..coarse
        })
    }

    /// A fine `w × h` mask on the coarse grid: a block is set where at least half of its
    /// pixels are.
    pub fn majority(&self, fine: &[bool]) -> Vec<bool> {
        let (cw, ch) = self.coarse();
        let mut counts = vec![[0usize; 2]; cw * ch];
        for (k, &v) in fine.iter().enumerate() {
            let c = &mut counts[self.block(k)];
            c[0] += 1;
            c[1] += usize::from(v);
        }
        counts.iter().map(|[n, on]| 2 * on >= *n).collect()
    }

    /// Each foreground pixel takes its block's value, the others `T::default()`.
    fn nearest<T: Copy + Default>(&self, coarse: &Gray<T>, fg: &[bool]) -> Gray<T> {
        let values = (0..self.w * self.h).map(|k| match fg[k] {
            true => coarse.as_slice()[self.block(k)],
            false => T::default(),
        });
        Gray::from_vec(self.w, self.h, values.collect()).expect("sized")
    }

    /// The coarse pixel holding fine pixel `k`.
    fn block(&self, k: usize) -> usize {
        (k / self.w / self.f) * self.coarse().0 + (k % self.w) / self.f
    }

    /// Bilinear interpolation at fine pixel `k` between the centres of the four blocks
    /// around it, over those that have a value (`value(block)`), weights renormalised;
    /// `None` where none has.
    fn interpolate<T>(&self, k: usize, value: impl Fn(usize) -> Option<T>) -> Option<T>
    where
        T: std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        let (cw, ch) = self.coarse();
        // Fine pixel centre x + 0.5 lies at coarse coordinate (x + 0.5) / f − 0.5.
        let axis = |x: usize, n: usize| {
            let u = ((x as f64 + 0.5) / self.f as f64 - 0.5).clamp(0.0, (n - 1) as f64);
            let i = (u as usize).min(n.saturating_sub(2));
            (i, (i + 1).min(n - 1), u - i as f64)
        };
        let (x0, x1, tx) = axis(k % self.w, cw);
        let (y0, y1, ty) = axis(k / self.w, ch);
        let corners = [
            (y0 * cw + x0, (1.0 - tx) * (1.0 - ty)),
            (y0 * cw + x1, tx * (1.0 - ty)),
            (y1 * cw + x0, (1.0 - tx) * ty),
            (y1 * cw + x1, tx * ty),
        ];
        let mut sum: Option<(T, f64)> = None;
        for (b, wt) in corners {
            if let Some(v) = value(b).filter(|_| wt > 0.0) {
                sum = Some(match sum {
                    Some((s, tw)) => (s + v * wt, tw + wt),
                    None => (v * wt, wt),
                });
            }
        }
        sum.map(|(s, tw)| s * tw.recip())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_working_factor_keeps_the_long_side_at_least_the_working_size() {
        for (w, h) in [
            (2, 2),
            (128, 96),
            (511, 300),
            (512, 512),
            (2448, 2048),
            (300, 1100),
        ] {
            let f = working_factor(w, h, WORKING_SIZE);
            let long = w.max(h);
            assert!(f == 1 || long / f >= WORKING_SIZE, "{w}x{h}: {f}");
            assert!(
                long / (f + 1) < WORKING_SIZE,
                "{w}x{h}: {f} is not the largest"
            );
            assert_eq!(working_factor(w, h, 0), 1, "{w}x{h}");
        }
    }

    #[test]
    fn interpolation_reproduces_a_linear_field_and_skips_missing_blocks() {
        // Coarse 4x3 of a 12x9 image (f = 3): the value 2x + 5y at block (x, y).
        let g = Grid { w: 12, h: 9, f: 3 };
        let coarse: Vec<f64> = (0..12)
            .map(|b| 2.0 * (b % 4) as f64 + 5.0 * (b / 4) as f64)
            .collect();
        for k in 0..g.w * g.h {
            let (x, y) = ((k % 12) as f64, (k / 12) as f64);
            // Fine centre x + 0.5 sits at block coordinate (x + 0.5) / 3 − 0.5, clamped.
            let u = ((x + 0.5) / 3.0 - 0.5).clamp(0.0, 3.0);
            let v = ((y + 0.5) / 3.0 - 0.5).clamp(0.0, 2.0);
            let got = g.interpolate(k, |b| Some(coarse[b])).unwrap();
            assert!(
                (got - (2.0 * u + 5.0 * v)).abs() < 1e-12,
                "pixel {k}: {got}"
            );
        }
        // Only block 0 has a value: every pixel near it takes that value; none far away.
        let one = |b: usize| (b == 0).then_some(7.0);
        for k in [0, 2, 12] {
            assert!(
                (g.interpolate(k, one).unwrap() - 7.0).abs() < 1e-12,
                "pixel {k}"
            );
        }
        assert_eq!(g.interpolate(4, one), None);
        assert_eq!(g.interpolate(11 + 12 * 8, one), None);
    }
}
