//! Errors of the hemicube crate.

/// What can go wrong building or using visibility maps.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HemicubeError {
    /// A model's resolution or aperture is out of range.
    #[error("visibility-map model: {0}")]
    Model(String),
    /// A build or lighting parameter is out of range.
    #[error("hemicube parameter: {0}")]
    Params(String),
    /// The scene was refused (non-finite positions, bad indices, no receivers).
    #[error(transparent)]
    Scene(#[from] occlusion_gpu::OcclusionError),
    /// The GPU failed (read-back, validation, device loss).
    #[error(transparent)]
    Gpu(#[from] gpu_context::GpuError),
    /// The adapter cannot clip the atlas tiles.
    #[error(
        "the GPU builder needs clip distances and the adapter {adapter} lacks them \
         (wgpu feature CLIP_DISTANCES): use the ray builder (--builder cpu)"
    )]
    NoClipDistances {
        /// The adapter's name.
        adapter: String,
    },
}
