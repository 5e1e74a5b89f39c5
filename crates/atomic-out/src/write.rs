//! The three ways to write a file atomically: through a buffered writer, from a byte slice, or
//! by an encoder that opens a path itself.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::error::{AtomicError, WriteError};
use crate::parents::CreatedParents;
use crate::temporary::Temporary;

/// Writes `path` atomically: `write` fills a buffered writer on a new temporary file beside
/// `path`, which is then flushed, synced to disk and renamed over `path`.
///
/// Missing parent folders of `path` are created first. On any error (or a panic in `write`)
/// the temporary file and the folders this call created are removed and `path` is left as it
/// was. An existing file at `path` is replaced.
///
/// # Errors
/// [`WriteError`] naming `path` and the step: `"create the folders of"` (a parent cannot be
/// created, or a file stands where a folder should), `"create"` (`path` names no file),
/// `"write"` (including any error `write` returns), `"sync"`, or
/// `"rename a temporary file onto"` (e.g. `path` is a folder).
///
/// # Examples
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("vertices.txt");
/// atomic_out::write_with(&path, |w| {
///     for v in 0..3 {
///         writeln!(w, "v {v} 0 0")?;
///     }
///     Ok(())
/// })?;
/// assert_eq!(std::fs::read_to_string(&path)?, "v 0 0 0\nv 1 0 0\nv 2 0 0\n");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_with(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), WriteError> {
    let fail = |op| move |e| WriteError::new(path, op, e);
    let parents = CreatedParents::create(path).map_err(fail("create the folders of"))?;
    let (temporary, file) = Temporary::create(path).map_err(fail("create"))?;
    let mut writer = BufWriter::new(file);
    write(&mut writer).map_err(fail("write"))?;
    writer.flush().map_err(fail("write"))?;
    let file = writer
        .into_inner()
        .map_err(|e| WriteError::new(path, "write", e.into_error()))?;
    file.sync_all().map_err(fail("sync"))?;
    drop(file);
    temporary
        .rename_onto(path)
        .map_err(fail("rename a temporary file onto"))?;
    parents.keep();
    Ok(())
}

/// Writes `bytes` to `path` atomically; see [`write_with`].
///
/// # Errors
/// As [`write_with`].
///
/// # Examples
/// ```
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("report.json");
/// atomic_out::write_bytes(&path, br#"{"frames": 120}"#)?;
/// assert_eq!(std::fs::read(&path)?, br#"{"frames": 120}"#);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    write_with(path, |w| w.write_all(bytes))
}

/// Writes `path` atomically with an encoder that opens a path itself: `write` is given the
/// path of a new, empty temporary file beside `path` and writes (or replaces) it; the result is
/// synced to disk and renamed over `path`.
///
/// Missing parent folders are created as for [`write_with`]. On any error (or a panic in
/// `write`) the temporary file and those folders are removed and `path` is left as it was.
///
/// # Errors
/// [`AtomicError::Writer`] with `write`'s own error, unchanged;
/// [`AtomicError::File`] with a [`WriteError`] as for [`write_with`] (`"create the folders
/// of"`, `"create"`, `"sync"` —
/// also when `write` removed the file — or `"rename a temporary file onto"`).
///
/// # Examples
/// ```
/// let dir = tempfile::tempdir()?;
/// let path = dir.path().join("frame.ppm");
/// atomic_out::write_via_path(&path, |tmp| std::fs::write(tmp, b"P6\n1 1\n255\n\0\0\0"))?;
/// assert!(path.exists());
///
/// // The encoder's error comes back as it was, and nothing is left behind.
/// let err = atomic_out::write_via_path(&dir.path().join("bad.png"), |_| Err("no encoder"))
///     .unwrap_err();
/// assert!(matches!(err, atomic_out::AtomicError::Writer("no encoder")));
/// assert_eq!(std::fs::read_dir(dir.path())?.count(), 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn write_via_path<E>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), AtomicError<E>> {
    let fail = |op| move |e| AtomicError::File(WriteError::new(path, op, e));
    let parents = CreatedParents::create(path).map_err(fail("create the folders of"))?;
    let (temporary, file) = Temporary::create(path).map_err(fail("create"))?;
    // The encoder opens the path itself; holding our handle open would only block it on
    // platforms that lock open files.
    drop(file);
    write(temporary.path()).map_err(AtomicError::Writer)?;
    // Reopen for writing: a read-only handle cannot be synced on every platform.
    File::options()
        .write(true)
        .open(temporary.path())
        .and_then(|file| file.sync_all())
        .map_err(fail("sync"))?;
    temporary
        .rename_onto(path)
        .map_err(fail("rename a temporary file onto"))?;
    parents.keep();
    Ok(())
}

/// Checks, before a long computation, that a write of `path` could start and end: no folder
/// stands at `path`, its missing parent folders can be created, and a temporary file can be
/// created beside it. Whatever the check creates it removes again (the file system is left as
/// it was), so a command can refuse an output it could not write in its first millisecond
/// rather than after minutes of work. A later write can still fail (a full disk, a folder
/// created meanwhile): the write reports that itself.
///
/// # Errors
/// [`WriteError`] as [`write_with`] would report it: `"create the folders of"`, `"create"`
/// (a parent that is read-only, a file system that does not take new files), or
/// `"replace"` with [`std::io::ErrorKind::IsADirectory`] when `path` is a folder.
///
/// # Examples
/// ```
/// let dir = tempfile::tempdir()?;
/// atomic_out::check_writable(&dir.path().join("renders/a.png"))?;
/// // Nothing was left behind: not the temporary file, not the `renders` folder.
/// assert_eq!(std::fs::read_dir(dir.path())?.count(), 0);
/// let err = atomic_out::check_writable(dir.path()).unwrap_err();
/// assert_eq!(err.op, "replace");
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub fn check_writable(path: &Path) -> Result<(), WriteError> {
    // Not followed through a symbolic link: the rename replaces a link, whatever it points to.
    if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_dir()) {
        return Err(WriteError::new(
            path,
            "replace",
            std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "it is a folder; give a file name",
            ),
        ));
    }
    let fail = |op| move |e| WriteError::new(path, op, e);
    let parents = CreatedParents::create(path).map_err(fail("create the folders of"))?;
    let (temporary, file) = Temporary::create(path).map_err(fail("create"))?;
    // Dropped in this order: the file closed, the temporary removed, then its new folders.
    drop(file);
    drop(temporary);
    drop(parents);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registered_temporaries;

    fn entries(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    #[test]
    fn write_with_replaces_an_existing_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        std::fs::write(&path, b"old").unwrap();
        write_with(&path, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert_eq!(entries(dir.path()), ["a.txt"]);
    }

    #[test]
    fn missing_parent_folders_are_created_and_removed_again_on_error() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("renders/run 1/a.txt");
        let err = write_with(&path, |_| Err(std::io::Error::other("no"))).unwrap_err();
        assert_eq!(err.op, "write");
        assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
        write_bytes(&path, b"yes").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"yes");
        let err = write_via_path(&dir.path().join("x/y/z.exr"), |_| Err("encoder")).unwrap_err();
        assert!(matches!(err, AtomicError::Writer("encoder")));
        assert_eq!(entries(dir.path()), ["renders"]);
    }

    #[test]
    fn write_bytes_writes_an_empty_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("empty");
        write_bytes(&path, &[]).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"");
    }

    #[test]
    fn writer_error_is_reported_as_write_of_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.bin");
        let err = write_with(&path, |_| Err(std::io::Error::other("encoder gave up"))).unwrap_err();
        assert_eq!((err.op, err.path.as_path()), ("write", path.as_path()));
        assert_eq!(
            err.to_string(),
            format!("cannot write {}: encoder gave up", path.display())
        );
        assert!(std::error::Error::source(&err).is_some());
        assert!(entries(dir.path()).is_empty());
    }

    #[test]
    fn a_panicking_writer_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.bin");
        let result = std::panic::catch_unwind(|| {
            let _ = write_with(&path, |w| {
                w.write_all(b"half")?;
                w.flush()?;
                panic!("bug in the encoder");
            });
        });
        assert!(result.is_err());
        assert!(entries(dir.path()).is_empty());
        assert!(
            registered_temporaries()
                .iter()
                .all(|t| !t.starts_with(dir.path()))
        );
    }

    #[test]
    fn write_via_path_sees_an_empty_temporary_beside_the_target() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("d.exr");
        write_via_path(&path, |tmp| {
            assert_eq!(tmp.parent(), Some(dir.path()));
            assert_eq!(std::fs::metadata(tmp)?.len(), 0);
            std::fs::write(tmp, b"pixels")
        })
        .unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"pixels");
        assert_eq!(entries(dir.path()), ["d.exr"]);
    }

    #[test]
    fn write_via_path_reports_a_writer_that_removed_its_file_as_sync() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("e.png");
        let err = write_via_path(&path, |tmp| std::fs::remove_file(tmp)).unwrap_err();
        assert!(
            matches!(&err, AtomicError::File(WriteError { op: "sync", .. })),
            "{err}"
        );
        assert!(entries(dir.path()).is_empty());
    }
}
