//! Shared helpers of the shadows tests: casters with known shadows, and mask comparisons that
//! forgive exactly the cells within one cell of a shadow boundary.
#![allow(dead_code)]

use glam::{DVec3, Vec3};
use shadows::GroundGrid;
use shadows::Light;
use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};

/// An icosphere (synth's obstacle mesh): counter-clockwise outside.
pub fn sphere(centre: Vec3, radius: f32, detail: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    synth::obstacle_mesh(&synth::Obstacle::Sphere { centre, radius }, detail)
}

/// An open n × n grid over [−side/2, side/2]² at heights `height(x, z)` (x, z ∈ [−½, ½]), wound
/// counter-clockwise seen from above.
pub fn height_field(
    n: u32,
    side: f32,
    height: impl Fn(f32, f32) -> f32,
) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
            positions.push(Vec3::new(side * x, height(x, z), side * z));
        }
    }
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let v = j * (n + 1) + i;
            triangles.push([v, v + n + 1, v + 1]);
            triangles.push([v + 1, v + n + 1, v + n + 2]);
        }
    }
    (positions, triangles)
}

/// The smallest distance from `centre` to a face plane: the polyhedron contains the ball of
/// this radius (and is contained in the ball through its vertices).
pub fn inscribed_radius(positions: &[Vec3], triangles: &[[u32; 3]], centre: Vec3) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            let n = (b - a).cross(c - a).normalize();
            (a - centre.as_dvec3()).dot(n).abs()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Cells whose 3 × 3 neighbourhood is not uniform in `reference`: within one cell of a boundary.
pub fn near_boundary(reference: &[f32], n: usize, i: usize, j: usize) -> bool {
    let v = reference[j * n + i];
    (j.saturating_sub(1)..=(j + 1).min(n - 1))
        .any(|jj| (i.saturating_sub(1)..=(i + 1).min(n - 1)).any(|ii| reference[jj * n + ii] != v))
}

/// (cells that differ away from boundaries, cells that differ near them, boundary cells).
pub fn compare(reference: &[f32], other: &[f32], n: usize) -> (usize, usize, usize) {
    let (mut far, mut near, mut boundary) = (0, 0, 0);
    for j in 0..n {
        for i in 0..n {
            let b = near_boundary(reference, n, i, j);
            boundary += usize::from(b);
            if reference[j * n + i] != other[j * n + i] {
                if b { near += 1 } else { far += 1 }
            }
        }
    }
    (far, near, boundary)
}

/// The volume's own answer per cell: winding number ≠ 0 along −y from the cell centre
/// (finite extrusion, relative to the grid's centre), what the stencil computes.
pub fn winding_mask(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    sides: Sides,
    grid: &GroundGrid,
) -> Vec<f32> {
    let topology = CasterTopology::new(positions.len(), triangles).unwrap();
    let mut volume = ShadowVolume::new();
    let params = VolumeParams {
        sides,
        extrusion: Extrusion::Finite(shadows::ground_extrusion(positions, grid)),
        origin: grid.centre(),
        ..Default::default()
    };
    volume.build(&topology, positions, light, &params).unwrap();
    let mut mask = Vec::with_capacity(grid.n * grid.n);
    // A direction off every axis, so the ray meets no volume edge exactly.
    let dir = DVec3::new(0.0123, -1.0, 0.0071);
    for j in 0..grid.n {
        for i in 0..grid.n {
            let p = grid.cell_centre(i, j) - grid.centre();
            let w = volume.winding_number(p, dir).unwrap();
            assert!(w >= 0, "negative winding {w} at cell ({i}, {j})");
            mask.push(f32::from(u8::from(w != 0)));
        }
    }
    mask
}

/// The stencil mask when an adapter exists (skipped otherwise, failing under CI); `None`
/// without the `gpu` feature.
pub fn stencil_mask(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    sides: Sides,
    grid: &GroundGrid,
) -> Option<Vec<f32>> {
    #[cfg(feature = "gpu")]
    {
        let gpu = gpu_context::testing::gpu_or_skip()?;
        let (mask, _) =
            shadows::stencil_ground_mask(&gpu, positions, triangles, light, sides, grid).unwrap();
        Some(mask)
    }
    #[cfg(not(feature = "gpu"))]
    {
        let _ = (positions, triangles, light, sides, grid);
        None
    }
}

#[cfg(feature = "gpu")]
pub mod frame;
