//! Exact nearest-direction queries through a cube-map grid of candidate lists.
//!
//! The seed does not need this (it only looks up the environment at each l_j), but the
//! cell-mean radiance I_j and later crates assign millions of directions to their Voronoi
//! cell, so a linear scan over k ≥ 1026 directions is too slow.
//!
//! Each face of the cube [−1, 1]³ is split into G × G cells; a query is sent to the cell that
//! holds its gnomonic projection. Every cell stores, in ascending index order, a *superset* of
//! the directions whose Voronoi cell meets it, and the query takes the arg-max of `l_j · q`
//! over that list with ties going to the lowest index — the same f64 arithmetic and rule as
//! the linear scan, so the answers are identical, not merely close.
//!
//! Why the list is complete: let the grid cell lie in the cap of centre c and angular radius
//! r (its corners' largest angle from c, plus [`LOCATOR_MARGIN`] for rounding). Let T be the
//! set of directions whose Voronoi cell meets that cap. (1) T is connected in the Delaunay
//! graph: the cap is connected and covered by the closed cells, and cells meeting at a point
//! of the cap are linked by Delaunay edges around it. (2) Any n ∈ T satisfies
//! angle(c, n) ≤ r + ρ_n, where ρ_n is n's cell radius. So a breadth-first search from the
//! direction nearest to c (which is in T), expanding only to Delaunay neighbours n with
//! angle(c, n) ≤ r + ρ_n, visits all of T.

use super::delaunay::Triangulation;
use super::voronoi::angle_between;
use glam::DVec3;
use rayon::prelude::*;

/// Angular safety margin (radians) added to every grid cell's cap. Rounding moves a query's
/// computed arg-max by at most ~1e-8 rad (the square root of the f64 dot-product error), and
/// grid cell assignment by ~1e-15; 1e-6 covers both by two orders of magnitude while adding
/// almost nothing to the lists.
pub(crate) const LOCATOR_MARGIN: f64 = 1e-6;

/// Grid cells per direction (6·G² ≈ this × k). Measured at k = 258…16386: 1 gives about 6
/// candidates per cell, 3 about 3.7 (at ~55 bytes of grid per direction); beyond that the
/// lists cannot shrink much (a cell near a Voronoi vertex always has ≥ 3 candidates).
pub(crate) const GRID_CELLS_PER_DIRECTION: f64 = 3.0;

/// Delaunay neighbours of every direction, in compressed-row form.
#[derive(Clone, Debug)]
pub(crate) struct Adjacency {
    offsets: Vec<u32>,
    neighbours: Vec<u32>,
}

impl Adjacency {
    pub(crate) fn new(vertex_count: usize, mesh: &Triangulation) -> Self {
        let mut degree = vec![0u32; vertex_count + 1];
        for t in &mesh.triangles {
            for &v in t {
                degree[v as usize + 1] += 1;
            }
        }
        for i in 1..degree.len() {
            degree[i] += degree[i - 1];
        }
        let offsets = degree;
        let mut fill = offsets.clone();
        let mut neighbours = vec![0u32; mesh.triangles.len() * 3];
        for t in &mesh.triangles {
            for i in 0..3 {
                let (a, b) = (t[i] as usize, t[(i + 1) % 3]);
                neighbours[fill[a] as usize] = b;
                fill[a] += 1;
            }
        }
        Self {
            offsets,
            neighbours,
        }
    }

    pub(crate) fn of(&self, v: usize) -> &[u32] {
        &self.neighbours[self.offsets[v] as usize..self.offsets[v + 1] as usize]
    }
}

/// Cube face (0..6: +X, −X, +Y, −Y, +Z, −Z) and face coordinates (u, v) ∈ [−1, 1]² of a
/// non-zero finite vector. Ties between axes go to the earlier axis.
fn face_uv(q: DVec3) -> (usize, f64, f64) {
    let a = q.abs();
    if a.x >= a.y && a.x >= a.z {
        (usize::from(q.x < 0.0), q.y / a.x, q.z / a.x)
    } else if a.y >= a.z {
        (2 + usize::from(q.y < 0.0), q.x / a.y, q.z / a.y)
    } else {
        (4 + usize::from(q.z < 0.0), q.x / a.z, q.y / a.z)
    }
}

/// The point of cube face `face` at face coordinates (u, v) (inverse of [`face_uv`]).
fn face_point(face: usize, u: f64, v: f64) -> DVec3 {
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    match face / 2 {
        0 => DVec3::new(s, u, v),
        1 => DVec3::new(u, s, v),
        _ => DVec3::new(u, v, s),
    }
}

/// The cube-map grid of candidate lists.
#[derive(Clone, Debug)]
pub(crate) struct Locator {
    cells_per_side: usize,
    offsets: Vec<u32>,
    candidates: Vec<u32>,
}

impl Locator {
    /// Build the grid for `points` (unit), their Delaunay `adjacency` and cell `radii`.
    pub(crate) fn new(points: &[DVec3], adjacency: &Adjacency, radii: &[f64]) -> Self {
        let g = ((GRID_CELLS_PER_DIRECTION * points.len() as f64 / 6.0)
            .sqrt()
            .ceil() as usize)
            .max(1);
        let rows: Vec<Vec<Vec<u32>>> = (0..6 * g)
            .into_par_iter()
            .map_init(
                || vec![u32::MAX; points.len()],
                |stamp, face_row| {
                    let (face, iv) = (face_row / g, face_row % g);
                    let mut seed = 0usize;
                    (0..g)
                        .map(|iu| {
                            let cell = (face_row * g + iu) as u32;
                            let (c, r) = cell_cap(face, iu, iv, g);
                            seed = walk_to_nearest(points, adjacency, c, seed);
                            collect(points, adjacency, radii, c, r, seed, stamp, cell)
                        })
                        .collect()
                },
            )
            .collect();
        let mut offsets = Vec::with_capacity(6 * g * g + 1);
        let mut candidates = Vec::new();
        offsets.push(0u32);
        for list in rows.into_iter().flatten() {
            candidates.extend_from_slice(&list);
            offsets.push(u32::try_from(candidates.len()).expect("candidate lists fit in u32"));
        }
        Self {
            cells_per_side: g,
            offsets,
            candidates,
        }
    }

    /// Candidate directions (ascending) for a non-zero finite query.
    pub(crate) fn candidates(&self, q: DVec3) -> &[u32] {
        let (face, u, v) = face_uv(q);
        let g = self.cells_per_side;
        let index = |t: f64| (((t + 1.0) * 0.5 * g as f64) as usize).min(g - 1);
        let cell = (face * g + index(v)) * g + index(u);
        &self.candidates[self.offsets[cell] as usize..self.offsets[cell + 1] as usize]
    }

    /// Mean candidate-list length (for reports and benches).
    pub(crate) fn mean_candidates(&self) -> f64 {
        self.candidates.len() as f64 / (self.offsets.len() - 1) as f64
    }
}

/// Centre (unit) and angular radius (with margin) of the cap around grid cell (iu, iv).
fn cell_cap(face: usize, iu: usize, iv: usize, g: usize) -> (DVec3, f64) {
    let coord = |i: usize| -1.0 + 2.0 * i as f64 / g as f64;
    let (u0, u1, v0, v1) = (coord(iu), coord(iu + 1), coord(iv), coord(iv + 1));
    let c = face_point(face, 0.5 * (u0 + u1), 0.5 * (v0 + v1)).normalize();
    let r = [(u0, v0), (u1, v0), (u0, v1), (u1, v1)]
        .into_iter()
        .map(|(u, v)| angle_between(c, face_point(face, u, v).normalize()))
        .fold(0.0, f64::max);
    (c, r + LOCATOR_MARGIN)
}

/// Greedy walk on the Delaunay graph to the direction nearest to `c` (exact up to rounding,
/// which [`LOCATOR_MARGIN`] absorbs).
fn walk_to_nearest(points: &[DVec3], adjacency: &Adjacency, c: DVec3, start: usize) -> usize {
    let mut current = start;
    let mut best_dot = points[current].dot(c);
    loop {
        let mut best = current;
        for &n in adjacency.of(current) {
            let d = points[n as usize].dot(c);
            if d > best_dot {
                best_dot = d;
                best = n as usize;
            }
        }
        if best == current {
            return current;
        }
        current = best;
    }
}

/// Breadth-first search from `seed` over directions that may own part of the cap (c, r).
#[allow(clippy::too_many_arguments)]
fn collect(
    points: &[DVec3],
    adjacency: &Adjacency,
    radii: &[f64],
    c: DVec3,
    r: f64,
    seed: usize,
    stamp: &mut [u32],
    cell: u32,
) -> Vec<u32> {
    let mut found = vec![seed as u32];
    stamp[seed] = cell;
    let mut next = 0;
    while next < found.len() {
        let v = found[next] as usize;
        next += 1;
        for &n in adjacency.of(v) {
            let n = n as usize;
            if stamp[n] == cell {
                continue;
            }
            stamp[n] = cell;
            if angle_between(c, points[n]) <= r + radii[n] {
                found.push(n as u32);
            }
        }
    }
    found.sort_unstable();
    found
}
