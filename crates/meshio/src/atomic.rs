//! Atomic file output: write a temporary file beside the target, then rename it over the
//! target, so that a reader never sees a half-written file and a failed write leaves no partial
//! output (DESIGN.md, "Conventions").

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::MeshIoError;

/// Distinguishes temporary files of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `path` atomically: `write` fills a temporary file in the same folder, which is
/// flushed, synced and renamed over `path`. On any error the temporary file is removed and
/// `path` is left untouched.
///
/// # Errors
/// [`MeshIoError::Io`] naming the temporary file or the target.
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
    let temp = temp_path(path);
    let result = (|| {
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temp)
            .map_err(|e| MeshIoError::io(&temp, "create", e))?;
        let mut writer = BufWriter::new(file);
        write(&mut writer).map_err(|e| MeshIoError::io(&temp, "write", e))?;
        writer
            .flush()
            .map_err(|e| MeshIoError::io(&temp, "write", e))?;
        let file = writer
            .into_inner()
            .map_err(|e| MeshIoError::io(&temp, "write", e.into_error()))?;
        file.sync_all()
            .map_err(|e| MeshIoError::io(&temp, "sync", e))?;
        std::fs::rename(&temp, path)
            .map_err(|e| MeshIoError::io(path, "rename a temporary file onto", e))
    })();
    if result.is_err() {
        // Best effort: the temporary file may not exist (creation failed).
        let _ = std::fs::remove_file(&temp);
    }
    result
}

/// `.<name>.<pid>.<n>.tmp` beside `path`.
fn temp_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let temp_name = format!(".{name}.{}.{n}.tmp", std::process::id());
    match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.join(temp_name),
        _ => PathBuf::from(temp_name),
    }
}
