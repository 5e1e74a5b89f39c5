//! `cloth-vis inspect`: a readable summary of what the loader found (issue #18: it printed a
//! Rust `Debug` dump), and the dump itself only with `--debug`.

use super::common::{cli, text};

#[test]
fn inspect_summarises_a_mesh_and_an_animation() {
    let dir = tempfile::tempdir().unwrap();
    // A quad (fan-triangulated), a triangle, an unreferenced vertex, an unknown keyword.
    let obj = dir.path().join("quad.obj");
    std::fs::write(
        &obj,
        "o thing\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\nf 1 2 3\n",
    )
    .unwrap();
    let out = cli(&["inspect", text(&obj)]);
    assert!(out.status.success(), "{out:?}");
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(s.contains("mesh (OBJ), 5 vertices, 3 triangles"), "{s}");
    assert!(
        s.contains("extent: (0.0000, 0.0000, 0.0000) .. (5.0000, 5.0000, 5.0000)"),
        "{s}"
    );
    assert!(
        s.contains("2 faces (3 triangles, 1 polygon fan-triangulated)"),
        "{s}"
    );
    assert!(s.contains("unreferenced vertices: 1"), "{s}");
    assert!(s.contains("skipped keywords: o ×1"), "{s}");
    assert!(!s.contains("LoadReport {"), "{s}");
    assert!(
        !s.contains("--up-axis"),
        "a cube's extent suggests no up axis: {s}"
    );
    let debug = String::from_utf8(cli(&["inspect", text(&obj), "--debug"]).stdout).unwrap();
    assert!(debug.contains("LoadReport {"), "{debug}");

    // Two OBJ frames: the second moves vertex 2 by 3 units.
    let frames = dir.path().join("frames");
    std::fs::create_dir(&frames).unwrap();
    for (i, z) in [(1, 0.0), (2, 3.0)] {
        std::fs::write(
            frames.join(format!("{i:04}.obj")),
            format!("v 0 0 0\nv 1 0 0\nv 0 1 {z}\nf 1 2 3\n"),
        )
        .unwrap();
    }
    let out = cli(&["inspect", text(&frames)]);
    assert!(out.status.success(), "{out:?}");
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(
        s.contains("animation (a folder of OBJ frames), 2 frames x 3 vertices, 1 triangle,"),
        "{s}"
    );
    assert!(
        s.contains("largest vertex travel from frame 0: 3.0000"),
        "{s}"
    );
    assert!(s.contains("frame files: 0001.obj … 0002.obj"), "{s}");
}

#[test]
fn a_mesh_tall_along_z_gets_the_up_axis_hint() {
    let dir = tempfile::tempdir().unwrap();
    // A strip 0.4 wide (x), 0.3 deep (y), 1 tall (z): a Z-up garment's proportions.
    let obj = dir.path().join("tall.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 0.4 0 0\nv 0.4 0.3 1\nv 0 0.3 1\nf 1 2 3 4\n",
    )
    .unwrap();
    let out = cli(&["inspect", text(&obj)]);
    assert!(out.status.success(), "{out:?}");
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(
        s.contains(
            "note: the extent along Z (1.0000) is over twice that along X (0.4000) and Y \
             (0.3000): if the asset stands along Z, pass --up-axis z"
        ),
        "{s}"
    );
    // The same strip standing along Y: no hint.
    std::fs::write(
        &obj,
        "v 0 0 0\nv 0.4 0 0\nv 0.4 1 0.3\nv 0 1 0.3\nf 1 2 3 4\n",
    )
    .unwrap();
    let s = String::from_utf8(cli(&["inspect", text(&obj)]).stdout).unwrap();
    assert!(s.contains("extent: ") && !s.contains("--up-axis"), "{s}");
}

#[test]
fn clip_selects_a_gltf_animation_by_name_or_index() {
    assert_eq!(
        crate::commands::parse::clip("2"),
        Ok(meshio::ClipSelector::Index(2))
    );
    assert_eq!(
        crate::commands::parse::clip(" Walk "),
        Ok(meshio::ClipSelector::Name("Walk".into()))
    );
    assert!(crate::commands::parse::clip(" ").is_err());
    // Issue #18: only the Fox's first clip (Survey) was reachable.
    let Some(fox) = test_data::shared_file("anim/gltf/Fox.glb") else {
        return;
    };
    for (clip, expected) in [("Walk", "clip 1 \"Walk\""), ("2", "clip 2 \"Run\"")] {
        let out = cli(&["inspect", text(&fox), "--clip", clip]);
        assert!(out.status.success(), "{out:?}");
        let s = String::from_utf8(out.stdout).unwrap();
        assert!(s.contains(expected), "{s}");
    }
    let out = cli(&["inspect", text(&fox), "--clip", "Trot"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("Fox.glb") && err.contains("\"Walk\""), "{err}");
}

#[test]
fn inspect_says_that_loaded_normals_are_not_the_ones_lit() {
    let dir = tempfile::tempdir().unwrap();
    // One normal per vertex (no hard edge): the loader keeps them.
    let obj = dir.path().join("with_normals.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//1\n",
    )
    .unwrap();
    let s = String::from_utf8(cli(&["inspect", text(&obj)]).stdout).unwrap();
    assert!(
        s.contains("normals: loaded (lighting and visibility use normals computed from the triangles instead, per frame)"),
        "{s}"
    );
    let bare = dir.path().join("bare.obj");
    std::fs::write(&bare, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let s = String::from_utf8(cli(&["inspect", text(&bare)]).stdout).unwrap();
    assert!(
        s.contains("normals: none in the file (computed from the triangles);"),
        "{s}"
    );
}
