//! Opening and reading regular files only.

use std::fs::File;
use std::io::{self, Read as _};
use std::path::Path;

/// Opens `path` for reading if it is a regular file (symbolic links followed).
///
/// The file is opened with `O_NONBLOCK` on Unix, so that a FIFO cannot block the open, and its
/// type is then taken from the open handle, so that nothing can be swapped in between a check
/// and the open. The flag is harmless for regular files (reads of regular files never block).
///
/// # Errors
/// The open's own error, or `InvalidInput` saying what the path is (`a FIFO`, `a character
/// device`, `a directory`, …) when it is not a regular file.
pub fn open_regular(path: &Path) -> io::Result<File> {
    let file = open_nonblocking(path)?;
    let file_type = file.metadata()?.file_type();
    if file_type.is_file() {
        return Ok(file);
    }
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!(
            "{} is {}, not a regular file; only regular files are read",
            path.display(),
            describe(&file_type)
        ),
    ))
}

/// Reads the whole of the regular file `path` (see [`open_regular`]). The buffer is sized from
/// the file's length, so memory is bounded by what the file holds.
///
/// # Errors
/// As [`open_regular`], and the read's own error.
pub fn read_regular(path: &Path) -> io::Result<Vec<u8>> {
    let mut file = open_regular(path)?;
    let length = file.metadata()?.len();
    let mut bytes = Vec::new();
    bytes.try_reserve_exact(usize::try_from(length).unwrap_or(usize::MAX))?;
    file.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Reads the regular file `path` as UTF-8 text (see [`read_regular`]).
///
/// # Errors
/// As [`read_regular`], and `InvalidData` when the bytes are not UTF-8.
pub fn read_regular_to_string(path: &Path) -> io::Result<String> {
    String::from_utf8(read_regular(path)?).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!("not UTF-8 text (byte {})", e.utf8_error().valid_up_to()),
        )
    })
}

#[cfg(unix)]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    use std::os::unix::fs::OpenOptionsExt as _;
    std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK)
        .open(path)
}

#[cfg(not(unix))]
fn open_nonblocking(path: &Path) -> io::Result<File> {
    File::open(path)
}

#[cfg(unix)]
fn describe(file_type: &std::fs::FileType) -> &'static str {
    use std::os::unix::fs::FileTypeExt as _;
    if file_type.is_dir() {
        "a directory"
    } else if file_type.is_fifo() {
        "a FIFO (named pipe)"
    } else if file_type.is_char_device() {
        "a character device"
    } else if file_type.is_block_device() {
        "a block device"
    } else if file_type.is_socket() {
        "a socket"
    } else {
        "not a file"
    }
}

#[cfg(not(unix))]
fn describe(file_type: &std::fs::FileType) -> &'static str {
    if file_type.is_dir() {
        "a directory"
    } else {
        "not a file"
    }
}
