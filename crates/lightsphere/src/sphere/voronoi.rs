//! Solid-angle weights ω_j: the areas of the spherical Voronoi cells of the directions.
//!
//! The seed (paper 000 §3.4) wants a distribution that "equally sample[s] the environment in
//! all directions" but does not say how much of the sphere each direction stands for. This
//! crate defines ω_j as the area of direction j's spherical Voronoi cell (the set of unit
//! vectors closer to l_j than to any other direction), so that Σ_j ω_j = 4π and the cells are
//! exactly what [`crate::Lightsphere::nearest`] returns.
//!
//! The Voronoi vertices are the circumcentres of the Delaunay triangles (see
//! [`super::delaunay`]). The cell of generator a is the fan of spherical triangles
//! (a, o_t', o_t) over the Delaunay edges a→b, where t is the triangle left of a→b and t' the
//! one right of it. Each fan triangle's signed area comes from the Van Oosterom–Strackee
//! formula tan(E/2) = a·(b×c) / (1 + a·b + b·c + c·a), evaluated with atan2, which is stable
//! for thin and for large triangles.

use super::delaunay::Triangulation;
use glam::DVec3;

/// Signed area (solid angle) of the spherical triangle (a, b, c) of unit vectors; positive
/// when counter-clockwise seen from outside (Van Oosterom & Strackee 1983).
pub(crate) fn spherical_triangle_area(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let numerator = a.dot(b.cross(c));
    let denominator = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
    2.0 * numerator.atan2(denominator)
}

/// Angle between two unit vectors, accurate for small and large angles.
pub(crate) fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Voronoi cell areas and cell radii of a Delaunay triangulation.
#[derive(Clone, Debug)]
pub(crate) struct VoronoiCells {
    /// Area of each generator's cell, in steradians.
    pub areas: Vec<f64>,
    /// Largest angle from each generator to a vertex of its cell, in radians.
    pub radii: Vec<f64>,
}

/// Circumcentre (on the unit sphere) of the counter-clockwise triangle (a, b, c).
fn circumcentre(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let n = (b - a).cross(c - a);
    n / n.length()
}

/// Cell areas and radii for `points` with Delaunay triangulation `mesh`.
pub(crate) fn voronoi_cells(points: &[DVec3], mesh: &Triangulation) -> VoronoiCells {
    let centres: Vec<DVec3> = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| points[i as usize]);
            circumcentre(a, b, c)
        })
        .collect();
    let mut areas = vec![0.0; points.len()];
    let mut radii = vec![0.0f64; points.len()];
    for he in 0..mesh.triangles.len() * 3 {
        let (t, i) = (he / 3, he % 3);
        let a = mesh.triangles[t][i] as usize;
        let t_right = mesh.twin[he] as usize / 3;
        let (o_left, o_right) = (centres[t], centres[t_right]);
        areas[a] += spherical_triangle_area(points[a], o_right, o_left);
        radii[a] = radii[a].max(angle_between(points[a], o_left));
    }
    VoronoiCells { areas, radii }
}
