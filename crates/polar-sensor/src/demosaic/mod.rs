//! Demosaicing: from a raw mosaic to the four polarizer images `I0, I45, I90, I135`.
//!
//! Methods are values of [`DemosaicMethod`], selectable by name:
//! - `superpixel`: one sample per 2x2 super-pixel (half resolution, no interpolation);
//! - `bilinear`: polanalyser's `COLOR_PolarMono`, i.e. OpenCV's Bayer bilinear
//!   (`COLOR_BayerBG2BGR` / `COLOR_BayerGR2BGR`) on the two diagonal sub-lattices,
//!   reproduced bit for bit, borders included (see [`bilinear`]);
//! - `newton`: Newton-polynomial interpolation with the polarization-difference
//!   model and edge classifier of Li, Zhao, Pan and Kong, "Demosaicking DoFP images
//!   using Newton's polynomial interpolation and polarization difference model",
//!   Opt. Express 27, 1376 (2019) (see [`newton`]);
//! - `residual`: edge-aware residual interpolation around an `S0/2` guide from the
//!   orthogonal polarizer pairs (Ahmed et al. 2017; Morimatsu et al. 2020), see [`residual`].
//!
//! A colour mosaic ([`crate::MosaicPattern::Rgb`]) is first split into one mosaic per
//! colour ([`color`]), each then demosaiced by any of these methods.

pub mod bilinear;
pub mod color;
pub mod newton;
pub mod residual;

use std::fmt;
use std::str::FromStr;

use polar_image::PolarizerStack;
use rayon::prelude::*;

use crate::layout::{Mosaic, MosaicSample, offset_of};
use crate::{SensorError, check_mosaic_size};

/// A demosaicing method.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DemosaicMethod {
    /// One Stokes sample per 2x2 super-pixel: output is half the mosaic size.
    Superpixel,
    /// Bilinear interpolation of each sub-lattice, identical to polanalyser's `COLOR_PolarMono`.
    Bilinear,
    /// Newton-polynomial interpolation with polarization-difference model (Li et al. 2019).
    Newton,
    /// Edge-aware residual interpolation around an `S0/2` guide (Ahmed et al. 2017, Morimatsu et al. 2020).
    Residual,
}

impl DemosaicMethod {
    /// Every method, in the order used by tables and help texts.
    pub const ALL: [DemosaicMethod; 4] = [
        Self::Superpixel,
        Self::Bilinear,
        Self::Newton,
        Self::Residual,
    ];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Superpixel => "superpixel",
            Self::Bilinear => "bilinear",
            Self::Newton => "newton",
            Self::Residual => "residual",
        }
    }

    /// All method names.
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|m| m.name()).collect()
    }

    /// Size of the demosaiced images for a `width x height` mosaic.
    pub fn output_size(self, width: usize, height: usize) -> (usize, usize) {
        match self {
            Self::Superpixel => (width / 2, height / 2),
            _ => (width, height),
        }
    }

    /// How far (in mosaic pixels) an output pixel's value can reach into the mosaic;
    /// used to spread the saturation mask over every output pixel a saturated sample affects.
    pub fn support_radius(self) -> usize {
        match self {
            Self::Superpixel => 0,
            Self::Bilinear => 1,
            Self::Newton => 10,
            Self::Residual => 3,
        }
    }
}

impl fmt::Display for DemosaicMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for DemosaicMethod {
    type Err = SensorError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|m| m.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| SensorError::UnknownMethod(s.to_string()))
    }
}

/// Demosaics `raw` into the four polarizer images (channels `I0, I45, I90, I135`, in DN).
///
/// The output is `method.output_size(width, height)`.
pub fn demosaic<T: MosaicSample>(
    raw: &Mosaic<T>,
    method: DemosaicMethod,
) -> Result<PolarizerStack, SensorError> {
    check_mosaic_size(raw.width(), raw.height())?;
    Ok(match method {
        DemosaicMethod::Superpixel => superpixel(raw),
        DemosaicMethod::Bilinear => bilinear::bilinear(raw),
        DemosaicMethod::Newton => newton::newton(raw),
        DemosaicMethod::Residual => residual::residual(raw),
    })
}

/// Half-resolution demosaicing: each 2x2 super-pixel gives one pixel with its four samples.
fn superpixel<T: MosaicSample>(raw: &Mosaic<T>) -> PolarizerStack {
    let (w, h) = raw.size();
    let mut out = PolarizerStack::new(w / 2, h / 2);
    let src = raw.as_slice();
    out.pixels_mut()
        .par_chunks_mut(w / 2)
        .enumerate()
        .for_each(|(sy, row)| {
            for (sx, px) in row.iter_mut().enumerate() {
                *px = std::array::from_fn(|c| {
                    let (dx, dy) = offset_of(c);
                    src[(2 * sy + dy) * w + 2 * sx + dx].into() as f32
                });
            }
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for m in DemosaicMethod::ALL {
            assert_eq!(m.name().parse::<DemosaicMethod>().unwrap(), m);
        }
        assert!(matches!(
            "cubic".parse::<DemosaicMethod>(),
            Err(SensorError::UnknownMethod(_))
        ));
    }

    #[test]
    fn superpixel_picks_each_angle_from_its_position() {
        // Super-pixel [[90, 45], [135, 0]] with values encoding the angle.
        let raw = Mosaic::<u8>::from_vec(2, 2, vec![90, 45, 135, 0]).unwrap();
        let out = demosaic(&raw, DemosaicMethod::Superpixel).unwrap();
        assert_eq!(out.pixels(), &[[0.0, 45.0, 90.0, 135.0]]);
    }

    #[test]
    fn odd_and_tiny_mosaics_are_rejected() {
        for m in DemosaicMethod::ALL {
            assert_eq!(
                demosaic(&Mosaic::<u8>::new(5, 4), m).unwrap_err(),
                SensorError::OddSize {
                    width: 5,
                    height: 4
                },
                "{m}"
            );
            assert_eq!(
                demosaic(&Mosaic::<u8>::new(4, 7), m).unwrap_err(),
                SensorError::OddSize {
                    width: 4,
                    height: 7
                },
                "{m}"
            );
            assert_eq!(
                demosaic(&Mosaic::<u8>::new(2, 1), m).unwrap_err(),
                SensorError::TooSmall {
                    width: 2,
                    height: 1
                },
                "{m}"
            );
        }
    }
}
