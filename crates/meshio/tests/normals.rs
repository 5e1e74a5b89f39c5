//! `compute_normals`: defining identities, extreme coordinates, and an f64 reference.

mod common;

use common::assert_close;
use glam::Vec3;
use meshio::{LoadOptions, NormalWeighting, compute_normals, load_mesh};

#[test]
fn angle_weighting_is_independent_of_triangulation_area_weighting_is_not() {
    // Three faces of a unit cube meet at the origin. The xy face is split by the diagonal
    // through the origin (two triangles touch it), the others by the other diagonal.
    let p = [
        Vec3::ZERO,
        Vec3::X,
        Vec3::Y,
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::Z,
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    ];
    let tris = [
        // xy face (normal -z), diagonal 0-3.
        [0, 3, 1],
        [0, 2, 3],
        // xz face (normal -y), diagonal 1-4: one triangle at the origin.
        [0, 1, 4],
        [1, 5, 4],
        // yz face (normal -x), diagonal 2-4.
        [0, 4, 2],
        [2, 4, 6],
    ];
    let angle = compute_normals(&p, &tris, NormalWeighting::Angle)[0];
    assert_close(angle, -Vec3::ONE.normalize(), 1e-6);
    let area = compute_normals(&p, &tris, NormalWeighting::Area)[0];
    assert_close(area, -Vec3::new(0.5, 0.5, 1.0).normalize(), 1e-6);
}

#[test]
fn normals_stay_unit_at_huge_offsets_and_tiny_triangles() {
    let offset = Vec3::splat(1.0e6);
    let p = [
        offset,
        offset + Vec3::new(0.125, 0.0, 0.0),
        offset + Vec3::new(0.0, 0.125, 0.0),
    ];
    let n = compute_normals(&p, &[[0, 1, 2]], NormalWeighting::Angle);
    for n in n {
        assert_close(n, Vec3::Z, 1e-6);
    }
    let huge = [
        Vec3::ZERO,
        Vec3::new(3.0e38, 0.0, 0.0),
        Vec3::new(0.0, 3.0e38, 0.0),
    ];
    for w in [NormalWeighting::Angle, NormalWeighting::Area] {
        for n in compute_normals(&huge, &[[0, 1, 2]], w) {
            assert_close(n, Vec3::Z, 1e-6);
        }
    }
    let tiny = [
        Vec3::ZERO,
        Vec3::new(1e-30, 0.0, 0.0),
        Vec3::new(0.0, 1e-30, 0.0),
    ];
    assert_close(
        compute_normals(&tiny, &[[0, 1, 2]], NormalWeighting::Area)[0],
        Vec3::Z,
        1e-6,
    );
}

#[test]
fn area_normals_match_an_f64_brute_force_reference() {
    let Some(path) = test_data::shared_file("meshes/bun_zipper_res4.ply") else {
        return;
    };
    let (mesh, _) = load_mesh(&path, &LoadOptions::default()).unwrap();
    let normals = compute_normals(&mesh.positions, &mesh.triangles, NormalWeighting::Area);
    for v in 0..mesh.vertex_count() as u32 {
        let reference =
            common::reference_area_normal(&mesh.positions, &mesh.triangles, v).as_vec3();
        assert_close(normals[v as usize], reference, 4.0 * f32::EPSILON);
    }
}

/// The decimated bunny's zero-thickness flaps (70 back-to-back triangle pairs): each lone
/// flap tip rendered as a dark speck while its normal was rounding noise. Now every vertex a
/// triangle uses has a unit normal, the tips their neighbours' mean.
#[test]
fn the_bunny_res3_flap_tips_take_their_neighbours_normals() {
    let Some(path) = test_data::shared_file("meshes/bun_zipper_res3.ply") else {
        return;
    };
    let (mesh, report) = load_mesh(&path, &LoadOptions::default()).unwrap();
    // Counted independently (a Python pass over the PLY): 70 pairs, and 12 vertex sets
    // written three times, two in one winding.
    assert_eq!(report.repeated_triangles.back_to_back, 70);
    assert_eq!(report.repeated_triangles.repeated, 12);
    assert_eq!(report.unreferenced_vertices.len(), 2);
    let around = |v: usize| -> Vec<[u32; 3]> {
        let v = v as u32;
        mesh.triangles
            .iter()
            .copied()
            .filter(|t| t.contains(&v))
            .collect()
    };
    // The vertex set of a triangle, and whether its winding is the set's ascending one.
    let winding = |t: &[u32; 3]| {
        let m = (0..3).min_by_key(|&i| t[i]).unwrap();
        let mut key = [t[m], t[(m + 1) % 3], t[(m + 2) % 3]];
        let forward = key[1] < key[2];
        key[1..].sort_unstable();
        (key, forward)
    };
    // A tip: around it, every vertex set is written as often in one winding as in the other,
    // so its own normals cancel.
    let is_tip: Vec<bool> = (0..mesh.vertex_count())
        .map(|v| {
            let around = around(v);
            !around.is_empty()
                && around.iter().all(|t| {
                    let key = winding(t).0;
                    let same: Vec<bool> = around
                        .iter()
                        .map(winding)
                        .filter(|(k, _)| *k == key)
                        .map(|(_, forward)| forward)
                        .collect();
                    2 * same.iter().filter(|&&f| f).count() == same.len()
                })
        })
        .collect();
    for (v, n) in mesh.normals.iter().enumerate() {
        if report.unreferenced_vertices.contains(&(v as u32)) {
            assert_eq!(*n, glam::Vec3::ZERO);
            continue;
        }
        assert!((n.length() - 1.0).abs() < 1e-6, "vertex {v}: {n}");
        if is_tip[v] {
            // The mean of the neighbours that have a normal of their own (not other tips).
            let mean: glam::Vec3 = around(v)
                .iter()
                .flat_map(|t| t.iter().filter(|&&o| o != v as u32 && !is_tip[o as usize]))
                .map(|&o| mesh.normals[o as usize])
                .sum();
            assert_close(*n, mean.normalize(), 1e-6);
        }
    }
    // Also counted in the Python pass: the vertices whose own normals sum below 1e-9.
    assert_eq!(is_tip.iter().filter(|&&t| t).count(), 10);
}
