//! Corrupt and hostile glTF files: errors naming the element, never a panic; streamed GLB
//! animations that fail, grow or change under the reader.

use std::path::{Path, PathBuf};

use super::common::{self, write};
use glam::Vec3;
use meshio::MeshIoError;

use super::load;

fn gltf(dir: &Path, doc: serde_json::Value) -> PathBuf {
    write(dir, "bad.gltf", serde_json::to_vec(&doc).unwrap())
}

#[test]
fn corrupt_gltf_files_are_errors_not_panics() {
    let dir = tempfile::tempdir().unwrap();
    let positions = common::base64(&[0u8; 36]);
    let base = |accessor: serde_json::Value, uri: String| common::one_mesh_gltf(accessor, &uri);
    let good = serde_json::json!({"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [0, 0, 0]});
    let data_uri = format!("data:application/octet-stream;base64,{positions}");
    // Sanity: the good file loads (one degenerate triangle at the origin).
    assert!(load(&gltf(dir.path(), base(good.clone(), data_uri.clone()))).is_ok());
    let mut too_many = good.clone();
    too_many["count"] = serde_json::json!(1_000_000_000u64);
    let mut bad_offset = good.clone();
    bad_offset["byteOffset"] = serde_json::json!(4_000_000_000u64);
    let mut vec2 = good.clone();
    vec2["type"] = serde_json::json!("VEC2");
    let cases = [
        ("count beyond view", base(too_many, data_uri.clone())),
        ("offset beyond view", base(bad_offset, data_uri.clone())),
        ("wrong type", base(vec2, data_uri.clone())),
        (
            "bad base64",
            base(
                good.clone(),
                "data:application/octet-stream;base64,@@@@".into(),
            ),
        ),
        ("bad percent escape", base(good.clone(), "a%FF.bin".into())),
        ("missing file", base(good.clone(), "missing.bin".into())),
        (
            "short buffer",
            base(
                good.clone(),
                format!(
                    "data:application/octet-stream;base64,{}",
                    common::base64(&[0u8; 8])
                ),
            ),
        ),
    ];
    for (name, doc) in cases {
        let result = load(&gltf(dir.path(), doc));
        assert!(result.is_err(), "{name}: {result:?}");
    }
    let mut no_accessor = base(good.clone(), data_uri.clone());
    no_accessor["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = serde_json::json!(7);
    assert!(matches!(
        load(&gltf(dir.path(), no_accessor)),
        Err(MeshIoError::Gltf { .. })
    ));
    let mut cycle = base(good.clone(), data_uri.clone());
    cycle["nodes"] = serde_json::json!([{"mesh": 0, "children": [1]}, {"children": [0]}]);
    assert!(matches!(
        load(&gltf(dir.path(), cycle)),
        Err(MeshIoError::Gltf { .. })
    ));
    let truncated_glb = write(
        dir.path(),
        "cut.glb",
        b"glTF\x02\x00\x00\x00\xff\x00\x00\x00",
    );
    assert!(matches!(
        load(&truncated_glb),
        Err(MeshIoError::Gltf { .. })
    ));
    let no_scene_mesh = serde_json::json!({"asset": {"version": "2.0"}, "scenes": [{"nodes": []}]});
    assert!(matches!(
        load(&gltf(dir.path(), no_scene_mesh)),
        Err(MeshIoError::EmptyMesh { .. })
    ));
}

// ---------------------------------------------------------------- streamed .glb animations

/// The streamed writer asks for frame 0 once and every other frame twice (bounds, then bytes);
/// a clip longer than the format's weights can sensibly hold, a source that fails, and a
/// source that changes between the passes are errors that leave no file.
#[test]
fn streamed_glb_animation_refuses_long_failing_and_changing_sources() {
    let dir = tempfile::tempdir().unwrap();
    let triangles = [[0u32, 1, 2]];
    let clip = |frames| meshio::GlbClip {
        triangles: &triangles,
        uvs: None,
        frame_rate: 30.0,
        frames,
        vertices: 3,
    };
    let tri = |f: usize| [Vec3::ZERO, Vec3::X, Vec3::Y].map(|v| v + Vec3::Z * f as f32);
    let path = dir.path().join("a.glb");
    let mut calls = Vec::new();
    meshio::write_glb_animation_with(&path, &clip(4), |f, p: &mut [Vec3]| {
        calls.push(f);
        p.copy_from_slice(&tri(f));
        Ok::<(), MeshIoError>(())
    })
    .unwrap();
    assert_eq!(calls, [0, 1, 2, 3, 1, 2, 3]);

    let long = dir.path().join("long.glb");
    let err = meshio::write_glb_animation_with(
        &long,
        &clip(meshio::MAX_GLB_ANIMATION_FRAMES + 1),
        |_, _: &mut [Vec3]| -> Result<(), MeshIoError> { panic!("refused before any frame") },
    )
    .unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("4097 frames") && message.contains("MAX_GLB_ANIMATION_FRAMES"),
        "{message}"
    );

    #[derive(Debug)]
    enum SourceError {
        Decoder(usize),
        Mesh(MeshIoError),
    }
    impl From<MeshIoError> for SourceError {
        fn from(e: MeshIoError) -> Self {
            Self::Mesh(e)
        }
    }
    let failing = dir.path().join("failing.glb");
    let mut second_pass = false;
    let err = meshio::write_glb_animation_with(&failing, &clip(4), |f, p: &mut [Vec3]| {
        second_pass |= f == 3;
        if second_pass && f == 2 {
            return Err(SourceError::Decoder(f));
        }
        p.copy_from_slice(&tri(f));
        Ok(())
    })
    .unwrap_err();
    assert!(matches!(err, SourceError::Decoder(2)), "{err:?}");
    // The writer's own errors come back through the caller's `From<MeshIoError>`.
    let err = meshio::write_glb_animation_with(&failing, &clip(0), |_, _: &mut [Vec3]| Ok(()))
        .unwrap_err();
    let SourceError::Mesh(mesh) = err else {
        panic!("{err:?}");
    };
    assert!(mesh.to_string().contains("has 0 frames"), "{mesh}");

    let changing = dir.path().join("changing.glb");
    let mut call = 0;
    let err = meshio::write_glb_animation_with(&changing, &clip(3), |f, p: &mut [Vec3]| {
        call += 1;
        p.copy_from_slice(&tri(f + usize::from(call > 3)));
        Ok::<(), MeshIoError>(())
    })
    .unwrap_err();
    let message = err.to_string();
    assert!(
        message.contains("frame 1 POSITION") && message.contains("deterministic"),
        "{message}"
    );
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["a.glb"]);
}
