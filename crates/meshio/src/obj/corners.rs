//! Per-corner OBJ attributes (`vt`, `vn`) to per-vertex ones.
//!
//! OBJ indexes texture coordinates and normals per face corner, independently of positions.
//! This crate keeps positions exactly as the `v` lines give them (per-vertex outputs line up
//! with the file, which the animation and visibility code relies on), so an attribute survives
//! only when every corner of each vertex carries the same value (compared bit for bit, so
//! duplicated but equal `vt` lines are fine). Otherwise — a UV seam, as in the garment files
//! whose `vt` are sewing-pattern coordinates, or a hard normal edge — the attribute is dropped
//! and the report says how many vertices disagree. Vertices that no face references get zero.

use super::parse::NO_INDEX;
use crate::AttributeStatus;

/// Resolves per-corner indices into one value per vertex.
///
/// Returns the values when every referenced vertex has one consistent value, otherwise the
/// [`AttributeStatus::DroppedPerCorner`] explaining why not.
pub(crate) fn per_vertex<T: Copy + Default>(
    vertex_count: usize,
    triangles: &[[u32; 3]],
    corner_indices: &[[u32; 3]],
    values: &[T],
    same: impl Fn(&T, &T) -> bool,
) -> Result<Vec<T>, AttributeStatus> {
    let mut out: Vec<Option<T>> = vec![None; vertex_count];
    let mut conflicting = vec![false; vertex_count];
    let mut missing_corners = 0usize;
    for (tri, idx) in triangles.iter().zip(corner_indices) {
        for (&v, &a) in tri.iter().zip(idx) {
            if a == NO_INDEX {
                missing_corners += 1;
                continue;
            }
            // The parser has checked every index against the value count.
            let value = values[a as usize];
            let slot = &mut out[v as usize];
            match slot {
                None => *slot = Some(value),
                Some(existing) if same(existing, &value) => {}
                Some(_) => conflicting[v as usize] = true,
            }
        }
    }
    let conflicting_vertices = conflicting.iter().filter(|&&c| c).count();
    if conflicting_vertices > 0 || missing_corners > 0 {
        return Err(AttributeStatus::DroppedPerCorner {
            conflicting_vertices,
            missing_corners,
        });
    }
    Ok(out.into_iter().map(Option::unwrap_or_default).collect())
}

/// Bitwise equality of float arrays (`-0.0 == 0.0`), so that equal duplicates match.
pub(crate) fn same_bits<const N: usize>(a: [f32; N], b: [f32; N]) -> bool {
    a.iter()
        .zip(&b)
        .all(|(x, y)| x.to_bits() == y.to_bits() || (*x == 0.0 && *y == 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn consistent_corners_give_per_vertex_values() {
        let tris = [[0, 1, 2], [2, 1, 3]];
        // Corner indices differ but point at equal values for vertex 1 and 2.
        let idx = [[0, 1, 2], [3, 4, 5]];
        let values = [10.0, 11.0, 12.0, 12.0, 11.0, 13.0];
        let out = per_vertex(5, &tris, &idx, &values, |a: &f32, b| a == b).unwrap();
        assert_eq!(out, vec![10.0, 11.0, 12.0, 13.0, 0.0]);
    }

    #[test]
    fn seams_and_missing_corners_drop_the_attribute() {
        let tris = [[0, 1, 2], [2, 1, 3]];
        let idx = [[0, 1, 2], [3, NO_INDEX, 5]];
        let values = [10.0, 11.0, 12.0, 99.0, 11.0, 13.0];
        let status = per_vertex(4, &tris, &idx, &values, |a: &f32, b| a == b).unwrap_err();
        assert_eq!(
            status,
            AttributeStatus::DroppedPerCorner {
                conflicting_vertices: 1,
                missing_corners: 1
            }
        );
    }
}
