//! Errors of the translucency crate: each names the element and the value.

/// What went wrong preparing or drawing translucency.
#[derive(Debug, thiserror::Error)]
pub enum TranslucencyError {
    /// A parameter outside its range (σ, η, map size, window, light, …).
    #[error("{name} = {value}: {reason}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Its value, formatted.
        value: String,
        /// What it must be.
        reason: &'static str,
    },
    /// A mesh the pipeline cannot use.
    #[error("mesh: {0}")]
    Mesh(String),
    /// A material name that is not a preset.
    #[error("material {name:?} is not a preset (presets: {known})")]
    UnknownMaterial {
        /// The name asked for.
        name: String,
        /// The presets, comma-separated.
        known: String,
    },
    /// A GPU failure (device limits, read-back).
    #[cfg(feature = "gpu")]
    #[error("GPU: {0}")]
    Gpu(#[from] gpu_context::GpuError),
}

/// Shorthand for a [`TranslucencyError::Parameter`].
pub(crate) fn bad_parameter(
    name: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> TranslucencyError {
    TranslucencyError::Parameter {
        name,
        value: value.to_string(),
        reason,
    }
}
