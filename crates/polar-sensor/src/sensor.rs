//! The camera's sensor: micro-polarizer array, photon and electron statistics, ADC.
//!
//! For a pixel under the micro-polarizer at angle θ (layout in [`crate::layout`]):
//! 1. intensity through the polarizer `I = m₀ · S` with `m₀` the first row of the
//!    Mueller matrix of a diattenuator with transmissions 1 and `1/ER` (extinction
//!    ratio ER) rotated to θ (`polar_optics::mueller`); ideal for `ER = ∞`;
//! 2. expected electrons `μ = QE · photons_per_unit · I`;
//! 3. Poisson shot noise (optional), clipped at the full-well capacity;
//! 4. Gaussian read noise `N(0, σ_read²)` in electrons;
//! 5. ADC: `DN = round(e / gain) + black_level`, clamped to `[0, 2^bits − 1]`.
//!
//! Randomness is a PCG-64 stream per mosaic row seeded from `(seed, row)`, so the
//! output is the same whatever the number of threads.

use polar_image::{Gray, PolarizerStack, StokesImage};
use polar_optics::mueller::{from_diagonal_jones, rotated_element};
use rand_distr::{Distribution, Normal, Poisson};
use rand_pcg::Pcg64;
use rayon::prelude::*;

use crate::layout::{CHANNEL_ANGLES_DEG, Mosaic, channel_at};
use crate::{SensorError, check_mosaic_size};

/// Parameters of a DoFP polarization sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorModel {
    /// Photons reaching a pixel (before its polarizer) per unit of input `S0`:
    /// the exposure scale from renderer radiance to photon counts.
    pub photons_per_unit: f64,
    /// Micro-polarizer extinction ratio `T_max / T_min` (`f64::INFINITY` = ideal).
    pub extinction_ratio: f64,
    /// Quantum efficiency: electrons per photon, in `(0, 1]`.
    pub quantum_efficiency: f64,
    /// Conversion gain in electrons per DN.
    pub gain: f64,
    /// Read noise standard deviation in electrons.
    pub read_noise: f64,
    /// Full-well capacity in electrons (the pixel saturates above it).
    pub full_well: f64,
    /// ADC bit depth, 1..=16.
    pub bit_depth: u32,
    /// Offset added to every DN (dark level).
    pub black_level: u16,
    /// Whether to draw Poisson shot noise (off: the expected electron count is used).
    pub shot_noise: bool,
    /// Seed of the noise streams.
    pub seed: u64,
}

/// The sensor's output for one exposure.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorOutput {
    /// Raw mosaic in DN, `bit_depth` significant bits, right-aligned.
    pub raw: Mosaic<u16>,
    /// 255 where the pixel saturated (full well reached or ADC at its maximum), else 0.
    pub saturated: Gray<u8>,
    /// Number of saturated pixels.
    pub saturated_count: usize,
}

impl SensorModel {
    /// A noiseless sensor with ideal polarizers, QE 1, 1 e-/DN, no black level and
    /// a full well at the top of the ADC range: DN = round(photons through the polarizer).
    pub fn ideal(bit_depth: u32) -> Self {
        Self {
            photons_per_unit: 1.0,
            extinction_ratio: f64::INFINITY,
            quantum_efficiency: 1.0,
            gain: 1.0,
            read_noise: 0.0,
            full_well: f64::INFINITY,
            bit_depth,
            black_level: 0,
            shot_noise: false,
            seed: 0,
        }
    }

    /// Typical figures of a Sony IMX250MZR (FLIR BFS-U3-51S5P) in 12-bit mode:
    /// ER ≈ 300 (Sony quotes ~300:1 at 525 nm), QE ≈ 0.6, full well ≈ 10 500 e-,
    /// read noise ≈ 2.3 e-, gain chosen so the full well spans the 12-bit range.
    pub fn imx250mzr() -> Self {
        Self {
            photons_per_unit: 1.0,
            extinction_ratio: 300.0,
            quantum_efficiency: 0.6,
            gain: 10_500.0 / 4095.0,
            read_noise: 2.3,
            full_well: 10_500.0,
            bit_depth: 12,
            black_level: 0,
            shot_noise: true,
            seed: 0,
        }
    }

    /// The largest DN the ADC produces.
    pub fn max_dn(&self) -> u16 {
        ((1u32 << self.bit_depth) - 1) as u16
    }

    /// Checks every parameter's range.
    pub fn validate(&self) -> Result<(), SensorError> {
        let bad = |name, value: f64, reason| {
            Err(SensorError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        let positive = "must be positive and finite";
        if !(self.photons_per_unit > 0.0 && self.photons_per_unit.is_finite()) {
            return bad("photons_per_unit", self.photons_per_unit, positive);
        }
        if self.extinction_ratio.is_nan() || self.extinction_ratio < 1.0 {
            return bad(
                "extinction_ratio",
                self.extinction_ratio,
                "must be >= 1 (infinity = ideal)",
            );
        }
        if !(self.quantum_efficiency > 0.0 && self.quantum_efficiency <= 1.0) {
            return bad(
                "quantum_efficiency",
                self.quantum_efficiency,
                "must be in (0, 1]",
            );
        }
        if !(self.gain > 0.0 && self.gain.is_finite()) {
            return bad("gain", self.gain, positive);
        }
        if !(self.read_noise >= 0.0 && self.read_noise.is_finite()) {
            return bad("read_noise", self.read_noise, "must be >= 0 and finite");
        }
        if self.full_well.is_nan() || self.full_well <= 0.0 {
            return bad(
                "full_well",
                self.full_well,
                "must be positive (infinity = none)",
            );
        }
        if !(1..=16).contains(&self.bit_depth) {
            return bad("bit_depth", f64::from(self.bit_depth), "must be in 1..=16");
        }
        if u32::from(self.black_level) >= u32::from(self.max_dn()) {
            return bad(
                "black_level",
                f64::from(self.black_level),
                "must be below the ADC maximum",
            );
        }
        Ok(())
    }

    /// First Mueller row of the micro-polarizer of each stack channel (`I0..I135`), f32.
    fn polarizer_rows(&self) -> [[f32; 4]; 4] {
        let t_min = if self.extinction_ratio.is_finite() {
            self.extinction_ratio.recip().sqrt()
        } else {
            0.0
        };
        let element = from_diagonal_jones(1.0.into(), t_min.into());
        CHANNEL_ANGLES_DEG.map(|deg| {
            let m = rotated_element(&element, deg.to_radians());
            std::array::from_fn(|j| m[(0, j)] as f32)
        })
    }

    /// The four full-resolution images behind the micro-polarizers (channels
    /// `I0, I45, I90, I135`), noiseless, in the units of the input Stokes image.
    pub fn polarizer_images(&self, stokes: &StokesImage) -> Result<PolarizerStack, SensorError> {
        self.validate()?;
        check_stokes(stokes)?;
        let rows = self.polarizer_rows();
        let mut out = PolarizerStack::new(stokes.width(), stokes.height());
        out.pixels_mut()
            .par_iter_mut()
            .zip(stokes.pixels())
            .for_each(|(px, s)| {
                *px = rows.map(|m| dot(&m, s));
            });
        Ok(out)
    }

    /// One exposure: Stokes image (`S0..S3` per pixel, even width and height) to a raw mosaic.
    pub fn expose(&self, stokes: &StokesImage) -> Result<SensorOutput, SensorError> {
        self.validate()?;
        let (w, h) = stokes.size();
        check_mosaic_size(w, h)?;
        check_stokes(stokes)?;
        let rows = self.polarizer_rows();
        let mut raw = Mosaic::<u16>::new(w, h);
        let mut saturated = Gray::<u8>::new(w, h);
        let read =
            Normal::new(0.0, self.read_noise).map_err(|_| SensorError::InvalidParameter {
                name: "read_noise",
                value: self.read_noise,
                reason: "must be >= 0 and finite",
            })?;
        raw.as_mut_slice()
            .par_chunks_mut(w)
            .zip(saturated.as_mut_slice().par_chunks_mut(w))
            .enumerate()
            .for_each(|(y, (raw_row, sat_row))| {
                let mut rng = Pcg64::new(
                    u128::from(self.seed) << 64 | y as u128,
                    0xda3e_39cb_94b9_5bdb,
                );
                for x in 0..w {
                    let intensity = f64::from(dot(&rows[channel_at(x, y)], stokes.pixel(x, y)));
                    let (dn, sat) = self.digitise(intensity, &read, &mut rng);
                    raw_row[x] = dn;
                    sat_row[x] = if sat { 255 } else { 0 };
                }
            });
        let saturated_count = saturated.as_slice().iter().filter(|&&s| s != 0).count();
        Ok(SensorOutput {
            raw,
            saturated,
            saturated_count,
        })
    }

    /// Electrons, noise and ADC for one pixel receiving `intensity`; returns `(DN, saturated)`.
    fn digitise(&self, intensity: f64, read: &Normal<f64>, rng: &mut Pcg64) -> (u16, bool) {
        let mean = (self.quantum_efficiency * self.photons_per_unit * intensity).max(0.0);
        let mut electrons = match Poisson::new(mean) {
            Ok(p) if self.shot_noise => p.sample(rng),
            _ => mean,
        };
        let full = electrons >= self.full_well;
        electrons = electrons.min(self.full_well);
        if self.read_noise > 0.0 {
            electrons += read.sample(rng);
        }
        let max = f64::from(self.max_dn());
        let dn = ((electrons / self.gain).round() + f64::from(self.black_level)).clamp(0.0, max);
        (dn as u16, full || dn >= max)
    }
}

/// `m · s` for a Mueller row and a Stokes pixel.
#[inline]
fn dot(m: &[f32; 4], s: &[f32; 4]) -> f32 {
    m[0] * s[0] + m[1] * s[1] + m[2] * s[2] + m[3] * s[3]
}

/// Rejects Stokes images with a negative or non-finite `S0` (no physical light).
fn check_stokes(stokes: &StokesImage) -> Result<(), SensorError> {
    match stokes
        .pixels()
        .iter()
        .position(|s| !(s[0] >= 0.0 && s.iter().all(|v| v.is_finite())))
    {
        None => Ok(()),
        Some(k) => {
            let w = stokes.width();
            Err(SensorError::BadStokes {
                x: k % w,
                y: k / w,
                s0: stokes.pixels()[k][0],
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::demosaic::{DemosaicMethod, demosaic};
    use crate::products::StokesPlanes;

    /// A Stokes image constant over each 2x2 super-pixel, with varied polarization.
    fn blocky_stokes(w: usize, h: usize) -> StokesImage {
        let mut s = StokesImage::new(w, h);
        for (k, px) in s.pixels_mut().iter_mut().enumerate() {
            let b = (k % w / 2 + (k / w / 2) * 7) as f32;
            let s0 = 1000.0 + 37.0 * b;
            let (p, a) = ((b * 0.13).fract(), b * 0.7);
            *px = [s0, s0 * p * (2.0 * a).cos(), s0 * p * (2.0 * a).sin(), 0.0];
        }
        s
    }

    /// Ideal, noiseless sensor: Stokes -> mosaic -> superpixel -> Stokes recovers the
    /// input up to the ADC rounding (each I within 0.5 DN, so S0 within 1, S1 and S2 within 1).
    #[test]
    fn ideal_round_trip_is_exact_to_quantisation() {
        let stokes = blocky_stokes(16, 12);
        let out = SensorModel::ideal(16).expose(&stokes).unwrap();
        let back =
            StokesPlanes::from_stack(&demosaic(&out.raw, DemosaicMethod::Superpixel).unwrap());
        for y in 0..6 {
            for x in 0..8 {
                let s = stokes.pixel(2 * x, 2 * y);
                let got = [
                    back.s0.pixel(x, y)[0],
                    back.s1.pixel(x, y)[0],
                    back.s2.pixel(x, y)[0],
                ];
                for c in 0..3 {
                    assert!(
                        (got[c] - s[c]).abs() <= 1.0 + 1e-3,
                        "({x},{y}) S{c}: {} vs {}",
                        got[c],
                        s[c]
                    );
                }
            }
        }
        assert_eq!(out.saturated_count, 0);
    }

    /// Noise statistics of a uniform unpolarized field: 128x128 pixels, mean μ = QE·N/2 e-.
    /// DN mean must be μ/g + black within 5 standard errors; variance must be
    /// (μ + σ²)/g² + 1/12 (shot + read + quantisation) within 5 standard errors of a
    /// variance estimate (≈ var·sqrt(2/n)).
    #[test]
    fn noise_mean_and_variance() {
        let model = SensorModel {
            gain: 2.0,
            read_noise: 3.0,
            black_level: 64,
            seed: 7,
            ..SensorModel::imx250mzr()
        };
        let n_photons = 4000.0f32;
        let stokes =
            StokesImage::from_vec(128, 128, [n_photons, 0.0, 0.0, 0.0].repeat(128 * 128)).unwrap();
        let raw = model.expose(&stokes).unwrap().raw;
        let v: Vec<f64> = raw.as_slice().iter().map(|&d| f64::from(d)).collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (n - 1.0);
        // The ER=300 polarizer passes (1 + 1/300)/2 of unpolarized light.
        let mu = model.quantum_efficiency * f64::from(n_photons) * 0.5 * (1.0 + 1.0 / 300.0);
        let want_var = (mu + model.read_noise.powi(2)) / model.gain.powi(2) + 1.0 / 12.0;
        let want_mean = mu / model.gain + 64.0;
        assert!(
            (mean - want_mean).abs() < 5.0 * (want_var / n).sqrt(),
            "mean {mean} vs {want_mean}"
        );
        assert!(
            (var - want_var).abs() < 5.0 * want_var * (2.0 / n).sqrt(),
            "var {var} vs {want_var}"
        );
    }

    #[test]
    fn same_seed_same_output_any_thread_count() {
        let model = SensorModel {
            seed: 3,
            ..SensorModel::imx250mzr()
        };
        let stokes = blocky_stokes(32, 32);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let a = one.install(|| model.expose(&stokes).unwrap());
        let b = model.expose(&stokes).unwrap();
        assert_eq!(a, b);
        let c = SensorModel { seed: 4, ..model }.expose(&stokes).unwrap();
        assert_ne!(a.raw, c.raw);
    }

    #[test]
    fn saturation_is_flagged() {
        let model = SensorModel::ideal(8);
        let stokes = StokesImage::from_vec(2, 2, [[600.0, 0.0, 0.0, 0.0]; 4].concat()).unwrap();
        let mut stokes_half = stokes.clone();
        stokes_half.pixels_mut()[3] = [100.0, 0.0, 0.0, 0.0];
        let out = model.expose(&stokes_half).unwrap();
        assert_eq!(out.raw.as_slice(), &[255, 255, 255, 50]);
        assert_eq!(out.saturated.as_slice(), &[255, 255, 255, 0]);
        assert_eq!(out.saturated_count, 3);
    }

    #[test]
    fn extinction_ratio_leaks_crossed_light() {
        let model = SensorModel {
            extinction_ratio: 100.0,
            ..SensorModel::ideal(16)
        };
        // Light fully polarized at 0°: the 90° polarizer passes 1/100 of what the 0° one does.
        let stokes = StokesImage::from_vec(1, 1, vec![1.0, 1.0, 0.0, 0.0]).unwrap();
        let i = model.polarizer_images(&stokes).unwrap().pixels()[0];
        assert!((i[2] / i[0] - 0.01).abs() < 1e-6, "{i:?}");
        assert!((i[1] - i[3]).abs() < 1e-6);
    }

    #[test]
    fn bad_parameters_and_stokes_are_rejected() {
        let bad = SensorModel {
            gain: 0.0,
            ..SensorModel::ideal(12)
        };
        assert!(matches!(
            bad.validate(),
            Err(SensorError::InvalidParameter { name: "gain", .. })
        ));
        let nan = StokesImage::from_vec(2, 2, vec![f32::NAN; 16]).unwrap();
        assert!(matches!(
            SensorModel::ideal(12).expose(&nan),
            Err(SensorError::BadStokes { x: 0, y: 0, .. })
        ));
        let odd = StokesImage::new(3, 2);
        assert!(matches!(
            SensorModel::ideal(12).expose(&odd),
            Err(SensorError::OddSize { .. })
        ));
    }
}
