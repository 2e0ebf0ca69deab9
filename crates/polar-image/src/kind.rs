//! What an image's channels mean: the zero-sized markers of the `K` parameter of
//! [`Image`](crate::Image). Two images with the same sample type and channel count but
//! different kinds are different types, so a Stokes image cannot be passed where the
//! polarizer images are expected; [`Image::into_kind`](crate::Image::into_kind) is the one
//! explicit (and free) way to change an image's meaning.
//!
//! ```compile_fail
//! use polar_image::{PolarizerStack, StokesImage};
//! fn decode(_: &PolarizerStack) {}
//! decode(&StokesImage::new(2, 2)); // error: a Stokes image is not a polarizer stack
//! ```
//! ```
//! use polar_image::{PolarizerStack, StokesImage};
//! fn decode(_: &PolarizerStack) {}
//! let stack: PolarizerStack = StokesImage::new(2, 2).into_kind(); // said out loud
//! decode(&stack);
//! ```

/// No particular meaning: masks, labels, DoLP and AoLP planes, pictures, the inputs and
/// outputs of the generic image operations. The default kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Plain;

/// Full Stokes `S0, S1, S2, S3` per pixel, in the camera frame of `docs/conventions.md`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Stokes;

/// Linear Stokes `S0, S1, S2` per pixel (what a division-of-focal-plane camera measures).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LinearStokes;

/// The intensities behind the four polarizers `I0, I45, I90, I135` per pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Polarizers;

/// Unit surface normals `x, y, z` in the camera frame; `0, 0, 0` where there is no surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Normals;

/// A raw division-of-focal-plane mosaic: one sample per pixel, each behind the
/// micro-polarizer of its position (layout in `polar_sensor::layout`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct RawMosaic;
