//! The crate's error type.

use std::path::PathBuf;

use clustering::ClusteringError;

/// Boxed error of an image decoder or encoder.
pub type CodecError = Box<dyn std::error::Error + Send + Sync + 'static>;

/// Everything that can go wrong in `btf`.
///
/// Each variant names the file (or the call), the element and the value, and its message says
/// how to fix the input.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BtfError {
    /// An operating-system I/O call failed.
    #[error("cannot {action} {path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was attempted ("read", "list", "create", "rename a temporary file onto", …).
        action: &'static str,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file has an image extension but its name does not follow the UBO2003 pattern.
    #[error(
        "{path}: the file name is not a BTF image name ({reason}); name light/view images \
         `tl{{θl:03}} pl{{φl:03}} tv{{θv:03}} pv{{φv:03}}.png` (jpg, jpeg, exr; `_` may replace \
         the spaces) or move the file out of the folder"
    )]
    BadFileName {
        /// The offending file.
        path: PathBuf,
        /// What is wrong with the name.
        reason: &'static str,
    },
    /// A file's θ is in neither sampling of Table 5.1, or the files mix both samplings.
    #[error(
        "{path}: {role} θ = {theta}° does not fit the sampling ({reason}); a UBO2003 BTF uses \
         θ ∈ {{0, 17, 34, 51, 68, 85}} (H1) or {{0, 15, 30, 45, 60, 75}} (H2) throughout"
    )]
    UnknownSampling {
        /// The first file whose θ does not fit.
        path: PathBuf,
        /// "light" or "view".
        role: &'static str,
        /// The θ found, in degrees.
        theta: u32,
        /// Why it does not fit.
        reason: &'static str,
    },
    /// A file's (θ, φ) is not one of the 81 measured directions of the sampling.
    #[error(
        "{path}: {role} direction (θ = {theta}°, φ = {phi}°) is not a measured direction of \
         sampling {sampling}; φ must be a multiple of the ring's Δφ (Table 5.1)"
    )]
    NotADirection {
        /// The offending file.
        path: PathBuf,
        /// "light" or "view".
        role: &'static str,
        /// θ in degrees.
        theta: u32,
        /// φ in degrees.
        phi: u32,
        /// The sampling the folder was found to use ("H1" or "H2").
        sampling: &'static str,
    },
    /// Two files name the same (view, light) pair.
    #[error(
        "{second}: view {view}, light {light} is already given by {first}; keep one of the two \
         files"
    )]
    DuplicateImage {
        /// The file seen first.
        first: PathBuf,
        /// The file seen second.
        second: PathBuf,
        /// View index (0..81).
        view: usize,
        /// Light index (0..81).
        light: usize,
    },
    /// A (view, light) pair has no file.
    #[error(
        "{dir}: {missing} of the 81 × 81 images are missing, the first is `{expected}` (view \
         {view}, light {light}); a BTF folder needs every pair of Table 5.1's directions"
    )]
    MissingImage {
        /// The BTF folder.
        dir: PathBuf,
        /// The expected file name of the first missing pair.
        expected: String,
        /// View index of the first missing pair.
        view: usize,
        /// Light index of the first missing pair.
        light: usize,
        /// How many pairs are missing.
        missing: usize,
    },
    /// A folder holds no BTF image at all.
    #[error("{dir}: no BTF image (`tl… pl… tv… pv….png|jpg|jpeg|exr`) found")]
    EmptyDir {
        /// The folder.
        dir: PathBuf,
    },
    /// An image header claims a size the resource policy refuses: larger than
    /// [`MAX_NORMTEXTURE_SIDE`](crate::MAX_NORMTEXTURE_SIDE), or (PNG) more pixels than its
    /// compressed bytes can hold.
    #[error("{path}: the header claims {width} × {height} pixels; {reason}")]
    ImageTooLarge {
        /// The file.
        path: PathBuf,
        /// Width from the header.
        width: usize,
        /// Height from the header.
        height: usize,
        /// Which limit and why.
        reason: String,
    },
    /// Images of one BTF differ in size.
    #[error(
        "{path}: the image is {found_w} × {found_h} but {reference} is {expected_w} × \
         {expected_h}; all normtextures of a BTF must have the same size"
    )]
    SizeMismatch {
        /// The offending file.
        path: PathBuf,
        /// The file whose size is taken as the reference.
        reference: PathBuf,
        /// Reference width.
        expected_w: usize,
        /// Reference height.
        expected_h: usize,
        /// Width found.
        found_w: usize,
        /// Height found.
        found_h: usize,
    },
    /// An image file could not be decoded (or encoded).
    #[error("{path}: cannot {action} the image: {source}")]
    Codec {
        /// The file.
        path: PathBuf,
        /// "decode", "read the header of" or "encode".
        action: &'static str,
        /// The codec's error.
        source: CodecError,
    },
    /// A parameter or argument is out of range.
    #[error("{what}: `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// The call.
        what: &'static str,
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: String,
        /// What is allowed.
        reason: &'static str,
    },
    /// An index is out of range.
    #[error("{what}: index {index} is out of range (there are {len}); pass an index below {len}")]
    IndexOutOfRange {
        /// What was indexed ("view slot", "light", "component", …).
        what: &'static str,
        /// The index given.
        index: usize,
        /// The number of elements.
        len: usize,
    },
    /// A buffer has the wrong length.
    #[error("{what}: expected {expected} values but got {found}; {hint}")]
    LengthMismatch {
        /// The buffer.
        what: &'static str,
        /// The length required.
        expected: usize,
        /// The length given.
        found: usize,
        /// How to fix it.
        hint: &'static str,
    },
    /// A value is NaN or infinite.
    #[error(
        "{what}: value {index} is {value}; BTF radiance must be finite (clamp or remove NaN/∞ \
         before compressing)"
    )]
    NonFinite {
        /// The buffer.
        what: String,
        /// Index of the value.
        index: usize,
        /// The value.
        value: f32,
    },
    /// The per-view PCA failed.
    #[error("view slot {view}: PCA failed: {source}")]
    Pca {
        /// The view slot.
        view: usize,
        /// The error of `clustering`.
        source: ClusteringError,
    },
    /// A `.btfpca` file is malformed.
    #[error(
        "{path}: invalid .btfpca file: field `{field}` = {value}: {reason}; the file is \
         truncated, corrupt or not a .btfpca file — write it again with BtfPca::write"
    )]
    Format {
        /// The file (`<bytes>` when reading from memory).
        path: PathBuf,
        /// The field.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// A `.finpca` file (a compressed fin BTF, [`crate::fin_pca`]) is malformed.
    #[error(
        "{path}: invalid .finpca file: field `{field}` = {value}: {reason}; the file is \
         truncated, corrupt or not a .finpca file — write it again with \
         `cloth-vis btf fins compress`"
    )]
    FinFormat {
        /// The file (`<bytes>` when reading from memory).
        path: PathBuf,
        /// The field.
        field: &'static str,
        /// Its value.
        value: String,
        /// What is wrong.
        reason: &'static str,
    },
    /// A fin BTF folder lacks light images or has an image of another view.
    #[error(
        "{dir}: {problem}; a fin BTF folder holds the 81 light directions of Table 5.3 \
         (θ ∈ {{0, 15, 30, 45, 60, 75}}) at the one grazing view, named \
         `tl{{θl:03}} pl{{φl:03}} tv090 pv000.png` (jpg, jpeg, exr), e.g. `{example}`"
    )]
    FinDir {
        /// The folder (or the offending file).
        dir: PathBuf,
        /// What is wrong.
        problem: String,
        /// A name the folder should hold.
        example: String,
    },
    /// A GPU resource would exceed a limit of the device (`render::GpuBtfRenderer`).
    #[error("{what}: needs {value} but the device limit `{limit}` is {maximum}; {hint}")]
    GpuLimit {
        /// The resource, e.g. `"eigen-normtexture layers"`.
        what: &'static str,
        /// The `wgpu::Limits` field that is exceeded.
        limit: &'static str,
        /// What the resource needs.
        value: u64,
        /// The device's limit.
        maximum: u64,
        /// How to fix it.
        hint: &'static str,
    },
    /// Reading a GPU result back failed (the device was lost or the mapping failed).
    #[error("{what}: reading the GPU result back failed: {reason}; check the GPU driver")]
    GpuReadback {
        /// The call that read back.
        what: &'static str,
        /// The error reported by wgpu.
        reason: String,
    },
}

/// The crate's result type.
pub type Result<T, E = BtfError> = std::result::Result<T, E>;

/// A failed atomic write is a [`BtfError::Io`] naming the target and the step.
impl From<atomic_out::WriteError> for BtfError {
    fn from(e: atomic_out::WriteError) -> Self {
        Self::io(e.path, e.op, e.source)
    }
}

impl BtfError {
    pub(crate) fn io(
        path: impl Into<PathBuf>,
        action: &'static str,
        source: std::io::Error,
    ) -> Self {
        Self::Io {
            path: path.into(),
            action,
            source,
        }
    }

    pub(crate) fn codec(
        path: impl Into<PathBuf>,
        action: &'static str,
        source: impl Into<CodecError>,
    ) -> Self {
        Self::Codec {
            path: path.into(),
            action,
            source: source.into(),
        }
    }
}

impl From<::render::CameraError> for BtfError {
    fn from(e: ::render::CameraError) -> Self {
        BtfError::InvalidParameter {
            what: "Camera",
            name: e.name,
            value: e.value,
            reason: e.reason,
        }
    }
}
