//! The division-of-focal-plane (DoFP) polarization sensor, both ways:
//!
//! - forward: [`SensorModel`] turns a Stokes image into the four polarizer
//!   images and a noisy, quantised raw mosaic (the camera of the simulator);
//! - inverse: [`demosaic()`] turns a raw mosaic into the four polarizer images
//!   with a selectable [`DemosaicMethod`], and [`products`] fuses demosaicing
//!   with Stokes, DoLP and AoLP for speed; [`mask`] flags pixels that cannot be
//!   trusted and [`picture`] renders 8-bit pictures;
//! - [`settings`]: the noise settings a user writes (a scene's `[sensor]` table) and
//!   their bounds.
//!
//! The mosaic layout is the Sony IMX250MZR one (see [`layout`]): super-pixel
//! row 0 = `[90°, 45°]`, row 1 = `[135°, 0°]`; colour sensors (IMX250MYR) put these
//! super-pixels under an RGGB Bayer pattern ([`MosaicPattern::Rgb`], [`stokes_planes_rgb`]). The physics (Malus's law, Stokes
//! from intensities, DoLP, AoLP, Mueller matrices) comes from `polar-optics`.

pub mod demosaic;
pub mod fastmath;
pub mod layout;
pub mod mask;
pub mod observation;
pub mod picture;
pub mod products;
pub mod sensor;
pub mod settings;

pub use demosaic::color::{demosaic_rgb, split_colors};
pub use demosaic::{DemosaicMethod, demosaic};
pub use layout::{Mosaic, MosaicPattern, MosaicSample};
pub use observation::Observation;
pub use products::{
    ColorStokesPlanes, StokesPlanes, stokes_planes, stokes_planes_from_angles, stokes_planes_rgb,
};
pub use sensor::{SensorModel, SensorOutput};
pub use settings::SensorSettings;

use thiserror::Error;

/// Errors of the sensor model and of the demosaicing front end.
#[derive(Debug, Error, PartialEq)]
pub enum SensorError {
    /// The mosaic has an odd width or height: it is not made of whole 2x2 super-pixels.
    #[error("mosaic is {width}x{height}: width and height must be even (whole 2x2 super-pixels)")]
    OddSize {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The mosaic is smaller than one 2x2 super-pixel.
    #[error("mosaic is {width}x{height}: at least one 2x2 super-pixel is needed")]
    TooSmall {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// A colour mosaic whose width or height is not a multiple of 4.
    #[error(
        "colour mosaic is {width}x{height}: width and height must be multiples of 4 (whole 4x4 tiles of R, G, G, B polarizer blocks)"
    )]
    ColorSize {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// A mosaic pattern name that is not known.
    #[error("unknown mosaic pattern `{0}` (known: {known})", known = MosaicPattern::names().join(", "))]
    UnknownPattern(String),
    /// A demosaicing method name that is not known.
    #[error("unknown demosaicing method `{0}` (known: {known})", known = DemosaicMethod::names().join(", "))]
    UnknownMethod(String),
    /// An output buffer has the wrong size.
    #[error("output is {got_width}x{got_height}, expected {width}x{height}")]
    OutputSize {
        /// Expected width.
        width: usize,
        /// Expected height.
        height: usize,
        /// Width given.
        got_width: usize,
        /// Height given.
        got_height: usize,
    },
    /// A sensor parameter is out of its valid range.
    #[error("invalid sensor parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// Valid range.
        reason: &'static str,
    },
    /// The polarizer angles do not determine linear Stokes (fewer than three distinct, NaN, ...).
    #[error("least-squares Stokes: {0}")]
    Fit(#[from] polar_optics::OpticsError),
    /// Images of a multi-angle stack differ in size, or their number differs from the angles'.
    #[error(
        "{images} image(s) of sizes {sizes:?} for {angles} angle(s): need one image per angle, all of one size"
    )]
    StackShape {
        /// Number of images.
        images: usize,
        /// Their sizes.
        sizes: Vec<(usize, usize)>,
        /// Number of angles.
        angles: usize,
    },
    /// An input Stokes value is negative or not finite.
    #[error("Stokes image pixel ({x}, {y}) has a non-finite or negative S0 ({s0})")]
    BadStokes {
        /// Column.
        x: usize,
        /// Row.
        y: usize,
        /// The offending S0.
        s0: f32,
    },
}

/// Checks that a mosaic of `width x height` is made of whole 2x2 super-pixels.
pub fn check_mosaic_size(width: usize, height: usize) -> Result<(), SensorError> {
    if polar_image::is_mosaic_size(width, height) {
        Ok(())
    } else if width < 2 || height < 2 {
        Err(SensorError::TooSmall { width, height })
    } else {
        Err(SensorError::OddSize { width, height })
    }
}
