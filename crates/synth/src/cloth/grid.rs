//! The square cloth mesh and its constraints.
//!
//! Cells are split along alternating diagonals (a checkerboard), so that the cloth has no
//! preferred shear direction. Stretch constraints keep every triangle edge at its rest
//! length. Bending uses the isometric quadratic bending model (Bergou, Wardetzky, Harmon,
//! Zorin, Grinspun, "A Quadratic Bending Model for Inextensible Surfaces", 2006): for each
//! interior edge with vertices x₀, x₁ and opposite vertices x₂, x₃, the curvature vector
//! `c = Σ K_j x_j` with cotangent weights `K = (c₀₃ + c₀₄, c₀₁ + c₀₂, −c₀₁ − c₀₃, −c₀₂ − c₀₄)`
//! vanishes for the flat rest state and the energy is `3/(A₀ + A₁) · |c|²` per edge. As an
//! XPBD constraint, `C = √(3/(A₀ + A₁)) · |c|`. Unlike distance-based bending (which is
//! second order in the hinge angle) it resists the grid-scale zig-zag buckling mode to
//! first order, so compressed cloth forms real folds instead of crinkling at the grid.

use glam::{DVec3, Vec2, Vec3};

/// A distance constraint between vertices `i` and `j`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DistanceConstraint {
    pub(crate) i: u32,
    pub(crate) j: u32,
    pub(crate) rest: f32,
}

/// An isometric bending constraint on the hinge of one interior edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BendConstraint {
    /// Edge vertices, then the two opposite vertices.
    pub(crate) v: [u32; 4],
    /// Gradient weights `√(3/(A₀ + A₁)) · K_j` (so that `C = |Σ k_j x_j|`).
    pub(crate) k: [f32; 4],
    /// `Σ w_j k_j²`, the generalised inverse mass of the constraint.
    pub(crate) w_sum: f32,
}

/// A unilateral long-range constraint `|x_j − x_i| ≤ rest` between vertices `steps` grid
/// steps apart along a row, column or diagonal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tether {
    pub(crate) i: u32,
    pub(crate) j: u32,
    pub(crate) rest: f32,
    /// Edges in series along the line (its compliance is this many edge compliances).
    pub(crate) steps: f32,
}

/// Grid steps of the tethers, tuned on the default drape: with 16 substeps the hanging
/// cloth stretched up to 15% at the top of the fold lines without tethers; 4- and 16-step
/// tethers carry the weight in two hops and bring that under 5% for ~10% of the run time.
const TETHER_STEPS: [usize; 2] = [4, 16];

/// Topology, rest state and masses of the cloth.
#[derive(Debug, Clone)]
pub(crate) struct GridMesh {
    pub(crate) triangles: Vec<[u32; 3]>,
    pub(crate) uvs: Vec<Vec2>,
    /// Flat rest positions in the xz plane, centred on the origin.
    pub(crate) rest: Vec<Vec3>,
    /// Inverse vertex masses (1/kg), from a third of the adjacent triangle areas.
    pub(crate) inv_mass: Vec<f32>,
    pub(crate) stretch: Vec<DistanceConstraint>,
    pub(crate) bend: Vec<BendConstraint>,
    pub(crate) tethers: Vec<Tether>,
}

impl GridMesh {
    /// Builds a `grid × grid` cloth of side `size` metres and `areal_density` kg/m².
    pub(crate) fn new(grid: usize, size: f32, areal_density: f32) -> Self {
        assert!(grid >= 2, "grid validated by ClothParams::validate");
        let last = (grid - 1) as f32;
        let mut uvs = Vec::with_capacity(grid * grid);
        let mut rest = Vec::with_capacity(grid * grid);
        for row in 0..grid {
            for col in 0..grid {
                let uv = Vec2::new(col as f32 / last, row as f32 / last);
                uvs.push(uv);
                rest.push(Vec3::new((uv.x - 0.5) * size, 0.0, (uv.y - 0.5) * size));
            }
        }
        let triangles = triangulate(grid);
        let inv_mass = inverse_masses(&rest, &triangles, areal_density);
        let (stretch, bend) = constraints(&rest, &triangles, &inv_mass);
        let tethers = tethers(grid, &rest);
        Self {
            triangles,
            uvs,
            rest,
            inv_mass,
            stretch,
            bend,
            tethers,
        }
    }
}

/// Two triangles per cell, diagonals alternating, counter-clockwise seen from +Y.
pub(crate) fn triangulate(grid: usize) -> Vec<[u32; 3]> {
    let index = |row: usize, col: usize| (row * grid + col) as u32;
    let mut triangles = Vec::with_capacity(2 * (grid - 1) * (grid - 1));
    for row in 0..grid - 1 {
        for col in 0..grid - 1 {
            let (v00, v01) = (index(row, col), index(row, col + 1));
            let (v10, v11) = (index(row + 1, col), index(row + 1, col + 1));
            if (row + col) % 2 == 0 {
                triangles.push([v00, v10, v11]);
                triangles.push([v00, v11, v01]);
            } else {
                triangles.push([v00, v10, v01]);
                triangles.push([v01, v10, v11]);
            }
        }
    }
    triangles
}

fn inverse_masses(rest: &[Vec3], triangles: &[[u32; 3]], areal_density: f32) -> Vec<f32> {
    let mut mass = vec![0.0f64; rest.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| rest[v as usize]);
        let area = 0.5 * f64::from((b - a).cross(c - a).length());
        for v in t {
            mass[*v as usize] += area * f64::from(areal_density) / 3.0;
        }
    }
    mass.iter().map(|m| (1.0 / m) as f32).collect()
}

/// Stretch constraints (one per edge) and bending constraints (one per interior edge), in
/// a deterministic, colour-grouped order.
fn constraints(
    rest: &[Vec3],
    triangles: &[[u32; 3]],
    inv_mass: &[f32],
) -> (Vec<DistanceConstraint>, Vec<BendConstraint>) {
    // (lower vertex, upper vertex, opposite vertex) for every triangle edge.
    let mut edges: Vec<(u32, u32, u32)> = triangles
        .iter()
        .flat_map(|&[a, b, c]| [(a, b, c), (b, c, a), (c, a, b)])
        .map(|(i, j, o)| (i.min(j), i.max(j), o))
        .collect();
    edges.sort_unstable();
    let mut stretch = Vec::new();
    let mut bend = Vec::new();
    for group in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (i, j) = (group[0].0, group[0].1);
        let rest_length = rest[i as usize].distance(rest[j as usize]);
        stretch.push(DistanceConstraint {
            i,
            j,
            rest: rest_length,
        });
        if let [(_, _, o1), (_, _, o2)] = *group {
            bend.push(bend_constraint([i, j, o1, o2], rest, inv_mass));
        }
    }
    (
        colour_order(stretch, |c| vec![c.i, c.j], rest.len()),
        colour_order(bend, |b| b.v.to_vec(), rest.len()),
    )
}

/// Long-range tethers (Kim, Chentanez, Müller, "Long Range Attachments", 2012, generalised
/// from pinned vertices to all pairs on grid lines): an inextensible sheet can only bend,
/// so two of its points are never farther apart than in the flat rest state. The
/// unilateral constraints are exact for inextensible cloth and pass the weight of hanging
/// cloth up in a few hops, where one Gauss–Seidel sweep per substep moves it one edge.
fn tethers(grid: usize, rest: &[Vec3]) -> Vec<Tether> {
    let index = |row: usize, col: usize| (row * grid + col) as u32;
    let mut tethers = Vec::new();
    for steps in TETHER_STEPS.into_iter().filter(|&k| k < grid) {
        for row in 0..grid {
            for col in 0..grid {
                // Along the row, the column, and both diagonals.
                let mut ends = Vec::with_capacity(4);
                if col + steps < grid {
                    ends.push(index(row, col + steps));
                }
                if row + steps < grid {
                    ends.push(index(row + steps, col));
                    if col + steps < grid {
                        ends.push(index(row + steps, col + steps));
                    }
                    if col >= steps {
                        ends.push(index(row + steps, col - steps));
                    }
                }
                let i = index(row, col);
                for j in ends {
                    let rest_length = rest[i as usize].distance(rest[j as usize]);
                    tethers.push(Tether {
                        i,
                        j,
                        rest: rest_length,
                        steps: steps as f32,
                    });
                }
            }
        }
    }
    colour_order(tethers, |t| vec![t.i, t.j], rest.len())
}

/// Reorders constraints by a greedy graph colouring, so that each colour is a set of
/// constraints that share no vertex, colours one after another (stable inside a colour).
///
/// The order of a Gauss–Seidel sweep matters for small-step XPBD: combined with the
/// velocity extrapolation `x + vΔt`, a sweep in plain vertex order has iteration
/// eigenvalues that amplify in-plane errors (a 66×66 cloth at rest in zero gravity blew
/// up within ~50 substeps); a coloured sweep is stable (see the `coloured_sweep_is_stable`
/// test of the solver). Colours also make the sweep independent of traversal details.
fn colour_order<T: Copy>(
    items: Vec<T>,
    vertices: impl Fn(&T) -> Vec<u32>,
    vertex_count: usize,
) -> Vec<T> {
    let mut used = vec![0u64; vertex_count];
    let mut coloured: Vec<(u32, T)> = items
        .into_iter()
        .map(|item| {
            let vs = vertices(&item);
            let mask = vs.iter().fold(0u64, |m, v| m | used[*v as usize]);
            // More than 64 colours cannot happen on a grid (≤ 6 edges or 12 hinges per
            // vertex); if it did, the last colour just holds dependent constraints.
            let colour = (!mask).trailing_zeros().min(63);
            for v in vs {
                used[v as usize] |= 1 << colour;
            }
            (colour, item)
        })
        .collect();
    coloured.sort_by_key(|(colour, _)| *colour);
    coloured.into_iter().map(|(_, item)| item).collect()
}

/// Cotangent of the angle between `a` and `b` (f64).
fn cot(a: DVec3, b: DVec3) -> f64 {
    a.dot(b) / a.cross(b).length()
}

/// The isometric bending constraint of the hinge `v = [x₀, x₁, x₂, x₃]` (edge x₀x₁).
pub(crate) fn bend_constraint(v: [u32; 4], rest: &[Vec3], inv_mass: &[f32]) -> BendConstraint {
    let x = v.map(|i| rest[i as usize].as_dvec3());
    let (e0, e1, e2) = (x[1] - x[0], x[2] - x[0], x[3] - x[0]);
    let (e3, e4) = (x[2] - x[1], x[3] - x[1]);
    let (c01, c02) = (cot(e0, e1), cot(e0, e2));
    let (c03, c04) = (cot(-e0, e3), cot(-e0, e4));
    let area = 0.5 * (e0.cross(e1).length() + e0.cross(e2).length());
    let scale = (3.0 / area).sqrt();
    let k = [c03 + c04, c01 + c02, -c01 - c03, -c02 - c04].map(|kj| kj * scale);
    let w_sum = (0..4)
        .map(|j| f64::from(inv_mass[v[j] as usize]) * k[j] * k[j])
        .sum::<f64>();
    BendConstraint {
        v,
        k: k.map(|kj| kj as f32),
        w_sum: w_sum as f32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_match_euler_and_mass_sums_to_total() {
        for grid in [2, 3, 7, 66] {
            let mesh = GridMesh::new(grid, 2.0, 0.2);
            let cells = (grid - 1) * (grid - 1);
            assert_eq!(mesh.triangles.len(), 2 * cells);
            // Edges: horizontal + vertical + one diagonal per cell.
            assert_eq!(mesh.stretch.len(), 2 * grid * (grid - 1) + cells);
            // Interior edges = all edges − boundary edges.
            assert_eq!(mesh.bend.len(), mesh.stretch.len() - 4 * (grid - 1));
            let total: f64 = mesh.inv_mass.iter().map(|w| 1.0 / f64::from(*w)).sum();
            assert!(
                (total - 0.8).abs() < 1e-5 * 0.8,
                "mass {total} != 0.2 kg/m² × 4 m²"
            );
        }
    }

    #[test]
    fn bending_vanishes_for_affine_maps_and_not_for_a_fold() {
        let mesh = GridMesh::new(6, 1.0, 1.0);
        let curvature = |b: &BendConstraint, p: &dyn Fn(Vec3) -> Vec3| {
            (0..4)
                .map(|j| p(mesh.rest[b.v[j] as usize]) * b.k[j])
                .sum::<Vec3>()
                .length()
        };
        let affine = |r: Vec3| Vec3::new(0.3 + r.x + 0.2 * r.z, 1.0 - 0.5 * r.x, 2.0 * r.z);
        let folded = |r: Vec3| Vec3::new(r.x, r.x.abs(), r.z); // 90° fold along x = 0
        let mut max_fold = 0.0f32;
        for b in &mesh.bend {
            assert!(curvature(b, &affine) < 1e-4, "{b:?}");
            max_fold = max_fold.max(curvature(b, &folded));
        }
        assert!(max_fold > 1.0, "fold not seen: {max_fold}");
        // The generalised inverse mass is Σ w k².
        let b = mesh.bend[7];
        let expected: f32 = (0..4)
            .map(|j| mesh.inv_mass[b.v[j] as usize] * b.k[j] * b.k[j])
            .sum();
        assert!((b.w_sum - expected).abs() < 1e-4 * expected);
    }

    #[test]
    fn triangles_face_up() {
        let mesh = GridMesh::new(5, 1.0, 1.0);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|v| mesh.rest[v as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.y > 0.0 && n.x == 0.0 && n.z == 0.0, "{t:?} normal {n}");
        }
    }
}
