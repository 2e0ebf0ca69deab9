//! Checks on decoded data: NaN/Inf where the format forbids them, negative S0, unknown labels.
//! Checks report the first offending pixel, so a bad file is easy to inspect.

use std::path::Path;

use polar_image::{Gray, Image, StokesImage};

use crate::error::{Error, Result};

/// Whether readers check values against the format's rules.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Validation {
    /// Check (the default): a bad value is an [`Error::InvalidValue`].
    #[default]
    Check,
    /// Trust the file and skip the checks (faster; for data known to be good).
    Skip,
}

/// A rule one float channel must obey.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// Any value, NaN and Inf included (e.g. DoLP, which is NaN where undefined).
    Any,
    /// Not NaN, not infinite.
    Finite,
    /// Finite and `>= 0` (S0, depth, intensities).
    FiniteNonNegative,
    /// In `[0, 1]` (transmittance, fractions).
    UnitInterval,
}

impl Rule {
    fn holds(self, v: f32) -> bool {
        match self {
            Rule::Any => true,
            Rule::Finite => v.is_finite(),
            Rule::FiniteNonNegative => v.is_finite() && v >= 0.0,
            Rule::UnitInterval => (0.0..=1.0).contains(&v),
        }
    }

    fn describe(self) -> &'static str {
        match self {
            Rule::Any => "any value",
            Rule::Finite => "finite",
            Rule::FiniteNonNegative => "finite and >= 0",
            Rule::UnitInterval => "in [0, 1]",
        }
    }
}

/// Checks every pixel of `image` against `rules[c]` for channel `c` (named `names[c]` in the
/// error). `path` is the file the image came from or goes to.
pub fn check_channels<const C: usize, K>(
    path: &Path,
    image: &Image<f32, C, K>,
    names: [&str; C],
    rules: [Rule; C],
) -> Result<()> {
    let width = image.width().max(1);
    for (i, px) in image.pixels().iter().enumerate() {
        for c in 0..C {
            if !rules[c].holds(px[c]) {
                return Err(Error::InvalidValue {
                    path: path.to_owned(),
                    channel: names[c].to_owned(),
                    x: i % width,
                    y: i / width,
                    value: f64::from(px[c]),
                    requirement: rules[c].describe(),
                });
            }
        }
    }
    Ok(())
}

/// Checks a Stokes image: S0 finite and `>= 0`, S1..S3 finite.
pub fn check_stokes(path: &Path, stokes: &StokesImage) -> Result<()> {
    use Rule::{Finite, FiniteNonNegative};
    check_channels(
        path,
        stokes,
        crate::STOKES_CHANNELS,
        [FiniteNonNegative, Finite, Finite, Finite],
    )
}

/// Checks that every sample of an 8-bit image satisfies `ok` (described by `requirement`).
pub fn check_u8(
    path: &Path,
    image: &Gray<u8>,
    requirement: &'static str,
    ok: impl Fn(u8) -> bool,
) -> Result<()> {
    let width = image.width().max(1);
    match image.as_slice().iter().position(|&v| !ok(v)) {
        None => Ok(()),
        Some(i) => Err(Error::InvalidValue {
            path: path.to_owned(),
            channel: "Y".to_owned(),
            x: i % width,
            y: i / width,
            value: f64::from(image.as_slice()[i]),
            requirement,
        }),
    }
}
