//! Named adversarial inputs: each gives a clear error (never a panic) or a documented result.

mod common;
// The glTF cases, in a folder beside this file (a file directly under tests/ would be a test
// target of its own).
#[path = "hard_cases/gltf.rs"]
mod gltf;

use std::path::{Path, PathBuf};

use common::{QUAD_VERTICES, assert_close, ply_ascii, ply_binary, write};
use glam::Vec3;
use meshio::{
    AnimationOptions, DegenerateKind, LoadOptions, MeshIoError, NormalWeighting, compute_normals,
    load_animation, load_mesh,
};

fn load(path: &Path) -> Result<(meshio::Mesh, meshio::LoadReport), MeshIoError> {
    load_mesh(path, &LoadOptions::default())
}

// ---------------------------------------------------------------- non-finite coordinates

#[test]
fn nan_vertex_in_ascii_ply_names_vertex_component_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "nan.ply",
        ply_ascii("0 0 0\n1 0 0\n0 nan 0\n", "3 0 1 2\n", 3, 1),
    );
    match load(&path) {
        Err(MeshIoError::NonFinite {
            element,
            component: "y",
            line: Some(12),
            value,
            ..
        }) => {
            assert_eq!(element, "vertex 2");
            assert!(value.is_nan());
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn infinite_vertex_in_obj_and_binary_ply() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(
        dir.path(),
        "inf.obj",
        "v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n",
    );
    let err = load(&obj).unwrap_err();
    assert!(
        matches!(&err, MeshIoError::NonFinite { component: "z", line: Some(2), value, .. } if value.is_infinite()),
        "{err}"
    );
    assert!(err.to_string().contains("vertex 1"), "{err}");
    let ply = write(
        dir.path(),
        "inf.ply",
        ply_binary(
            false,
            &[[0.0; 3], [f32::NEG_INFINITY, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[&[0, 1, 2]],
        ),
    );
    assert!(matches!(
        load(&ply),
        Err(MeshIoError::NonFinite { component: "x", .. })
    ));
}

#[test]
fn nan_frame_in_npy_animation_names_frame_and_vertex() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nan.npy");
    let mut data = vec![0.0f32; 2 * 3 * 3];
    data[3 * 3 + 2 * 3 + 1] = f32::NAN; // frame 1, vertex 2, y
    meshio::write_npy_f32(&path, &[2, 3, 3], &data).unwrap();
    match load_animation(&path, &AnimationOptions::default()) {
        Err(MeshIoError::NonFinite {
            element,
            component: "y",
            ..
        }) => assert_eq!(element, "frame 1 vertex 2"),
        other => panic!("{other:?}"),
    }
}

// ---------------------------------------------------------------- index ranges

#[test]
fn out_of_range_ply_face_index_names_face_index_and_count() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "oor.ply",
        ply_ascii(QUAD_VERTICES, "3 0 1 2\n3 0 2 4\n", 4, 2),
    );
    match load(&path) {
        Err(MeshIoError::IndexOutOfRange {
            element,
            index: 4,
            vertex_count: 4,
            line: Some(15),
            ..
        }) => {
            assert_eq!(element, "face 1");
        }
        other => panic!("{other:?}"),
    }
    let negative = write(
        dir.path(),
        "neg.ply",
        ply_ascii(QUAD_VERTICES, "3 0 -1 2\n", 4, 1),
    );
    assert!(matches!(
        load(&negative),
        Err(MeshIoError::IndexOutOfRange { index: -1, .. })
    ));
}

#[test]
fn out_of_range_obj_indices_positive_negative_and_zero() {
    let dir = tempfile::tempdir().unwrap();
    for (face, index) in [
        ("f 1 2 4", 4),
        ("f 1 2 -4", -4),
        ("f 0 1 2", 0),
        ("f 1/5 2/1 3/1", 5),
    ] {
        let text = format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n{face}\n");
        let path = write(dir.path(), "oor.obj", text);
        match load(&path) {
            Err(MeshIoError::IndexOutOfRange {
                index: i,
                line: Some(5),
                ..
            }) => assert_eq!(i, index, "{face}"),
            other => panic!("{face}: {other:?}"),
        }
    }
}

#[test]
fn obj_negative_indices_and_forward_references_resolve() {
    let dir = tempfile::tempdir().unwrap();
    // The face refers to vertices defined after it (legal in practice) and relative ones.
    let path = write(
        dir.path(),
        "rel.obj",
        "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf -3 -1 -2\n",
    );
    let (mesh, _) = load(&path).unwrap();
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
}

// ---------------------------------------------------------------- empty meshes

#[test]
fn empty_meshes_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("empty.obj", String::new()),
        ("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n".to_string()),
        ("empty.ply", ply_ascii("", "", 0, 0)),
        ("nofaces.ply", ply_ascii("0 0 0\n", "", 1, 0)),
    ];
    for (name, text) in cases {
        let path = write(dir.path(), name, text);
        assert!(
            matches!(load(&path), Err(MeshIoError::EmptyMesh { .. })),
            "{name}"
        );
    }
    let empty_folder = dir.path().join("frames");
    std::fs::create_dir(&empty_folder).unwrap();
    assert!(matches!(
        load_animation(&empty_folder, &AnimationOptions::default()),
        Err(MeshIoError::FrameFolder { .. })
    ));
}

// ---------------------------------------------------------------- huge or truncated counts

#[test]
fn huge_header_counts_fail_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let ascii = write(
        dir.path(),
        "huge.ply",
        ply_ascii(QUAD_VERTICES, "3 0 1 2\n", 1 << 40, 1),
    );
    assert!(
        matches!(load(&ascii), Err(MeshIoError::CountTooLarge { count, .. }) if count == 1 << 40)
    );
    let mut bin = ply_binary(false, &[[0.0; 3]; 3], &[&[0, 1, 2]]);
    let text = String::from_utf8_lossy(&bin).replace("element face 1", "element face 99999999999");
    bin = text.into_bytes();
    let path = write(dir.path(), "hugefaces.ply", bin);
    assert!(matches!(
        load(&path),
        Err(MeshIoError::CountTooLarge { .. })
    ));
    // u64 overflow of count × row size.
    let overflow = write(
        dir.path(),
        "overflow.ply",
        ply_ascii(QUAD_VERTICES, "", u64::MAX as usize, 0),
    );
    assert!(matches!(
        load(&overflow),
        Err(MeshIoError::CountTooLarge { .. })
    ));
    // A list length of 4 294 967 295 with little data behind it.
    let mut list = ply_binary(false, &[[0.0; 3]; 3], &[]);
    list = String::from_utf8_lossy(&list)
        .replace(
            "element face 0\nproperty list uchar int",
            "element face 1\nproperty list uint int",
        )
        .into_bytes();
    list.extend_from_slice(&u32::MAX.to_le_bytes());
    list.extend_from_slice(&[0; 12]);
    let path = write(dir.path(), "hugelist.ply", list);
    assert!(matches!(
        load(&path),
        Err(MeshIoError::Truncated {
            bytes_needed: 17_179_869_180,
            ..
        })
    ));
    // .npy claiming 2^40 values.
    let dict = b"{'descr': '<f4', 'fortran_order': False, 'shape': (1099511627776, 3), }\n";
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    bytes.extend_from_slice(dict);
    bytes.extend_from_slice(&[0; 24]);
    let npy = write(dir.path(), "huge.npy", bytes);
    assert!(matches!(
        meshio::read_npy_f32(&npy),
        Err(MeshIoError::Npy { .. })
    ));
}

#[test]
fn empty_elements_with_huge_counts_are_harmless() {
    // An element without properties occupies no bytes, whatever its count.
    let dir = tempfile::tempdir().unwrap();
    let text = ply_ascii(QUAD_VERTICES, "3 0 1 2\n", 4, 1)
        .replace("end_header", "element nothing 1099511627776\nend_header");
    let (mesh, report) = load(&write(dir.path(), "nothing.ply", text)).unwrap();
    assert_eq!(mesh.triangle_count(), 1);
    assert!(
        report
            .skipped_properties
            .iter()
            .any(|p| p.starts_with("element nothing"))
    );
}

#[test]
fn property_less_face_element_with_a_huge_count_is_an_error_not_an_abort() {
    // Issue #12, C1: `element face 2^40` with no property lines passed the size check (a row
    // of no properties occupies no bytes) and then reserved 2^40 triangles.
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1099511627776\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    let err = load(&write(dir.path(), "c1.ply", text)).unwrap_err();
    let message = err.to_string();
    assert!(message.contains("c1.ply"), "{message}");
    assert!(message.contains("face"), "{message}");
}

fn npy_with_shape(dir: &Path, name: &str, shape: &str) -> PathBuf {
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}\n");
    let mut bytes = b"\x93NUMPY\x01\x00".to_vec();
    bytes.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    bytes.extend_from_slice(dict.as_bytes());
    write(dir, name, bytes)
}

#[test]
fn npy_animation_without_vertices_or_frames_is_refused_before_allocating() {
    // Issue #12, C2: shape (2^40, 0, 3) and no data allocated one empty frame per claimed frame.
    let dir = tempfile::tempdir().unwrap();
    for (name, shape, what) in [
        ("c2.npy", "(1099511627776, 0, 3)", "no vertices"),
        ("c2b.npy", "(67108864, 0, 3)", "no vertices"),
        ("c2c.npy", "(0, 5, 3)", "no frames"),
    ] {
        let path = npy_with_shape(dir.path(), name, shape);
        let err = load_animation(&path, &AnimationOptions::default()).unwrap_err();
        let message = err.to_string();
        assert!(
            message.contains(name) && message.contains(what),
            "{message}"
        );
    }
}

#[test]
fn truncated_binary_ply_names_offset_and_length() {
    let dir = tempfile::tempdir().unwrap();
    let full = ply_binary(
        false,
        &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        &[&[0, 1, 2], &[2, 1, 0]],
    );
    let cut = &full[..full.len() - 3];
    let path = write(dir.path(), "cut.ply", cut);
    match load(&path) {
        Err(MeshIoError::Truncated {
            element, file_len, ..
        }) => {
            assert!(element.starts_with("face 1"), "{element}");
            assert_eq!(file_len, cut.len() as u64);
        }
        other => panic!("{other:?}"),
    }
    // Cut inside the vertex block: caught by the header size check.
    let path = write(dir.path(), "cut2.ply", &full[..full.len() - 30]);
    assert!(matches!(
        load(&path),
        Err(MeshIoError::CountTooLarge { .. } | MeshIoError::Truncated { .. })
    ));
}

#[test]
fn truncated_ascii_ply_names_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "cut.ply",
        ply_ascii(QUAD_VERTICES, "3 0 1 2\n3 0 2", 4, 2),
    );
    assert!(
        matches!(
            load(&path),
            Err(MeshIoError::UnexpectedEof { line: Some(15), .. })
        ),
        "{:?}",
        load(&path)
    );
}

// ---------------------------------------------------------------- malformed text

#[test]
fn malformed_numbers_name_the_line_and_token() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(
        dir.path(),
        "bad.obj",
        "v 0 0 0\nv 1 0 0\nv 1.0 abc 2\nf 1 2 3\n",
    );
    match load(&obj) {
        Err(MeshIoError::Malformed {
            line: Some(3),
            token,
            ..
        }) => assert_eq!(token, "abc"),
        other => panic!("{other:?}"),
    }
    let ply = write(
        dir.path(),
        "bad.ply",
        ply_ascii("0 0 0\n1 0 0\n0 1 zero\n", "3 0 1 2\n", 3, 1),
    );
    assert!(matches!(
        load(&ply),
        Err(MeshIoError::Malformed { line: Some(12), .. })
    ));
    let face = write(
        dir.path(),
        "badface.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3/1/1/1\n",
    );
    assert!(matches!(
        load(&face),
        Err(MeshIoError::Malformed { line: Some(4), .. })
    ));
    let short = write(dir.path(), "short.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
    assert!(matches!(
        load(&short),
        Err(MeshIoError::ShortFace {
            corners: 2,
            line: Some(3),
            ..
        })
    ));
}

#[test]
fn malformed_ply_headers() {
    let dir = tempfile::tempdir().unwrap();
    let good = ply_ascii(QUAD_VERTICES, "3 0 1 2\n", 4, 1);
    let cases = [
        ("magic", good.replacen("ply", "plx", 1)),
        (
            "format",
            good.replace("format ascii 1.0", "format utf8 1.0"),
        ),
        ("no end", good.replace("end_header", "end_headr")),
        (
            "float list count",
            good.replace("list uchar int", "list float int"),
        ),
        (
            "float index items",
            good.replace("list uchar int", "list uchar float"),
        ),
        (
            "property first",
            good.replace("element vertex 4\n", "").replacen(
                "property float x\n",
                "property float x\nelement vertex 4\n",
                1,
            ),
        ),
        ("missing z", good.replace("property float z\n", "")),
        (
            "duplicate element",
            good.replace("end_header", "element vertex 1\nend_header"),
        ),
    ];
    for (name, text) in cases {
        let path = write(dir.path(), "h.ply", text);
        assert!(
            matches!(load(&path), Err(MeshIoError::InvalidHeader { .. })),
            "{name}: {:?}",
            load(&path)
        );
    }
}

#[test]
fn unsupported_extension() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(dir.path(), "mesh.stl", "solid");
    assert!(
        matches!(load(&path), Err(MeshIoError::UnsupportedFormat { extension, .. }) if extension == "stl")
    );
    // Alembic is named, with the formats to export instead.
    let path = write(dir.path(), "cloth.abc", "Ogawa");
    let message = meshio::load_animation(&path, &meshio::AnimationOptions::default())
        .unwrap_err()
        .to_string();
    for needle in ["cloth.abc", "Alembic", ".pc2", "--topology"] {
        assert!(message.contains(needle), "{needle:?} missing: {message}");
    }
}

// ---------------------------------------------------------------- degenerate, duplicate, unreferenced

#[test]
fn degenerate_and_zero_area_triangles_are_reported_and_removed_on_request() {
    let dir = tempfile::tempdir().unwrap();
    // v4 duplicates v1's position; v5 lies on the segment v0-v1.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 1 0 0\nv 0.5 0 0\n\
                f 1 2 3\nf 1 1 2\nf 2 5 3\nf 1 6 2\nf 2 4 3\n";
    let path = write(dir.path(), "degenerate.obj", text);
    let (mesh, report) = load(&path).unwrap();
    assert_eq!(mesh.triangle_count(), 5);
    let kinds: Vec<(u32, DegenerateKind)> = report
        .degenerate_triangles
        .iter()
        .map(|d| (d.triangle, d.kind))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (1, DegenerateKind::RepeatedIndex),
            (2, DegenerateKind::ZeroArea),
            (3, DegenerateKind::ZeroArea)
        ]
    );
    assert_eq!(report.duplicate_positions, 1);
    // v5 is only in a degenerate triangle: it takes its neighbours' (v0 and v1) normal, +z
    // (the documented fallback).
    assert_close(mesh.normals[5], Vec3::Z, 1e-6);
    let options = LoadOptions {
        remove_degenerate: true,
        remove_unreferenced: true,
        ..LoadOptions::default()
    };
    let (clean, report) = load_mesh(&path, &options).unwrap();
    assert_eq!(clean.triangles.len(), 2);
    assert_eq!(report.removed_triangles, 3);
    // v4 and v5 were referenced only by degenerate triangles.
    assert_eq!(report.unreferenced_vertices, vec![4, 5]);
    assert_eq!(clean.vertex_count(), 4);
    assert!(clean.normals.iter().all(|n| (*n - Vec3::Z).length() < 1e-6));
}

#[test]
fn only_degenerate_triangles_left_is_an_error_after_removal() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "line.obj",
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
    );
    let (mesh, report) = load(&path).unwrap();
    assert_eq!(report.degenerate_triangles.len(), 1);
    assert!(mesh.normals.iter().all(|n| *n == Vec3::ZERO));
    let options = LoadOptions {
        remove_degenerate: true,
        ..LoadOptions::default()
    };
    assert!(matches!(
        load_mesh(&path, &options),
        Err(MeshIoError::EmptyMesh { .. })
    ));
}

/// A quad in a tilted plane with a zero-thickness flap on its diagonal: the triangles
/// [1, 3, 4] and [3, 1, 4] over the same vertices with opposite windings (70 such pairs in
/// `bun_zipper_res3.ply`), its tip at (a, b) over the quad at height h.
fn flap_mesh_at(a: f32, b: f32, h: f32) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec3) {
    let u = Vec3::new(1.0, 0.1, 0.3);
    let v = Vec3::new(-0.2, 0.9, 0.7);
    let at = |a: f32, b: f32| Vec3::new(0.13, -0.71, 0.37) + u * a + v * b;
    let plane = u.cross(v).normalize();
    let positions = vec![
        at(0.0, 0.0),
        at(1.0, 0.0),
        at(1.0, 1.0),
        at(0.0, 1.0),
        at(a, b) + plane * h,
    ];
    let triangles = vec![[0, 1, 3], [1, 2, 3], [1, 3, 4], [3, 1, 4]];
    (positions, triangles, plane)
}

fn flap_mesh() -> (Vec<Vec3>, Vec<[u32; 3]>, Vec3) {
    flap_mesh_at(0.537, 0.411, 0.29)
}

#[test]
fn back_to_back_flap_tip_takes_its_neighbours_normal_not_rounding_noise() {
    // Tips at off-grid places: the flap's two normals cancel to exactly zero at some and to
    // rounding noise (1e-16) at others, whose direction is arbitrary.
    let tips = [
        (0.134, 0.847, 0.764),
        (0.255, 0.495, 0.449),
        (0.652, 0.789, 0.094),
        (0.722, 0.229, 0.945),
        (0.901, 0.031, 0.025),
        (0.541, 0.939, 0.381),
        (0.537, 0.411, 0.29),
    ];
    for (a, b, h) in tips {
        let (positions, triangles, plane) = flap_mesh_at(a, b, h);
        for weighting in [NormalWeighting::Angle, NormalWeighting::Area] {
            let normals = compute_normals(&positions, &triangles, weighting);
            // The flap cancels on the quad's vertices: all four keep the plane's normal …
            for n in &normals[..4] {
                assert_close(*n, plane, 1e-6);
            }
            // … and the tip, whose own normals give no direction, takes theirs (v1 and v3).
            assert_close(normals[4], plane, 1e-6);
        }
    }
    let counted = meshio::count_repeated_triangles(&flap_mesh().1);
    assert_eq!((counted.repeated, counted.back_to_back), (0, 1));
}

#[test]
fn a_fin_of_back_to_back_pairs_fills_from_the_surface_inwards() {
    let (mut positions, mut triangles, plane) = flap_mesh();
    // Two more pairs: [3, 4, 5] beside the first flap, and [4, 5, 6], whose tip 6 touches
    // only flap vertices — it has a normal only once 4 and 5 have one (a second round).
    positions.push(positions[4] + Vec3::new(0.21, 0.17, -0.05));
    positions.push(positions[4] + Vec3::new(0.08, 0.33, 0.19));
    triangles.extend([[3, 4, 5], [4, 3, 5], [4, 5, 6], [5, 4, 6]]);
    let normals = compute_normals(&positions, &triangles, NormalWeighting::Angle);
    for n in &normals {
        assert_close(*n, plane, 1e-6);
    }
    let counted = meshio::count_repeated_triangles(&triangles);
    assert_eq!((counted.repeated, counted.back_to_back), (0, 3));
}

#[test]
fn isolated_back_to_back_pair_has_no_normal() {
    let (positions, _, _) = flap_mesh();
    // The flap alone: every vertex's normals cancel and no neighbour has one to lend.
    let normals = compute_normals(&positions, &[[1, 3, 4], [3, 1, 4]], NormalWeighting::Angle);
    assert!(normals.iter().all(|n| *n == Vec3::ZERO), "{normals:?}");
}

#[test]
fn repeated_triangles_and_back_to_back_pairs_are_told_apart_by_winding() {
    // [1, 2, 0] is [0, 1, 2] rotated (a repeat), [2, 1, 0] and [0, 2, 1] are reversed: two
    // windings of one vertex set, written 2 + 2 times, make two pairs; a repeated index is a
    // degenerate triangle, not counted here.
    let triangles = [
        [0, 1, 2],
        [1, 2, 0],
        [2, 1, 0],
        [0, 2, 1],
        [3, 4, 5],
        [0, 0, 1],
    ];
    let counted = meshio::count_repeated_triangles(&triangles);
    assert_eq!((counted.repeated, counted.back_to_back), (0, 2));
    let counted = meshio::count_repeated_triangles(&[[5, 6, 7], [6, 7, 5], [7, 5, 6], [7, 6, 5]]);
    assert_eq!((counted.repeated, counted.back_to_back), (2, 1));
}

#[test]
fn duplicate_positions_count_signed_zeros_as_equal() {
    let positions = [
        Vec3::ZERO,
        Vec3::new(-0.0, 0.0, -0.0),
        Vec3::X,
        Vec3::X,
        Vec3::X,
    ];
    assert_eq!(meshio::count_duplicate_positions(&positions), 3);
}

#[test]
fn unreferenced_vertices_are_kept_in_place_by_default_and_remapped_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let path = write(
        dir.path(),
        "unref.obj",
        "v 9 9 9\nv 0 0 0\nv 8 8 8\nv 1 0 0\nv 0 1 0\nf 2 4 5\n",
    );
    let (mesh, report) = load(&path).unwrap();
    assert_eq!(mesh.vertex_count(), 5);
    assert_eq!(report.unreferenced_vertices, vec![0, 2]);
    assert_eq!(mesh.positions[2], Vec3::splat(8.0));
    let options = LoadOptions {
        remove_unreferenced: true,
        ..LoadOptions::default()
    };
    let (mesh, report) = load_mesh(&path, &options).unwrap();
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(
        report.vertex_remap,
        Some(vec![None, Some(0), None, Some(1), Some(2)])
    );
}

// ---------------------------------------------------------------- strips and polygons

fn strip_ply(dir: &Path, strip: &[i32]) -> PathBuf {
    let header = format!(
        "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n\
         element tristrips 1\nproperty list int int vertex_indices\nend_header\n\
         0 0 0\n0 1 0\n1 0 0\n1 1 0\n2 0 0\n2 1 0\n{} {}\n",
        strip.len(),
        strip
            .iter()
            .map(i32::to_string)
            .collect::<Vec<_>>()
            .join(" ")
    );
    write(dir, "strip.ply", header)
}

#[test]
fn strip_restarts_at_start_end_and_consecutive() {
    let dir = tempfile::tempdir().unwrap();
    // Vertices zig-zag along x: 0 2 4 at y = 0, 1 3 5 at y = 1.
    let continuous = load(&strip_ply(dir.path(), &[0, 1, 2, 3, 4, 5])).unwrap().0;
    assert_eq!(
        continuous.triangles,
        vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]]
    );
    let restarted = load(&strip_ply(
        dir.path(),
        &[-1, -1, 0, 1, 2, 3, -1, -1, 2, 3, 4, 5, -1],
    ))
    .unwrap()
    .0;
    assert_eq!(
        restarted.triangles,
        vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]]
    );
    // All triangles face the same way (alternating winding): normals are all -z here.
    for n in compute_normals(
        &restarted.positions,
        &restarted.triangles,
        NormalWeighting::Area,
    ) {
        assert_close(n, -Vec3::Z, 1e-6);
    }
    let bad = strip_ply(dir.path(), &[0, 1, -2, 3]);
    assert!(matches!(
        load(&bad),
        Err(MeshIoError::IndexOutOfRange { index: -2, .. })
    ));
}

#[test]
fn mixed_polygon_sizes_are_fan_triangulated() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(
        dir.path(),
        "mixed.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv -1 0.5 0\nf 1 2 3\nf 1 2 3 4\nf 1 2 3 4 5\n",
    );
    let (mesh, report) = load(&obj).unwrap();
    assert_eq!(
        mesh.triangles,
        vec![
            [0, 1, 2],
            [0, 1, 2],
            [0, 2, 3],
            [0, 1, 2],
            [0, 2, 3],
            [0, 3, 4]
        ]
    );
    assert_eq!(report.polygons_triangulated, 2);
    assert_eq!(report.file_face_count, 3);
    let ply = write(
        dir.path(),
        "mixed.ply",
        ply_ascii(
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n-1 0.5 0\n",
            "3 0 1 2\n4 0 1 2 3\n5 0 1 2 3 4\n",
            5,
            3,
        ),
    );
    assert_eq!(load(&ply).unwrap().0.triangles, mesh.triangles);
}

// ---------------------------------------------------------------- line endings and encodings

#[test]
fn crlf_line_endings_and_missing_trailing_newline() {
    let dir = tempfile::tempdir().unwrap();
    let unix = write(
        dir.path(),
        "unix.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let crlf = write(
        dir.path(),
        "crlf.obj",
        "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n",
    );
    let no_newline = write(dir.path(), "nonl.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3");
    let reference = load(&unix).unwrap().0;
    assert_eq!(load(&crlf).unwrap().0, reference);
    assert_eq!(load(&no_newline).unwrap().0, reference);
    let ply = ply_ascii("0 0 0\n1 0 0\n0 1 0\n", "3 0 1 2", 3, 1);
    let ply_crlf = write(dir.path(), "crlf.ply", ply.replace('\n', "\r\n"));
    let ply_nonl = write(dir.path(), "nonl.ply", ply);
    assert_eq!(load(&ply_crlf).unwrap().0, reference);
    assert_eq!(load(&ply_nonl).unwrap().0, reference);
}
