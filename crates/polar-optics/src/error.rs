//! The one error type of this crate.

/// What can go wrong when building an element or estimating/decomposing a quantity.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OpticsError {
    /// A parameter lies outside its physical range (NaN included).
    #[error("{name} = {value} is outside {expected}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// Polarizer angles and measured intensities differ in number.
    #[error("{angles} polarizer angles but {intensities} intensities")]
    LengthMismatch {
        /// Number of angles.
        angles: usize,
        /// Number of intensities.
        intensities: usize,
    },
    /// Linear Stokes needs three unknowns, so at least three distinct polarizer
    /// angles modulo 180 degrees.
    #[error("need at least 3 polarizer angles distinct modulo 180 degrees, got {distinct}")]
    TooFewAngles {
        /// Number of distinct angles found.
        distinct: usize,
    },
    /// An input value is NaN or infinite where a finite value is required.
    #[error("{what}[{index}] = {value} is not finite")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// Position of the bad value.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A decomposition step is undefined for this matrix (e.g. an ideal
    /// polarizer has no inverse diattenuator).
    #[error("decomposition undefined: {reason} ({value})")]
    Singular {
        /// Which step failed and why.
        reason: &'static str,
        /// The offending quantity.
        value: f64,
    },
}
