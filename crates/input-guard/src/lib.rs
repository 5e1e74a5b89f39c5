//! Input rules every cloth-vis reader shares (issue #12, "files are files"):
//!
//! - **only regular files are read.** A FIFO blocks its reader forever, `/dev/zero` never ends,
//!   a socket or a directory is not data. [`open_regular`] opens without blocking, checks the
//!   type of what it opened (not of what the name pointed to a moment before) and refuses
//!   anything but a regular file by name; [`read_regular`] reads it whole, with the buffer
//!   sized from the file's length.
//! - **paths an asset names stay inside the asset's folder.** A glTF buffer `uri` of
//!   `/etc/passwd` or `../../secret` must not be read: [`confined_join`] resolves a relative
//!   reference against the asset's folder and refuses absolute paths, `..` that leaves the
//!   folder, and symbolic links that lead out of it.
//!
//! Errors are [`std::io::Error`]s (kind `InvalidInput` or `PermissionDenied`) whose message
//! says what the path is, so every reader's existing "cannot read FILE: …" error names the file
//! and the reason without a new error variant.
//!
//! No seed section: this is infrastructure (ARCHITECTURE.md, "Resource policy").
//!
//! # Examples
//!
//! ```
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("mesh.bin"), [1u8, 2, 3])?;
//! assert_eq!(input_guard::read_regular(&dir.path().join("mesh.bin"))?, [1, 2, 3]);
//! // A directory is not a file to read; neither is a reference that leaves the folder.
//! assert!(input_guard::read_regular(dir.path()).is_err());
//! assert!(input_guard::confined_join(dir.path(), "../outside.bin").is_err());
//! # Ok::<(), std::io::Error>(())
//! ```

mod confine;
mod regular;

pub use confine::confined_join;
pub use regular::{open_regular, read_regular, read_regular_to_string};
