//! The crate's one error type.
//!
//! Every variant names the file (`path`), the element that is wrong (a vertex, a face, a header
//! line, a frame, a glTF accessor …) and the offending value, and its message says how to fix
//! the input. Text formats add the 1-based line number where it is known.

use std::path::PathBuf;

/// Formats an optional line number as `" (line N)"`, or nothing.
fn at_line(line: &Option<usize>) -> String {
    match line {
        Some(line) => format!(" (line {line})"),
        None => String::new(),
    }
}

/// Everything that can go wrong while reading or writing meshes, animations and arrays.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshIoError {
    /// The operating system refused to read or write a file.
    #[error("cannot {operation} {}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was attempted ("read", "write", "rename", "list").
        operation: &'static str,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },

    /// The file extension does not name a supported format.
    #[error(
        "{}: unsupported file type {extension:?}; {expected}. Convert the file or rename it \
         with the right extension",
        path.display()
    )]
    UnsupportedFormat {
        /// The file.
        path: PathBuf,
        /// Its extension (empty when there is none).
        extension: String,
        /// The formats accepted by the call.
        expected: &'static str,
    },

    /// A token could not be parsed as the number (or keyword) the format requires.
    #[error(
        "{}{}: malformed {element}: {token:?} is not {expected}; fix or re-export the file",
        path.display(), at_line(line)
    )]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number (text formats).
        line: Option<usize>,
        /// What was being read, e.g. `"vertex 12 property y"`.
        element: String,
        /// The offending token (truncated to 64 bytes).
        token: String,
        /// What the token should have been, e.g. `"a float"`.
        expected: &'static str,
    },

    /// A PLY or .npy header is malformed or describes something unsupported.
    #[error("{}{}: invalid header: {message}", path.display(), at_line(line))]
    InvalidHeader {
        /// The file.
        path: PathBuf,
        /// 1-based header line number, when known.
        line: Option<usize>,
        /// What is wrong and how to fix it.
        message: String,
    },

    /// A coordinate (position, normal or texture coordinate) is NaN or infinite.
    #[error(
        "{}{}: {element} has a non-finite {component} = {value}; positions, normals and texture \
         coordinates must be finite. Repair the exporter or remove the vertex",
        path.display(), at_line(line)
    )]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// 1-based line number (text formats).
        line: Option<usize>,
        /// The element, e.g. `"vertex 17"` or `"frame 3 vertex 17"`.
        element: String,
        /// The component, e.g. `"x"` or `"normal y"`.
        component: &'static str,
        /// The offending value.
        value: f64,
    },

    /// A face, strip or primitive refers to a vertex that does not exist.
    #[error(
        "{}{}: {element} has index {index} (as written in the file), but only {vertex_count} \
         are defined; the file is corrupt or was cut",
        path.display(), at_line(line)
    )]
    IndexOutOfRange {
        /// The file.
        path: PathBuf,
        /// 1-based line number (text formats).
        line: Option<usize>,
        /// The element, e.g. `"face 12"` or `"tristrip 0 entry 5"`.
        element: String,
        /// The index as written in the file (OBJ: 1-based or negative).
        index: i64,
        /// Number of vertices (or OBJ texture coordinates / normals) available.
        vertex_count: usize,
    },

    /// A face lists fewer than three vertices.
    #[error(
        "{}{}: {element} has {corners} vertex indices; a face needs at least 3. Remove the face",
        path.display(), at_line(line)
    )]
    ShortFace {
        /// The file.
        path: PathBuf,
        /// 1-based line number (text formats).
        line: Option<usize>,
        /// The face, e.g. `"face 7"`.
        element: String,
        /// How many indices it has.
        corners: usize,
    },

    /// The file has no vertices or no triangles.
    #[error("{}: empty mesh: {what}; a mesh needs at least one vertex and one triangle", path.display())]
    EmptyMesh {
        /// The file.
        path: PathBuf,
        /// What is missing.
        what: String,
    },

    /// A header declares more elements than the file can possibly hold.
    #[error(
        "{}: {element} declares {count} entries, which need at least {bytes_needed} bytes, but \
         only {bytes_available} bytes follow the header; the header is corrupt or the file is \
         truncated",
        path.display()
    )]
    CountTooLarge {
        /// The file.
        path: PathBuf,
        /// The element, e.g. `"element vertex"`.
        element: String,
        /// The declared count.
        count: u64,
        /// Minimum bytes the declared count needs (saturated at `u64::MAX`).
        bytes_needed: u64,
        /// Bytes actually available.
        bytes_available: u64,
    },

    /// Binary data ends before the declared content does.
    #[error(
        "{}: truncated data: {element} needs {bytes_needed} bytes at offset {offset}, but the \
         file has {file_len} bytes; the file was cut, re-download or re-export it",
        path.display()
    )]
    Truncated {
        /// The file.
        path: PathBuf,
        /// What was being read.
        element: String,
        /// Byte offset where reading started.
        offset: u64,
        /// Bytes needed from `offset`.
        bytes_needed: u64,
        /// Length of the file (or buffer).
        file_len: u64,
    },

    /// A text file ends before the declared content does.
    #[error(
        "{}{}: unexpected end of file while reading {element}; the file is truncated",
        path.display(), at_line(line)
    )]
    UnexpectedEof {
        /// The file.
        path: PathBuf,
        /// Line number of the end of the file.
        line: Option<usize>,
        /// What was being read.
        element: String,
    },

    /// A frame of an animation has a different vertex or triangle count than frame 0.
    #[error(
        "{}: frame {frame} ({}) has {found} {what}, but frame 0 ({}) has {expected}; all frames \
         of an animation must share one topology",
        path.display(), file.display(), first_file.display()
    )]
    FrameCountMismatch {
        /// The folder (or file) of the animation.
        path: PathBuf,
        /// 0-based frame index (in numeric order).
        frame: usize,
        /// The offending frame's file.
        file: PathBuf,
        /// Frame 0's file.
        first_file: PathBuf,
        /// `"vertices"` or `"triangles"`.
        what: &'static str,
        /// Frame 0's count.
        expected: usize,
        /// The offending frame's count.
        found: usize,
    },

    /// A frame of an animation has a different face list than frame 0.
    #[error(
        "{}: frame {frame} ({}) has triangle {triangle} = {found:?}, but frame 0 has {expected:?}; \
         all frames of an animation must share one face list",
        path.display(), file.display()
    )]
    FrameTopologyMismatch {
        /// The folder of the animation.
        path: PathBuf,
        /// 0-based frame index.
        frame: usize,
        /// The offending frame's file.
        file: PathBuf,
        /// First differing triangle.
        triangle: usize,
        /// Frame 0's triangle.
        expected: [u32; 3],
        /// The offending frame's triangle.
        found: [u32; 3],
    },

    /// A folder of numbered frames cannot be ordered or is empty.
    #[error("{}: frame folder: {message}", path.display())]
    FrameFolder {
        /// The folder.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },

    /// A glTF document is invalid or uses something this crate does not read.
    #[error("{}: glTF {element}: {message}", path.display())]
    Gltf {
        /// The file.
        path: PathBuf,
        /// The glTF object, e.g. `"accessor 3"` or `"mesh 0 primitive 2"`.
        element: String,
        /// What is wrong and how to fix it.
        message: String,
    },

    /// A `.npy` array has an unexpected shape or type for the request.
    #[error("{}: .npy array: {message}", path.display())]
    Npy {
        /// The file.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },

    /// The topology mesh given for a `.npy` animation does not match its vertex count.
    #[error(
        "{}: the topology mesh {} has {topology_vertices} vertices, but the animation has \
         {animation_vertices} per frame; pass the mesh the positions were exported from",
        path.display(), topology.display()
    )]
    TopologyMismatch {
        /// The animation file.
        path: PathBuf,
        /// The topology file.
        topology: PathBuf,
        /// Vertices in the topology mesh.
        topology_vertices: usize,
        /// Vertices per animation frame.
        animation_vertices: usize,
    },

    /// `write_npy_f32` was given a shape whose element count differs from the data length.
    #[error(
        "{}: cannot write .npy: shape {shape:?} holds {expected:?} values but {actual} were given \
         (None = the product overflows)",
        path.display()
    )]
    ShapeMismatch {
        /// The target file.
        path: PathBuf,
        /// The requested shape.
        shape: Vec<usize>,
        /// Product of the shape, `None` when it overflows `usize`.
        expected: Option<usize>,
        /// Length of the data.
        actual: usize,
    },

    /// Data given to a writer ([`crate::write_glb`], [`crate::write_glb_animation`]) is
    /// inconsistent or not representable; nothing was written.
    #[error("{}: cannot write {element}: {problem}; nothing was written", path.display())]
    InvalidWriteInput {
        /// The target file.
        path: PathBuf,
        /// What is wrong, e.g. `"triangle 3"`, `"COLOR_0 of vertex 7"`, `"attribute \"AO\""`.
        element: String,
        /// The offending value and how to fix it.
        problem: String,
    },

    /// An option has a value the loader cannot use.
    #[error("{}: option {option} = {value} is invalid: {message}", path.display())]
    InvalidOption {
        /// The file being loaded.
        path: PathBuf,
        /// The option's name, e.g. `"frame_rate"`.
        option: &'static str,
        /// Its value.
        value: String,
        /// Why it is invalid and what to use instead.
        message: String,
    },
}

impl MeshIoError {
    /// Wraps an I/O error with the path and the attempted operation.
    pub(crate) fn io(
        path: &std::path::Path,
        operation: &'static str,
        source: std::io::Error,
    ) -> Self {
        Self::Io {
            path: path.to_path_buf(),
            operation,
            source,
        }
    }
}

/// Shortens a token for an error message (at most 64 bytes, lossy UTF-8).
pub(crate) fn token_text(token: &[u8]) -> String {
    const MAX_TOKEN_BYTES: usize = 64;
    let cut = &token[..token.len().min(MAX_TOKEN_BYTES)];
    let mut text = String::from_utf8_lossy(cut).into_owned();
    if token.len() > MAX_TOKEN_BYTES {
        text.push('…');
    }
    text
}

/// Atomic writes ([`atomic_out`], the workspace's one temp + rename) fail as [`MeshIoError::Io`]
/// naming the target and the step (`create`, `write`, `sync`, `rename a temporary file onto`).
impl From<atomic_out::WriteError> for MeshIoError {
    fn from(e: atomic_out::WriteError) -> Self {
        Self::io(&e.path, e.op, e.source)
    }
}
