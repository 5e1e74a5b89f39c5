//! Atomic file output: a file a cloth-vis program writes appears complete or not at all.
//!
//! DESIGN.md, "Conventions": the CLI "writes no partial output file (temp file + rename)". Every
//! crate that writes a file does it through this one:
//!
//! 1. the bytes go to a hidden temporary file beside the target, `.NAME.PID.N.tmp` (same
//!    folder, so the final rename never crosses a file system; `PID` and a process-wide counter
//!    `N` keep concurrent writers apart), created with `create_new`;
//! 2. it is flushed, synced to disk and renamed over the target, which a reader sees either as
//!    it was before or complete;
//! 3. missing parent folders are created (every writer, so `--out renders/a.png` behaves the
//!    same in every command); on any error — including a panic in the caller's closure — the
//!    temporary file and the folders this write created are removed and the target is left
//!    untouched;
//! 4. while a temporary file exists it is registered, and a binary that called
//!    [`remove_temporaries_on_signal`] once at start removes every registered temporary when it
//!    receives SIGINT (Ctrl-C) or SIGTERM, and the (then empty) folders created for them, then
//!    exits with status 130. Libraries never install
//!    signal handlers: that is the binary's decision.
//!
//! Folder outputs (numbered frames, image sets) go through [`write_dir`]: a hidden temporary
//! folder beside the target, renamed into place when complete, removed on error and on the
//! same signals; an existing folder that holds files is refused unless the caller replaces it
//! ([`ExistingFolder`]).
//!
//! [`check_writable`] tells a command, before its work, whether a write of a path could start
//! and end, leaving nothing behind. [`write_with`] hands the caller a buffered writer; [`write_bytes`] writes a slice;
//! [`write_via_path`] is for encoders that insist on opening a path themselves (the `image`
//! crate's `save`, `exr`'s `to_file`). Errors are [`WriteError`] (which step failed, on which
//! target) or, for [`write_via_path`], [`AtomicError`], which also carries the encoder's own
//! error unchanged.
//!
//! # Examples
//! ```
//! use std::io::Write;
//! let dir = tempfile::tempdir()?;
//! let path = dir.path().join("table.md");
//! atomic_out::write_with(&path, |w| writeln!(w, "| k | error |"))?;
//! atomic_out::write_bytes(&path, b"replaced, atomically\n")?;
//! assert_eq!(std::fs::read(&path)?, b"replaced, atomically\n");
//! // Only the target is left in the folder: no temporary file.
//! assert_eq!(std::fs::read_dir(dir.path())?.count(), 1);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
mod folder;
mod parents;
mod signal;
mod temporary;
mod write;

pub use error::{AtomicError, SignalError, WriteError};
pub use folder::{ExistingFolder, write_dir};
pub use signal::remove_temporaries_on_signal;
pub use temporary::registered_temporaries;
pub use write::{check_writable, write_bytes, write_via_path, write_with};
