//! OBJ UV seams kept by splitting vertices ([`meshio::load_mesh_split_seams`]): every face
//! corner gets exactly the `vt` the file gives it, the file's vertices keep their indices, the
//! copies map back, and normals are those of the welded mesh.

use glam::{Vec2, Vec3};
use meshio::{LoadOptions, load_mesh, load_mesh_split_seams};

/// Per-corner `vt` of a parsed OBJ's faces (triangles only, `f a/t b/t c/t`), 0-based.
fn corner_uvs(text: &str) -> Vec<[Vec2; 3]> {
    let vts: Vec<Vec2> = text
        .lines()
        .filter_map(|l| l.strip_prefix("vt "))
        .map(|l| {
            let v: Vec<f32> = l.split_whitespace().map(|t| t.parse().unwrap()).collect();
            Vec2::new(v[0], v[1])
        })
        .collect();
    text.lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            let c: Vec<Vec2> = l
                .split_whitespace()
                .map(|t| vts[t.split('/').nth(1).unwrap().parse::<usize>().unwrap() - 1])
                .collect();
            [c[0], c[1], c[2]]
        })
        .collect()
}

fn check_split(path: &std::path::Path, text: &str) -> usize {
    let (file_mesh, _) = load_mesh(path, &LoadOptions::default()).unwrap();
    let (split, report) = load_mesh_split_seams(path, &LoadOptions::default()).unwrap();
    let n = file_mesh.positions.len();
    assert_eq!(split.source_count, n);
    assert_eq!(split.source.len(), split.mesh.positions.len());
    assert_eq!(split.mesh.positions[..n], file_mesh.positions[..]);
    let uvs = split.mesh.uvs.as_ref().expect("UVs kept");
    for (i, &s) in split.source.iter().enumerate() {
        assert_eq!(split.mesh.positions[i], file_mesh.positions[s as usize]);
        assert_eq!(
            split.mesh.normals[i], file_mesh.normals[s as usize],
            "welded normal {i}"
        );
        if i < n {
            assert_eq!(s as usize, i);
        }
    }
    for (t, (tri, corners)) in split
        .mesh
        .triangles
        .iter()
        .zip(corner_uvs(text))
        .enumerate()
    {
        let original = file_mesh.triangles[t];
        for k in 0..3 {
            assert_eq!(
                split.source[tri[k] as usize], original[k],
                "triangle {t} corner {k}"
            );
            assert_eq!(uvs[tri[k] as usize], corners[k], "triangle {t} corner {k}");
        }
    }
    assert!(report.notes.iter().any(|n| n.contains("UV seams")) || split.mesh.positions.len() == n);
    split.mesh.positions.len() - n
}

#[test]
fn a_seam_splits_only_the_vertices_on_it() {
    // Two quads sharing the edge 2–3, with different vt on each side of it (a seam).
    let text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0\nvt 0.5 1\nvt 1 0\nvt 1 1\n\
                f 1/1 2/2 3/3\nf 1/1 3/3 4/4\nf 2/5 5/7 6/8\nf 2/5 6/8 3/6\n";
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("seam.obj");
    std::fs::write(&path, text).unwrap();
    // Vertices 2 and 3 (1-based) carry two UVs each: two copies.
    assert_eq!(check_split(&path, text), 2);
    // A file without seams loads unchanged, identity map.
    let plain = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let path = dir.path().join("plain.obj");
    std::fs::write(&path, plain).unwrap();
    assert_eq!(check_split(&path, plain), 0);
    let (split, _) = load_mesh_split_seams(&path, &LoadOptions::default()).unwrap();
    assert_eq!(
        split.mesh,
        load_mesh(&path, &LoadOptions::default()).unwrap().0
    );
    assert_eq!(split.mesh.normals[0], Vec3::Z);
}

/// The Berkeley dress (sewing-pattern UVs, 46 vertices on seams): every corner keeps its `vt`.
#[test]
fn the_shared_dress_keeps_its_sewing_pattern_uvs() {
    let Some(path) = test_data::shared_file("meshes/garments/dress-victor-iso-draped.obj") else {
        return;
    };
    let text = std::fs::read_to_string(&path).unwrap();
    let added = check_split(&path, &text);
    assert!(
        (46..=92).contains(&added),
        "{added} copies for 46 seam vertices"
    );
}
