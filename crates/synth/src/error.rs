//! The crate's single error type.

use thiserror::Error;

/// Why a parameter set was rejected. Every variant names the offending field and value and
/// says what a valid value looks like.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SynthError {
    /// A numeric parameter is out of its valid range or not finite.
    #[error("invalid parameter `{field}` = {value}: expected {expected}")]
    InvalidParameter {
        /// The parameter, as `Struct::field` (e.g. `ClothParams::grid`).
        field: &'static str,
        /// The value that was given (converted to `f64` for the message).
        value: f64,
        /// What a valid value looks like.
        expected: &'static str,
    },
    /// The requested output would need more memory than the crate is willing to allocate.
    #[error(
        "`{field}` asks for {requested} {unit}, more than the maximum of {maximum}; \
         reduce the resolution or the frame count"
    )]
    TooLarge {
        /// The parameter(s) that determine the size (e.g. `SkyParams::width × height`).
        field: &'static str,
        /// How many elements were requested.
        requested: u128,
        /// The largest accepted element count.
        maximum: u128,
        /// What is being counted (`"texels"`, `"vertices"`, `"vertex positions"`).
        unit: &'static str,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = SynthError> = std::result::Result<T, E>;

/// Checks that `value` is finite and inside `[min, max]`.
pub(crate) fn check_range(
    field: &'static str,
    value: f32,
    min: f32,
    max: f32,
    expected: &'static str,
) -> Result<()> {
    if value.is_finite() && value >= min && value <= max {
        Ok(())
    } else {
        Err(SynthError::InvalidParameter {
            field,
            value: f64::from(value),
            expected,
        })
    }
}

/// Checks that every component of `value` is finite.
pub(crate) fn check_finite3(field: &'static str, value: glam::Vec3) -> Result<()> {
    match value.to_array().into_iter().find(|c| !c.is_finite()) {
        None => Ok(()),
        Some(bad) => Err(SynthError::InvalidParameter {
            field,
            value: f64::from(bad),
            expected: "finite components",
        }),
    }
}
