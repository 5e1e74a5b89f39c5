//! Fin geometry (thesis §5.7.3): silhouettes exact against a brute-force test on random views,
//! texture coordinates continuous along every chain in the corrected reading of eqs. 5.18–5.21,
//! fins standing on the vertex normals, buffers reused from frame to frame.

#[path = "common/fin_meshes.rs"]
mod fin_meshes;

use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
use fin_meshes::*;
use glam::Vec3;

const PARAMS: FinParams = FinParams {
    material_size: 0.05,
    height: 0.5,
    offset: 0.1,
};

/// Every silhouette edge and no other, for eyes around and directions towards the viewer, on a
/// closed convex mesh, a torus (several loops) and an open sheet (border edges).
#[test]
fn silhouettes_equal_a_brute_force_test_on_random_views() {
    let mut next = uniform(17);
    for (name, mesh) in [
        ("sphere", sphere(1.0, 12, 18)),
        ("torus", torus(1.0, 0.35, 24, 12)),
        ("sheet", sheet(10, 0.3)),
    ] {
        let mut builder = FinBuilder::new(&mesh.triangles, mesh.positions.len()).unwrap();
        for view in 0..24 {
            let dir = random_direction(&mut next);
            let (viewer, expected) = if view % 2 == 0 {
                let eye = dir * (2.0 + 3.0 * next());
                let reference = brute_force_silhouette(&mesh, |p| eye.as_dvec3() - p);
                (Viewer::Eye(eye), reference)
            } else {
                (
                    Viewer::Direction(dir),
                    brute_force_silhouette(&mesh, |_| dir.as_dvec3()),
                )
            };
            let found = builder.silhouette_edges(&mesh.positions, viewer);
            assert_eq!(
                unordered(&found),
                expected,
                "{name} view {view} ({viewer:?})"
            );
            assert!(!found.is_empty(), "{name} view {view}");
        }
    }
}

/// Along every chain the next fin starts at the vertex where the last one ended, with the same
/// texture coordinate s (the same float); each fin spans its world length in material units,
/// V1: (D, O), V2: (D + L, O), V3: (D, 1), V4: (D + L, 1); a closed loop returns to its start.
#[test]
fn texture_runs_on_across_every_joint_of_a_chain() {
    let mut next = uniform(5);
    for (name, mesh) in [
        ("torus", torus(1.0, 0.35, 24, 12)),
        ("sheet", sheet(10, 0.3)),
    ] {
        let mut builder = FinBuilder::new(&mesh.triangles, mesh.positions.len()).unwrap();
        let mut fins = FinMesh::default();
        for view in 0..12 {
            let eye = random_direction(&mut next) * 3.0;
            builder.build(
                &mesh.positions,
                &mesh.normals,
                Viewer::Eye(eye),
                &PARAMS,
                &mut fins,
            );
            assert!(!fins.is_empty());
            let mut closed = 0;
            for f in 0..fins.len() {
                let [a, b] = fins.ends[f];
                let st = &fins.texcoords[4 * f..4 * f + 4];
                let length = mesh.positions[a as usize].distance(mesh.positions[b as usize])
                    / PARAMS.material_size;
                let (d, o) = (st[0].x, PARAMS.offset);
                assert_eq!(st[0].y, o);
                assert_eq!((st[2].x, st[2].y), (d, 1.0));
                assert_eq!(st[1], glam::Vec2::new(st[3].x, o));
                assert_eq!(st[3].y, 1.0);
                assert!(
                    (st[1].x - d - length).abs() <= 1e-4 * st[1].x.max(1.0),
                    "{name}: fin {f} spans {} for L = {length}",
                    st[1].x - d
                );
                assert_eq!(fins.end_weight[4 * f..4 * f + 4], [0.0, 1.0, 0.0, 1.0]);
                let first_of_chain = f == 0 || fins.chain[f - 1] != fins.chain[f];
                if first_of_chain {
                    assert_eq!(d, 0.0, "{name}: a chain starts at D = 0");
                } else {
                    assert_eq!(fins.ends[f - 1][1], a, "{name} view {view}: chain broken");
                    assert_eq!(
                        fins.texcoords[4 * (f - 1) + 1].x,
                        d,
                        "{name}: s jumps at {a}"
                    );
                }
                let last_of_chain = f + 1 == fins.len() || fins.chain[f + 1] != fins.chain[f];
                if last_of_chain {
                    let start = (0..=f)
                        .rev()
                        .take_while(|&g| fins.chain[g] == fins.chain[f])
                        .last();
                    if fins.ends[start.unwrap()][0] == b {
                        closed += 1;
                    }
                }
            }
            // A closed mesh's silhouette is made of closed loops only.
            if name == "torus" {
                assert_eq!(closed, fins.chains(), "torus view {view}");
            }
        }
    }
}

/// V3 and V4 stand on V1 and V2 along their unit vertex normals, `height × material_size`
/// high; the fins' triangles index their own four vertices.
#[test]
fn fins_stand_on_the_vertex_normals() {
    let mesh = sphere(1.0, 10, 16);
    let mut builder = FinBuilder::new(&mesh.triangles, mesh.positions.len()).unwrap();
    let mut fins = FinMesh::default();
    builder.build(
        &mesh.positions,
        &mesh.normals,
        Viewer::Direction(Vec3::new(0.3, 0.2, 1.0).normalize()),
        &PARAMS,
        &mut fins,
    );
    let h = PARAMS.height * PARAMS.material_size;
    for f in 0..fins.len() {
        for (base, tip, v) in [(0, 2, fins.ends[f][0]), (1, 3, fins.ends[f][1])] {
            let rise = fins.positions[4 * f + tip] - fins.positions[4 * f + base];
            let expected = h * mesh.normals[v as usize];
            assert!(
                (rise - expected).length() < 1e-6,
                "fin {f}: {rise} vs {expected}"
            );
            assert_eq!(fins.positions[4 * f + base], mesh.positions[v as usize]);
        }
    }
    let triangles: Vec<[u32; 3]> = fins.triangles().collect();
    assert_eq!(triangles.len(), 2 * fins.len());
    assert!(
        triangles
            .iter()
            .flatten()
            .all(|&i| (i as usize) < fins.positions.len())
    );
}

/// A deforming sheet over 20 frames and a moving eye: the output buffers are reserved for the
/// worst case once and never reallocated.
#[test]
fn a_deforming_mesh_is_processed_every_frame_without_allocating() {
    let base = sheet(16, 0.0);
    let mut builder = FinBuilder::new(&base.triangles, base.positions.len()).unwrap();
    let mut fins = FinMesh::default();
    let mut pointers = None;
    for frame in 0..20 {
        let t = frame as f32 * 0.3;
        let mesh = sheet(16, 0.2 + 0.2 * t.sin());
        let eye = Vec3::new(2.0 * t.cos(), 1.0, 2.0 * t.sin());
        builder.build(
            &mesh.positions,
            &mesh.normals,
            Viewer::Eye(eye),
            &PARAMS,
            &mut fins,
        );
        let now = (
            fins.positions.as_ptr(),
            fins.texcoords.as_ptr(),
            fins.ends.as_ptr(),
        );
        assert_eq!(
            *pointers.get_or_insert(now),
            now,
            "frame {frame} reallocated"
        );
    }
}

#[test]
fn a_triangle_naming_a_missing_vertex_is_refused() {
    let e = FinBuilder::new(&[[0, 1, 7]], 3).unwrap_err();
    assert_eq!(
        e.to_string(),
        "triangle 0 names vertex 7, but the mesh has 3 vertices"
    );
}
