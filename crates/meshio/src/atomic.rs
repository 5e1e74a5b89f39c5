//! Atomic file output through the workspace's one implementation, [`atomic_out`] (temporary
//! file beside the target, then rename; DESIGN.md, "Conventions"), with its errors as
//! [`MeshIoError::Io`].

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::MeshIoError;

impl From<atomic_out::WriteError> for MeshIoError {
    fn from(e: atomic_out::WriteError) -> Self {
        Self::io(&e.path, e.op, e.source)
    }
}

/// Writes `path` atomically with [`atomic_out::write_with`], returning its error as a
/// [`MeshIoError`]. Kept for callers that return `MeshIoError`; new code calls `atomic_out`.
///
/// # Errors
/// [`MeshIoError::Io`] naming `path` and the step that failed (`create`, `write`, `sync`,
/// `rename a temporary file onto`); `path` is then untouched and no temporary file is left.
///
/// # Examples
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("hello.txt");
/// meshio::write_atomic(&path, |w| w.write_all(b"hello")).unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// ```
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), MeshIoError> {
    Ok(atomic_out::write_with(path, write)?)
}
