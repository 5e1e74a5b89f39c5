//! Folders of numbered OBJ frames: numeric order, mismatches, bad frames.

mod common;

use std::path::{Path, PathBuf};

use common::write;
use glam::Vec3;
use meshio::{AnimationOptions, MeshIoError, load_animation};

fn frames_dir(dir: &Path, frames: &[(&str, &str)]) -> PathBuf {
    let folder = dir.join("frames");
    for (name, text) in frames {
        write(&folder, name, text);
    }
    folder
}

const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn frame_folder_orders_numerically_and_reports_mismatches() {
    let dir = tempfile::tempdir().unwrap();
    let moved = "v 0 0 5\nv 1 0 5\nv 0 1 5\nf 1 2 3\n";
    let folder = frames_dir(
        dir.path(),
        &[
            ("f10.obj", moved),
            ("f2.obj", TRI),
            ("readme.txt", "not a frame"),
        ],
    );
    let (anim, report) = load_animation(&folder, &AnimationOptions::default()).unwrap();
    assert_eq!(anim.frames[0][0], Vec3::ZERO); // 2 before 10
    assert_eq!(anim.frames[1][0], Vec3::new(0.0, 0.0, 5.0));
    assert!(report.notes.iter().any(|n| n.contains("ignored")));

    let folder = frames_dir(
        &dir.path().join("b"),
        &[
            ("1.obj", TRI),
            ("2.obj", TRI),
            ("3.obj", "v 0 0 0\nv 1 0 0\nf 1 2 1\n"),
        ],
    );
    match load_animation(&folder, &AnimationOptions::default()) {
        Err(MeshIoError::FrameCountMismatch {
            frame: 2,
            file,
            expected: 3,
            found: 2,
            what: "vertices",
            ..
        }) => {
            assert!(file.ends_with("3.obj"));
        }
        other => panic!("{other:?}"),
    }
    let folder = frames_dir(
        &dir.path().join("c"),
        &[
            ("1.obj", TRI),
            ("2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 3 2\n"),
        ],
    );
    assert!(matches!(
        load_animation(&folder, &AnimationOptions::default()),
        Err(MeshIoError::FrameTopologyMismatch {
            frame: 1,
            triangle: 0,
            expected: [0, 1, 2],
            found: [0, 2, 1],
            ..
        })
    ));
    let folder = frames_dir(&dir.path().join("d"), &[("1.obj", TRI), ("01.obj", TRI)]);
    assert!(matches!(
        load_animation(&folder, &AnimationOptions::default()),
        Err(MeshIoError::FrameFolder { .. })
    ));
    let folder = frames_dir(&dir.path().join("e"), &[("1.obj", TRI), ("rest.obj", TRI)]);
    assert!(matches!(
        load_animation(&folder, &AnimationOptions::default()),
        Err(MeshIoError::FrameFolder { .. })
    ));
    let bad_rate = AnimationOptions {
        frame_rate: 0.0,
        ..AnimationOptions::default()
    };
    assert!(matches!(
        load_animation(&folder, &bad_rate),
        Err(MeshIoError::InvalidOption {
            option: "frame_rate",
            ..
        })
    ));
}

#[test]
fn a_bad_frame_names_its_own_file() {
    let dir = tempfile::tempdir().unwrap();
    let folder = frames_dir(
        dir.path(),
        &[
            ("1.obj", TRI),
            ("2.obj", "v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n"),
        ],
    );
    let err = load_animation(&folder, &AnimationOptions::default()).unwrap_err();
    assert!(
        err.to_string().contains("2.obj") && err.to_string().contains("line 2"),
        "{err}"
    );
}
