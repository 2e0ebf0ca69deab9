//! One observation of a polarization camera, as every analysis task receives it: the
//! linear Stokes planes (with DoLP and AoLP), S3 where known, the validity flags of
//! [`crate::mask`] and what is known of the camera. Nothing here depends on where the
//! frame came from (our renderer, another one, a real sensor).

use polar_image::{Gray, quantile};
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
}
