//! The crate's error type.

use clustering::ClusteringError;

/// Everything that can go wrong in `anim-pca`.
///
/// Each variant names the call (`what`), the element and the value, and its message says how
/// to fix the input.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AnimPcaError {
    /// The clip has no frames or its frames have no vertices.
    #[error(
        "{what}: the clip has {frames} frame(s) of {vertices} vertices; pass at least one \
         frame with at least one vertex"
    )]
    EmptyClip {
        /// The call that received the clip.
        what: &'static str,
        /// Frames given.
        frames: usize,
        /// Vertices in frame 0 (0 when there is no frame).
        vertices: usize,
    },
    /// The clip has too few frames for the operation.
    #[error(
        "{what}: the clip has {frames} frame(s) but at least {min} are needed; pass a longer clip"
    )]
    TooFewFrames {
        /// The call that received the clip.
        what: &'static str,
        /// Frames given.
        frames: usize,
        /// Frames needed.
        min: usize,
    },
    /// A frame has a different vertex count than frame 0.
    #[error(
        "{what}: frame {frame} has {found} vertices but frame 0 has {expected}; every frame of \
         a clip must have the same vertices (constant connectivity, thesis §3.2.2)"
    )]
    VertexCountMismatch {
        /// The call that received the clip.
        what: &'static str,
        /// Index of the offending frame.
        frame: usize,
        /// Vertex count of frame 0.
        expected: usize,
        /// Vertex count of the offending frame.
        found: usize,
    },
    /// A coordinate is NaN or infinite.
    #[error(
        "{what}: frame {frame}, vertex {vertex} has the non-finite coordinate {value}; remove \
         or repair the frame"
    )]
    NonFinite {
        /// The call that received the clip.
        what: &'static str,
        /// Frame index.
        frame: usize,
        /// Vertex index.
        vertex: usize,
        /// The offending value.
        value: f32,
    },
    /// A parameter is out of range.
    #[error("{what}: parameter `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The call that received the parameter.
        what: &'static str,
        /// Field name, e.g. `"sigma"`.
        name: &'static str,
        /// The value given, printed.
        value: String,
        /// What range is valid.
        reason: &'static str,
    },
    /// A slice has the wrong length.
    #[error("{what}: expected {expected} elements but got {found}")]
    LengthMismatch {
        /// The call and argument, e.g. `"Reconstructor::reconstruct weights"`.
        what: &'static str,
        /// Length needed.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// The clips given as cells (thesis §3.2.2 "Motion Control") do not fit together, or a
    /// cell index is out of range.
    #[error("{what}: cell {cell}: {reason}")]
    InvalidCell {
        /// The call that received the cells.
        what: &'static str,
        /// Index of the offending cell.
        cell: usize,
        /// What is wrong and how to fix it.
        reason: String,
    },
    /// A `.cpca` file (thesis §3.3) is shorter than its header or a section says.
    #[error(
        "cpca file: {section} needs {needed} bytes but only {available} remain; the file is \
         truncated — copy or download it again"
    )]
    Truncated {
        /// The part being read, e.g. `"header"` or `"section WGHT"`.
        section: &'static str,
        /// Bytes needed.
        needed: u64,
        /// Bytes left in the file.
        available: u64,
    },
    /// The CRC-32 at the end of a `.cpca` file does not match its contents.
    #[error(
        "cpca file: checksum mismatch (stored {stored:#010x}, computed {computed:#010x}); the \
         file is corrupt — copy or download it again"
    )]
    ChecksumMismatch {
        /// CRC-32 stored in the file.
        stored: u32,
        /// CRC-32 of the bytes read.
        computed: u32,
    },
    /// A `.cpca` file has a field with an impossible or unsupported value.
    #[error("cpca file: field `{field}` = {value} is invalid: {reason}")]
    InvalidFile {
        /// The field, e.g. `"version"` or `"clusters"`.
        field: &'static str,
        /// The value found, printed.
        value: String,
        /// What was expected.
        reason: &'static str,
    },
    /// A GPU buffer would exceed a limit of the device (`compress::GpuDecoder`).
    #[error(
        "{what}: {value} exceeds the device limit {maximum}; request a device with larger \
         limits, or compress with fewer frames, components or with time components"
    )]
    GpuLimit {
        /// The buffer, e.g. `"GpuDecoder rows bytes"`.
        what: &'static str,
        /// Its size.
        value: u64,
        /// The device's limit, also capped at 2³² − 1 elements (the shader's u32 indices).
        maximum: u64,
    },
    /// Reading a GPU buffer back failed (the device was lost or the mapping failed).
    #[error("{what}: reading the GPU buffer back failed: {reason}; check the GPU driver")]
    GpuReadback {
        /// The call that read back.
        what: &'static str,
        /// The error reported by wgpu.
        reason: String,
    },
    /// The PCA failed (see the inner error).
    #[error("PCA of the clip failed: {0}")]
    Pca(#[from] ClusteringError),
}

/// Result alias of this crate.
pub type Result<T, E = AnimPcaError> = std::result::Result<T, E>;

/// An [`AnimPcaError::InvalidParameter`].
pub(crate) fn invalid(
    what: &'static str,
    name: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> AnimPcaError {
    AnimPcaError::InvalidParameter {
        what,
        name,
        value: value.to_string(),
        reason,
    }
}

/// An [`AnimPcaError::InvalidFile`]: `field` of a container holds `value`, which breaks `reason`.
pub(crate) fn bad_file(
    field: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> AnimPcaError {
    AnimPcaError::InvalidFile {
        field,
        value: value.to_string(),
        reason,
    }
}
