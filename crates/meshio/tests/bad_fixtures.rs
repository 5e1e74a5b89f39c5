//! The hand-written bad inputs under `data/bad/` (used by the CLI too) give the documented
//! errors.

use std::path::PathBuf;

use meshio::{AnimationOptions, LoadOptions, MeshIoError, load_animation, load_mesh};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data/bad")
        .join(name)
}

#[test]
fn each_fixture_gives_its_documented_error() {
    let load = |name: &str| {
        load_mesh(&fixture(name), &LoadOptions::default())
            .map(|_| ())
            .unwrap_err()
    };
    let err = load("nan_vertex.ply");
    assert!(
        matches!(&err, MeshIoError::NonFinite { element, component: "y", line: Some(13), .. } if element == "vertex 2"),
        "{err}"
    );
    let err = load("index_out_of_range.obj");
    assert!(
        matches!(
            err,
            MeshIoError::IndexOutOfRange {
                index: 4,
                vertex_count: 3,
                line: Some(6),
                ..
            }
        ),
        "{err}"
    );
    let err = load("truncated_binary.ply");
    assert!(matches!(err, MeshIoError::Truncated { .. }), "{err}");
    let err = load("huge_count.ply");
    assert!(
        matches!(
            err,
            MeshIoError::CountTooLarge {
                count: 1_099_511_627_776,
                ..
            }
        ),
        "{err}"
    );
    let err = load("malformed_number.obj");
    assert!(
        matches!(&err, MeshIoError::Malformed { line: Some(3), token, .. } if token == "1.0.0"),
        "{err}"
    );
    let err = load_animation(&fixture("mismatched_frames"), &AnimationOptions::default())
        .map(|_| ())
        .unwrap_err();
    assert!(
        matches!(&err, MeshIoError::FrameCountMismatch { frame: 1, expected: 3, found: 4, file, .. } if file.ends_with("2.obj")),
        "{err}"
    );
    // Messages name the file.
    assert!(
        err.to_string().contains("2.obj") && err.to_string().contains("mismatched_frames"),
        "{err}"
    );
}
