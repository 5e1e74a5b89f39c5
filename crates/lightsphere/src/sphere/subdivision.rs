//! Octahedron midpoint subdivision (paper 000 §3.4, thesis §4.4.3 "Creating the Lightsphere").
//!
//! "We start with the vertices of a unit octahedron, i.e. k = 6 light directions at subdivision
//! level s = 0. To generate level s + 1, we do midpoint subdivision of the edges on level s and
//! project the new vertices on the unit sphere, thus creating a polyhedron with 2·4^(s+1) faces
//! and 2 + 4^(s+1) vertices."
//!
//! Order: level 0 is +X, −X, +Y, −Y, +Z, −Z. Level s+1 keeps level s's directions first, in
//! the same order, then appends one midpoint per level-s edge, in the order the edges are
//! first met when walking level s's triangles in order (edges v0v1, v1v2, v2v0 of each). So
//! the first k(s) directions of every finer level are level s's, bit for bit.
//!
//! Triangles are counter-clockwise seen from outside the sphere. Each level-s triangle
//! (a, b, c) becomes, in this order, (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca).

use glam::DVec3;
use std::collections::HashMap;

/// Directions (unit, f64) and triangles of one subdivision level.
#[derive(Clone, Debug)]
pub(crate) struct Subdivision {
    /// Unit directions in the nested order.
    pub directions: Vec<DVec3>,
    /// Counter-clockwise (from outside) triangles indexing `directions`.
    pub triangles: Vec<[u32; 3]>,
}

/// Level 0: the octahedron.
fn octahedron() -> Subdivision {
    let directions = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let mut triangles = Vec::with_capacity(8);
    // One face per octant (sx, sy, sz); (x, y, z) is counter-clockwise from outside when
    // sx·sy·sz > 0, otherwise swap two corners.
    for sx in [0u32, 1] {
        for sy in [0u32, 1] {
            for sz in [0u32, 1] {
                let (x, y, z) = (sx, 2 + sy, 4 + sz);
                if (sx + sy + sz) % 2 == 0 {
                    triangles.push([x, y, z]);
                } else {
                    triangles.push([x, z, y]);
                }
            }
        }
    }
    Subdivision {
        directions,
        triangles,
    }
}

/// One midpoint-subdivision step: 1 → 4 triangles, new vertices projected onto the sphere.
fn refine(coarse: &Subdivision) -> Subdivision {
    let mut directions = coarse.directions.clone();
    let edge_count = coarse.triangles.len() * 3 / 2;
    directions.reserve(edge_count);
    let mut midpoint_of: HashMap<(u32, u32), u32> = HashMap::with_capacity(edge_count);
    let mut midpoint = |a: u32, b: u32, directions: &mut Vec<DVec3>| -> u32 {
        let key = (a.min(b), a.max(b));
        *midpoint_of.entry(key).or_insert_with(|| {
            let m = directions[a as usize] + directions[b as usize];
            directions.push(m / m.length());
            u32::try_from(directions.len() - 1).expect("direction count is bounded by MAX_LEVEL")
        })
    };
    let mut triangles = Vec::with_capacity(coarse.triangles.len() * 4);
    for &[a, b, c] in &coarse.triangles {
        let ab = midpoint(a, b, &mut directions);
        let bc = midpoint(b, c, &mut directions);
        let ca = midpoint(c, a, &mut directions);
        triangles.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    Subdivision {
        directions,
        triangles,
    }
}

/// The subdivision at `level` (no bound check: callers check [`crate::MAX_LEVEL`]).
pub(crate) fn subdivide(level: u32) -> Subdivision {
    let mut current = octahedron();
    for _ in 0..level {
        current = refine(&current);
    }
    debug_assert_eq!(current.directions.len(), crate::direction_count(level));
    current
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedron_faces_point_outwards() {
        let s = octahedron();
        for t in &s.triangles {
            let [a, b, c] = t.map(|i| s.directions[i as usize]);
            let normal = (b - a).cross(c - a);
            assert!(normal.dot(a + b + c) > 0.0, "face {t:?} is clockwise");
        }
    }

    #[test]
    fn counts_follow_the_seed_formula() {
        for level in 0..=4 {
            let s = subdivide(level);
            assert_eq!(s.directions.len(), 2 + 4usize.pow(level + 1));
            assert_eq!(s.triangles.len(), 2 * 4usize.pow(level + 1));
        }
    }
}
