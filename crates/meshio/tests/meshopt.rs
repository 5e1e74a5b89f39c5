//! gltfpack output loads: `EXT_meshopt_compression` (`-c`, `-cc`) decodes to exactly the
//! quantized file gltfpack writes without compression (positions, triangles, UVs bit for bit;
//! normals within the octahedral filter's rounding), and both lie within the quantization step
//! of the original asset. A corrupt compressed view is an error naming it, not a panic.

use std::collections::HashMap;
use std::ffi::OsStr;
use std::path::Path;

use glam::Vec3;
use meshio::{LoadOptions, Mesh, load_mesh};

fn pack(input: &Path, output: &Path, flags: &[&str]) -> Option<Mesh> {
    let mut args: Vec<&OsStr> = vec![
        OsStr::new("-i"),
        input.as_os_str(),
        OsStr::new("-o"),
        output.as_os_str(),
    ];
    args.extend(flags.iter().map(OsStr::new));
    test_data::gltfpack(&args)?;
    Some(load_mesh(output, &LoadOptions::default()).unwrap().0)
}

/// Largest distance from a point of `a` to the nearest point of `b` (brute force).
fn one_sided(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .map(|p| {
            b.iter()
                .map(|q| p.distance(*q))
                .fold(f32::INFINITY, f32::min)
        })
        .fold(0.0, f32::max)
}

#[test]
fn meshopt_compressed_files_decode_to_the_quantized_ones() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["Fox", "CesiumMan", "BrainStem"] {
        let Some(input) = test_data::shared_file(&format!("anim/gltf/{name}.glb")) else {
            return;
        };
        let plain_path = dir.path().join(format!("{name}-q.glb"));
        let Some(quantized) = pack(&input, &plain_path, &[]) else {
            return;
        };
        for flags in [&["-c"][..], &["-cc"][..]] {
            let out = dir.path().join(format!("{name}{}.glb", flags[0]));
            let compressed = pack(&input, &out, flags).unwrap();
            // -cc may also reorder vertices for the codec: compare the triangles as position
            // triples (each started at its smallest corner, same winding), bit for bit.
            let triangles = |m: &Mesh| {
                let mut t: Vec<[[u32; 3]; 3]> = m
                    .triangles
                    .iter()
                    .map(|t| {
                        let corners =
                            t.map(|i| m.positions[i as usize].to_array().map(f32::to_bits));
                        let k = (0..3).min_by_key(|&k| corners[k]).unwrap_or(0);
                        [corners[k], corners[(k + 1) % 3], corners[(k + 2) % 3]]
                    })
                    .collect();
                t.sort_unstable();
                t
            };
            assert!(
                triangles(&compressed) == triangles(&quantized),
                "{name} {flags:?} triangles"
            );
            if flags == ["-c"] {
                assert!(
                    compressed.positions == quantized.positions,
                    "{name} -c vertex order"
                );
            }
            // Vertices matched by their (bit-identical) rest position; a position shared by
            // several vertices (hard edges) matches the closest normal among them.
            let mut at: HashMap<[u32; 3], Vec<usize>> = HashMap::new();
            for (i, p) in quantized.positions.iter().enumerate() {
                at.entry(p.to_array().map(f32::to_bits))
                    .or_default()
                    .push(i);
            }
            let matches = |i: usize| &at[&compressed.positions[i].to_array().map(f32::to_bits)];
            let worst_normal = (0..compressed.positions.len())
                .map(|i| {
                    matches(i)
                        .iter()
                        .map(|&j| compressed.normals[i].distance(quantized.normals[j]))
                        .fold(f32::INFINITY, f32::min)
                })
                .fold(0.0, f32::max);
            assert!(
                worst_normal < 0.03,
                "{name} {flags:?}: normals differ by {worst_normal}"
            );
            // The clip (rotations through the QUATERNION filter under -cc): frames agree with
            // the plain quantized file's within the 16-bit quaternions' rounding.
            let options = meshio::AnimationOptions::default();
            let (plain, _) = meshio::load_animation(&plain_path, &options).unwrap();
            let (packed, _) = meshio::load_animation(&out, &options).unwrap();
            assert_eq!(plain.frames.len(), packed.frames.len(), "{name}");
            let diag = quantized
                .bounding_box()
                .map_or(1.0, |(lo, hi)| lo.distance(hi));
            let worst = plain
                .frames
                .iter()
                .zip(&packed.frames)
                .flat_map(|(a, b)| (0..b.len()).map(move |i| (a, b, i)))
                .map(|(a, b, i)| {
                    matches(i)
                        .iter()
                        .map(|&j| a[j].distance(b[i]))
                        .fold(f32::INFINITY, f32::min)
                })
                .fold(0.0, f32::max);
            assert!(
                worst <= 2e-3 * diag,
                "{name} {flags:?}: clip frames differ by {worst} (diagonal {diag})"
            );
            eprintln!(
                "{name} {flags:?}: normals within {worst_normal:.4}, clip frames within {:.2e} of the diagonal",
                worst / diag
            );
            assert_eq!(
                compressed.uvs.is_some(),
                quantized.uvs.is_some(),
                "{name} {flags:?}"
            );
        }
        // Against the original: gltfpack welds and reorders vertices, so compare the point sets;
        // positions are quantized to 14 bits of the bounding box per axis.
        let (original, _) = load_mesh(&input, &LoadOptions::default()).unwrap();
        let (lo, hi) = original.bounding_box().unwrap();
        let step = (hi - lo).max_element() / 16383.0;
        let d = one_sided(&quantized.positions, &original.positions)
            .max(one_sided(&original.positions, &quantized.positions));
        assert!(d <= 1.5 * step, "{name}: Hausdorff {d} vs step {step}");
        eprintln!("{name}: Hausdorff to the original {:.3} steps", d / step);
    }
}

#[test]
fn a_corrupt_compressed_view_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let Some(input) = test_data::shared_file("anim/gltf/Fox.glb") else {
        return;
    };
    let packed = dir.path().join("fox-c.glb");
    if pack(&input, &packed, &["-c"]).is_none() {
        return;
    }
    let mut bytes = std::fs::read(&packed).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    // Scramble the compressed bytes of the BIN chunk (after the JSON chunk and BIN header).
    let bin = 20 + json_len + 8;
    for b in &mut bytes[bin..] {
        *b = b.wrapping_mul(31).wrapping_add(7);
    }
    let corrupt = dir.path().join("corrupt.glb");
    std::fs::write(&corrupt, &bytes).unwrap();
    let error = load_mesh(&corrupt, &LoadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(error.contains("EXT_meshopt_compression"), "{error}");
}

/// A `.gltf` grid of `n`×`n` vertices with a wavy height, normals and a different colour per
/// vertex (seeded), so the YCoCg colour filter sees chroma, not only grey.
fn coloured_grid(dir: &Path, n: u32) -> std::path::PathBuf {
    let mut positions = Vec::new();
    let mut colours = Vec::new();
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    for y in 0..n {
        for x in 0..n {
            let (u, v) = (x as f32 / (n - 1) as f32, y as f32 / (n - 1) as f32);
            positions.extend([u, 0.1 * (6.0 * u).sin() * (5.0 * v).cos(), v]);
            colours.extend([random(), random(), random(), 0.25 + 0.75 * random()]);
        }
    }
    let mut indices = Vec::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let i = y * n + x;
            indices.extend([i, i + n, i + 1, i + 1, i + n, i + n + 1]);
        }
    }
    let mut bin: Vec<u8> = positions.iter().flat_map(|f| f.to_le_bytes()).collect();
    let colour_offset = bin.len();
    bin.extend(colours.iter().flat_map(|f| f.to_le_bytes()));
    let index_offset = bin.len();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let count = (n * n) as usize;
    let doc = serde_json::json!({
        "asset": { "version": "2.0" },
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": [{ "primitives": [{
            "attributes": { "POSITION": 0, "COLOR_0": 1 }, "indices": 2 }] }],
        "accessors": [
            { "bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3",
              "min": [0.0, -0.1, 0.0], "max": [1.0, 0.1, 1.0] },
            { "bufferView": 1, "componentType": 5126, "count": count, "type": "VEC4" },
            { "bufferView": 2, "componentType": 5125, "count": indices.len(), "type": "SCALAR" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteOffset": 0, "byteLength": colour_offset },
            { "buffer": 0, "byteOffset": colour_offset, "byteLength": index_offset - colour_offset },
            { "buffer": 0, "byteOffset": index_offset, "byteLength": bin.len() - index_offset }
        ],
        "buffers": [{ "uri": "grid.bin", "byteLength": bin.len() }]
    });
    std::fs::write(dir.join("grid.bin"), &bin).unwrap();
    let path = dir.join("grid.gltf");
    std::fs::write(&path, serde_json::to_vec(&doc).unwrap()).unwrap();
    path
}

/// A compressed view's (mode, filter, first byte: the vertex codec's version header).
type CompressedView = (String, String, u8);

/// The compression extension entries of a GLB — (mode, filter, codec version byte) per view —
/// and, for a file without them, every attribute's bytes (accessor `count` × element size,
/// strides removed).
fn glb_contents(path: &Path) -> (HashMap<String, Vec<u8>>, Vec<CompressedView>) {
    let bytes = std::fs::read(path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let root: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin = &bytes[20 + json_len + 8..];
    let mut views = Vec::new();
    for view in root["bufferViews"].as_array().unwrap() {
        if let Some(ext) = view["extensions"]
            .as_object()
            .and_then(|e| e.values().next())
        {
            let offset = ext["byteOffset"].as_u64().unwrap_or(0) as usize;
            views.push((
                ext["mode"].as_str().unwrap().to_owned(),
                ext["filter"].as_str().unwrap_or("NONE").to_owned(),
                bin[offset],
            ));
        }
    }
    let mut attributes = HashMap::new();
    if !views.is_empty() {
        return (attributes, views);
    }
    let primitive = &root["meshes"][0]["primitives"][0];
    let named = primitive["attributes"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(k, v)| (k.clone(), v.as_u64().unwrap()))
        .chain([("indices".to_owned(), primitive["indices"].as_u64().unwrap())]);
    for (name, accessor) in named {
        let a = &root["accessors"][accessor as usize];
        let v = &root["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
        let component = match a["componentType"].as_u64().unwrap() {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            _ => 4,
        };
        let width = component
            * match a["type"].as_str().unwrap() {
                "SCALAR" => 1,
                "VEC2" => 2,
                "VEC3" => 3,
                _ => 4,
            };
        let stride = v["byteStride"].as_u64().map_or(width, |s| s as usize);
        let start = v["byteOffset"].as_u64().unwrap_or(0) as usize
            + a["byteOffset"].as_u64().unwrap_or(0) as usize;
        let data = (0..a["count"].as_u64().unwrap() as usize)
            .flat_map(|i| &bin[start + i * stride..start + i * stride + width])
            .copied()
            .collect();
        attributes.insert(name, data);
    }
    (attributes, views)
}

/// `packed` written back by the bake writer with nothing added: every view decoded, the
/// compression extension dropped; returns `plain`.
fn write_decoded(packed: &Path, plain: &Path) -> std::path::PathBuf {
    let nothing = meshio::GltfBake {
        colour: None,
        attributes: Vec::new(),
        double_sided: meshio::DoubleSided::Keep,
    };
    meshio::write_gltf_with(packed, plain, &nothing).unwrap();
    plain.to_owned()
}

/// The first `len` bytes of buffer view `view` of a GLB whose views all lie in its BIN chunk.
fn decoded_view(path: &Path, view: usize, len: usize) -> Vec<u8> {
    let bytes = std::fs::read(path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let root: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let offset = root["bufferViews"][view]["byteOffset"]
        .as_u64()
        .unwrap_or(0) as usize;
    bytes[20 + json_len + 8 + offset..][..len].to_vec()
}

/// `KHR_meshopt_compression` (gltfpack `-ce khr`: vertex codec version 1, colours through the
/// YCoCg `COLOR` filter) and `EXT_meshopt_compression` (`-ce ext`: codec version 0, colours
/// stored as they are): every decoded view is byte for byte what meshoptimizer's own decoder
/// (its npm WebAssembly build) gives, and the two forms agree attribute by attribute — exactly,
/// but for the colours, which YCoCg rounds by at most one unit at 8 bits.
#[test]
fn the_khr_form_decodes_to_the_same_bytes_as_the_ext_form() {
    let dir = tempfile::tempdir().unwrap();
    let input = coloured_grid(dir.path(), 24);
    let mut decoded = Vec::new();
    for form in ["ext", "khr"] {
        let packed = dir.path().join(format!("grid-{form}.glb"));
        let Some(mesh) = pack(&input, &packed, &["-cc", "-ce", form]) else {
            return;
        };
        let (_, views) = glb_contents(&packed);
        let versions: std::collections::BTreeSet<u8> = views
            .iter()
            .filter(|(mode, ..)| mode == "ATTRIBUTES")
            .map(|(.., header)| *header)
            .collect();
        let colour_filtered = views.iter().any(|(_, filter, _)| filter == "COLOR");
        if form == "khr" {
            assert_eq!(versions, [0xa1].into(), "KHR: vertex codec v1 expected");
            assert!(colour_filtered, "KHR -cc filters colours: {views:?}");
        } else {
            assert_eq!(versions, [0xa0].into());
            assert!(!colour_filtered);
        }
        // Written back decoded (no compression extension), then read byte for byte.
        let plain = write_decoded(
            &packed,
            &dir.path().join(format!("grid-{form}-decoded.glb")),
        );
        let (attributes, views) = glb_contents(&plain);
        assert!(views.is_empty(), "{form}: still compressed: {views:?}");
        if let Some(reference) = test_data::meshopt_reference_decode(&packed) {
            assert_eq!(reference.len(), 3, "{form}: positions, colours, indices");
            for (view, expected) in reference {
                assert!(
                    decoded_view(&plain, view, expected.len()) == expected,
                    "{form}: view {view} differs from meshoptimizer's decoder"
                );
            }
        }
        decoded.push((mesh, attributes));
    }
    // Colours at 6 and 12 bits: the filter rescales (2^8 − 1)/(2^6 − 1) and 16-bit storage,
    // where its rounding shows; again byte for byte meshoptimizer's decoder.
    for bits in ["6", "12"] {
        let packed = dir.path().join(format!("grid-khr-{bits}.glb"));
        pack(&input, &packed, &["-cc", "-ce", "khr", "-vc", bits]).unwrap();
        let plain = write_decoded(
            &packed,
            &dir.path().join(format!("grid-khr-{bits}-decoded.glb")),
        );
        let reference = test_data::meshopt_reference_decode(&packed).unwrap();
        for (view, expected) in reference {
            assert!(
                decoded_view(&plain, view, expected.len()) == expected,
                "{bits}-bit colours: view {view} differs from meshoptimizer's decoder"
            );
        }
    }
    let ((ext_mesh, ext), (khr_mesh, khr)) = (&decoded[0], &decoded[1]);
    assert_eq!(
        ext.keys().collect::<std::collections::BTreeSet<_>>(),
        khr.keys().collect()
    );
    for (name, bytes) in ext {
        if name == "COLOR_0" {
            // YCoCg at 8 bits rounds each channel once more than plain 8-bit RGBA.
            let worst = khr[name]
                .iter()
                .zip(bytes)
                .map(|(a, b)| a.abs_diff(*b))
                .max();
            assert_eq!(worst, Some(1), "COLOR_0: the filter's rounding");
        } else {
            assert!(
                &khr[name] == bytes,
                "{name} differs between the KHR and EXT forms"
            );
        }
    }
    assert_eq!(khr_mesh.positions, ext_mesh.positions);
    assert_eq!(khr_mesh.triangles, ext_mesh.triangles);
    // And the colours are those of the input within 8-bit quantization.
    let colours = &khr["COLOR_0"];
    assert_eq!(colours.len(), 24 * 24 * 4, "8-bit RGBA");
    assert!(
        colours.chunks(4).any(|c| c[0] != c[1] || c[1] != c[2]),
        "chroma kept"
    );
}
