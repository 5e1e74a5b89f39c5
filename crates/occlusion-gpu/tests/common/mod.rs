//! Shared test geometry, references and comparison helpers.
#![allow(dead_code)]

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use lightsphere::Lightsphere;
use occlusion_gpu::{BvhUpdate, Scene, SceneObject, VisibilityEngine};

/// A triangle mesh with per-vertex normals.
pub struct TestMesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl TestMesh {
    pub fn object(&self) -> SceneObject {
        SceneObject::new(
            self.positions.clone(),
            self.normals.clone(),
            self.triangles.clone(),
        )
    }
}

/// An n×n-quad grid in the xz plane, centred at the origin, side `size`, normal +y; triangles
/// wound counter-clockwise seen from +y.
pub fn grid(n: u32, size: f32) -> TestMesh {
    let mut positions = Vec::new();
    for r in 0..=n {
        for c in 0..=n {
            let x = (c as f32 / n as f32 - 0.5) * size;
            let z = (r as f32 / n as f32 - 0.5) * size;
            positions.push(Vec3::new(x, 0.0, z));
        }
    }
    let mut triangles = Vec::new();
    let at = |r: u32, c: u32| r * (n + 1) + c;
    for r in 0..n {
        for c in 0..n {
            triangles.push([at(r, c), at(r + 1, c), at(r + 1, c + 1)]);
            triangles.push([at(r, c), at(r + 1, c + 1), at(r, c + 1)]);
        }
    }
    let normals = vec![Vec3::Y; positions.len()];
    TestMesh {
        positions,
        normals,
        triangles,
    }
}

/// A UV sphere of `rings` × `segments` with outward normals.
pub fn uv_sphere(center: Vec3, radius: f32, rings: u32, segments: u32) -> TestMesh {
    let mut positions = vec![center + Vec3::Y * radius];
    let mut normals = vec![Vec3::Y];
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            let n = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            positions.push(center + n * radius);
            normals.push(n);
        }
    }
    positions.push(center - Vec3::Y * radius);
    normals.push(-Vec3::Y);
    let bottom = positions.len() as u32 - 1;
    let ring = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, ring(1, s + 1), ring(1, s)]);
        triangles.push([bottom, ring(rings - 1, s), ring(rings - 1, s + 1)]);
        for r in 1..rings - 1 {
            let (a, b, c, d) = (
                ring(r, s),
                ring(r, s + 1),
                ring(r + 1, s),
                ring(r + 1, s + 1),
            );
            triangles.push([a, b, d]);
            triangles.push([a, d, c]);
        }
    }
    TestMesh {
        positions,
        normals,
        triangles,
    }
}

/// A sphere of radius 0.5 at height 0.7 over a 4×4 plane.
pub fn sphere_over_plane() -> Scene {
    let mut scene = Scene::new();
    scene.push(grid(24, 4.0).object()).unwrap();
    scene
        .push(uv_sphere(Vec3::new(0.0, 0.7, 0.0), 0.5, 16, 32).object())
        .unwrap();
    scene
}

/// Loads a shared mesh as a one-object scene (None when the data is missing).
pub fn shared_scene(relative: &str) -> Option<Scene> {
    let path = test_data::shared_file(relative)?;
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).unwrap();
    Some(Scene::single(mesh.positions, mesh.normals, mesh.triangles).unwrap())
}

/// The discrete ambient term of an unoccluded vertex with normal n: Σ_{n·l>0} ω_j n·l_j / π.
pub fn open_ambient(sphere: &Lightsphere, n: DVec3) -> f64 {
    sphere
        .directions_f64()
        .iter()
        .zip(sphere.solid_angles())
        .map(|(l, w)| w * n.dot(*l).max(0.0))
        .sum::<f64>()
        / PI
}

/// Brute-force f64 visibility: does a ray from `origin` along `dir` hit any triangle?
pub fn brute_force_hit(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    origin: DVec3,
    dir: DVec3,
) -> bool {
    brute_force_hit_within(positions, triangles, origin, dir, f64::INFINITY)
}

/// [`brute_force_hit`] counting only hits at 0 < t < `max_t` (`dir` unit: t is a distance).
pub fn brute_force_hit_within(
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    origin: DVec3,
    dir: DVec3,
    max_t: f64,
) -> bool {
    triangles.iter().any(|t| {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        let (e1, e2) = (b - a, c - a);
        let p = dir.cross(e2);
        let det = e1.dot(p);
        if det == 0.0 {
            return false;
        }
        let s = origin - a;
        let u = s.dot(p) / det;
        let q = s.cross(e1);
        let v = dir.dot(q) / det;
        let t = e2.dot(q) / det;
        u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0 && t < max_t
    })
}

/// Mean |a - b| and the share of entries with |a - b| > 0.05 over entries finite in both.
pub fn ambient_difference(a: &[f32], b: &[f32]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let pairs: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| f64::from((x - y).abs()))
        .collect();
    let n = pairs.len().max(1) as f64;
    let mean = pairs.iter().sum::<f64>() / n;
    let share = pairs.iter().filter(|d| **d > 0.05).count() as f64 / n;
    (mean, share)
}

#[track_caller]
pub fn assert_close(actual: f64, expected: f64, tolerance: f64, what: &str) {
    assert!(
        (actual - expected).abs() <= tolerance,
        "{what}: {actual} vs expected {expected} (|Δ| = {:.3e} > tolerance {tolerance:.3e})",
        (actual - expected).abs()
    );
}

/// A mesh: positions and triangles.
pub type Mesh = (Vec<Vec3>, Vec<[u32; 3]>);

/// The synthetic drape (a `grid` × `grid` cloth falling over its ball), `frames` frames:
/// positions per frame, the cloth's triangles, and the ball subdivided `ball_level` times.
pub fn drape_frames(
    grid: usize,
    frames: usize,
    ball_level: u32,
) -> (Vec<Vec<Vec3>>, Vec<[u32; 3]>, Mesh) {
    let params = synth::ClothParams {
        grid,
        frames,
        ..Default::default()
    };
    let cloth = synth::simulate_cloth(&params).unwrap();
    let ball = synth::obstacle_mesh(&params.obstacle, ball_level);
    (cloth.frames, cloth.triangles, ball)
}

/// One drape frame over its ball (an occluder only), normals computed from the frame.
pub fn drape_scene(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    (ball, ball_triangles): &Mesh,
) -> Scene {
    let normals = meshio::compute_normals(positions, triangles, meshio::NormalWeighting::Angle);
    let mut scene = Scene::new();
    scene
        .push(SceneObject::new(
            positions.to_vec(),
            normals,
            triangles.to_vec(),
        ))
        .unwrap();
    scene
        .push(
            SceneObject::new(
                ball.clone(),
                vec![Vec3::Y; ball.len()],
                ball_triangles.clone(),
            )
            .occluder_only(),
        )
        .unwrap();
    scene
}

/// Every third of `frames` through both engines: the same bits on every frame, some sky and
/// some shadow, `rebuilding` building each time and `refitting` refitting within
/// [`occlusion_gpu::REBUILD_SAH_RATIO`] (or building: the first frame, a degraded tree).
/// Returns the number of refits; `what` names the case in messages.
pub fn refits_over_frames(
    refitting: &mut VisibilityEngine,
    rebuilding: &mut VisibilityEngine,
    (frames, triangles, ball): &(Vec<Vec<Vec3>>, Vec<[u32; 3]>, Mesh),
    sphere: &Lightsphere,
    what: &str,
) -> usize {
    let mut refits = 0;
    for (f, positions) in frames.iter().enumerate().step_by(3) {
        let scene = drape_scene(positions, triangles, ball);
        let a = refitting.compute(&scene, sphere).unwrap();
        let b = rebuilding.compute(&scene, sphere).unwrap();
        assert_eq!(a.bits(), b.bits(), "{what} frame {f}");
        let open = a.visible_count();
        assert!(
            open > 0 && open < a.rows() * sphere.len(),
            "{what} frame {f}"
        );
        assert_eq!(
            rebuilding.last_bvh().update,
            BvhUpdate::Built,
            "{what} frame {f}"
        );
        match refitting.last_bvh().update {
            BvhUpdate::Refitted { sah_ratio } => {
                refits += 1;
                assert!(sah_ratio > 0.0 && sah_ratio <= occlusion_gpu::REBUILD_SAH_RATIO);
            }
            BvhUpdate::Built => {}
            other => panic!("{what} frame {f}: {other:?}"),
        }
    }
    refits
}
