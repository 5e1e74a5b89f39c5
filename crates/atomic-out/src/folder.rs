//! Folder outputs (numbered frames, BTF image sets): built in a hidden temporary folder beside
//! the target and renamed into place, so a folder appears complete or not at all.

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{AtomicError, WriteError};
use crate::parents::CreatedParents;
use crate::temporary::{deregister, registry};

/// Distinguishes the temporary folders of concurrent writes within one process.
static COUNTER: AtomicU64 = AtomicU64::new(0);

/// What to do when the target folder exists and holds files.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExistingFolder {
    /// Refuse before any work (the default of every command): old frames beside new ones, or
    /// a shorter clip overwriting the start of a longer one, would look valid.
    Refuse,
    /// Replace it with the new folder once the new one is complete (`--force`).
    Replace,
}

/// Fills a new folder through `fill` and moves it to `target` when `fill` succeeds.
///
/// `fill` receives a temporary folder `.NAME.partial-PID-N` beside `target` (created, empty,
/// registered so that the signal handler of [`crate::remove_temporaries_on_signal`] removes it
/// on SIGINT/SIGTERM). On success it is renamed to `target`: an empty existing `target` gives
/// way; a non-empty one is refused before `fill` runs, or with [`ExistingFolder::Replace`]
/// moved aside, replaced, and removed. Missing parent folders of `target` are created first.
/// On error or panic in `fill` the temporary folder and the parents this call created are
/// removed and `target` is untouched.
///
/// # Errors
/// [`AtomicError::File`] when `target` exists and is not an empty folder (with
/// [`ExistingFolder::Refuse`]), names no folder, or creating/renaming fails;
/// [`AtomicError::Writer`] with `fill`'s error.
///
/// # Examples
/// ```
/// use atomic_out::{ExistingFolder, write_dir};
/// let dir = tempfile::tempdir()?;
/// let frames = dir.path().join("frames");
/// write_dir(&frames, ExistingFolder::Refuse, |tmp| {
///     std::fs::write(tmp.join("frame_00000.obj"), "v 0 0 0\n")
/// })?;
/// assert!(frames.join("frame_00000.obj").is_file());
/// // A second run into the same folder is refused: its old frames would mix with new ones.
/// assert!(write_dir(&frames, ExistingFolder::Refuse, |_| Ok::<(), std::io::Error>(())).is_err());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_dir<E>(
    target: &Path,
    existing: ExistingFolder,
    fill: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), AtomicError<E>> {
    let fail = |op: &'static str| move |e| AtomicError::File(WriteError::new(target, op, e));
    let occupied = match std::fs::read_dir(target) {
        Ok(mut entries) => entries.next().is_some(),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
        Err(e) if target.exists() => {
            // A file, or an unreadable folder.
            return Err(fail("use as an output folder")(std::io::Error::new(
                e.kind(),
                format!("exists and is not a readable folder ({e})"),
            )));
        }
        Err(e) => return Err(fail("list")(e)),
    };
    if occupied && existing == ExistingFolder::Refuse {
        return Err(fail("write into")(std::io::Error::new(
            std::io::ErrorKind::AlreadyExists,
            "the folder exists and holds files; choose a new folder, or pass --force to \
             replace it once the new one is complete",
        )));
    }
    let parents = CreatedParents::create(target).map_err(fail("create the folders of"))?;
    let temporary = TemporaryDir::create(target).map_err(fail("create a temporary folder for"))?;
    fill(&temporary.path).map_err(AtomicError::Writer)?;
    temporary
        .move_onto(target)
        .map_err(fail("move the finished folder onto"))?;
    parents.keep();
    Ok(())
}

/// A temporary folder: registered while it exists, removed with its contents on drop unless
/// it was renamed onto the target.
struct TemporaryDir {
    path: PathBuf,
    renamed: bool,
}

impl TemporaryDir {
    fn create(target: &Path) -> std::io::Result<Self> {
        let Some(name) = target.file_name() else {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the path names no folder; give a folder name",
            ));
        };
        let parent = target
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let path = parent.join(hidden(name, "partial"));
        let mut registry = registry();
        std::fs::create_dir(&path)?;
        registry.push(path.clone());
        Ok(Self {
            path,
            renamed: false,
        })
    }

    fn move_onto(mut self, target: &Path) -> std::io::Result<()> {
        match std::fs::rename(&self.path, target) {
            Ok(()) => {}
            // An existing target: an empty folder is simply removed; a full one (the caller
            // asked to replace it) is moved aside first, so that it is never half-deleted.
            Err(_) if target.is_dir() => {
                if std::fs::remove_dir(target).is_err() {
                    let parent = target.parent().unwrap_or(Path::new("."));
                    let name = target.file_name().unwrap_or_default();
                    let aside = parent.join(hidden(name, "old"));
                    std::fs::rename(target, &aside)?;
                    std::fs::rename(&self.path, target)?;
                    self.renamed = true;
                    return std::fs::remove_dir_all(&aside);
                }
                std::fs::rename(&self.path, target)?;
            }
            Err(e) => return Err(e),
        }
        self.renamed = true;
        Ok(())
    }
}

impl Drop for TemporaryDir {
    fn drop(&mut self) {
        if !self.renamed {
            let _ = std::fs::remove_dir_all(&self.path);
        }
        deregister(&self.path);
    }
}

/// `.NAME.KIND-PID-N`.
fn hidden(name: &std::ffi::OsStr, kind: &str) -> OsString {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let mut hidden = OsString::from(".");
    hidden.push(name);
    hidden.push(format!(".{kind}-{}-{n}", std::process::id()));
    hidden
}
