//! The crate's error type.

use thiserror::Error;

/// Everything that can go wrong building a scene or computing visibility.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum OcclusionError {
    /// An object's normal array does not match its position array.
    #[error(
        "object {object}: {normals} normals for {positions} positions; give one normal per vertex \
         (zero for vertices used by no triangle)"
    )]
    NormalCountMismatch {
        /// Index of the object in the scene.
        object: usize,
        /// Number of positions.
        positions: usize,
        /// Number of normals.
        normals: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error(
        "object {object}, triangle {triangle}: vertex index {index} is out of range (the object \
         has {vertex_count} vertices); fix the index buffer"
    )]
    IndexOutOfRange {
        /// Index of the object in the scene.
        object: usize,
        /// Index of the triangle in the object.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices of the object.
        vertex_count: usize,
    },
    /// A position, normal or transform entry is NaN or infinite.
    #[error("object {object}: {element} {index} is not finite ({value}); remove NaN/inf input")]
    NonFinite {
        /// Index of the object in the scene.
        object: usize,
        /// What was not finite ("position", "normal", "world_from_object").
        element: &'static str,
        /// Index of the element (vertex index, or 0 for the transform).
        index: usize,
        /// The offending value.
        value: f32,
    },
    /// The scene has no receiver vertices or no triangles at all.
    #[error("the scene is empty: {what}; add at least one receiver object with triangles")]
    EmptyScene {
        /// What is missing.
        what: &'static str,
    },
    /// The scene has more vertices or triangles than the 32-bit indices the GPU uses allow.
    #[error("the scene has {value} {element}, more than the maximum {maximum}; split the scene")]
    TooLarge {
        /// "vertices" or "triangles".
        element: &'static str,
        /// The count requested.
        value: usize,
        /// The largest count supported.
        maximum: usize,
    },
    /// A matrix was refined with a lightsphere that is not a finer level of its own.
    #[error(
        "cannot refine a visibility matrix of {have} directions with a lightsphere of {requested} \
         directions; refine only to a finer (or equal) level of the same lightsphere"
    )]
    NotARefinement {
        /// Directions already computed.
        have: usize,
        /// Directions of the requested lightsphere.
        requested: usize,
    },
    /// A matrix was used with a scene whose receiver vertex count differs.
    #[error(
        "the visibility matrix has {matrix} rows but the scene has {scene} receiver vertices; \
         recompute instead of refining after a topology change"
    )]
    RowCountMismatch {
        /// Rows of the matrix.
        matrix: usize,
        /// Receiver vertices of the scene.
        scene: usize,
    },
    /// The radiance array does not have one entry per direction.
    #[error("{given} radiance values for {expected} directions; pass one I_j per direction")]
    RadianceCountMismatch {
        /// Entries given.
        given: usize,
        /// Directions of the matrix.
        expected: usize,
    },
    /// A matrix row index passed to [`crate::VisibilityEngine::compute_rows`] does not exist.
    #[error(
        "row {row} is out of range: the visibility matrix has {rows} rows; pass receiver rows < {rows}"
    )]
    RowOutOfRange {
        /// The offending row index.
        row: u32,
        /// Rows of the matrix.
        rows: usize,
    },
    /// An array given to the vertex filter or level controller has the wrong length.
    #[error("{what} has {given} entries but {expected} were expected; rebuild it for this scene")]
    SizeMismatch {
        /// Which array.
        what: &'static str,
        /// Entries given.
        given: usize,
        /// Entries expected.
        expected: usize,
    },
    /// A parameter of the vertex filter, camera or level controller is out of its range.
    #[error("{what} = {value} is invalid; it must be {expected}")]
    InvalidParameter {
        /// Which parameter.
        what: &'static str,
        /// The value given.
        value: f64,
        /// The valid range, in words.
        expected: &'static str,
    },
    /// A GPU backend was asked for without a device.
    #[error("backend {backend} needs a wgpu device and queue; use VisibilityEngine::with_gpu")]
    NoDevice {
        /// The backend's name.
        backend: &'static str,
    },
    /// A GPU parameter is outside what the device supports.
    #[error("{what} = {value} is outside 1..={maximum} on this device; lower it")]
    GpuLimit {
        /// Which parameter.
        what: &'static str,
        /// Requested value.
        value: u64,
        /// The device's maximum.
        maximum: u64,
    },
    /// The scene's BVH is deeper than the `rays` backend's shader can walk (its stack holds a
    /// fixed number of nodes; real meshes build trees 13–24 deep).
    #[error(
        "the scene's BVH is {depth} nodes deep and the rays backend walks at most {maximum}: \
         use the cpu backend (the same exact rays)"
    )]
    BvhTooDeep {
        /// Nodes on the tree's longest root-to-leaf path.
        depth: u64,
        /// The most the shader's stack holds.
        maximum: u64,
    },
    /// A GPU-resident result was asked of a backend that computes M on the CPU.
    #[error(
        "backend {backend} computes M on the CPU and has no GPU-resident result; use the depth \
         or query backend with VisibilityEngine::with_gpu"
    )]
    NotGpuResident {
        /// The backend's name.
        backend: &'static str,
    },
    /// Reading results back from the GPU failed.
    #[error("GPU read-back failed: {0}")]
    Readback(String),
    /// Light look-up failed (a rotation that cannot be normalised, a bad prefilter σ).
    #[error("lighting: {0}")]
    Lighting(#[from] lightsphere::LightsphereError),
}
