//! Test geometry for the hemicube tests.
#![allow(dead_code)]

use std::sync::Arc;

use glam::{DVec3, Vec3};
use hemicube::{FormFactorRule, Model, PixelLayout};
use occlusion_gpu::{Scene, SceneObject};

/// A mesh with per-vertex normals.
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    pub fn object(&self) -> SceneObject {
        SceneObject::new(
            self.positions.clone(),
            self.normals.clone(),
            self.triangles.clone(),
        )
    }

    pub fn occluder(&self) -> SceneObject {
        self.object().occluder_only()
    }

    pub fn translated(mut self, by: Vec3) -> Self {
        for p in &mut self.positions {
            *p += by;
        }
        self
    }
}

/// An n × n quad grid spanning `origin + s·u + t·v`, s, t ∈ [0, 1], normal `u × v`.
pub fn sheet(origin: Vec3, u: Vec3, v: Vec3, n: u32) -> Mesh {
    let normal = u.cross(v).normalize();
    let mut positions = Vec::new();
    for r in 0..=n {
        for c in 0..=n {
            positions.push(origin + u * (c as f32 / n as f32) + v * (r as f32 / n as f32));
        }
    }
    let at = |r: u32, c: u32| r * (n + 1) + c;
    let mut triangles = Vec::new();
    for r in 0..n {
        for c in 0..n {
            triangles.push([at(r, c), at(r, c + 1), at(r + 1, c + 1)]);
            triangles.push([at(r, c), at(r + 1, c + 1), at(r + 1, c)]);
        }
    }
    let normals = vec![normal; positions.len()];
    Mesh {
        positions,
        normals,
        triangles,
    }
}

/// A flat square floor in the xz plane (normal +y), side `size`, centred on the origin.
pub fn floor(size: f32, n: u32) -> Mesh {
    let h = size / 2.0;
    sheet(
        Vec3::new(-h, 0.0, h),
        Vec3::new(size, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -size),
        n,
    )
}

pub fn layout(model: Model) -> Arc<PixelLayout> {
    Arc::new(PixelLayout::new(model, FormFactorRule::Exact).unwrap())
}

/// One receiver vertex at `p` with normal `n`, as a tiny triangle (all three vertices share
/// the normal); the triangle is too small to occlude anything seen from its first vertex.
pub fn probe(p: Vec3, n: Vec3) -> Mesh {
    let t = n.any_orthonormal_vector() * 1e-4;
    let b = n.cross(t);
    Mesh {
        positions: vec![p, p + t, p + b],
        normals: vec![n; 3],
        triangles: vec![[0, 1, 2]],
    }
}

pub fn scene(receiver: Mesh, occluders: &[Mesh]) -> Scene {
    let mut scene = Scene::new();
    scene.push(receiver.object()).unwrap();
    for o in occluders {
        scene.push(o.occluder()).unwrap();
    }
    scene
}

/// Form factor of a planar convex polygon (world corners) from a differential area at `p` with
/// normal `n`, exactly (contour formula in f64).
pub fn polygon_ff(p: Vec3, n: Vec3, corners: &[Vec3]) -> f64 {
    let n = n.as_dvec3().normalize();
    let t = n.any_orthonormal_vector();
    let b = n.cross(t);
    let local: Vec<DVec3> = corners
        .iter()
        .map(|c| {
            let d = c.as_dvec3() - p.as_dvec3();
            DVec3::new(d.dot(t), d.dot(b), d.dot(n))
        })
        .collect();
    hemicube::layout::polygon_form_factor(&local)
}

pub fn assert_close(actual: f64, expected: f64, tolerance: f64, what: &str) {
    assert!(
        (actual - expected).abs() <= tolerance,
        "{what}: {actual} vs {expected} (tolerance {tolerance})"
    );
}
