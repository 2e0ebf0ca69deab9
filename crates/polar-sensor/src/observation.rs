//! One observation of a polarization camera, as every analysis task receives it: the
//! linear Stokes planes (with DoLP and AoLP), S3 where known, the validity flags of
//! [`crate::mask`] and what is known of the camera. Nothing here depends on where the
//! frame came from (our renderer, another one, a real sensor).

use polar_image::{Gray, LinearStokesImage, quantile};
use polar_optics::pixel_frame::{CameraModel, PixelFrame};

use crate::mask::{SATURATED, ZERO};
use crate::products::StokesPlanes;

/// The input of the vision tasks.
#[derive(Clone, Debug)]
pub struct Observation {
    /// S0, S1, S2, DoLP and AoLP, in any linear unit (DN, radiance): tasks must not depend
    /// on the global scale.
    pub planes: StokesPlanes,
    /// S3 where the source knows it (a simulated `stokes.exr`); cameras do not measure it.
    pub s3: Option<Gray<f32>>,
    /// Per-pixel flags, `0` valid, else [`SATURATED`] and/or [`ZERO`].
    pub flags: Gray<u8>,
    /// The camera, for the per-pixel Stokes frame.
    pub camera: CameraModel,
}

impl Observation {
    /// An observation of `planes` with flags derived from S0 alone ([`ZERO`] where S0 is
    /// not a positive finite number); use [`Self::with_flags`] to add saturation.
    pub fn new(planes: StokesPlanes, camera: CameraModel) -> Self {
        let mut flags = Gray::new(planes.s0.width(), planes.s0.height());
        for (f, &s0) in flags.as_mut_slice().iter_mut().zip(planes.s0.as_slice()) {
            *f = if s0 > 0.0 && s0.is_finite() { 0 } else { ZERO };
        }
        Self {
            planes,
            s3: None,
            flags,
            camera,
        }
    }

    /// Replaces the flags (e.g. those of [`crate::mask::validity_mask`]).
    pub fn with_flags(mut self, flags: Gray<u8>) -> Self {
        assert_eq!(
            flags.size(),
            self.planes.size(),
            "flags and planes differ in size"
        );
        self.flags = flags;
        self
    }

    /// `(width, height)`.
    pub fn size(&self) -> (usize, usize) {
        self.planes.size()
    }

    /// `true` where the pixel is neither saturated nor without light.
    pub fn is_valid(&self, k: usize) -> bool {
        self.flags.as_slice()[k] & (SATURATED | ZERO) == 0
    }

    /// A robust brightness scale: the 99th percentile of S0 over valid pixels (1 where
    /// there are none). Tasks divide S0 by it so that exposure and bit depth drop out.
    pub fn s0_scale(&self) -> f32 {
        let s0 = self.planes.s0.as_slice();
        let valid = (0..s0.len()).filter(|&k| self.is_valid(k)).map(|k| s0[k]);
        quantile(valid, 0.99).filter(|&q| q > 0.0).unwrap_or(1.0)
    }

    /// The observation of a camera with `f × f` times larger pixels: each block's mean
    /// Stokes vector over its valid pixels (Stokes vectors of light add, so this is what
    /// the larger pixel would measure, with `f` times less noise). Blocks at the right and
    /// bottom edges may be smaller. A block is valid where at least half its pixels are,
    /// else it carries the union of their flags. `f` of 0 or 1 gives a copy.
    pub fn binned(&self, f: usize) -> Observation {
        if f <= 1 {
            return self.clone();
        }
        let (w, h) = self.size();
        let (bw, bh) = (w.div_ceil(f), h.div_ceil(f));
        let block = |k: usize| (k / w / f) * bw + (k % w) / f;
        let ok: Vec<bool> = (0..w * h).map(|k| self.is_valid(k)).collect();
        let mut members = vec![0u32; bw * bh];
        let mut valid = vec![0u32; bw * bh];
        let mut flags = vec![0u8; bw * bh];
        for (k, &fk) in self.flags.as_slice().iter().enumerate() {
            let b = block(k);
            members[b] += 1;
            match ok[k] {
                true => valid[b] += 1,
                false => flags[b] |= fk,
            }
        }
        let means = |plane: &Gray<f32>| {
            let mut sums = vec![0f64; bw * bh];
            for (k, &v) in plane.as_slice().iter().enumerate() {
                if ok[k] {
                    sums[block(k)] += f64::from(v);
                }
            }
            let m = sums.iter().zip(&valid);
            let m = m.map(|(&s, &n)| {
                if n == 0 {
                    0.0
                } else {
                    (s / f64::from(n)) as f32
                }
            });
            Gray::from_vec(bw, bh, m.collect()).expect("sized")
        };
        let p = &self.planes;
        let stokes =
            LinearStokesImage::from_channels([&means(&p.s0), &means(&p.s1), &means(&p.s2)])
                .expect("same sizes");
        for ((fl, &n), &m) in flags.iter_mut().zip(&valid).zip(&members) {
            if 2 * n >= m {
                *fl = 0;
            }
        }
        Observation {
            planes: StokesPlanes::from_linear_stokes(&stokes),
            s3: self.s3.as_ref().map(means),
            flags: Gray::from_vec(bw, bh, flags).expect("sized"),
            camera: self.camera,
        }
    }

    /// The ray and Stokes frame through the centre of pixel `(x, y)`.
    pub fn pixel_frame(&self, x: usize, y: usize) -> PixelFrame {
        let (w, h) = self.size();
        self.camera.frame(w, h, x as f64, y as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn planes(s0: &[f32]) -> StokesPlanes {
        let n = s0.len();
        let mut p = StokesPlanes::new(n, 1);
        p.s0.as_mut_slice().copy_from_slice(s0);
        p
    }

    #[test]
    fn zero_and_non_finite_s0_are_flagged() {
        let o = Observation::new(
            planes(&[1.0, 0.0, f32::NAN, -1.0, 2.0]),
            CameraModel::Orthographic,
        );
        let valid: Vec<bool> = (0..5).map(|k| o.is_valid(k)).collect();
        assert_eq!(valid, [true, false, false, false, true]);
    }

    #[test]
    fn scale_is_the_valid_high_quantile_and_never_zero() {
        let s0: Vec<f32> = (1..=100).map(|v| v as f32).collect();
        let o = Observation::new(planes(&s0), CameraModel::Orthographic);
        assert_eq!(o.s0_scale(), 99.0);
        let dark = Observation::new(planes(&[0.0; 4]), CameraModel::Orthographic);
        assert_eq!(dark.s0_scale(), 1.0);
    }

    #[test]
    fn binning_adds_stokes_vectors_so_crossed_polarizations_cancel() {
        // A 3x2 image binned by 2: block 0 holds +S1 and -S1 light (DoLP 1 each) whose sum
        // is unpolarized; block 1 is the partial right column.
        let mut p = StokesPlanes::new(3, 2);
        p.s0.as_mut_slice()
            .copy_from_slice(&[1.0, 1.0, 2.0, 1.0, 1.0, 4.0]);
        p.s1.as_mut_slice()
            .copy_from_slice(&[1.0, -1.0, 2.0, 1.0, -1.0, 0.0]);
        let o = Observation::new(p, CameraModel::Orthographic).binned(2);
        assert_eq!(o.size(), (2, 1));
        assert_eq!(o.planes.s0.as_slice(), [1.0, 3.0]);
        assert_eq!(o.planes.s1.as_slice(), [0.0, 1.0]);
        assert_eq!(o.planes.dolp.as_slice(), [0.0, 1.0 / 3.0]);
        assert!(o.is_valid(0) && o.is_valid(1));
    }

    #[test]
    fn a_block_is_valid_when_at_least_half_its_pixels_are() {
        // Block 0: one saturated pixel of four (valid, mean of the other three);
        // block 1: three flagged of four (invalid, union of the flags).
        let s0 = [1.0, 8.0, 5.0, 0.0, 3.0, 2.0, 0.0, 7.0];
        let mut p = StokesPlanes::new(4, 2);
        p.s0.as_mut_slice().copy_from_slice(&s0);
        let mut flags = Gray::new(4, 2);
        flags
            .as_mut_slice()
            .copy_from_slice(&[0, SATURATED, SATURATED, ZERO, 0, 0, ZERO, 0]);
        let o = Observation::new(p, CameraModel::Orthographic).with_flags(flags);
        let b = o.binned(2);
        assert_eq!(b.planes.s0.as_slice()[0], 2.0);
        assert!(b.is_valid(0));
        assert!(!b.is_valid(1));
        assert_eq!(b.flags.as_slice()[1], SATURATED | ZERO);
        assert_eq!(o.binned(1).planes, o.planes);
    }
}
