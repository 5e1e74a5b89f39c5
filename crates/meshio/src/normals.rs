//! Vertex normals from positions and triangles.
//!
//! None of the project's sequences stores normals (shared/data SOURCES.md, "Sequences"), and the
//! visibility computation of the thesis (§4.4) needs a normal per vertex to orient its
//! hemisphere, so every frame's normals are computed here.
//!
//! A vertex normal is the normalised sum of the unit normals of the triangles around it,
//! weighted by the triangle's interior angle at the vertex ([`NormalWeighting::Angle`], the
//! default: independent of how a polygon was split into triangles) or by the triangle's area
//! ([`NormalWeighting::Area`]). All arithmetic is f64, so coordinates near the f32 range (1e30)
//! neither overflow nor lose the small cross products of tiny triangles.
//!
//! **Fallback:** a vertex that no triangle references, or whose triangles are all degenerate
//! (or whose weighted normals cancel exactly), gets the zero vector. Zero rather than an
//! invented direction (+Z) so that a consumer can tell "no normal" from a real one; every
//! other output is finite and unit length.

use glam::{DVec3, Vec3};

use crate::NormalWeighting;

/// Computes one normal per vertex.
///
/// Output `i` is a finite unit vector, or exactly [`Vec3::ZERO`] when vertex `i` is referenced
/// by no non-degenerate triangle (see the module docs). Triangles with an index outside
/// `positions` are ignored (loaders reject those before calling this).
///
/// Counter-clockwise triangles (seen from outside) give outward normals.
///
/// # Examples
/// ```
/// use glam::Vec3;
/// use meshio::{compute_normals, NormalWeighting};
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::splat(9.0)];
/// let normals = compute_normals(&positions, &[[0, 1, 2]], NormalWeighting::Angle);
/// assert_eq!(normals[0], Vec3::Z);
/// assert_eq!(normals[3], Vec3::ZERO); // unreferenced
/// ```
pub fn compute_normals(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    weighting: NormalWeighting,
) -> Vec<Vec3> {
    let mut sums = vec![DVec3::ZERO; positions.len()];
    accumulate(positions, triangles, weighting, &mut sums);
    sums.iter()
        .map(|sum| sum.normalize_or_zero().as_vec3())
        .map(finite_or_zero)
        .collect()
}

/// Like [`compute_normals`], writing into `out` (which must have `positions.len()` entries) and
/// reusing `scratch` for the f64 sums, so that per-frame loops do not allocate.
///
/// # Panics
/// If `out.len() != positions.len()`.
pub fn compute_normals_into(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    weighting: NormalWeighting,
    scratch: &mut Vec<DVec3>,
    out: &mut [Vec3],
) {
    assert_eq!(
        out.len(),
        positions.len(),
        "output slice must have one entry per position"
    );
    scratch.clear();
    scratch.resize(positions.len(), DVec3::ZERO);
    accumulate(positions, triangles, weighting, scratch);
    for (normal, sum) in out.iter_mut().zip(scratch.iter()) {
        *normal = finite_or_zero(sum.normalize_or_zero().as_vec3());
    }
}

/// Adds each triangle's weighted normal to its three vertices' sums.
fn accumulate(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    weighting: NormalWeighting,
    sums: &mut [DVec3],
) {
    let n = positions.len();
    for tri in triangles {
        let [a, b, c] = tri.map(|i| i as usize);
        if a >= n || b >= n || c >= n {
            continue;
        }
        let (pa, pb, pc) = (
            positions[a].as_dvec3(),
            positions[b].as_dvec3(),
            positions[c].as_dvec3(),
        );
        let cross = (pb - pa).cross(pc - pa);
        match weighting {
            NormalWeighting::Area => {
                // |cross| = 2 × area, so the plain cross product is the area-weighted normal.
                sums[a] += cross;
                sums[b] += cross;
                sums[c] += cross;
            }
            NormalWeighting::Angle => {
                let twice_area = cross.length();
                if twice_area <= 0.0 || !twice_area.is_finite() {
                    continue;
                }
                let unit = cross / twice_area;
                // Every corner's edge vectors span the same |cross| = 2·area, so each angle is
                // atan2(2·area, dot), and the third is π minus the other two.
                let angle_a = twice_area.atan2((pb - pa).dot(pc - pa));
                let angle_b = twice_area.atan2((pc - pb).dot(pa - pb));
                let angle_c = (std::f64::consts::PI - angle_a - angle_b).max(0.0);
                sums[a] += unit * angle_a;
                sums[b] += unit * angle_b;
                sums[c] += unit * angle_c;
            }
        }
    }
}

/// Maps any non-finite result (impossible for finite input, kept as a guarantee) to zero.
fn finite_or_zero(v: Vec3) -> Vec3 {
    if v.is_finite() { v } else { Vec3::ZERO }
}
