//! The real static meshes of shared/data load with the counts SOURCES.md states.

mod common;

use common::{directed_edges, undirected_edges};
use meshio::{AttributeStatus, LoadOptions, SourceFormat, load_mesh};

fn load(relative: &str) -> Option<(meshio::Mesh, meshio::LoadReport)> {
    let path = test_data::shared_file(relative)?;
    Some(load_mesh(&path, &LoadOptions::default()).unwrap_or_else(|e| panic!("{relative}: {e}")))
}

#[track_caller]
fn assert_unit_or_zero(normals: &[glam::Vec3]) {
    for (i, n) in normals.iter().enumerate() {
        let len = n.length();
        assert!(
            n.is_finite() && (len == 0.0 || (len - 1.0).abs() < 1e-5),
            "normal {i} = {n} (length {len})"
        );
    }
}

#[test]
fn bunny_zipper_counts_and_unreferenced_vertices_kept_in_place() {
    let Some((mesh, report)) = load("meshes/bun_zipper.ply") else {
        return;
    };
    assert_eq!(report.format, SourceFormat::PlyAscii);
    assert_eq!(mesh.vertex_count(), 35_947);
    assert_eq!(mesh.triangle_count(), 69_451);
    assert_eq!(report.unreferenced_vertices.len(), 1_113);
    assert!(report.normals_computed);
    assert!(
        report
            .skipped_properties
            .contains(&"vertex.confidence".to_string())
    );
    assert!(
        report
            .skipped_properties
            .contains(&"vertex.intensity".to_string())
    );
    assert_unit_or_zero(&mesh.normals);
    // Unreferenced vertices get exactly zero normals; referenced ones unit normals.
    for &v in &report.unreferenced_vertices {
        assert_eq!(mesh.normals[v as usize], glam::Vec3::ZERO);
    }
    // 223 boundary edges (SOURCES.md caveats).
    let boundary = undirected_edges(&mesh.triangles)
        .values()
        .filter(|&&n| n == 1)
        .count();
    assert_eq!(boundary, 223);
    // The first vertex line is "-0.0378297 0.12794 0.00447467": positions line up with the file.
    assert_eq!(
        mesh.positions[0],
        glam::Vec3::new(-0.0378297, 0.12794, 0.00447467)
    );
}

#[test]
fn bunny_zipper_cleanup_removes_exactly_the_unreferenced_vertices() {
    let Some(path) = test_data::shared_file("meshes/bun_zipper.ply") else {
        return;
    };
    let (full, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    let options = LoadOptions {
        remove_unreferenced: true,
        ..LoadOptions::default()
    };
    let (mesh, report) = load_mesh(&path, &options).unwrap();
    assert_eq!(mesh.vertex_count(), 34_834);
    assert_eq!(report.removed_vertices, 1_113);
    let remap = report.vertex_remap.unwrap();
    for (old, new) in remap.iter().enumerate() {
        if let Some(new) = new {
            assert_eq!(mesh.positions[*new as usize], full.positions[old]);
        }
    }
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let old = full.triangles[t];
        assert_eq!(*tri, old.map(|i| remap[i as usize].unwrap()));
    }
}

#[test]
fn bunny_decimations_counts_and_unreferenced() {
    for (file, vertices, triangles, unreferenced) in [
        ("meshes/bun_zipper_res2.ply", 8_171, 16_301, 25),
        ("meshes/bun_zipper_res3.ply", 1_889, 3_851, 2),
        ("meshes/bun_zipper_res4.ply", 453, 948, 0),
    ] {
        let Some((mesh, report)) = load(file) else {
            return;
        };
        assert_eq!(
            (mesh.vertex_count(), mesh.triangle_count()),
            (vertices, triangles),
            "{file}"
        );
        assert_eq!(report.unreferenced_vertices.len(), unreferenced, "{file}");
        assert_unit_or_zero(&mesh.normals);
    }
}

#[test]
fn dragon_res2_counts() {
    let Some((mesh, report)) = load("meshes/dragon_vrip_res2.ply") else {
        return;
    };
    assert_eq!(mesh.vertex_count(), 100_250);
    assert_eq!(mesh.triangle_count(), 202_520);
    assert_eq!(report.unreferenced_vertices.len(), 43);
    assert!(
        report.skipped_properties.is_empty(),
        "{:?}",
        report.skipped_properties
    );
}

#[test]
fn igea_strips_decode_to_a_closed_consistently_oriented_manifold() {
    let Some((mesh, report)) = load("meshes/igea.ply") else {
        return;
    };
    assert_eq!(report.format, SourceFormat::PlyBinaryLittleEndian);
    assert_eq!(mesh.vertex_count(), 134_345);
    assert_eq!(mesh.triangle_count(), 268_686);
    assert!(report.unreferenced_vertices.is_empty());
    // Closed manifold: every undirected edge in exactly two triangles.
    let edges = undirected_edges(&mesh.triangles);
    assert!(
        edges.values().all(|&n| n == 2),
        "{} edges not shared by exactly 2 triangles",
        edges.values().filter(|&&n| n != 2).count()
    );
    // Alternating winding decoded correctly: each directed edge once, its reverse once.
    let directed = directed_edges(&mesh.triangles);
    assert!(
        directed
            .iter()
            .all(|(&(a, b), &n)| n == 1 && directed.get(&(b, a)) == Some(&1))
    );
    // Euler characteristic of a closed orientable surface is even: V - E + F = 2 - 2g.
    let chi = mesh.vertex_count() as i64 - edges.len() as i64 + mesh.triangle_count() as i64;
    assert_eq!(chi % 2, 0);
    let (lo, hi) = mesh.bounding_box().unwrap();
    assert!(
        lo.min_element() > -0.06 && hi.max_element() < 0.06,
        "{lo} {hi}"
    );
}

#[test]
fn teapot_counts_and_duplicates() {
    let Some((mesh, report)) = load("meshes/teapot.obj") else {
        return;
    };
    assert_eq!(mesh.vertex_count(), 3_644);
    assert_eq!(mesh.triangle_count(), 6_320);
    assert_eq!(report.duplicate_positions, 403);
    assert!(report.normals_computed);
    assert_eq!(report.uvs, AttributeStatus::Absent);
    let boundary = undirected_edges(&mesh.triangles)
        .values()
        .filter(|&&n| n == 1)
        .count();
    assert_eq!(boundary, 1_036);
}

#[test]
fn garment_skips_vv_and_t_lines_and_drops_seamed_uvs() {
    let Some((mesh, report)) = load("meshes/garments/dress-victor-iso-draped.obj") else {
        return;
    };
    assert_eq!(mesh.vertex_count(), 4_589);
    assert_eq!(mesh.triangle_count(), 8_958);
    assert_eq!(report.skipped_keywords.get("vv"), Some(&4_589));
    assert_eq!(report.skipped_keywords.get("t"), Some(&8_958));
    let boundary = undirected_edges(&mesh.triangles)
        .values()
        .filter(|&&n| n == 1)
        .count();
    assert_eq!(boundary, 222);
    // Sewing-pattern UVs differ across the merged seams, so no per-vertex UV exists.
    match report.uvs {
        AttributeStatus::DroppedPerCorner {
            conflicting_vertices,
            missing_corners,
        } => {
            assert!(conflicting_vertices > 0);
            assert_eq!(missing_corners, 0);
            assert!(mesh.uvs.is_none());
        }
        other => panic!("expected dropped UVs, got {other:?}"),
    }
}
