//! Thin pass-through sheets for validation scenes: an ideal linear polarizer and
//! a linear retarder. Light goes straight through (`wi = −wo`, a delta
//! transmission) and meets the element whose axis is the direction
//! `(cos θ, sin θ, 0)` of the local frame (θ from the tangent x toward y),
//! projected onto the plane perpendicular to the ray.
//!
//! Against Mitsuba 3 (`tools/bsdf_crosscheck.py`): at normal incidence a
//! polarizer at `angle` equals Mitsuba's `polarizer` with `theta = −angle` and a
//! retarder equals its `retarder` with the same `theta`; off normal Mitsuba
//! uses the unprojected tangent and scales the retardance by `|cos θ|`.

use crate::geometry::{V3, to_bsdf_bases};
use crate::{BsdfSample, Model};
use polar_optics::Polarization;
use polar_optics::mueller::{linear_polarizer, retarder};
use polar_optics::{Mueller, stokes_basis};

/// Which optical element a [`Sheet`] is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SheetKind {
    /// Ideal linear polarizer transmitting along the axis (half of unpolarized light passes).
    Polarizer,
    /// Lossless linear retarder with its fast axis along the axis; the slow axis
    /// lags by `retardance` radians (Jones `diag(1, e^{iδ})` in the axis frame,
    /// `exp(−iωt)` convention): π/2 is a quarter-wave plate.
    Retarder {
        /// Phase delay δ of the slow axis, in radians.
        retardance: f64,
    },
}

/// A thin polarizer or retarder sheet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sheet {
    /// The element.
    pub kind: SheetKind,
    /// Angle of the transmission / fast axis from the tangent x toward y, radians.
    pub angle: f64,
}

impl Sheet {
    /// The element's Mueller matrix for light travelling along `k`, in the frame `stokes_basis(k)`.
    pub fn mueller(&self, k: &V3) -> Mueller {
        let element = match self.kind {
            SheetKind::Polarizer => linear_polarizer(0.0),
            SheetKind::Retarder { retardance } => retarder(retardance, 0.0),
        };
        let (sin, cos) = self.angle.sin_cos();
        let axis = V3::new(cos, sin, 0.0);
        let projected = axis - axis.dot(k) * k;
        // A ray along the axis itself sees no preferred direction; any frame will do.
        let x = if projected.norm_squared() > 1e-24 {
            projected.normalize()
        } else {
            stokes_basis(k)
        };
        to_bsdf_bases(&element, k, &x, k, &x)
    }
}

impl Model for Sheet {
    fn eval(&self, _wo: &V3, _wi: &V3) -> Mueller {
        Mueller::zeros()
    }

    fn pdf(&self, _wo: &V3, _wi: &V3) -> f64 {
        0.0
    }

    fn sample(&self, wo: &V3, _u: [f64; 3]) -> Option<BsdfSample> {
        Some(BsdfSample {
            wi: -wo,
            weight: self.mueller(wo),
            pdf: 1.0,
            is_delta: true,
            is_transmission: true,
            eta: 1.0,
        })
    }

    fn has_delta(&self) -> bool {
        true
    }

    /// A polarizer and a half-wave (or full-wave) retarder keep S3 uncoupled;
    /// any other retardance converts linear to circular light.
    fn polarization(&self) -> Polarization {
        match self.kind {
            SheetKind::Polarizer => Polarization::Linear,
            SheetKind::Retarder { retardance } if retardance.sin().abs() < 1e-12 => {
                Polarization::Linear
            }
            SheetKind::Retarder { .. } => Polarization::Full,
        }
    }
}
