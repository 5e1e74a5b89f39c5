//! Format details: byte orders, PLY property handling, OBJ per-corner attributes.

mod common;

use std::path::Path;

use common::{ply_ascii, ply_binary, write};
use glam::Vec3;
use meshio::{AttributeStatus, LoadOptions, MeshIoError, load_mesh};

fn load(path: &Path) -> Result<(meshio::Mesh, meshio::LoadReport), MeshIoError> {
    load_mesh(path, &LoadOptions::default())
}

#[test]
fn binary_big_and_little_endian_match_ascii() {
    let dir = tempfile::tempdir().unwrap();
    let vertices = [
        [0.0, 0.0, 0.0],
        [1.5, 0.0, 0.25],
        [0.0, 1.0, -2.0],
        [1.0, 1.0, 1.0],
    ];
    let faces: [&[i32]; 2] = [&[0, 1, 2], &[1, 3, 2]];
    let le = load(&write(
        dir.path(),
        "le.ply",
        ply_binary(false, &vertices, &faces),
    ))
    .unwrap();
    let be = load(&write(
        dir.path(),
        "be.ply",
        ply_binary(true, &vertices, &faces),
    ))
    .unwrap();
    let ascii = load(&write(
        dir.path(),
        "a.ply",
        ply_ascii(
            "0 0 0\n1.5 0 0.25\n0 1 -2\n1 1 1\n",
            "3 0 1 2\n3 1 3 2\n",
            4,
            2,
        ),
    ))
    .unwrap();
    assert_eq!(le.0, ascii.0);
    assert_eq!(be.0, ascii.0);
    assert_eq!(be.1.format, meshio::SourceFormat::PlyBinaryBigEndian);
}

#[test]
fn ply_properties_normals_uvs_extra_and_other_index_types() {
    let dir = tempfile::tempdir().unwrap();
    let text = "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty double x\nproperty double y\n\
                property double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n\
                property uchar red\nproperty list uchar float extra\n\
                element face 1\nproperty uchar flags\nproperty list ushort uint vertex_index\nelement edge 1\n\
                property int vertex1\nproperty int vertex2\nend_header\n\
                0 0 0 0 0 2 0 0 255 2 1.5 2.5\n1 0 0 0 0 1 1 0 255 0\n0 1 0 0 0 1 0 1 255 1 7\n9 3 0 1 2\n0 1\n";
    let (mesh, report) = load(&write(dir.path(), "props.ply", text)).unwrap();
    assert_eq!(mesh.triangles, vec![[0, 1, 2]]);
    assert!(!report.normals_computed);
    assert_eq!(mesh.normals[0], Vec3::Z); // normalised from (0, 0, 2)
    assert_eq!(mesh.uvs.as_ref().unwrap()[2], glam::Vec2::new(0.0, 1.0));
    for skipped in ["vertex.red", "vertex.extra", "face.flags"] {
        assert!(
            report.skipped_properties.iter().any(|p| p == skipped),
            "{skipped}: {:?}",
            report.skipped_properties
        );
    }
}

#[test]
fn obj_per_corner_attributes_kept_when_consistent_dropped_at_seams() {
    let dir = tempfile::tempdir().unwrap();
    let consistent = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1\nf 2/4/1 1/1/1 3/3/1\n";
    let (mesh, report) = load(&write(dir.path(), "ok.obj", consistent)).unwrap();
    assert_eq!(report.uvs, AttributeStatus::Loaded);
    assert_eq!(mesh.uvs.unwrap()[1], glam::Vec2::new(1.0, 0.0));
    assert_eq!(report.file_normals, AttributeStatus::Loaded);
    assert!(!report.normals_computed);
    let seam = consistent.replace("vt 1 0\nvn", "vt 0.5 0.5\nvn");
    let (mesh, report) = load(&write(dir.path(), "seam.obj", seam)).unwrap();
    assert!(mesh.uvs.is_none());
    assert_eq!(
        report.uvs,
        AttributeStatus::DroppedPerCorner {
            conflicting_vertices: 1,
            missing_corners: 0
        }
    );
    // Readable as printed by `cloth-vis inspect` and in the notes (not the Debug form).
    assert_eq!(
        report.uvs.to_string(),
        "dropped: per face corner, 1 vertex whose corners differ"
    );
    assert!(
        report.notes.iter().any(|n| n.starts_with(
            "texture coordinates dropped: per face corner, 1 vertex whose corners differ ("
        )),
        "{:?}",
        report.notes
    );
    let partial = AttributeStatus::DroppedPerCorner {
        conflicting_vertices: 0,
        missing_corners: 2,
    };
    assert_eq!(
        partial.to_string(),
        "dropped: per face corner, 2 corners without a value"
    );
    assert_eq!(AttributeStatus::Absent.to_string(), "none in the file");
}

#[test]
fn formats_read_as_words_in_reports() {
    use meshio::SourceFormat;
    assert_eq!(SourceFormat::PlyAscii.to_string(), "ascii PLY");
    assert_eq!(
        SourceFormat::PlyBinaryBigEndian.to_string(),
        "binary big-endian PLY"
    );
    assert_eq!(
        SourceFormat::ObjFrames.to_string(),
        "a folder of OBJ frames"
    );
    assert_eq!(SourceFormat::Glb.to_string(), "glTF binary");
    assert_eq!(SourceFormat::Pc2.to_string(), "PC2 point cache");
}
