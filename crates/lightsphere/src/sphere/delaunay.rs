//! Spherical Delaunay triangulation by Lawson edge flips.
//!
//! The spherical Voronoi diagram of unit directions is the dual of their spherical Delaunay
//! triangulation, which is the convex hull of the points. The octahedron subdivision is a
//! triangulation of the same points but is *not assumed* to be Delaunay: every edge is
//! checked for the empty-circumcircle property and flipped when it fails (Lawson's algorithm
//! lifted to the sphere, where "d lies inside the circumcircle of abc" is "d lies strictly
//! above the plane through a, b, c").
//!
//! Co-circular quads (d exactly on that plane, which the symmetric subdivision produces) are
//! left alone: both diagonals are Delaunay, the two triangles share one circumcentre, and the
//! Voronoi cells — hence the solid angles — are the same for either choice. A flip happens
//! only when the violation exceeds [`FLIP_TOLERANCE`] relative to the edge lengths, so
//! rounding noise cannot make two co-circular diagonals flip back and forth.

use glam::DVec3;
use std::collections::HashMap;

/// Relative in-circle violation below which an edge counts as Delaunay (co-circular).
/// The in-circle determinant of unit vectors carries rounding error of order 1e-16 times the
/// product of the three edge lengths; 1e-12 leaves four orders of margin and is far below any
/// genuine violation (those are of the order of the edge lengths cubed).
pub(crate) const FLIP_TOLERANCE: f64 = 1e-12;

/// A closed triangulation of the sphere with half-edge twins.
#[derive(Clone, Debug)]
pub(crate) struct Triangulation {
    /// Counter-clockwise (from outside) triangles.
    pub triangles: Vec<[u32; 3]>,
    /// `twin[3t + i]` is the half-edge opposite to half-edge `3t + i`, which runs from
    /// `triangles[t][i]` to `triangles[t][(i + 1) % 3]`.
    pub twin: Vec<u32>,
    /// How many flips the Delaunay pass made.
    pub flips: usize,
}

impl Triangulation {
    /// Build twins for a closed, consistently oriented triangle mesh.
    ///
    /// # Panics
    /// When the mesh is not closed and manifold (an internal bug: the subdivision always is).
    pub(crate) fn new(triangles: Vec<[u32; 3]>) -> Self {
        let mut by_edge: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
        for (t, tri) in triangles.iter().enumerate() {
            for i in 0..3 {
                let he = (3 * t + i) as u32;
                let previous = by_edge.insert((tri[i], tri[(i + 1) % 3]), he);
                assert!(
                    previous.is_none(),
                    "half-edge {:?} appears twice",
                    (tri[i], tri[(i + 1) % 3])
                );
            }
        }
        let mut twin = vec![u32::MAX; triangles.len() * 3];
        for (t, tri) in triangles.iter().enumerate() {
            for i in 0..3 {
                let reverse = (tri[(i + 1) % 3], tri[i]);
                twin[3 * t + i] = *by_edge
                    .get(&reverse)
                    .unwrap_or_else(|| panic!("edge {reverse:?} has no twin: mesh not closed"));
            }
        }
        Self {
            triangles,
            twin,
            flips: 0,
        }
    }

    /// Vertex at the start of half-edge `he`.
    fn origin(&self, he: usize) -> u32 {
        self.triangles[he / 3][he % 3]
    }

    /// Vertex opposite half-edge `he` in its triangle.
    fn opposite(&self, he: usize) -> u32 {
        self.triangles[he / 3][(he % 3 + 2) % 3]
    }

    fn link(&mut self, a: usize, b: usize) {
        self.twin[a] = b as u32;
        self.twin[b] = a as u32;
    }

    /// Flip the edge of half-edge `he`: triangles (a, b, c) and (b, a, d) become (c, a, d)
    /// and (d, b, c). Returns the four outer half-edges, to be re-checked.
    fn flip(&mut self, he: usize) -> [usize; 4] {
        let (t, i) = (he / 3, he % 3);
        let tw = self.twin[he] as usize;
        let (t2, i2) = (tw / 3, tw % 3);
        let a = self.origin(he);
        let b = self.triangles[t][(i + 1) % 3];
        let c = self.opposite(he);
        let d = self.opposite(tw);
        // Outer half-edges' twins: b→c, c→a in t; a→d, d→b in t2.
        let bc = self.twin[3 * t + (i + 1) % 3] as usize;
        let ca = self.twin[3 * t + (i + 2) % 3] as usize;
        let ad = self.twin[3 * t2 + (i2 + 1) % 3] as usize;
        let db = self.twin[3 * t2 + (i2 + 2) % 3] as usize;
        self.triangles[t] = [c, a, d];
        self.triangles[t2] = [d, b, c];
        self.link(3 * t, ca);
        self.link(3 * t + 1, ad);
        self.link(3 * t + 2, 3 * t2 + 2);
        self.link(3 * t2, db);
        self.link(3 * t2 + 1, bc);
        self.flips += 1;
        [3 * t, 3 * t + 1, 3 * t2, 3 * t2 + 1]
    }
}

/// Positive when `d` lies strictly inside the circumcircle of the counter-clockwise
/// spherical triangle (a, b, c), i.e. above its plane; returns the violation relative to the
/// edge lengths (0 for co-circular points).
pub(crate) fn in_circle(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let (ab, ac, ad) = (b - a, c - a, d - a);
    let scale = ab.length() * ac.length() * ad.length();
    if scale == 0.0 {
        return 0.0;
    }
    ad.dot(ab.cross(ac)) / scale
}

/// Turn `mesh` into the Delaunay triangulation of `points` by Lawson flips.
///
/// # Panics
/// When the flips do not converge (an internal bug: the input is a valid triangulation of
/// points in convex position).
pub(crate) fn make_delaunay(points: &[DVec3], mesh: &mut Triangulation) {
    let half_edges = mesh.triangles.len() * 3;
    let mut stack: Vec<usize> = (0..half_edges)
        .filter(|&he| (he as u32) < mesh.twin[he])
        .collect();
    let flip_limit = 64 * half_edges + 64;
    while let Some(he) = stack.pop() {
        let tw = mesh.twin[he] as usize;
        let p = |v: u32| points[v as usize];
        let a = p(mesh.origin(he));
        let b = p(mesh.origin(tw));
        let c = p(mesh.opposite(he));
        let d = p(mesh.opposite(tw));
        if in_circle(a, b, c, d) > FLIP_TOLERANCE {
            stack.extend_from_slice(&mesh.flip(he));
            assert!(mesh.flips <= flip_limit, "Delaunay flips do not converge");
        }
    }
}

#[cfg(test)]
/// Largest relative in-circle violation over all edges (≤ [`FLIP_TOLERANCE`] after
/// [`make_delaunay`]).
pub(crate) fn max_violation(points: &[DVec3], mesh: &Triangulation) -> f64 {
    let p = |v: u32| points[v as usize];
    (0..mesh.triangles.len() * 3)
        .map(|he| {
            let tw = mesh.twin[he] as usize;
            in_circle(
                p(mesh.origin(he)),
                p(mesh.origin(tw)),
                p(mesh.opposite(he)),
                p(mesh.opposite(tw)),
            )
        })
        .fold(f64::NEG_INFINITY, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sphere::subdivision::subdivide;

    /// A deliberately non-Delaunay start: flip every third edge of a Delaunay mesh, then the
    /// Lawson pass must restore the empty-circle property everywhere.
    #[test]
    fn lawson_repairs_a_scrambled_triangulation() {
        let s = subdivide(2);
        let mut mesh = Triangulation::new(s.triangles.clone());
        let edges: Vec<usize> = (0..mesh.triangles.len() * 3)
            .filter(|&he| (he as u32) < mesh.twin[he])
            .step_by(3)
            .collect();
        let mut scrambled = 0;
        for he in edges {
            // Flip only where the quad stays a valid (convex) triangulation.
            let tw = mesh.twin[he] as usize;
            let p = |v: u32| s.directions[v as usize];
            let (a, b) = (p(mesh.origin(he)), p(mesh.origin(tw)));
            let (c, d) = (p(mesh.opposite(he)), p(mesh.opposite(tw)));
            let convex = (a - c).cross(d - c).dot(c) > 0.0 && (b - d).cross(c - d).dot(d) > 0.0;
            let shares_edge = mesh.triangles.iter().any(|t| {
                let has = |v| t.contains(&v);
                has(mesh.opposite(he)) && has(mesh.opposite(tw))
            });
            if convex && !shares_edge {
                mesh.flip(he);
                scrambled += 1;
            }
        }
        assert!(scrambled > 10);
        assert!(max_violation(&s.directions, &mesh) > 1e-3);
        mesh.flips = 0;
        make_delaunay(&s.directions, &mut mesh);
        assert!(mesh.flips >= scrambled / 2);
        assert!(max_violation(&s.directions, &mesh) <= FLIP_TOLERANCE);
    }
}
