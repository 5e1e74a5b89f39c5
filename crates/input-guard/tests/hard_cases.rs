//! The hard cases input-guard defends: a FIFO (which would block a reader forever), a
//! character device (`/dev/zero` never ends), a directory, a symbolic link to a regular file
//! (followed), glTF-style references that are absolute, climb out with `..`, or leave through
//! a symbolic link, and `..` that stays inside.

use std::io::ErrorKind;

use input_guard::{confined_join, open_regular, read_regular, read_regular_to_string};

#[cfg(unix)]
#[test]
fn a_fifo_is_refused_without_blocking() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("image.png");
    let status = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(status.success());
    // Nobody writes to the FIFO: a blocking open would never return and the test would hang.
    let err = read_regular(&fifo).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::InvalidInput);
    assert!(err.to_string().contains("FIFO"), "{err}");
    assert!(err.to_string().contains("image.png"), "{err}");
}

#[cfg(unix)]
#[test]
fn a_device_that_never_ends_is_refused() {
    let err = read_regular(std::path::Path::new("/dev/zero")).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::InvalidInput);
    assert!(err.to_string().contains("character device"), "{err}");
}

#[test]
fn a_directory_is_refused_and_a_missing_file_keeps_its_error() {
    let dir = tempfile::tempdir().unwrap();
    let err = open_regular(dir.path()).unwrap_err();
    assert!(err.to_string().contains("a directory"), "{err}");
    let err = read_regular(&dir.path().join("missing.ply")).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::NotFound);
}

#[cfg(unix)]
#[test]
fn a_link_to_a_regular_file_is_followed() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("a.obj"), "v 0 0 0\n").unwrap();
    std::os::unix::fs::symlink("a.obj", dir.path().join("b.obj")).unwrap();
    assert_eq!(
        read_regular_to_string(&dir.path().join("b.obj")).unwrap(),
        "v 0 0 0\n"
    );
}

#[test]
fn text_that_is_not_utf8_is_refused_with_its_offset() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.toml");
    std::fs::write(&path, b"name = \"\xff\"").unwrap();
    let err = read_regular_to_string(&path).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::InvalidData);
    assert!(err.to_string().contains("byte 8"), "{err}");
}

#[test]
fn references_that_leave_the_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("asset");
    std::fs::create_dir_all(base.join("sub")).unwrap();
    std::fs::write(base.join("mesh.bin"), [0u8; 4]).unwrap();
    for (reference, why) in [
        ("/etc/passwd", "absolute"),
        ("../mesh.bin", "climbs out"),
        ("sub/../../mesh.bin", "climbs out"),
        ("", "empty"),
    ] {
        let err = confined_join(&base, reference).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::PermissionDenied, "{reference}");
        assert!(err.to_string().contains(why), "{reference}: {err}");
    }
    // Inside, however spelled, and a file that is not there yet (its open fails later).
    assert_eq!(
        confined_join(&base, "sub/../mesh.bin").unwrap(),
        base.join("sub/../mesh.bin")
    );
    assert_eq!(
        confined_join(&base, "./mesh.bin").unwrap(),
        base.join("./mesh.bin")
    );
    assert!(confined_join(&base, "missing.bin").is_ok());
}

#[cfg(unix)]
#[test]
fn a_symbolic_link_out_of_the_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("asset");
    std::fs::create_dir(&base).unwrap();
    std::fs::write(dir.path().join("secret.bin"), [7u8; 4]).unwrap();
    std::os::unix::fs::symlink("../secret.bin", base.join("buffer.bin")).unwrap();
    let err = confined_join(&base, "buffer.bin").unwrap_err();
    assert!(err.to_string().contains("symbolic link"), "{err}");
    // A link that stays inside is fine.
    std::fs::write(base.join("real.bin"), [1u8; 4]).unwrap();
    std::os::unix::fs::symlink("real.bin", base.join("alias.bin")).unwrap();
    assert!(confined_join(&base, "alias.bin").is_ok());
}
