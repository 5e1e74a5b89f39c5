//! Missing parent folders of a target: every writer creates them (`--out renders/a/b.png`
//! works whether or not `renders/a` exists), and a write that fails or is interrupted removes
//! the ones it created, so an error leaves the file system as it was.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// Folders created for writes still under way, innermost last: the signal handler removes
/// them (each only if empty) after the temporaries inside them.
static CREATED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

pub(crate) fn created() -> MutexGuard<'static, Vec<PathBuf>> {
    CREATED.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The folders one write created for its target, removed on drop unless [`Self::keep`] was
/// called (the target is in place).
pub(crate) struct CreatedParents {
    /// Outermost first.
    dirs: Vec<PathBuf>,
}

impl CreatedParents {
    /// Creates every missing ancestor folder of `target` (outermost first) and records it.
    ///
    /// # Errors
    /// The first folder that cannot be created (folders created before it are removed again),
    /// or an ancestor that exists and is not a folder.
    pub(crate) fn create(target: &Path) -> std::io::Result<Self> {
        let mut missing = Vec::new();
        let mut dir = target.parent();
        while let Some(d) = dir.filter(|d| !d.as_os_str().is_empty()) {
            match std::fs::metadata(d) {
                Ok(m) if m.is_dir() => break,
                Ok(_) => {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::NotADirectory,
                        format!("{} exists and is not a folder", d.display()),
                    ));
                }
                // Below a file (`NotADirectory`): the walk up finds the file and refuses it.
                Err(e)
                    if matches!(
                        e.kind(),
                        std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory
                    ) =>
                {
                    missing.push(d.to_owned());
                }
                Err(e) => return Err(e),
            }
            dir = d.parent();
        }
        missing.reverse();
        let mut parents = Self { dirs: Vec::new() };
        for d in missing {
            let mut registry = created();
            match std::fs::create_dir(&d) {
                Ok(()) => {
                    registry.push(d.clone());
                    parents.dirs.push(d);
                }
                // Another writer created it a moment ago: it is theirs.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {}
                Err(e) => {
                    return Err(std::io::Error::new(
                        e.kind(),
                        format!("cannot create the folder {}: {e}", d.display()),
                    ));
                }
            }
        }
        Ok(parents)
    }

    /// The target is in place: the folders stay.
    pub(crate) fn keep(mut self) {
        let dirs = std::mem::take(&mut self.dirs);
        let mut registry = created();
        registry.retain(|p| !dirs.contains(p));
    }
}

impl Drop for CreatedParents {
    fn drop(&mut self) {
        let mut registry = created();
        for d in self.dirs.iter().rev() {
            // Only if empty: another write may have put its finished file there meanwhile.
            let _ = std::fs::remove_dir(d);
            registry.retain(|p| p != d);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn creates_the_missing_chain_and_removes_it_unless_kept() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("a/b/c/out.png");
        let parents = CreatedParents::create(&target).unwrap();
        assert!(dir.path().join("a/b/c").is_dir());
        assert_eq!(
            created()
                .iter()
                .filter(|p| p.starts_with(dir.path()))
                .count(),
            3
        );
        drop(parents);
        assert!(!dir.path().join("a").exists());
        assert!(created().iter().all(|p| !p.starts_with(dir.path())));

        CreatedParents::create(&target).unwrap().keep();
        assert!(dir.path().join("a/b/c").is_dir());
        assert!(created().iter().all(|p| !p.starts_with(dir.path())));
    }

    #[test]
    fn a_file_in_the_way_is_an_error_and_nothing_is_created() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("f"), b"x").unwrap();
        let err = CreatedParents::create(&dir.path().join("f/g/out.png"))
            .err()
            .unwrap();
        assert_eq!(err.kind(), std::io::ErrorKind::NotADirectory);
        assert!(err.to_string().contains("is not a folder"), "{err}");
        assert!(!dir.path().join("f/g").exists());
    }

    #[test]
    fn a_folder_that_holds_a_file_by_then_is_left() {
        let dir = tempfile::tempdir().unwrap();
        let parents = CreatedParents::create(&dir.path().join("a/out.png")).unwrap();
        std::fs::write(dir.path().join("a/other.png"), b"x").unwrap();
        drop(parents);
        assert!(dir.path().join("a/other.png").is_file());
    }
}
