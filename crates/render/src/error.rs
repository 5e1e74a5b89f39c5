//! The crate's error type.

use crate::camera::CameraError;

/// What can go wrong while rendering a frame.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The camera makes no image.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// A mesh handed to a pass is inconsistent.
    #[error("mesh {index}: {reason}")]
    Mesh {
        /// Position of the mesh in the list given.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// Target creation, read-back or file output failed.
    #[error(transparent)]
    Gpu(#[from] gpu_context::GpuError),
}
