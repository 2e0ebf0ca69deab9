//! The one error type of this crate.

/// Invalid material parameters, found by [`crate::Material::validate`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Error {
    /// A parameter has a value outside its physical range.
    #[error("invalid `{field}`: {reason}")]
    InvalidParameter {
        /// The parameter's key as written in the scene file.
        field: &'static str,
        /// Why the value is rejected, including the value itself.
        reason: String,
    },
}

impl Error {
    pub(crate) fn invalid(field: &'static str, reason: impl Into<String>) -> Self {
        Self::InvalidParameter {
            field,
            reason: reason.into(),
        }
    }
}
