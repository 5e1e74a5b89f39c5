//! The temporary file of one write, and the process-wide registry of those that exist, which
//! the signal handler ([`crate::remove_temporaries_on_signal`]) empties.

use std::ffi::{OsStr, OsString};
use std::fs::File;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Distinguishes the temporary files of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Every temporary file that exists now (a handful at most: one per writing thread).
static REGISTRY: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The registry, even if a thread panicked while holding it (a `Vec` push or removal cannot
/// leave it inconsistent).
pub(crate) fn registry() -> MutexGuard<'static, Vec<PathBuf>> {
    REGISTRY.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The temporary files of atomic writes in progress in this process, oldest first.
///
/// For diagnostics, tests, and programs with their own SIGINT/SIGTERM handler, which should
/// remove these files before exiting (as [`crate::remove_temporaries_on_signal`]'s does).
pub fn registered_temporaries() -> Vec<PathBuf> {
    registry().clone()
}

/// The temporary file of one write: registered while it exists, removed on drop unless it was
/// renamed onto the target. Dropping during a panic's unwinding removes it too.
pub(crate) struct Temporary {
    path: PathBuf,
    renamed: bool,
}

impl Temporary {
    /// Creates the empty temporary file for `target` with `create_new` and registers it. The
    /// file is created while the registry is locked, so the signal handler, which removes
    /// files under the same lock, never misses one created just after its sweep.
    ///
    /// A `target` without a file name (`/`, `out/..`) is an `InvalidInput` error.
    pub(crate) fn create(target: &Path) -> std::io::Result<(Self, File)> {
        let Some(name) = target.file_name() else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the path names a folder, not a file; give a file name",
            ));
        };
        let path = temporary_path(target, name);
        let mut registry = registry();
        let file = File::options().write(true).create_new(true).open(&path)?;
        registry.push(path.clone());
        Ok((
            Self {
                path,
                renamed: false,
            },
            file,
        ))
    }

    /// The temporary file's path.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the temporary file onto `target`; on error it stays, to be removed on drop.
    pub(crate) fn rename_onto(mut self, target: &Path) -> std::io::Result<()> {
        std::fs::rename(&self.path, target)?;
        self.renamed = true;
        Ok(())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.renamed {
            // Best effort: the file may already be gone (removed by the caller's closure).
            let _ = std::fs::remove_file(&self.path);
        }
        deregister(&self.path);
    }
}

/// Removes `path` from the registry (a temporary file or folder that is gone or in place).
pub(crate) fn deregister(path: &Path) {
    let mut registry = registry();
    if let Some(i) = registry.iter().position(|p| p == path) {
        registry.swap_remove(i);
    }
}

/// `.<name>.<pid>.<n>.tmp` beside `target`, whose file name is `name`.
fn temporary_path(target: &Path, name: &OsStr) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut temporary = OsString::from(".");
    temporary.push(name);
    temporary.push(format!(".{}.{n}.tmp", std::process::id()));
    match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent.join(temporary),
        _ => PathBuf::from(temporary),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn temporary_names_are_hidden_beside_the_target_and_distinct() {
        let target = Path::new("out/frame.png");
        let a = temporary_path(target, target.file_name().unwrap());
        let b = temporary_path(target, target.file_name().unwrap());
        assert_ne!(a, b);
        assert_eq!(a.parent(), Some(Path::new("out")));
        let name = a.file_name().unwrap().to_str().unwrap();
        assert!(
            name.starts_with(".frame.png.") && name.ends_with(".tmp"),
            "{name}"
        );
        assert!(
            name.contains(&format!(".{}.", std::process::id())),
            "{name}"
        );
    }

    #[test]
    fn a_bare_file_name_gets_a_temporary_in_the_current_folder() {
        let t = temporary_path(Path::new("report.json"), OsStr::new("report.json"));
        assert_eq!(t.parent(), Some(Path::new("")));
    }

    #[test]
    fn a_path_without_a_file_name_is_invalid_input() {
        for target in ["/", "out/..", ""] {
            let err = Temporary::create(Path::new(target)).err().unwrap();
            assert_eq!(err.kind(), std::io::ErrorKind::InvalidInput, "{target}");
        }
    }

    #[test]
    fn dropping_an_unrenamed_temporary_removes_and_deregisters_it() {
        let dir = tempfile::tempdir().unwrap();
        let (temporary, file) = Temporary::create(&dir.path().join("x")).unwrap();
        drop(file);
        let path = temporary.path().to_path_buf();
        assert!(path.exists());
        assert!(registered_temporaries().contains(&path));
        drop(temporary);
        assert!(!path.exists());
        assert!(!registered_temporaries().contains(&path));
    }
}
