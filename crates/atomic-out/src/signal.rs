//! Removing temporary files when the program is interrupted (SIGINT) or terminated (SIGTERM).

use std::sync::Mutex;

use crate::error::SignalError;
use crate::temporary::registry;

/// Exit status after the handler ran: 128 + SIGINT, the shell's convention for Ctrl-C (used for
/// SIGTERM too, since `ctrlc` does not say which signal arrived).
const EXIT_STATUS_ON_SIGNAL: i32 = 130;

/// Whether this crate's handler is installed (so that a second call is a no-op).
static INSTALLED: Mutex<bool> = Mutex::new(false);

/// Installs a SIGINT/SIGTERM handler that removes every temporary file of an atomic write in
/// progress, then exits the process with status 130. Without it, a program interrupted
/// mid-write leaves a hidden `.NAME.PID.N.tmp` beside its output (the output itself is never
/// partial either way).
///
/// A binary calls this once at start; calling it again is a no-op. Libraries never call it:
/// installing a signal handler is the program's decision. The handler runs on its own thread
/// (via the `ctrlc` crate), not in signal context.
///
/// # Errors
/// [`SignalError`] if a SIGINT/SIGTERM handler was already installed through `ctrlc` by
/// someone else, or the operating system refused; the program then runs without it.
///
/// # Examples
/// ```no_run
/// fn main() -> Result<(), Box<dyn std::error::Error>> {
///     atomic_out::remove_temporaries_on_signal()?;
///     atomic_out::write_bytes("out.txt".as_ref(), b"...")?;
///     Ok(())
/// }
/// ```
pub fn remove_temporaries_on_signal() -> Result<(), SignalError> {
    let mut installed = INSTALLED
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if !*installed {
        ctrlc::set_handler(remove_temporaries_and_exit).map_err(SignalError::new)?;
        *installed = true;
    }
    Ok(())
}

fn remove_temporaries_and_exit() {
    // Holding the registry lock until exit: a writer cannot create (and register) a new
    // temporary file after this sweep, since creation takes the same lock.
    let registry = registry();
    for path in registry.iter() {
        // Best effort: a file renamed onto its target a moment ago is simply gone. Temporary
        // folders (`write_dir`) go with their contents.
        if path.is_dir() {
            remove_folder_being_written(path);
        } else {
            let _ = std::fs::remove_file(path);
        }
    }
    // Then the parent folders created for them, innermost first, each only if empty.
    for dir in crate::parents::created().iter().rev() {
        let _ = std::fs::remove_dir(dir);
    }
    exit_now(EXIT_STATUS_ON_SIGNAL)
}

/// Ends the process without the C libraries' exit handlers. `std::process::exit` runs them
/// (`atexit`, static destructors) while the program's other threads are still running — in a
/// program that renders, inside Mesa's and LLVM's code — which tears their state down under
/// those threads: one CI run (2 cores, under load) saw the killed `demo` end with SIGSEGV
/// instead of 130, after the temporaries had gone. Rust's own buffered stdout is not flushed
/// either way that matters here: an interrupted command prints no summary.
#[cfg(unix)]
#[allow(unsafe_code)]
fn exit_now(status: i32) -> ! {
    // SAFETY: `_exit` takes a plain integer, touches no memory of this process and does not
    // return; it is async-signal-safe.
    unsafe { libc::_exit(status) }
}

/// [`std::process::exit`] where `_exit` is not available.
#[cfg(not(unix))]
fn exit_now(status: i32) -> ! {
    std::process::exit(status)
}

/// Removes a temporary folder that another thread may still be writing into. It is first
/// renamed, so that the writer's next file creation (by the old path) fails instead of adding
/// to it; a creation already under way can still land, so the removal is retried.
fn remove_folder_being_written(path: &std::path::Path) {
    let mut doomed = path.as_os_str().to_owned();
    doomed.push(".removing");
    let doomed = std::path::PathBuf::from(doomed);
    let target = if std::fs::rename(path, &doomed).is_ok() {
        doomed
    } else {
        path.to_path_buf()
    };
    for _ in 0..100 {
        if std::fs::remove_dir_all(&target).is_ok() || !target.exists() {
            return;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}
