//! `write_glb` / `write_glb_animation`: round trips through `meshio`'s loaders and through the
//! `gltf` crate's own importer (which validates the document), the container layout, and
//! refusal of bad input without touching the target file.

use std::path::Path;

use glam::{Vec2, Vec3};
use meshio::{
    Animation, AnimationOptions, GlbMesh, LoadOptions, MeshIoError, load_animation, load_mesh,
    write_glb, write_glb_animation,
};

/// An n × n grid in the XY plane (normals +Z), two triangles per cell, counter-clockwise.
fn grid(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for r in 0..n {
        for c in 0..n {
            positions.push(Vec3::new(
                c as f32 / (n - 1) as f32,
                r as f32 / (n - 1) as f32,
                0.0,
            ));
        }
    }
    let mut triangles = Vec::new();
    for r in 0..n - 1 {
        for c in 0..n - 1 {
            let i = (r * n + c) as u32;
            let n = n as u32;
            triangles.push([i, i + 1, i + n + 1]);
            triangles.push([i, i + n + 1, i + n]);
        }
    }
    (positions, triangles)
}

#[track_caller]
fn assert_close(a: &[Vec3], b: &[Vec3], tolerance: f32) {
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (*x - *y).abs().max_element() <= tolerance,
            "vertex {i}: {x} vs {y} (tolerance {tolerance})"
        );
    }
}

/// Imports with the `gltf` crate (full validation) and returns the first primitive's data.
struct Imported {
    document: gltf::Document,
    buffers: Vec<gltf::buffer::Data>,
}

fn import(path: &Path) -> Imported {
    let (document, buffers, _) = gltf::import(path).expect("gltf::import validates the file");
    Imported { document, buffers }
}

impl Imported {
    fn primitive(&self) -> gltf::Primitive<'_> {
        self.document
            .meshes()
            .next()
            .unwrap()
            .primitives()
            .next()
            .unwrap()
    }

    fn custom(&self, name: &str) -> Vec<f32> {
        let accessor = self
            .primitive()
            .get(&gltf::Semantic::Extras(name.into()))
            .unwrap_or_else(|| panic!("attribute _{name} missing"));
        assert_eq!(accessor.data_type(), gltf::accessor::DataType::F32);
        assert_eq!(accessor.dimensions(), gltf::accessor::Dimensions::Scalar);
        gltf::accessor::Iter::<f32>::new(accessor, |b| {
            self.buffers.get(b.index()).map(|d| &d.0[..])
        })
        .unwrap()
        .collect()
    }
}

#[test]
fn mesh_round_trips_through_meshio_and_the_gltf_importer() {
    let (positions, triangles) = grid(5);
    let normals = vec![Vec3::Z; positions.len()];
    let colors: Vec<Vec3> = (0..positions.len())
        .map(|i| Vec3::new(i as f32 / 24.0, 0.5, 1.0 - i as f32 / 24.0))
        .collect();
    let ao: Vec<f32> = (0..positions.len())
        .map(|i| 0.01 * i as f32 - 0.05)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("grid.glb");
    let mesh = GlbMesh::new(&positions, &triangles)
        .with_normals(&normals)
        .with_colors(&colors)
        .with_attribute("_AO", &ao);
    write_glb(&path, &mesh).unwrap();

    let (loaded, report) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(loaded.positions, positions);
    assert_eq!(loaded.triangles, triangles);
    assert_eq!(loaded.normals, normals);
    assert_eq!(report.format, meshio::SourceFormat::Glb);

    let imported = import(&path);
    let primitive = imported.primitive();
    let reader = primitive.reader(|b| imported.buffers.get(b.index()).map(|d| &d.0[..]));
    let read: Vec<Vec3> = reader.read_positions().unwrap().map(Vec3::from).collect();
    assert_eq!(read, positions);
    let read: Vec<Vec3> = reader
        .read_colors(0)
        .unwrap()
        .into_rgb_f32()
        .map(Vec3::from)
        .collect();
    assert_eq!(read, colors);
    let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
    assert_eq!(indices, triangles.concat());
    assert_eq!(
        imported.custom("AO"),
        ao,
        "the _AO values are written exactly"
    );
    let bounds = imported.primitive().bounding_box();
    assert_eq!(bounds.min, [0.0, 0.0, 0.0]);
    assert_eq!(bounds.max, [1.0, 1.0, 0.0]);
}

#[test]
fn container_layout_follows_the_glb_spec() {
    let (positions, triangles) = grid(3);
    // 9 scalars (36 bytes) and a 3-vertex odd layout would misalign a careless writer.
    let a: Vec<f32> = vec![0.25; positions.len()];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("layout.glb");
    write_glb(
        &path,
        &GlbMesh::new(&positions, &triangles)
            .with_attribute("_A", &a)
            .with_attribute("_B_2", &a),
    )
    .unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(4), 2);
    assert_eq!(word(8), bytes.len());
    let json_len = word(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json = &bytes[20..20 + json_len];
    let root: serde_json::Value = serde_json::from_slice(json).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = word(bin_at);
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_at + 8 + bin_len, bytes.len());
    assert_eq!(root["buffers"][0]["byteLength"], bin_len);
    for view in root["bufferViews"].as_array().unwrap() {
        assert_eq!(view["byteOffset"].as_u64().unwrap() % 4, 0, "{view}");
        assert!(view.get("byteStride").is_none());
    }
    // POSITION carries min and max.
    let pos = root["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
        .as_u64()
        .unwrap() as usize;
    assert_eq!(
        root["accessors"][pos]["min"],
        serde_json::json!([0.0, 0.0, 0.0])
    );
    assert_eq!(
        root["accessors"][pos]["max"],
        serde_json::json!([1.0, 1.0, 0.0])
    );
    import(&path);
}

#[test]
fn bad_input_is_refused_and_leaves_the_target_untouched() {
    let (positions, triangles) = grid(3);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.glb");
    std::fs::write(&path, b"previous").unwrap();

    let mut nan = positions.clone();
    nan[4].y = f32::NAN;
    let short = vec![0.5f32; positions.len() - 1];
    let nan_ao: Vec<f32> = (0..positions.len())
        .map(|i| if i == 2 { f32::NAN } else { 1.0 })
        .collect();
    let ok_ao = vec![1.0f32; positions.len()];
    let bright = vec![Vec3::splat(1.5); positions.len()];
    let long_normals = vec![Vec3::new(0.0, 0.0, 2.0); positions.len()];
    let bad_triangles = [[0u32, 1, 9]];
    let cases: Vec<(&str, GlbMesh<'_>)> = vec![
        ("vertex 4", GlbMesh::new(&nan, &triangles)),
        ("triangle 0", GlbMesh::new(&positions, &bad_triangles)),
        ("mesh", GlbMesh::new(&positions, &[])),
        (
            "_AO",
            GlbMesh::new(&positions, &triangles).with_attribute("_AO", &short),
        ),
        (
            "_AO value 2",
            GlbMesh::new(&positions, &triangles).with_attribute("_AO", &nan_ao),
        ),
        (
            "\"AO\"",
            GlbMesh::new(&positions, &triangles).with_attribute("AO", &ok_ao),
        ),
        (
            "attribute _AO",
            GlbMesh::new(&positions, &triangles)
                .with_attribute("_AO", &ok_ao)
                .with_attribute("_AO", &ok_ao),
        ),
        (
            "COLOR_0 of vertex 0",
            GlbMesh::new(&positions, &triangles).with_colors(&bright),
        ),
        (
            "NORMAL of vertex 0",
            GlbMesh::new(&positions, &triangles).with_normals(&long_normals),
        ),
    ];
    for (element, mesh) in cases {
        let err = write_glb(&path, &mesh).expect_err(element);
        assert!(
            matches!(err, MeshIoError::InvalidWriteInput { .. }),
            "{element}: {err}"
        );
        let text = err.to_string();
        assert!(text.contains(element), "{text:?} should name {element}");
        assert!(text.contains("bad.glb"), "{text}");
        assert_eq!(std::fs::read(&path).unwrap(), b"previous");
    }
    // No temporary file is left behind either.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// A grid waving over time, with a large offset (a hard case for the delta encoding).
fn waving_animation(frames: usize, offset: Vec3) -> Animation {
    let (base, triangles) = grid(6);
    let frames = (0..frames)
        .map(|f| {
            base.iter()
                .map(|p| {
                    let z = 0.2 * ((p.x * 3.0 + f as f32 * 0.4).sin() * p.y);
                    *p + Vec3::new(0.0, 0.0, z) + offset
                })
                .collect()
        })
        .collect();
    let uvs = base.iter().map(|p| Vec2::new(p.x, 1.0 - p.y)).collect();
    Animation {
        triangles,
        frames,
        frame_rate: 24.0,
        uvs: Some(uvs),
    }
}

#[test]
fn animation_round_trips_through_load_animation() {
    let dir = tempfile::tempdir().unwrap();
    for (name, offset) in [("near", Vec3::ZERO), ("far", Vec3::new(1e4, -2e4, 5e3))] {
        let animation = waving_animation(17, offset);
        let path = dir.path().join(format!("{name}.glb"));
        write_glb_animation(&path, &animation).unwrap();
        import(&path);
        let options = AnimationOptions {
            frame_rate: animation.frame_rate,
            ..AnimationOptions::default()
        };
        let (loaded, report) = load_animation(&path, &options).unwrap();
        assert_eq!(loaded.frame_count(), animation.frame_count(), "{name}");
        assert_eq!(loaded.triangles, animation.triangles);
        assert_eq!(loaded.uvs, animation.uvs);
        assert_eq!(report.clip.as_ref().unwrap().start_s, 0.0);
        // p_0 + 1·(p_f − p_0) in f32: a few ulps of the coordinates' magnitude.
        let scale = 1.0 + offset.abs().max_element();
        for (f, (a, b)) in loaded.frames.iter().zip(&animation.frames).enumerate() {
            assert!(
                a.iter()
                    .zip(b)
                    .all(|(x, y)| (*x - *y).abs().max_element() <= 4.0 * f32::EPSILON * scale),
                "{name} frame {f}"
            );
        }
        assert_close(&loaded.frames[0], &animation.frames[0], 0.0);
    }
}

#[test]
fn animation_morph_targets_hold_normal_deltas_and_step_weights() {
    let animation = waving_animation(4, Vec3::ZERO);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("anim.glb");
    write_glb_animation(&path, &animation).unwrap();
    let imported = import(&path);
    let primitive = imported.primitive();
    assert_eq!(primitive.morph_targets().len(), 3);
    assert!(primitive.morph_targets().all(|t| t.normals().is_some()));
    let clip = imported.document.animations().next().unwrap();
    let channel = clip.channels().next().unwrap();
    assert_eq!(
        channel.sampler().interpolation(),
        gltf::animation::Interpolation::Step
    );
    let reader = channel.reader(|b| imported.buffers.get(b.index()).map(|d| &d.0[..]));
    let times: Vec<f32> = reader.read_inputs().unwrap().collect();
    assert_eq!(times, [0.0, 1.0 / 24.0, 2.0 / 24.0, 3.0 / 24.0]);
    let gltf::animation::util::ReadOutputs::MorphTargetWeights(weights) =
        reader.read_outputs().unwrap()
    else {
        panic!("weights channel expected");
    };
    let weights: Vec<f32> = weights.into_f32().collect();
    #[rustfmt::skip]
    assert_eq!(weights, [
        0.0, 0.0, 0.0,
        1.0, 0.0, 0.0,
        0.0, 1.0, 0.0,
        0.0, 0.0, 1.0,
    ]);
}

#[test]
fn single_frame_animation_is_a_static_mesh_and_bad_animations_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let one = waving_animation(1, Vec3::ZERO);
    let path = dir.path().join("one.glb");
    write_glb_animation(&path, &one).unwrap();
    let imported = import(&path);
    assert_eq!(imported.document.animations().count(), 0);
    let (loaded, _) = load_animation(&path, &AnimationOptions::default()).unwrap();
    assert_eq!(loaded.frames, one.frames);

    let bad_path = dir.path().join("bad.glb");
    let mut ragged = waving_animation(3, Vec3::ZERO);
    ragged.frames[2].pop();
    let mut slow = waving_animation(3, Vec3::ZERO);
    slow.frame_rate = 0.0;
    let mut inf = waving_animation(3, Vec3::ZERO);
    inf.frames[1][0].x = f32::INFINITY;
    let empty = Animation {
        frames: Vec::new(),
        ..waving_animation(1, Vec3::ZERO)
    };
    for (element, animation) in [
        ("frame 2 POSITION", ragged),
        ("frame_rate", slow),
        ("frame 1 POSITION of vertex 0", inf),
        ("animation", empty),
    ] {
        let err = write_glb_animation(&bad_path, &animation).expect_err(element);
        assert!(err.to_string().contains(element), "{err}");
        assert!(!bad_path.exists());
    }
}

/// A 1,000-frame clip: the file is linear in F (under 3× the `.npy` of its positions, which is
/// 12·N·F bytes: position and normal deltas plus a sparse one-hot weights track; a dense track
/// would add 4·F·(F − 1) bytes, 4 MB here, and fail the bound), loads back frame for frame, and
/// the Khronos validator accepts the sparse weights.
#[test]
fn thousand_frame_animation_is_linear_in_frames_and_validates() {
    let frames = 1000;
    let animation = waving_animation(frames, Vec3::ZERO);
    let n = animation.vertex_count();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.glb");
    write_glb_animation(&path, &animation).unwrap();
    let size = std::fs::metadata(&path).unwrap().len() as usize;
    let npy = 12 * n * frames;
    assert!(size < 3 * npy, "{size} bytes for a {npy}-byte .npy");
    assert!(
        4 * frames * (frames - 1) > npy,
        "the dense track would break the bound"
    );
    let options = AnimationOptions {
        frame_rate: animation.frame_rate,
        ..AnimationOptions::default()
    };
    let (loaded, _) = load_animation(&path, &options).unwrap();
    assert_eq!(loaded.frame_count(), frames);
    for f in [0, 1, 499, 999] {
        assert_close(&loaded.frames[f], &animation.frames[f], 4.0 * f32::EPSILON);
    }
    if let Some(report) = test_data::validate_gltf(&path) {
        assert!(report.ok, "{}", report.summary);
    }
}
