//! The observation in normalised units: S0, S1, S2 divided by `s0_scale`, non-finite
//! values replaced by 0, and one validity flag per pixel.

use polar_image::Gray;
use polar_sensor::Observation;
use polar_sensor::mask::SATURATED;
use rayon::prelude::*;

/// Normalised, sanitised Stokes planes.
#[derive(Clone, Debug)]
pub struct Normalized {
    /// `S0 / scale` (0 where not finite).
    pub s0: Gray<f32>,
    /// `S1 / scale` (0 where not finite).
    pub s1: Gray<f32>,
    /// `S2 / scale` (0 where not finite).
    pub s2: Gray<f32>,
    /// `true` where the pixel is valid ([`Observation::is_valid`]) and S0, S1, S2 are finite.
    pub valid: Vec<bool>,
    /// The divisor, [`Observation::s0_scale`].
    pub scale: f32,
    /// Pixels flagged saturated.
    pub saturated: usize,
    /// Other invalid pixels (S0 zero, negative or not finite; S1 or S2 not finite).
    pub unusable: usize,
    /// Robust standard deviation of the pixel noise of the normalised S0
    /// ([`crate::refine::noise_sigma`]).
    pub noise: f32,
}

impl Normalized {
    /// Divides the planes of `obs` by its `s0_scale`.
    pub fn new(obs: &Observation) -> Self {
        let scale = obs.s0_scale();
        let p = &obs.planes;
        let norm = |g: &Gray<f32>| {
            let v = g
                .as_slice()
                .par_iter()
                .map(|&x| if x.is_finite() { x / scale } else { 0.0 })
                .collect();
            Gray::from_vec(g.width(), g.height(), v).expect("size matches")
        };
        let (s0, s1, s2) = (p.s0.as_slice(), p.s1.as_slice(), p.s2.as_slice());
        let valid: Vec<bool> = (0..s0.len())
            .into_par_iter()
            .map(|k| obs.is_valid(k) && s0[k].is_finite() && s1[k].is_finite() && s2[k].is_finite())
            .collect();
        let saturated = obs
            .flags
            .as_slice()
            .par_iter()
            .filter(|&&f| f & SATURATED != 0)
            .count();
        let unusable = valid
            .par_iter()
            .filter(|v| !**v)
            .count()
            .saturating_sub(saturated);
        let mut out = Self {
            s0: norm(&p.s0),
            s1: norm(&p.s1),
            s2: norm(&p.s2),
            valid,
            scale,
            saturated,
            unusable,
            noise: 0.0,
        };
        out.noise = crate::refine::noise_sigma(&out);
        out
    }

    /// Number of valid pixels.
    pub fn valid_count(&self) -> usize {
        self.valid.iter().filter(|v| **v).count()
    }

    /// Warnings about excluded pixels.
    pub fn warnings(&self) -> Vec<String> {
        let n = self.valid.len();
        let mut w = Vec::new();
        if self.saturated > 0 {
            w.push(format!(
                "{} of {n} pixels saturated: excluded from the estimates, their transmission \
                 interpolated from valid neighbours and their radiance computed from the clipped S0",
                self.saturated
            ));
        }
        if self.unusable > 0 {
            w.push(format!(
                "{} of {n} pixels without light or not finite: excluded from the estimates, \
                 their transmission interpolated from valid neighbours",
                self.unusable
            ));
        }
        w
    }
}
