//! `cloth-vis bake` through the binary: the input kept, a_i where it belongs (compared with
//! `visibility`'s .npy of the same mesh), instances, embedded images, materials, OBJ lines,
//! hostile inputs, and the shared glTF assets checked by the Khronos validator.

use std::path::{Path, PathBuf};

use serde_json::{Value, json};

use super::common::{cli, text};
use crate::commands::visibility::{VisibilityRequest, run_visibility};

/// Runs `cloth-vis ARGS` and asserts it succeeded; returns its output.
fn bake_ok(args: &[&str]) -> std::process::Output {
    let run = cli(args);
    assert!(
        run.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&run.stderr)
    );
    run
}

/// A GLB's JSON and BIN chunk.
fn read_glb(path: &Path) -> (Value, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let root = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = bytes.get(20 + json_len + 8..).unwrap_or_default().to_vec();
    (root, bin)
}

/// The bytes of buffer view `view` of a GLB whose buffers are all its BIN chunk.
fn view_bytes<'a>(root: &Value, bin: &'a [u8], view: usize) -> &'a [u8] {
    let v = &root["bufferViews"][view];
    assert_eq!(v["buffer"].as_u64().unwrap_or(0), 0);
    let offset = v["byteOffset"].as_u64().unwrap_or(0) as usize;
    &bin[offset..offset + v["byteLength"].as_u64().unwrap() as usize]
}

/// The f32 values of `attribute` of every primitive of every node-instantiated mesh, in node
/// order (the scenes tested here list their mesh nodes as roots, in order).
fn attribute_values(root: &Value, bin: &[u8], mesh: usize, attribute: &str) -> Vec<f32> {
    let mut out = Vec::new();
    for prim in root["meshes"][mesh]["primitives"].as_array().unwrap() {
        let a = &root["accessors"][prim["attributes"][attribute].as_u64().unwrap() as usize];
        assert_eq!(a["componentType"], 5126);
        let bytes = view_bytes(root, bin, a["bufferView"].as_u64().unwrap() as usize);
        out.extend(
            bytes
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes(c.try_into().unwrap())),
        );
    }
    out
}

/// The meshes the default scene instantiates, in the loader's order (depth first, children in
/// order), which is the order of the merged vertices.
fn scene_meshes(root: &Value) -> Vec<usize> {
    let scene = root["scene"].as_u64().unwrap_or(0) as usize;
    let ids = |v: &Value| -> Vec<usize> {
        v.as_array()
            .into_iter()
            .flatten()
            .map(|n| n.as_u64().unwrap() as usize)
            .collect()
    };
    let mut stack: Vec<usize> = ids(&root["scenes"][scene]["nodes"])
        .into_iter()
        .rev()
        .collect();
    let mut meshes = Vec::new();
    while let Some(node) = stack.pop() {
        if let Some(m) = root["nodes"][node]["mesh"].as_u64() {
            meshes.push(m as usize);
        }
        stack.extend(ids(&root["nodes"][node]["children"]).into_iter().rev());
    }
    meshes
}

/// `visibility`'s a_i (level 2, cpu) of `input` as loaded (rest pose), through a static copy.
fn reference_ambient(input: &Path, dir: &Path) -> Vec<f32> {
    let (mesh, _) = meshio::load_mesh(input, &meshio::LoadOptions::default()).unwrap();
    let copy = dir.join("rest-pose-copy.glb");
    meshio::write_glb(
        &copy,
        &meshio::GlbMesh::new(&mesh.positions, &mesh.triangles),
    )
    .unwrap();
    let npy = dir.join("reference.npy");
    run_visibility(
        &VisibilityRequest {
            level: 2,
            backend: Some(occlusion_gpu::Backend::Cpu),
            out: Some(npy.clone()),
            ..VisibilityRequest::new(copy)
        },
        None,
    )
    .unwrap();
    meshio::read_npy_f32(&npy).unwrap().data
}

/// A `.gltf` with an external `.bin` and image: one unit quad facing +Y (no material) placed
/// by two nodes, the second `gap` above the first, and an image `tex.png` beside it.
fn two_quads(dir: &Path, gap: f32, image_uri: &str) -> PathBuf {
    let positions: [[f32; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ];
    let indices: [u32; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|f| f.to_le_bytes())
        .collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("quads.bin"), &bin).unwrap();
    std::fs::write(dir.join("tex.png"), b"\x89PNG\r\n\x1a\n-not-decoded-").unwrap();
    let doc = json!({
        "asset": { "version": "2.0" },
        "scene": 0,
        "scenes": [{ "nodes": [0, 1] }],
        "nodes": [{ "mesh": 0 }, { "mesh": 0, "translation": [0.0, gap, 0.0] }],
        "meshes": [{ "primitives": [{ "attributes": { "POSITION": 0 }, "indices": 1 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
              "min": [0.0, 0.0, 0.0], "max": [1.0, 0.0, 1.0] },
            { "bufferView": 1, "componentType": 5125, "count": 6, "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": 48 },
            { "buffer": 0, "byteOffset": 48, "byteLength": 24 }
        ],
        "buffers": [{ "uri": "quads.bin", "byteLength": 72 }],
        "images": [{ "uri": image_uri }]
    });
    let path = dir.join("quads.gltf");
    std::fs::write(&path, serde_json::to_vec_pretty(&doc).unwrap()).unwrap();
    path
}

#[test]
fn two_instances_bake_apart_embedded_and_equal_to_visibility() {
    let dir = tempfile::tempdir().unwrap();
    let input = two_quads(dir.path(), 0.3, "tex.png");
    let out = dir.path().join("baked.glb");
    let run = bake_ok(&[
        "bake",
        text(&input),
        "--out",
        text(&out),
        "--level",
        "2",
        "--backend",
        "cpu",
    ]);
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("1 mesh(es) duplicated"), "{stdout}");
    let (root, bin) = read_glb(&out);
    // The second node got its own copy of the mesh, sharing POSITION and indices.
    assert_eq!(root["nodes"][1]["mesh"], 1);
    assert_eq!(root["meshes"].as_array().unwrap().len(), 2);
    assert_eq!(
        root["meshes"][1]["primitives"][0]["attributes"]["POSITION"],
        root["meshes"][0]["primitives"][0]["attributes"]["POSITION"]
    );
    // The external buffer and image are embedded byte for byte.
    let original = std::fs::read(dir.path().join("quads.bin")).unwrap();
    assert_eq!(view_bytes(&root, &bin, 0), &original[..48]);
    let image = &root["images"][0];
    assert_eq!(image["mimeType"], "image/png");
    assert!(image.get("uri").is_none());
    let png = std::fs::read(dir.path().join("tex.png")).unwrap();
    assert_eq!(
        view_bytes(&root, &bin, image["bufferView"].as_u64().unwrap() as usize),
        png
    );
    // A non-metallic default material, double-sided because the quads are open.
    let material = &root["materials"][0];
    assert_eq!(material["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    assert_eq!(material["doubleSided"], true);
    // COLOR_0 = (a, a, a) with a from `visibility` on the same mesh: lower quad first.
    let lower = attribute_values(&root, &bin, 0, "COLOR_0");
    let upper = attribute_values(&root, &bin, 1, "COLOR_0");
    let reference = reference_ambient(&input, dir.path());
    assert_eq!(reference.len(), 8);
    for (v, a) in reference.iter().enumerate() {
        let rgb = if v < 4 {
            &lower[3 * v..3 * v + 3]
        } else {
            &upper[3 * (v - 4)..3 * (v - 4) + 3]
        };
        assert_eq!(rgb, [*a; 3], "vertex {v}");
    }
    // The covered quad is darker: much of its sky is the other quad.
    assert!(reference[..4].iter().all(|a| *a < 0.7), "{reference:?}");
    assert!(reference[4..].iter().all(|a| *a > 0.9), "{reference:?}");

    // --max-distance below the gap: both quads see an open sky, identical values.
    let bounded = dir.path().join("bounded.glb");
    bake_ok(&[
        "bake",
        text(&input),
        "--out",
        text(&bounded),
        "--level",
        "2",
        "--max-distance",
        "0.25",
    ]);
    let (root, bin) = read_glb(&bounded);
    assert_eq!(
        attribute_values(&root, &bin, 0, "COLOR_0"),
        attribute_values(&root, &bin, 1, "COLOR_0")
    );
}

#[test]
fn hostile_bakes_are_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.glb");
    let obj = dir.path().join("x.obj");
    let escaping = two_quads(dir.path(), 0.3, "../outside.png");
    let cases: [(&[&str], &str); 5] = [
        (&["--out", text(&out)], "images[0].uri"),
        (&["--out", text(&obj)], "--out must be a .glb"),
        (
            &["--out", text(&out), "--max-distance", "0"],
            "--max-distance 0 must be finite and > 0",
        ),
        (
            &[
                "--out",
                text(&out),
                "--max-distance",
                "1",
                "--backend",
                "depth",
            ],
            "needs the cpu or rays backend",
        ),
        (&["--out", text(&escaping)], "is the input"),
    ];
    for (flags, expected) in cases {
        let mut args = vec!["bake", text(&escaping)];
        args.extend_from_slice(flags);
        let run = cli(&args);
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert!(!run.status.success(), "{flags:?} succeeded");
        assert!(stderr.contains(expected), "{flags:?}: {stderr}");
        assert!(!out.exists(), "{flags:?} left {}", out.display());
    }
}

#[test]
fn obj_keeps_every_line_and_colours_each_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("fold.obj");
    // A floor and a wall meeting at a fold, UVs with a seam, comments, groups, CRLF endings.
    let mut obj = String::from("# a fold\r\nmtllib fold.mtl\r\no fold\r\n");
    for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        obj.push_str(&format!("v {x} 0 {y}\r\n"));
    }
    for (y, z) in [(0.05, 0.0), (1.0, 0.0), (1.0, 1.0), (0.05, 1.0)] {
        obj.push_str(&format!("v 0 {y} {z} 0.5 0.5 0.5\r\n"));
    }
    obj.push_str("vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\ng floor\r\nusemtl cloth\r\n");
    obj.push_str("f 1/1 3/3 2/2\r\nf 1/1 4/4 3/3\r\ng wall\r\nf 5/2 6/3 7/4\r\nf 5/2 7/4 8/1\r\n");
    std::fs::write(&input, &obj).unwrap();
    let out = dir.path().join("baked.obj");
    bake_ok(&[
        "bake",
        text(&input),
        "--out",
        text(&out),
        "--level",
        "2",
        "--backend",
        "cpu",
    ]);
    let reference = reference_ambient(&input, dir.path());
    let baked = std::fs::read_to_string(&out).unwrap();
    let (mut v, mut lines) = (0, 0);
    for (original, line) in obj.split_inclusive('\n').zip(baked.split_inclusive('\n')) {
        lines += 1;
        if !original.starts_with("v ") {
            assert_eq!(line, original);
            continue;
        }
        let fields: Vec<f32> = line
            .split_whitespace()
            .skip(1)
            .map(|t| t.parse().unwrap())
            .collect();
        let position: Vec<f32> = original
            .split_whitespace()
            .skip(1)
            .take(3)
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(fields.len(), 6, "{line:?}");
        assert_eq!(fields[..3], position[..]);
        assert_eq!(fields[3..], [reference[v]; 3], "vertex {v}");
        assert!(line.ends_with("\r\n"));
        v += 1;
    }
    assert_eq!((v, lines), (8, obj.lines().count()));
    // The wall darkens the floor facing it (x = 1), not its own foot (x = 0), nor the floor the
    // wall's bottom faces.
    assert!(
        reference[1] < reference[0] && reference[4] < reference[5],
        "{reference:?}"
    );
}

/// Fox, CesiumMan and BrainStem: every material, texture, sampler, image, skin, animation and
/// accessor of the input unchanged, every buffer view's bytes unchanged, COLOR_0 = a_i of
/// `visibility` on the rest pose, and no validator error or warning the input did not have.
#[test]
fn shared_gltf_assets_keep_everything_and_validate() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["Fox", "CesiumMan", "BrainStem"] {
        let Some(input) = test_data::shared_file(&format!("anim/gltf/{name}.glb")) else {
            return;
        };
        let out = dir.path().join(format!("{name}.glb"));
        bake_ok(&[
            "bake",
            text(&input),
            "--out",
            text(&out),
            "--level",
            "2",
            "--backend",
            "cpu",
            "--sky",
            "--bent-normals",
        ]);
        let (before, bin_before) = read_glb(&input);
        let (after, bin_after) = read_glb(&out);
        for key in [
            "materials",
            "textures",
            "samplers",
            "skins",
            "animations",
            "scenes",
            "extensionsUsed",
        ] {
            if key == "materials" && after["materials"] != before["materials"] {
                // Only `doubleSided` may have been set.
                let mut cleaned = after["materials"].clone();
                for (m, b) in cleaned
                    .as_array_mut()
                    .unwrap()
                    .iter_mut()
                    .zip(before["materials"].as_array().unwrap())
                {
                    if b.get("doubleSided").is_none() {
                        m.as_object_mut().unwrap().remove("doubleSided");
                    }
                }
                assert_eq!(cleaned, before["materials"], "{name} materials");
                continue;
            }
            assert_eq!(after[key], before[key], "{name} {key}");
        }
        let accessors = before["accessors"].as_array().unwrap();
        assert_eq!(
            after["accessors"].as_array().unwrap()[..accessors.len()],
            accessors[..],
            "{name}"
        );
        for view in 0..before["bufferViews"].as_array().unwrap().len() {
            assert_eq!(
                view_bytes(&after, &bin_after, view),
                view_bytes(&before, &bin_before, view),
                "{name} bufferView {view}"
            );
        }
        for (i, image) in before["images"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            assert_eq!(after["images"][i], *image, "{name} image {i}");
        }
        let colours: Vec<f32> = scene_meshes(&after)
            .into_iter()
            .flat_map(|m| attribute_values(&after, &bin_after, m, "COLOR_0"))
            .collect();
        let reference = reference_ambient(&input, dir.path());
        assert_eq!(colours.len(), 3 * reference.len(), "{name}");
        for (v, a) in reference.iter().enumerate() {
            let a = if a.is_finite() { *a } else { 1.0 };
            assert_eq!(colours[3 * v..3 * v + 3], [a; 3], "{name} vertex {v}");
        }
        let Some(input_report) = test_data::validate_gltf(&input) else {
            continue;
        };
        let report = test_data::validate_gltf(&out).unwrap();
        assert!(report.ok, "{name}: {}", report.summary);
        let warnings = |s: &str| {
            s.split("\"warnings\":")
                .nth(1)
                .and_then(|t| t.split(',').next())
                .map(str::to_owned)
        };
        assert_eq!(
            warnings(&report.summary),
            warnings(&input_report.summary),
            "{name}: {}",
            report.summary
        );
    }
}

/// An animation of two quads drifting apart, baked per frame into a float VAT: positions are the
/// frames, alpha is `visibility --frames`'s a_i of the same frame, exactly.
#[test]
fn animation_bakes_per_frame_into_a_vertex_animation_texture() {
    let dir = tempfile::tempdir().unwrap();
    let clip = dir.path().join("clip");
    std::fs::create_dir(&clip).unwrap();
    let gaps = [0.2f32, 0.5, 2.0];
    for (f, gap) in gaps.iter().enumerate() {
        let mut obj = String::new();
        for y in [0.0, *gap] {
            for (x, z) in [(0.0, 0.0), (0.0, 1.0), (1.0, 1.0), (1.0, 0.0)] {
                obj.push_str(&format!("v {x} {y} {z}\n"));
            }
        }
        obj.push_str("f 1 2 3\nf 1 3 4\nf 5 6 7\nf 5 7 8\n");
        std::fs::write(clip.join(format!("frame_{f:03}.obj")), obj).unwrap();
    }
    let vat = dir.path().join("clip.vat.exr");
    bake_ok(&[
        "bake",
        text(&clip),
        "--out",
        text(&vat),
        "--level",
        "2",
        "--backend",
        "cpu",
        "--quiet",
    ]);
    let npy = dir.path().join("a.npy");
    run_visibility(
        &VisibilityRequest {
            level: 2,
            backend: Some(occlusion_gpu::Backend::Cpu),
            out: Some(npy.clone()),
            ..VisibilityRequest::new(clip.clone())
        },
        None,
    )
    .unwrap();
    let reference = meshio::read_npy_f32(&npy).unwrap();
    assert_eq!(reference.shape, [3, 8]);
    let (_, _, texels) = super::common::read_exr_rgba(&vat);
    let (clip_frames, _) =
        meshio::load_animation(&clip, &meshio::AnimationOptions::default()).unwrap();
    for f in 0..3 {
        for v in 0..8 {
            let t = texels[f * 8 + v];
            assert_eq!(
                [t[0], t[1], t[2]],
                clip_frames.frames[f][v].to_array(),
                "frame {f} vertex {v}"
            );
            assert_eq!(
                t[3],
                reference.data[f * 8 + v],
                "a_i of frame {f} vertex {v}"
            );
        }
    }
    // The lower quad opens up as the upper one drifts away.
    assert!(texels[0][3] < texels[8][3] && texels[8][3] < texels[16][3]);
    // A point cache without --topology has no triangles: refused, naming the way out.
    let cache = dir.path().join("clip.npy");
    meshio::write_npy_f32(
        &cache,
        &[3, 8, 3],
        &clip_frames
            .frames
            .concat()
            .iter()
            .flat_map(|p| p.to_array())
            .collect::<Vec<_>>(),
    )
    .unwrap();
    let refused = dir.path().join("refused.vat.png");
    let run = cli(&["bake", text(&cache), "--out", text(&refused)]);
    assert!(!run.status.success());
    assert!(
        String::from_utf8_lossy(&run.stderr).contains("--topology"),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(!refused.exists());
}

/// A gltfpack -cc file (quantized, EXT_meshopt_compression with the octahedral and quaternion
/// filters) bakes too: written decoded (the extension dropped), valid, COLOR_0 on every vertex
/// equal to `visibility` on the same (decoded) mesh.
#[test]
fn a_meshopt_compressed_asset_bakes_decoded_and_valid() {
    let dir = tempfile::tempdir().unwrap();
    let Some(input) = test_data::shared_file("anim/gltf/BrainStem.glb") else {
        return;
    };
    let packed = dir.path().join("brainstem-cc.glb");
    let args = [
        std::ffi::OsStr::new("-i"),
        input.as_os_str(),
        std::ffi::OsStr::new("-o"),
        packed.as_os_str(),
        std::ffi::OsStr::new("-cc"),
    ];
    if test_data::gltfpack(&args).is_none() {
        return;
    }
    let out = dir.path().join("baked.glb");
    bake_ok(&[
        "bake",
        text(&packed),
        "--out",
        text(&out),
        "--level",
        "2",
        "--backend",
        "cpu",
        "--quiet",
    ]);
    let (root, bin) = read_glb(&out);
    assert!(
        !serde_json::to_string(&root)
            .unwrap()
            .contains("EXT_meshopt_compression")
    );
    let colours: Vec<f32> = scene_meshes(&root)
        .into_iter()
        .flat_map(|m| attribute_values(&root, &bin, m, "COLOR_0"))
        .collect();
    let reference = reference_ambient(&packed, dir.path());
    assert_eq!(colours.len(), 3 * reference.len());
    for (v, a) in reference.iter().enumerate() {
        let a = if a.is_finite() { *a } else { 1.0 };
        assert_eq!(colours[3 * v], a, "vertex {v}");
    }
    if let Some(report) = test_data::validate_gltf(&out) {
        assert!(report.ok, "{}", report.summary);
    }
}

/// `--per-face`: a_f at each triangle's centroid about its face normal — equal to the engine's
/// ambient term of that point computed on its own, darker under the other quad.
#[test]
fn per_face_values_are_the_ambient_term_at_the_centroids() {
    let dir = tempfile::tempdir().unwrap();
    let input = two_quads(dir.path(), 0.3, "tex.png");
    let out = dir.path().join("baked.glb");
    let faces = dir.path().join("faces.npy");
    bake_ok(&[
        "bake",
        text(&input),
        "--out",
        text(&out),
        "--level",
        "2",
        "--backend",
        "cpu",
        "--per-face",
        text(&faces),
        "--quiet",
    ]);
    let a_f = meshio::read_npy_f32(&faces).unwrap();
    assert_eq!(a_f.shape, [4]);
    let (mesh, _) = meshio::load_mesh(&input, &meshio::LoadOptions::default()).unwrap();
    let sphere = lightsphere::Lightsphere::new(2).unwrap();
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
        let centroid = ((a + b + c) / 3.0).as_vec3();
        let mut scene = occlusion_gpu::Scene::new();
        scene
            .push(
                occlusion_gpu::SceneObject::new(
                    mesh.positions.clone(),
                    mesh.normals.clone(),
                    mesh.triangles.clone(),
                )
                .occluder_only(),
            )
            .unwrap();
        scene
            .push(occlusion_gpu::SceneObject::new(
                vec![centroid],
                vec![glam::Vec3::Y],
                Vec::new(),
            ))
            .unwrap();
        let mut engine =
            occlusion_gpu::VisibilityEngine::cpu(occlusion_gpu::VisibilityParams::default());
        let alone = engine.compute(&scene, &sphere).unwrap().ambient()[0];
        assert_eq!(a_f.data[t], alone, "triangle {t}");
    }
    assert!(
        a_f.data[0] < a_f.data[2] && a_f.data[1] < a_f.data[3],
        "{:?}",
        a_f.data
    );
    // Not with a VAT output, and only as .npy.
    let run = cli(&[
        "bake",
        text(&input),
        "--out",
        text(&out),
        "--per-face",
        text(&dir.path().join("f.txt")),
    ]);
    assert!(!run.status.success());
}

/// `--out X.gltf`: the JSON and one `X.bin` beside it (a URI-safe name: `baked_quads.bin`), the
/// same values as the `.glb` output, loadable again; a buffer name that is the input's own
/// buffer is refused before anything is written.
#[test]
fn a_gltf_output_writes_its_buffer_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = two_quads(dir.path(), 0.3, "tex.png");
    let glb = dir.path().join("baked.glb");
    let gltf = dir.path().join("baked quads.gltf");
    for out in [&glb, &gltf] {
        bake_ok(&["bake", text(&input), "--out", text(out), "--level", "2"]);
    }
    let bin_path = dir.path().join("baked_quads.bin");
    let root: Value = serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
    let bin = std::fs::read(&bin_path).unwrap();
    assert_eq!(
        root["buffers"],
        json!([{ "byteLength": bin.len(), "uri": "baked_quads.bin" }])
    );
    let (glb_root, glb_bin) = read_glb(&glb);
    assert_eq!(bin, glb_bin, "the .bin is the .glb's BIN chunk");
    for mesh in 0..2 {
        assert_eq!(
            attribute_values(&root, &bin, mesh, "COLOR_0"),
            attribute_values(&glb_root, &glb_bin, mesh, "COLOR_0"),
        );
    }
    let (reloaded, _) = meshio::load_mesh(&gltf, &meshio::LoadOptions::default()).unwrap();
    let (original, _) = meshio::load_mesh(&input, &meshio::LoadOptions::default()).unwrap();
    assert_eq!(reloaded.positions, original.positions);
    assert_eq!(reloaded.triangles, original.triangles);
    if let Some(report) = test_data::validate_gltf(&gltf) {
        // The test's image is not a decodable PNG; only its errors may remain.
        let glb_report = test_data::validate_gltf(&glb).unwrap();
        let errors = |s: &str| s.split("\"errors\":").nth(1).map(|t| t[..2].to_owned());
        assert!(errors(&report.summary).is_some(), "{}", report.summary);
        assert_eq!(
            errors(&report.summary),
            errors(&glb_report.summary),
            "{}",
            report.summary
        );
    }

    // `quads.GLTF` would write `quads.bin`, the input's own buffer.
    let clash = dir.path().join("quads.GLTF");
    let before = std::fs::read(dir.path().join("quads.bin")).unwrap();
    let run = cli(&["bake", text(&input), "--out", text(&clash), "--level", "1"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(stderr.contains("buffers[0].uri"), "{stderr}");
    assert!(stderr.contains("a file the input reads"), "{stderr}");
    assert!(!clash.exists());
    assert_eq!(std::fs::read(dir.path().join("quads.bin")).unwrap(), before);
}

/// `--back-side`: `_AO_BACK` is a_i with the normals flipped. The two quads mirror each other
/// about the plane between them, and the lightsphere is symmetric under y → −y, so the upper
/// quad's underside sees exactly what the lower quad's top sees, and the lower quad's underside
/// is as open as the upper quad's top. The front values are those of a bake without the flag.
#[test]
fn the_back_side_mirrors_the_front_of_the_facing_quad() {
    let dir = tempfile::tempdir().unwrap();
    let input = two_quads(dir.path(), 0.3, "tex.png");
    let (plain, both) = (dir.path().join("plain.glb"), dir.path().join("both.glb"));
    let common = ["--level", "2", "--backend", "cpu"];
    bake_ok(&[&["bake", text(&input), "--out", text(&plain)], &common[..]].concat());
    bake_ok(
        &[
            &["bake", text(&input), "--out", text(&both), "--back-side"],
            &common[..],
        ]
        .concat(),
    );
    let (root, bin) = read_glb(&both);
    let (plain_root, plain_bin) = read_glb(&plain);
    for mesh in 0..2 {
        assert_eq!(
            attribute_values(&root, &bin, mesh, "COLOR_0"),
            attribute_values(&plain_root, &plain_bin, mesh, "COLOR_0"),
            "mesh {mesh}: the front changed"
        );
    }
    let front = |mesh| -> Vec<f32> {
        attribute_values(&root, &bin, mesh, "COLOR_0")
            .chunks(3)
            .map(|c| c[0])
            .collect()
    };
    let back = |mesh| attribute_values(&root, &bin, mesh, "_AO_BACK");
    let (lower, upper) = (0, 1);
    for (a, b) in back(upper).iter().zip(front(lower)) {
        assert!(
            (a - b).abs() <= 1e-6,
            "upper underside {a} vs lower top {b}"
        );
    }
    for (a, b) in back(lower).iter().zip(front(upper)) {
        assert!(
            (a - b).abs() <= 1e-6,
            "lower underside {a} vs upper top {b}"
        );
    }
    assert!(back(upper).iter().all(|a| *a < 0.7), "{:?}", back(upper));
    // Only where a glTF can carry it.
    let obj = dir.path().join("x.obj");
    std::fs::write(&obj, "v 0 0 0\nv 1 0 0\nv 0 0 1\nf 1 2 3\n").unwrap();
    let out = dir.path().join("y.obj");
    let run = cli(&["bake", text(&obj), "--out", text(&out), "--back-side"]);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("_AO_BACK"));
    assert!(!out.exists());
}
