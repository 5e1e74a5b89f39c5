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
//! **Cancelled sums.** Two triangles over the same three vertices with opposite windings (a
//! zero-thickness flap, "back to back") add opposite normals: a vertex that only such pairs use
//! sums to exactly zero or to rounding noise, about 1e-16 of its weights, whose direction is
//! arbitrary. The Stanford bunny's `bun_zipper_res3.ply` has 70 such pairs and 10 vertices only
//! they use: 7 summed to zero and 3 to noise, and all 10 rendered as dark specks. A sum
//! shorter than [`CANCELLED_RELATIVE`] × the sum of its weights counts as no direction at all.
//!
//! **Fallback.** A vertex whose own triangles give no direction — all degenerate, or their
//! normals cancel — takes the normalised mean of its neighbours' normals (the other corners of
//! its triangles that have one): a flap's tip is shaded like the surface the flap grows from.
//! Rounds repeat while they lend a normal, so a fin of several back-to-back pairs fills from
//! the surface inwards. A vertex that no triangle references, or whose whole connected part
//! has no normal (an isolated back-to-back pair), gets the zero vector. On
//! `dragon_vrip_res2.ply` (1,408 back-to-back pairs) 387 vertices had no normal before this
//! rule, and others a noise direction; 54 have none now: the 43 no triangle uses and 11 in
//! loose back-to-back pieces. Zero rather than an invented direction (+Z), so that a consumer
//! can tell "no normal" from a real one; every other output is finite and unit length.

use glam::{DVec3, Vec3};

use crate::NormalWeighting;

/// A vertex's weighted normals cancel when their sum is at most this fraction of the sum of
/// their weights (angles in radians, or twice the triangles' areas): f64 rounding leaves
/// about 1e-16, and no real surface folds to within 1e-9 rad of flat back onto itself.
pub const CANCELLED_RELATIVE: f64 = 1e-9;

/// Reusable buffers of [`compute_normals_into`], so that per-frame loops do not allocate.
#[derive(Clone, Debug, Default)]
pub struct NormalScratch {
    sums: Vec<DVec3>,
    weights: Vec<f64>,
    referenced: Vec<bool>,
}

/// Computes one normal per vertex.
///
/// Output `i` is a finite unit vector, or exactly [`Vec3::ZERO`] when neither vertex `i`'s
/// triangles nor its neighbours give a direction (see the module docs). Triangles with an
/// index outside `positions` are ignored (loaders reject those before calling this).
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
    let mut out = vec![Vec3::ZERO; positions.len()];
    compute_normals_into(
        positions,
        triangles,
        weighting,
        &mut NormalScratch::default(),
        &mut out,
    );
    out
}

/// Like [`compute_normals`], writing into `out` (which must have `positions.len()` entries) and
/// reusing `scratch`'s buffers.
///
/// # Panics
/// If `out.len() != positions.len()`.
pub fn compute_normals_into(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    weighting: NormalWeighting,
    scratch: &mut NormalScratch,
    out: &mut [Vec3],
) {
    assert_eq!(
        out.len(),
        positions.len(),
        "output slice must have one entry per position"
    );
    let n = positions.len();
    let NormalScratch {
        sums,
        weights,
        referenced,
    } = scratch;
    sums.clear();
    sums.resize(n, DVec3::ZERO);
    weights.clear();
    weights.resize(n, 0.0);
    referenced.clear();
    referenced.resize(n, false);
    accumulate(positions, triangles, weighting, sums, weights, referenced);
    let mut missing = false;
    for (v, normal) in out.iter_mut().enumerate() {
        *normal = direction(sums[v], weights[v]);
        missing |= *normal == Vec3::ZERO && referenced[v];
    }
    // Each round lends the normals of the round before to the vertices still without one, so
    // a fin of several triangles fills from the surface inwards; it stops when a round lends
    // none (every remaining vertex is in a component without any normal).
    while missing {
        missing = borrow_from_neighbours(triangles, out, sums, weights, referenced);
    }
}

/// The unit direction of a weighted sum, or zero when it has none: no weight, a sum cancelled
/// to rounding noise ([`CANCELLED_RELATIVE`]), or a non-finite result (impossible for finite
/// input, kept as a guarantee).
fn direction(sum: DVec3, weight: f64) -> Vec3 {
    if sum.length() > CANCELLED_RELATIVE * weight {
        let v = sum.normalize_or_zero().as_vec3();
        if v.is_finite() {
            return v;
        }
    }
    Vec3::ZERO
}

/// One round of the fallback of the module docs: each referenced vertex left without a normal
/// takes the normalised mean of the normals its triangles' other corners had before this
/// round (so the result does not depend on the order of the triangles). Returns whether a
/// vertex got one and some are still without.
fn borrow_from_neighbours(
    triangles: &[[u32; 3]],
    out: &mut [Vec3],
    sums: &mut [DVec3],
    weights: &mut [f64],
    referenced: &[bool],
) -> bool {
    let n = out.len();
    let needs: Vec<bool> = (0..n)
        .map(|v| out[v] == Vec3::ZERO && referenced[v])
        .collect();
    sums.fill(DVec3::ZERO);
    weights.fill(0.0);
    for tri in triangles {
        let [a, b, c] = tri.map(|i| i as usize);
        if a >= n || b >= n || c >= n {
            continue;
        }
        for (v, others) in [(a, [b, c]), (b, [c, a]), (c, [a, b])] {
            if !needs[v] {
                continue;
            }
            for o in others {
                if out[o] != Vec3::ZERO {
                    sums[v] += out[o].as_dvec3();
                    weights[v] += 1.0;
                }
            }
        }
    }
    let (mut lent, mut left) = (false, false);
    for v in (0..n).filter(|&v| needs[v]) {
        out[v] = direction(sums[v], weights[v]);
        lent |= out[v] != Vec3::ZERO;
        left |= out[v] == Vec3::ZERO;
    }
    lent && left
}

/// Adds each triangle's weighted normal to its three vertices' sums, the weights' magnitudes
/// to `weights`, and marks every vertex a triangle references.
fn accumulate(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    weighting: NormalWeighting,
    sums: &mut [DVec3],
    weights: &mut [f64],
    referenced: &mut [bool],
) {
    let n = positions.len();
    for tri in triangles {
        let [a, b, c] = tri.map(|i| i as usize);
        if a >= n || b >= n || c >= n {
            continue;
        }
        for v in [a, b, c] {
            referenced[v] = true;
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
                let twice_area = cross.length();
                for v in [a, b, c] {
                    sums[v] += cross;
                    weights[v] += twice_area;
                }
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
                for (v, angle) in [(a, angle_a), (b, angle_b), (c, angle_c)] {
                    sums[v] += unit * angle;
                    weights[v] += angle;
                }
            }
        }
    }
}
