//! Locates the real data in `../shared/data` for tests and benchmarks.
//!
//! The project's rule: a test that needs `../shared/data` (or a GPU adapter) **fails** when the
//! `CI` environment variable is set, and **skips with a printed warning** otherwise, so that a
//! user's fresh clone passes and CI tests everything.
//!
//! The data root is `$CLOTH_VIS_DATA` when set, else `<workspace>/../shared/data`.
//!
//! ```
//! // In a test: returns None (after printing a warning) when the file is absent and CI is unset.
//! if let Some(path) = test_data::shared_file("meshes/bun_zipper.ply") {
//!     assert!(path.is_file());
//! }
//! ```

use std::path::PathBuf;

/// Environment variable that overrides the data root.
pub const DATA_ENV: &str = "CLOTH_VIS_DATA";

/// True when running under CI (`CI` set to anything but `""`, `0` or `false`).
pub fn in_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && !v.eq_ignore_ascii_case("false"))
}

/// The root of the shared data, whether or not it exists.
pub fn data_root() -> PathBuf {
    if let Ok(dir) = std::env::var(DATA_ENV) {
        return PathBuf::from(dir);
    }
    // crates/test-data -> workspace root -> ../shared/data
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

/// Path of `relative` under the shared data root if it exists.
///
/// # Panics
/// When the path is missing and [`in_ci`] is true: CI must test everything.
/// Otherwise a missing path prints a warning to stderr and returns `None`.
#[track_caller]
pub fn shared_file(relative: &str) -> Option<PathBuf> {
    let path = data_root().join(relative);
    if path.exists() {
        return Some(path);
    }
    skip(&format!("shared data file {} not found", path.display()))
}

/// Skips so far in this test binary.
static SKIPS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Report that a test cannot run for `reason` (missing data or GPU adapter).
///
/// The message goes to the process's stderr handle directly, not through `eprintln!`: libtest
/// captures the macros' output of passing tests, so a skip printed with them never reaches the
/// terminal and "N passed" would hide tests that did nothing.
///
/// # Panics
/// When [`in_ci`] is true. Otherwise prints
/// `SKIPPED (n in this binary): <caller>: <reason>` to stderr and returns `None`.
#[track_caller]
pub fn skip<T>(reason: &str) -> Option<T> {
    use std::io::Write;
    let caller = std::panic::Location::caller();
    if in_ci() {
        panic!("{caller}: {reason} (CI is set, so this test must not be skipped)");
    }
    let n = SKIPS.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
    // One write of the whole line, so it does not interleave with libtest's own lines; a
    // failed write to stderr leaves nothing better to report to.
    let line = format!(
        "SKIPPED ({n} in this binary): {caller}: {reason} (set CI=1 to make this a failure)\n"
    );
    let _ = std::io::stderr().lock().write_all(line.as_bytes());
    None
}

/// How many tests of this binary have skipped so far.
pub fn skipped_so_far() -> usize {
    SKIPS.load(std::sync::atomic::Ordering::Relaxed)
}

/// Creates a FIFO (named pipe) at `path` with the system's `mkfifo`, for the tests that check
/// a reader refuses it instead of blocking on it (issue #12). Unix only.
///
/// # Panics
/// When `mkfifo` cannot run or fails: the test cannot do what it means to.
#[cfg(unix)]
pub fn make_fifo(path: &std::path::Path) {
    let status = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .expect("mkfifo runs");
    assert!(status.success(), "mkfifo {} failed", path.display());
}
