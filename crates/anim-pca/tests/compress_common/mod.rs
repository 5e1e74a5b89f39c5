//! Synthetic clips of the CPCA tests: independently moving parts.
#![allow(dead_code)]

use glam::Vec3;

/// `parts` rigid bars of `per_part` vertices (a 3-D lattice of points), each spinning about
/// its own axis through its own centre at its own rate, over `frames` frames. Each part's
/// trajectories span a 3-dimensional affine space, so k = parts clusters of c = 3 components
/// reproduce it exactly, while one global PCA needs 3·parts components.
pub fn rigid_parts(parts: usize, per_part: usize, frames: usize) -> Vec<Vec<Vec3>> {
    (0..frames)
        .map(|t| {
            (0..parts * per_part)
                .map(|m| {
                    let (p, i) = (m / per_part, m % per_part);
                    let local = Vec3::new(
                        (i % 7) as f32 * 0.3 - 0.9,
                        ((i / 7) % 5) as f32 * 0.2 - 0.4,
                        (i / 35) as f32 * 0.25,
                    );
                    let axis = Vec3::new(1.0, 0.3 * p as f32, 0.5 + 0.2 * p as f32).normalize();
                    let angle = t as f32 * (0.05 + 0.037 * p as f32);
                    let centre = Vec3::new(6.0 * p as f32, (p % 2) as f32, 0.0);
                    centre + glam::Quat::from_axis_angle(axis, angle) * local
                })
                .collect()
        })
        .collect()
}

/// Triangles rotated so that the smallest index comes first (winding kept) and sorted: equal
/// for two lists holding the same triangles in any order and rotation.
pub fn canonical_triangles(tris: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = tris
        .iter()
        .map(|t| {
            let r = (0..3).min_by_key(|&i| t[i]).unwrap();
            [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
        })
        .collect();
    out.sort_unstable();
    out
}
