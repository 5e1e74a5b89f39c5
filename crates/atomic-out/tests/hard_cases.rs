//! Named hard cases: every way an atomic write can fail leaves the target as it was and no
//! temporary file behind — including a SIGTERM in the middle of a write, inside a folder
//! output under construction; folder outputs that would mix old files with new ones are
//! refused, replaced only on request, and never left half-built.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::sync::{Arc, Barrier, mpsc};
use std::time::{Duration, Instant};

use atomic_out::{
    AtomicError, ExistingFolder, WriteError, check_writable, registered_temporaries,
    remove_temporaries_on_signal, write_bytes, write_dir, write_via_path, write_with,
};

/// How long the signal test waits for its child process at each step before failing (it takes
/// milliseconds; the margin is for a loaded CI machine).
const CHILD_TIMEOUT: Duration = Duration::from_secs(20);

/// Set (to a folder) in the child process of the signal test.
const SIGTERM_CHILD_DIR: &str = "ATOMIC_OUT_SIGTERM_CHILD_DIR";
/// Set in the child process of the foreign-handler test.
const FOREIGN_HANDLER_CHILD: &str = "ATOMIC_OUT_FOREIGN_HANDLER_CHILD";

/// The names in `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// The registered temporaries in `dir` (other tests of this binary run concurrently).
fn registered_in(dir: &Path) -> Vec<PathBuf> {
    registered_temporaries()
        .into_iter()
        .filter(|t| t.starts_with(dir))
        .collect()
}

#[test]
fn writer_failing_midway_keeps_the_old_target_and_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mesh.glb");
    std::fs::write(&path, b"previous complete file").unwrap();
    let err = write_with(&path, |w| {
        w.write_all(&[7; 100_000])?; // past the buffer: bytes reach the temporary file
        Err(std::io::Error::other("disk full"))
    })
    .unwrap_err();
    assert_eq!(err.op, "write");
    assert!(err.to_string().contains("mesh.glb") && err.to_string().contains("disk full"));
    assert_eq!(std::fs::read(&path).unwrap(), b"previous complete file");
    assert_eq!(entries(dir.path()), ["mesh.glb"]);
}

#[test]
fn missing_folders_are_created_and_a_file_in_their_place_is_an_error_naming_the_target() {
    let dir = tempfile::tempdir().unwrap();
    // Every writer creates missing parents: `--out renders/a/out.npy` works everywhere.
    let path = dir.path().join("renders").join("a").join("out.npy");
    write_bytes(&path, b"x").unwrap();
    assert_eq!(std::fs::read(&path).unwrap(), b"x");
    // A file standing where a folder should be: refused, naming the target and the file.
    std::fs::write(dir.path().join("taken"), b"file").unwrap();
    let path = dir.path().join("taken").join("b").join("out.npy");
    let err = write_bytes(&path, b"x").unwrap_err();
    assert_eq!(
        (err.op, err.path.as_path()),
        ("create the folders of", path.as_path())
    );
    assert_eq!(err.source.kind(), std::io::ErrorKind::NotADirectory);
    let message = err.to_string();
    assert!(
        message.starts_with(&format!(
            "cannot create the folders of {}: ",
            path.display()
        )) && message.contains("taken exists and is not a folder"),
        "{message}"
    );
    assert_eq!(entries(dir.path()), ["renders", "taken"]);
}

/// The check a command makes before its work refuses what the write would refuse, with the
/// write's step, and leaves nothing behind whether it passes or not.
#[test]
fn check_writable_refuses_what_a_write_would_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // Missing folders: they could be created, and are removed again.
    check_writable(&dir.path().join("renders/a/out.npy")).unwrap();
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
    // An existing file: it could be replaced, and is not touched.
    let kept = dir.path().join("kept.npy");
    std::fs::write(&kept, b"old").unwrap();
    check_writable(&kept).unwrap();
    assert_eq!(std::fs::read(&kept).unwrap(), b"old");
    // A folder at the target: refused before any temporary, the folder untouched.
    let folder = dir.path().join("frame.png");
    std::fs::create_dir(&folder).unwrap();
    std::fs::write(folder.join("inside"), b"kept").unwrap();
    let err = check_writable(&folder).unwrap_err();
    assert_eq!(
        (err.op, err.source.kind()),
        ("replace", std::io::ErrorKind::IsADirectory)
    );
    assert_eq!(entries(&folder), ["inside"]);
    // A symbolic link to a folder: the write replaces the link, so the check lets it be.
    #[cfg(unix)]
    {
        let link = dir.path().join("link.png");
        std::os::unix::fs::symlink(&folder, &link).unwrap();
        check_writable(&link).unwrap();
        write_bytes(&link, b"png").unwrap();
        assert!(!link.is_symlink() && std::fs::read(&link).unwrap() == b"png");
        assert_eq!(entries(&folder), ["inside"]);
        std::fs::remove_file(&link).unwrap();
    }
    // A file where a folder should be: the write's own error.
    let err = check_writable(&kept.join("b.npy")).unwrap_err();
    assert_eq!(err.op, "create the folders of");
    // A file system that takes no new files (a path under /proc): the write's "create".
    #[cfg(target_os = "linux")]
    {
        let err = check_writable(Path::new("/proc/cloth-vis-check.npy")).unwrap_err();
        assert_eq!(err.op, "create");
        assert!(
            err.to_string()
                .starts_with("cannot create /proc/cloth-vis-check.npy: ")
        );
    }
    assert_eq!(entries(dir.path()), ["frame.png", "kept.npy"]);
    assert!(registered_in(dir.path()).is_empty());
}

#[test]
fn target_that_is_a_folder_is_a_rename_error_and_the_temporary_is_removed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame.png");
    std::fs::create_dir(&path).unwrap();
    std::fs::write(path.join("inside"), b"kept").unwrap();
    let err = write_bytes(&path, b"png").unwrap_err();
    assert_eq!(
        (err.op, err.path.as_path()),
        ("rename a temporary file onto", path.as_path())
    );
    assert_eq!(entries(dir.path()), ["frame.png"]);
    assert_eq!(entries(&path), ["inside"]);
    assert!(registered_in(dir.path()).is_empty());
}

#[test]
fn two_threads_writing_in_one_folder_use_distinct_temporaries() {
    let dir = tempfile::tempdir().unwrap();
    // Both writes hold their temporary file at the same moment.
    let barrier = Arc::new(Barrier::new(2));
    let seen: Vec<Vec<PathBuf>> = std::thread::scope(|scope| {
        let handles: Vec<_> = ["a.txt", "b.txt"]
            .into_iter()
            .map(|name| {
                let (barrier, dir) = (Arc::clone(&barrier), dir.path());
                scope.spawn(move || {
                    let mut seen = Vec::new();
                    write_with(&dir.join(name), |w| {
                        barrier.wait();
                        seen = registered_in(dir);
                        barrier.wait();
                        w.write_all(name.repeat(1000).as_bytes())
                    })
                    .unwrap();
                    seen
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for s in &seen {
        assert_eq!(s.len(), 2, "{s:?}");
        assert_ne!(s[0], s[1]);
    }
    assert_eq!(entries(dir.path()), ["a.txt", "b.txt"]);
    for name in ["a.txt", "b.txt"] {
        let text = std::fs::read_to_string(dir.path().join(name)).unwrap();
        assert_eq!(text, name.repeat(1000));
    }
}

#[test]
fn registry_is_empty_after_success_and_after_failure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.bin");
    write_with(&path, |w| {
        assert_eq!(registered_in(dir.path()).len(), 1);
        w.write_all(b"ok")
    })
    .unwrap();
    assert!(registered_in(dir.path()).is_empty());
    write_with(&path, |_| Err(std::io::Error::other("fail"))).unwrap_err();
    assert!(registered_in(dir.path()).is_empty());
    write_via_path(&path, |_| Err("fail")).unwrap_err();
    assert!(registered_in(dir.path()).is_empty());
    assert_eq!(std::fs::read(&path).unwrap(), b"ok");
}

#[test]
fn write_via_path_returns_the_closure_error_and_removes_the_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sky.exr");
    let err = write_via_path(&path, |tmp| {
        std::fs::write(tmp, b"half an image").map_err(|e| e.to_string())?;
        Err("exr: unsupported sample type".to_owned())
    })
    .unwrap_err();
    match err {
        AtomicError::Writer(reason) => assert_eq!(reason, "exr: unsupported sample type"),
        AtomicError::File(e) => panic!("expected the writer's error, got {e}"),
    }
    assert!(entries(dir.path()).is_empty());
    assert!(registered_in(dir.path()).is_empty());
}

#[test]
fn write_via_path_below_a_file_fails_before_calling_the_encoder() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("file"), b"x").unwrap();
    let path = dir.path().join("file").join("a.png");
    let err = write_via_path(&path, |_| -> Result<(), String> {
        panic!("the encoder must not run without a temporary file")
    })
    .unwrap_err();
    assert!(
        matches!(&err, AtomicError::File(WriteError { op: "create the folders of", path: p, .. }) if *p == path),
        "{err}"
    );
    // With a file name that is no file: the temporary cannot be created.
    let err = write_via_path(Path::new("/"), |_| -> Result<(), String> {
        panic!("the encoder must not run without a temporary file")
    })
    .unwrap_err();
    assert!(
        matches!(&err, AtomicError::File(WriteError { op: "create", .. })),
        "{err}"
    );
}

/// Spawns this test binary running only `test` (with `env` set), stdout piped.
fn spawn_child(test: &str, env: (&str, &std::ffi::OsStr)) -> std::process::Child {
    Command::new(std::env::current_exe().unwrap())
        .args(["--exact", test, "--nocapture", "--test-threads=1"])
        .env(env.0, env.1)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap()
}

/// Waits for `child` to exit, polling, for at most [`CHILD_TIMEOUT`]; kills it on timeout.
fn wait_with_timeout(child: &mut std::process::Child) -> ExitStatus {
    let deadline = Instant::now() + CHILD_TIMEOUT;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            panic!("the child process did not exit within {CHILD_TIMEOUT:?}");
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[cfg(unix)]
#[test]
fn sigterm_mid_write_removes_the_temporary_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let mut child = spawn_child(
        "sigterm_child_blocks_mid_write",
        (SIGTERM_CHILD_DIR, dir.path().as_os_str()),
    );
    // Read the child's stdout on a thread so that waiting for its line can time out.
    let (lines, received) = mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            if lines.send(line).is_err() {
                break;
            }
        }
    });
    let deadline = Instant::now() + CHILD_TIMEOUT;
    let temporaries: Vec<PathBuf> = loop {
        let line = received.recv_timeout(deadline.saturating_duration_since(Instant::now()));
        match line {
            Ok(Ok(line)) => {
                // libtest prints `test NAME ... ` on the same line before it.
                if let Some((_, paths)) = line.split_once("TEMPORARIES ") {
                    break paths.split('|').map(PathBuf::from).collect();
                }
            }
            _ => {
                let _ = child.kill();
                panic!("the child never reported its temporary file: {line:?}");
            }
        }
    };
    // The temporary folder of a frame folder, and a temporary file being written inside it.
    assert_eq!(temporaries.len(), 2, "{temporaries:?}");
    assert!(temporaries.iter().any(|t| t.is_dir()), "{temporaries:?}");
    for temporary in &temporaries {
        assert!(temporary.exists(), "{}", temporary.display());
    }
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = wait_with_timeout(&mut child);
    assert_eq!(status.code(), Some(130), "{status}");
    for temporary in &temporaries {
        assert!(!temporary.exists(), "{} was left", temporary.display());
    }
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
}

/// The child of [`sigterm_mid_write_removes_the_temporary_and_exits_130`]; does nothing in a
/// normal test run. Installs the handler (twice: the second call is a no-op), starts a write,
/// reports its temporary file and blocks until the parent's SIGTERM.
#[test]
fn sigterm_child_blocks_mid_write() {
    let Some(dir) = std::env::var_os(SIGTERM_CHILD_DIR).map(PathBuf::from) else {
        return;
    };
    remove_temporaries_on_signal().unwrap();
    remove_temporaries_on_signal().unwrap();
    // Into a missing parent, which the handler removes too.
    let result = write_dir(&dir.join("run/frames"), ExistingFolder::Refuse, |folder| {
        std::fs::write(folder.join("frame_00000.obj"), "v 0 0 0\n").unwrap();
        write_with(&folder.join("frame_00001.obj"), |w| {
            w.write_all(&[1; 100_000])?;
            w.flush()?;
            let names: Vec<String> = registered_temporaries()
                .iter()
                .map(|t| t.display().to_string())
                .collect();
            println!("TEMPORARIES {}", names.join("|"));
            let deadline = Instant::now() + CHILD_TIMEOUT;
            while Instant::now() < deadline {
                std::thread::sleep(Duration::from_millis(5));
            }
            Err(std::io::Error::other("no signal arrived"))
        })
    });
    panic!("the write returned without a signal: {result:?}");
}

#[test]
fn a_handler_installed_by_someone_else_is_an_error_not_a_panic() {
    let mut child = spawn_child(
        "foreign_handler_child_installs_first",
        (FOREIGN_HANDLER_CHILD, "1".as_ref()),
    );
    let status = wait_with_timeout(&mut child);
    assert!(status.success(), "{status}");
}

/// The child of [`a_handler_installed_by_someone_else_is_an_error_not_a_panic`]; does nothing
/// in a normal test run.
#[test]
fn foreign_handler_child_installs_first() {
    if std::env::var_os(FOREIGN_HANDLER_CHILD).is_none() {
        return;
    }
    ctrlc::set_handler(|| std::process::exit(1)).unwrap();
    let err = remove_temporaries_on_signal().unwrap_err();
    assert!(err.to_string().contains("registered_temporaries"), "{err}");
    assert!(std::error::Error::source(&err).is_some());
}

#[test]
fn a_folder_output_appears_complete_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    // A failure half-way leaves nothing: no target, no temporary folder.
    let err = write_dir(&frames, ExistingFolder::Refuse, |tmp| {
        std::fs::write(tmp.join("frame_00000.obj"), "v 0 0 0\n")?;
        Err(std::io::Error::other("disk full at frame 1"))
    })
    .unwrap_err();
    assert!(matches!(err, AtomicError::Writer(_)), "{err}");
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
    assert!(registered_in(dir.path()).is_empty());
    // Success: the folder appears with its files; an empty existing folder gives way.
    std::fs::create_dir(&frames).unwrap();
    write_dir(&frames, ExistingFolder::Refuse, |tmp| {
        for f in 0..3 {
            std::fs::write(tmp.join(format!("frame_{f:05}.obj")), "v 0 0 0\n")?;
        }
        Ok::<(), std::io::Error>(())
    })
    .unwrap();
    assert_eq!(entries(&frames).len(), 3);
    assert_eq!(entries(dir.path()), ["frames"]);
    // A folder with files is refused before any work: stale frames would sit beside new ones.
    let mut called = false;
    let err = write_dir(&frames, ExistingFolder::Refuse, |_| {
        called = true;
        Ok::<(), std::io::Error>(())
    })
    .unwrap_err();
    assert!(!called);
    let message = err.to_string();
    assert!(
        message.contains("frames") && message.contains("--force"),
        "{message}"
    );
    // Replaced on request: only the new (shorter) clip remains.
    write_dir(&frames, ExistingFolder::Replace, |tmp| {
        std::fs::write(tmp.join("frame_00000.obj"), "v 1 1 1\n")
    })
    .unwrap();
    assert_eq!(entries(&frames), ["frame_00000.obj"]);
    assert_eq!(entries(dir.path()), ["frames"], "the old folder is gone");
    // A file where the folder should go is an error naming the target.
    let file = dir.path().join("file");
    std::fs::write(&file, "x").unwrap();
    let message = write_dir(&file, ExistingFolder::Replace, |_| {
        Ok::<(), std::io::Error>(())
    })
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("file") && message.contains("not a readable folder"),
        "{message}"
    );
    // Missing parents are created, and removed again when the fill fails.
    let missing = dir.path().join("missing/deeper/frames");
    let err = write_dir(&missing, ExistingFolder::Refuse, |_| {
        Err(std::io::Error::other("no frames"))
    });
    assert!(matches!(err, Err(AtomicError::Writer(_))));
    assert_eq!(entries(dir.path()), ["file", "frames"]);
    write_dir(&missing, ExistingFolder::Refuse, |tmp| {
        std::fs::write(tmp.join("frame_00000.obj"), "v 0 0 0\n")
    })
    .unwrap();
    assert_eq!(entries(&missing), ["frame_00000.obj"]);
}

#[test]
fn a_panic_while_filling_a_folder_removes_it() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    let result = std::panic::catch_unwind(|| {
        write_dir(&frames, ExistingFolder::Refuse, |tmp| {
            std::fs::write(tmp.join("frame_00000.obj"), "v 0 0 0\n").unwrap();
            panic!("bug in the writer");
            #[allow(unreachable_code)]
            Ok::<(), std::io::Error>(())
        })
    });
    assert!(result.is_err());
    assert!(entries(dir.path()).is_empty(), "{:?}", entries(dir.path()));
}
