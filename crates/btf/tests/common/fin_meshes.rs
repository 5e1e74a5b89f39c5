//! Meshes and a brute-force silhouette for the fin tests.

#![allow(dead_code)]

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};

/// Positions, angle-weighted-free vertex normals (the mean of the incident face normals) and
/// triangles.
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Mesh {
    fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        let mut normals = vec![Vec3::ZERO; positions.len()];
        for t in &triangles {
            let [a, b, c] = t.map(|v| positions[v as usize]);
            let n = (b - a).cross(c - a);
            for v in t {
                normals[*v as usize] += n;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or_zero();
        }
        Self {
            positions,
            normals,
            triangles,
        }
    }

    pub fn offset(mut self, by: Vec3) -> Self {
        for p in &mut self.positions {
            *p += by;
        }
        self
    }
}

/// A closed UV sphere (poles shared), outward winding.
pub fn sphere(radius: f32, rings: u32, segments: u32) -> Mesh {
    let mut positions = vec![Vec3::new(0.0, radius, 0.0)];
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(
                radius
                    * Vec3::new(
                        theta.sin() * phi.cos(),
                        theta.cos(),
                        -theta.sin() * phi.sin(),
                    ),
            );
        }
    }
    positions.push(Vec3::new(0.0, -radius, 0.0));
    let south = positions.len() as u32 - 1;
    let at = |r: u32, s: u32| 1 + (r - 1) * segments + s % segments;
    let mut triangles = Vec::new();
    for s in 0..segments {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([south, at(rings - 1, s + 1), at(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (at(r, s), at(r, s + 1), at(r + 1, s), at(r + 1, s + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    Mesh::new(positions, triangles)
}

/// A torus about +Y (radii `big`, `small`), outward winding: non-convex, so a view sees several
/// silhouette loops, some of them with T-junction-free crossings of the outline.
pub fn torus(big: f32, small: f32, rings: u32, segments: u32) -> Mesh {
    let mut positions = Vec::new();
    for i in 0..rings {
        let u = std::f32::consts::TAU * i as f32 / rings as f32;
        for j in 0..segments {
            let v = std::f32::consts::TAU * j as f32 / segments as f32;
            let r = big + small * v.cos();
            positions.push(Vec3::new(r * u.cos(), small * v.sin(), r * u.sin()));
        }
    }
    let at = |i: u32, j: u32| (i % rings) * segments + j % segments;
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    Mesh::new(positions, triangles)
}

/// An open wavy sheet of `n`×`n` quads over [−1, 1]² in xz, facing +Y: border edges all round.
pub fn sheet(n: u32, wave: f32) -> Mesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (
                2.0 * i as f32 / n as f32 - 1.0,
                2.0 * j as f32 / n as f32 - 1.0,
            );
            positions.push(Vec3::new(x, wave * (3.0 * x).sin() * (2.0 * z).cos(), z));
        }
    }
    let at = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
            triangles.push([a, c, b]);
            triangles.push([b, c, d]);
        }
    }
    Mesh::new(positions, triangles)
}

/// A closed cylinder about +Z from z = 0 to 1 with capped ends (cap centres shared).
pub fn closed_cylinder(segments: u32) -> Mesh {
    let mut positions = Vec::new();
    for z in [0.0, 1.0] {
        for s in 0..segments {
            let a = std::f32::consts::TAU * s as f32 / segments as f32;
            positions.push(Vec3::new(a.cos(), a.sin(), z));
        }
    }
    positions.push(Vec3::ZERO);
    positions.push(Vec3::Z);
    let (bottom, top) = (2 * segments, 2 * segments + 1);
    let mut triangles = Vec::new();
    for s in 0..segments {
        let (a, b) = (s, (s + 1) % segments);
        let (c, d) = (a + segments, b + segments);
        triangles.push([a, b, c]);
        triangles.push([b, d, c]);
        triangles.push([bottom, b, a]);
        triangles.push([top, c, d]);
    }
    Mesh::new(positions, triangles)
}

/// The silhouette edges by brute force, in f64 with each triangle's centroid: for every edge of
/// every triangle, all triangles holding both its vertices (O(T²)); the edge is a silhouette
/// when it has one triangle, or front- and back-facing ones. Unordered (lo, hi) pairs.
pub fn brute_force_silhouette(mesh: &Mesh, towards: impl Fn(DVec3) -> DVec3) -> Vec<[u32; 2]> {
    let front = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|v| mesh.positions[v as usize].as_dvec3());
        let centroid = (a + b + c) / 3.0;
        (b - a).cross(c - a).dot(towards(centroid)) > 0.0
    };
    let mut seen: BTreeMap<[u32; 2], bool> = BTreeMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let key = [a.min(b), a.max(b)];
            if seen.contains_key(&key) || a == b {
                continue;
            }
            let faces: Vec<bool> = mesh
                .triangles
                .iter()
                .filter(|u| u.contains(&a) && u.contains(&b))
                .map(front)
                .collect();
            let silhouette = faces.len() == 1 || (faces.contains(&true) && faces.contains(&false));
            seen.insert(key, silhouette);
        }
    }
    seen.into_iter()
        .filter(|(_, s)| *s)
        .map(|(k, _)| k)
        .collect()
}

/// Unordered, sorted copies of oriented edges.
pub fn unordered(edges: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut out: Vec<[u32; 2]> = edges.iter().map(|&[a, b]| [a.min(b), a.max(b)]).collect();
    out.sort_unstable();
    out
}

/// A small xorshift generator of floats in [0, 1).
pub fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A random unit vector.
pub fn random_direction(next: &mut impl FnMut() -> f32) -> Vec3 {
    loop {
        let v = Vec3::new(2.0 * next() - 1.0, 2.0 * next() - 1.0, 2.0 * next() - 1.0);
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}
