//! The facade's error type.

use std::path::PathBuf;

/// Everything a scene run can fail with. Messages name the file, the element and the value.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene text is malformed or a value is out of range.
    #[error("scene {origin}: {message}")]
    Scene {
        /// Scene file (or `embedded demo scene`).
        origin: String,
        /// What is wrong, with the key and value.
        message: String,
    },
    /// A command's request cannot be carried out (bad option value for this input).
    #[error("{path}: {message}")]
    Request {
        /// The file or folder concerned.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {reason}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A mesh or animation could not be loaded.
    #[error(transparent)]
    Mesh(#[from] meshio::MeshIoError),
    /// An environment or lightsphere problem.
    #[error(transparent)]
    Light(#[from] lightsphere::LightsphereError),
    /// The visibility engine failed.
    #[error(transparent)]
    Visibility(#[from] occlusion_gpu::OcclusionError),
    /// A visibility-map model, build or look-up failed (static self-shadowing).
    #[error(transparent)]
    Hemicube(#[from] hemicube::HemicubeError),
    /// A BTF folder or `.btfpca` file is invalid, or BTF compression failed (the message
    /// names the file and element).
    /// (Boxed: `BtfError` is large, and every `Result` of the facade would carry its size.)
    #[error(transparent)]
    Btf(Box<btf::BtfError>),
    /// Procedural data could not be made.
    #[error(transparent)]
    Synth(#[from] synth::SynthError),
    /// GPU acquisition, rendering or image output failed.
    #[error(transparent)]
    Gpu(#[from] gpu_context::GpuError),
    /// A chart or strip could not be drawn or written.
    #[error(transparent)]
    Figure(#[from] figures::FigureError),
    /// The renderer refused a frame (camera, mesh, target).
    #[error(transparent)]
    Render(#[from] render::RenderError),
    /// An object's frame index is outside its animation.
    #[error(
        "scene {origin}: {key}: frame {frame} is outside the animation's {count} frames (use 0..{count} or -1 for the last)"
    )]
    Frame {
        /// Where the scene came from (file path or "embedded demo").
        origin: String,
        /// The scene key, `object[i] (name).frame`.
        key: String,
        /// Requested frame.
        frame: i64,
        /// Frames available.
        count: usize,
    },
}

impl From<btf::BtfError> for Error {
    fn from(e: btf::BtfError) -> Self {
        Self::Btf(Box::new(e))
    }
}

impl From<atomic_out::WriteError> for Error {
    fn from(e: atomic_out::WriteError) -> Self {
        Self::Io {
            reason: format!("cannot {} it: {}", e.op, e.source),
            path: e.path,
        }
    }
}

/// A folder output ([`atomic_out::write_dir`]) whose filling returned our own error.
impl From<atomic_out::AtomicError<Error>> for Error {
    fn from(e: atomic_out::AtomicError<Error>) -> Self {
        match e {
            atomic_out::AtomicError::Writer(e) => e,
            atomic_out::AtomicError::File(e) => e.into(),
        }
    }
}
