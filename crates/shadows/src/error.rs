//! Errors of the shadows crate: each names the element and the value.

/// What went wrong building or drawing shadows.
#[derive(Debug, thiserror::Error)]
pub enum ShadowError {
    /// A light with a non-finite position or a zero direction.
    #[error("light: {0}")]
    Light(String),
    /// A caster mesh the volume builder cannot use.
    #[error("caster: {0}")]
    Mesh(String),
    /// A parameter outside its range (grid size, extent, α, LOD ratio, …).
    #[error("{name} = {value}: {reason}")]
    Parameter {
        /// The parameter.
        name: &'static str,
        /// Its value, formatted.
        value: String,
        /// What it must be.
        reason: &'static str,
    },
    /// The exact ray twin could not prepare the scene.
    #[error("exact rays: {0}")]
    Rays(#[from] occlusion_gpu::OcclusionError),
    /// A GPU failure (device limits, read-back).
    #[cfg(feature = "gpu")]
    #[error("GPU: {0}")]
    Gpu(#[from] gpu_context::GpuError),
}

/// Shorthand for a [`ShadowError::Parameter`].
pub(crate) fn bad_parameter(
    name: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> ShadowError {
    ShadowError::Parameter {
        name,
        value: value.to_string(),
        reason,
    }
}
