//! `cloth-vis render` and `demo` outputs (issue #12): the folder appears complete or not at all —
//! built in a hidden temporary folder beside it, renamed into place, refused when it already
//! holds files unless `--force`, with missing parents created and removed again on failure
//! and on SIGTERM. The runs need a GPU adapter (lavapipe is fine) and skip through
//! `test_data::skip` without one.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use super::common::{binary, cli_env, text};

/// Lavapipe wants `XDG_RUNTIME_DIR`.
const ENV: [(&str, &str); 1] = [("XDG_RUNTIME_DIR", "/tmp")];

fn names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

/// Whether a GPU adapter exists (gpu-context's skip policy: a warning, or a failure under CI).
fn have_gpu() -> bool {
    gpu_context::testing::gpu_or_skip().is_some()
}

#[test]
fn a_run_folder_is_refused_when_it_holds_files_and_replaced_with_force() {
    if !have_gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs/a/demo");
    let run = cli_env(&["demo", "--quiet", "--out", text(&out)], &ENV);
    assert!(run.status.success(), "{run:?}");
    // Missing parents were created; nothing hidden is left beside the folder.
    assert_eq!(names(&dir.path().join("runs/a")), ["demo"]);
    let files = names(&out);
    for f in [
        "btf.png",
        "demo.exr",
        "demo.png",
        "run-report.json",
        "run-report.txt",
    ] {
        assert!(files.iter().any(|n| n == f), "{f} missing from {files:?}");
    }
    // The report names the files where they are, not in the temporary folder they were
    // written into.
    let report = std::fs::read_to_string(out.join("run-report.json")).unwrap();
    assert!(
        report.contains(&format!("{}/demo.png", text(&out))),
        "{report}"
    );
    assert!(!report.contains(".partial"), "{report}");

    // A second run into the same folder: refused before any work, the folder untouched.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let again = cli_env(&["demo", "--quiet", "--out", text(&out)], &ENV);
    assert_eq!(again.status.code(), Some(1));
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(err.contains(text(&out)) && err.contains("--force"), "{err}");
    assert!(err.contains("is a folder that holds files"), "{err}");
    assert!(out.join("notes.txt").is_file());
    // A file where the folder would go is called a file.
    let file = out.join("notes.txt");
    let refused = cli_env(&["demo", "--quiet", "--out", text(&file)], &ENV);
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(
        err.contains("notes.txt: is a file, and this output is a folder"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "mine");

    // --force: replaced whole once the new run is complete.
    let forced = cli_env(&["demo", "--quiet", "--force", "--out", text(&out)], &ENV);
    assert!(forced.status.success(), "{forced:?}");
    assert!(!out.join("notes.txt").exists());
    assert!(out.join("demo.png").is_file());
    assert_eq!(names(&dir.path().join("runs/a")), ["demo"]);
}

#[test]
fn a_failed_run_leaves_no_folder_and_no_parents() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("scene.toml");
    std::fs::write(
        dir.path().join("broken.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\n",
    )
    .unwrap();
    std::fs::write(
        &scene,
        "[[object]]\nname = \"cloth\"\nsource = \"broken.ply\"\n\n[output]\npng = \"a.png\"\n",
    )
    .unwrap();
    let out = dir.path().join("new/deeper/run");
    let run = cli_env(
        &["render", text(&scene), "--quiet", "--out", text(&out)],
        &ENV,
    );
    assert_eq!(run.status.code(), Some(1), "{run:?}");
    assert_eq!(names(dir.path()), ["broken.ply", "scene.toml"]);
}

/// SIGTERM while a sequence is being written: the handler removes the temporary folder with
/// the frames written so far, and the parent folders the run created; exit status 130.
#[cfg(unix)]
#[test]
fn sigterm_during_a_sequence_leaves_nothing() {
    if !have_gpu() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let parent = dir.path().join("made");
    let out = parent.join("frames");
    let mut child = Command::new(binary())
        .args(["demo", "--quiet", "--frames", "0..120", "--out", text(&out)])
        .envs(ENV)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Wait for the first frame in the hidden temporary folder beside `frames`.
    let deadline = Instant::now() + Duration::from_secs(120);
    let partial = loop {
        let found = names(&parent)
            .into_iter()
            .find(|n| n.starts_with(".frames.partial-"))
            .filter(|n| names(&parent.join(n)).iter().any(|f| f.ends_with(".png")));
        if let Some(name) = found {
            break parent.join(name);
        }
        if Instant::now() > deadline || child.try_wait().unwrap().is_some() {
            let _ = child.kill();
            panic!(
                "no frame appeared in a temporary folder: {:?}",
                names(&parent)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    assert!(!out.exists(), "the folder appears only when complete");
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status}");
    assert!(!partial.exists(), "{} was left", partial.display());
    assert_eq!(
        names(dir.path()),
        Vec::<String>::new(),
        "the created parent is gone too"
    );
}
