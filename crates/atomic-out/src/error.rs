//! The two error types: a failed step of the write itself ([`WriteError`]) and, for
//! [`crate::write_via_path`], either that or the caller's encoder error ([`AtomicError`]).

use std::fmt;
use std::path::PathBuf;

/// A step of an atomic write failed; the target was left untouched and the temporary file was
/// removed.
///
/// Displays as `cannot {op} {path}: {source}`, e.g. `cannot create out/demo.png: No such file
/// or directory (os error 2)` — create the folder first; `cannot rename a temporary file onto
/// out/demo.png: Is a directory` — the target path names a folder.
#[derive(Debug)]
pub struct WriteError {
    /// The target file (not the temporary file, which no longer exists).
    pub path: PathBuf,
    /// The step that failed: `"create"` (the temporary file beside the target), `"write"`,
    /// `"sync"` or `"rename a temporary file onto"`.
    pub op: &'static str,
    /// The operating system's error.
    pub source: std::io::Error,
}

impl WriteError {
    pub(crate) fn new(path: &std::path::Path, op: &'static str, source: std::io::Error) -> Self {
        Self {
            path: path.to_path_buf(),
            op,
            source,
        }
    }
}

impl fmt::Display for WriteError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot {} {}: {}",
            self.op,
            self.path.display(),
            self.source
        )
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}

/// The error of [`crate::write_via_path`]: the atomic write failed, or the caller's writer did.
/// Either way the target was left untouched and the temporary file was removed.
#[derive(Debug)]
pub enum AtomicError<E> {
    /// Creating, syncing or renaming the temporary file failed.
    File(WriteError),
    /// The caller's closure returned this error, unchanged, so the caller keeps its own message.
    Writer(E),
}

impl<E: fmt::Display> fmt::Display for AtomicError<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::File(e) => e.fmt(f),
            Self::Writer(e) => e.fmt(f),
        }
    }
}

/// Transparent: it displays as the inner error, so its source is the inner error's source.
impl<E: std::error::Error + 'static> std::error::Error for AtomicError<E> {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::File(e) => std::error::Error::source(e),
            Self::Writer(e) => e.source(),
        }
    }
}

impl<E> From<WriteError> for AtomicError<E> {
    fn from(e: WriteError) -> Self {
        Self::File(e)
    }
}

/// [`crate::remove_temporaries_on_signal`] could not install its handler, usually because the
/// program already installed a SIGINT/SIGTERM handler of its own (through `ctrlc`). Such a
/// program should remove the temporary files from its own handler: see
/// [`crate::registered_temporaries`].
#[derive(Debug)]
pub struct SignalError {
    source: ctrlc::Error,
}

impl SignalError {
    pub(crate) fn new(source: ctrlc::Error) -> Self {
        Self { source }
    }
}

impl fmt::Display for SignalError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "cannot install the SIGINT/SIGTERM handler that removes temporary files: {}; \
             if the program has its own handler, remove atomic_out::registered_temporaries() \
             from it instead",
            self.source
        )
    }
}

impl std::error::Error for SignalError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.source)
    }
}
