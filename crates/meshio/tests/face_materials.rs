//! Per-face materials (garment parts, thesis §5.6): OBJ `usemtl` and glTF primitive materials,
//! one entry per triangle of `load_mesh`, on crafted files and a real multi-material glTF.

mod common;

use common::{base64, write};
use meshio::{LoadOptions, load_face_materials, load_mesh, load_mesh_split_seams};
use serde_json::json;

#[test]
fn obj_usemtl_names_every_triangle_in_load_order_polygons_included() {
    let dir = tempfile::tempdir().unwrap();
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n\
               f 1/1 2/2 3/3\n\
               usemtl front panel\nf 1/1 2/2 3/3 4/4\n\
               usemtl sleeve\nf 2/5 5/2 3/3\n\
               usemtl front panel\nf 3/3 4/4 1/1\n";
    let path = write(dir.path(), "parts.obj", obj);
    let m = load_face_materials(&path).unwrap().unwrap();
    assert_eq!(m.names, ["front panel", "sleeve"]);
    assert_eq!(
        m.per_triangle,
        [None, Some(0), Some(0), Some(1), Some(0)],
        "the quad is two triangles of its material"
    );
    assert_eq!(m.index_of("sleeve"), Some(1));
    assert_eq!(m.index_of("collar"), None);
    // Same count as the mesh, with and without UV seams split (vertex 2 has two UVs).
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(mesh.triangles.len(), m.per_triangle.len());
    let (split, _) = load_mesh_split_seams(&path, &LoadOptions::default()).unwrap();
    assert!(split.mesh.positions.len() > 5, "the seam was split");
    assert_eq!(split.mesh.triangles.len(), m.per_triangle.len());
    // A PLY has no materials.
    let ply = write(
        dir.path(),
        "t.ply",
        common::ply_ascii("0 0 0\n1 0 0\n0 1 0\n", "3 0 1 2\n", 3, 1),
    );
    assert_eq!(load_face_materials(&ply).unwrap(), None);
}

#[test]
fn gltf_primitive_materials_follow_the_merged_triangles() {
    let dir = tempfile::tempdir().unwrap();
    // One mesh, three primitives: material 1, none, material 0; two triangles, one, one.
    let positions: Vec<f32> = vec![0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    let quad: Vec<u16> = vec![0, 1, 2, 0, 2, 3];
    let tri: Vec<u16> = vec![0, 1, 2];
    let mut bin: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    let quad_at = bin.len();
    bin.extend(quad.iter().flat_map(|v| v.to_le_bytes()));
    let tri_at = bin.len();
    bin.extend(tri.iter().flat_map(|v| v.to_le_bytes()));
    bin.extend([0u8; 2]);
    let doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "materials": [{"name": "cotton"}, {}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0}, "indices": 1, "material": 1},
            {"attributes": {"POSITION": 0}, "indices": 2},
            {"attributes": {"POSITION": 0}, "indices": 2, "material": 0}
        ]}],
        "buffers": [{"byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bin))}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 48},
            {"buffer": 0, "byteOffset": quad_at, "byteLength": 12},
            {"buffer": 0, "byteOffset": tri_at, "byteLength": 6}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
            {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}
        ]
    });
    let path = write(dir.path(), "parts.gltf", doc.to_string());
    let m = load_face_materials(&path).unwrap().unwrap();
    assert_eq!(m.names, ["cotton", "material 1"]);
    assert_eq!(m.per_triangle, [Some(1), Some(1), None, Some(0)]);
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(mesh.triangles.len(), 4);
}

#[test]
fn a_real_multi_material_gltf_has_one_material_per_loaded_triangle() {
    let Some(path) = test_data::shared_file("anim/gltf/BrainStem.glb") else {
        return;
    };
    let m = load_face_materials(&path).unwrap().unwrap();
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    assert_eq!(m.per_triangle.len(), mesh.triangles.len());
    let used: std::collections::BTreeSet<u32> = m.per_triangle.iter().flatten().copied().collect();
    assert!(
        used.len() > 1,
        "BrainStem has several materials: {:?}",
        m.names
    );
    assert!(used.iter().all(|&i| (i as usize) < m.names.len()));
}
