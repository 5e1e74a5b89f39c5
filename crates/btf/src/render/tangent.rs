//! Per-vertex tangent frames from texture coordinates (the standard per-triangle ∂P/∂(u, v)
//! accumulation, Lengyel 2001, orthonormalised against the normal).

use glam::{Vec2, Vec3, Vec4};

use super::mesh::{MIN_NORMAL_LENGTH, check_lengths, check_triangles};
use crate::error::{BtfError, Result};

/// A triangle whose UV area |Δu₁Δv₂ − Δu₂Δv₁| is below this fraction of the product of its UV
/// edge lengths is degenerate in UV (its edges are parallel in texture space) and skipped.
/// 10⁻⁶ is a sine of 10⁻⁶ rad: only collapsed triangles, never a thin but valid one.
const MIN_UV_SINE: f32 = 1e-6;

/// A vertex whose accumulated tangent, made perpendicular to the normal, is shorter than this
/// fraction of its length gets an arbitrary perpendicular tangent.
const MIN_TANGENT_SINE: f32 = 1e-4;

/// Per-vertex tangents for [`BtfMesh::tangents`](super::BtfMesh::tangents): xyz the unit
/// tangent along increasing u, perpendicular to the normal; w = ±1 so that w · (n × t) points
/// along increasing v.
///
/// Each triangle contributes ∂P/∂u and ∂P/∂v (from its edges and UV differences) to its three
/// vertices; the sums are orthonormalised against the vertex normal (Gram–Schmidt). Triangles
/// with a degenerate UV mapping are skipped; a vertex with no valid contribution (or whose
/// ∂P/∂u is parallel to its normal) gets an arbitrary unit tangent perpendicular to its normal
/// and w = 1.
///
/// # Errors
/// [`BtfError::LengthMismatch`] if `normals` or `uvs` do not have one entry per position;
/// [`BtfError::InvalidParameter`] for a triangle index out of range or a zero normal;
/// [`BtfError::NonFinite`] for a NaN or infinite value.
///
/// # Examples
/// ```
/// use glam::{Vec2, Vec3};
/// let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
/// let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
/// let t = btf::render::tangent_frames(&p, &[Vec3::Z; 3], &uv, &[[0, 1, 2]])?;
/// assert_eq!(t[0], glam::Vec4::new(1.0, 0.0, 0.0, 1.0));
/// # Ok::<(), btf::BtfError>(())
/// ```
pub fn tangent_frames(
    positions: &[Vec3],
    normals: &[Vec3],
    uvs: &[Vec2],
    triangles: &[[u32; 3]],
) -> Result<Vec<Vec4>> {
    let n = positions.len();
    check_lengths(
        n,
        &[
            (
                "tangent_frames normals",
                normals.len(),
                "give one normal per vertex",
            ),
            (
                "tangent_frames uvs",
                uvs.len(),
                "give one texture coordinate per vertex",
            ),
        ],
    )?;
    check_triangles(triangles, n)?;
    let finite = |what: &'static str, i: usize, v: &[f32]| match v.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(BtfError::NonFinite {
            what: format!("tangent_frames {what} (vertex {i})"),
            index: i,
            value,
        }),
        None => Ok(()),
    };
    for i in 0..n {
        finite("positions", i, positions[i].as_ref())?;
        finite("normals", i, normals[i].as_ref())?;
        finite("uvs", i, uvs[i].as_ref())?;
    }

    let mut dp_du = vec![Vec3::ZERO; n];
    let mut dp_dv = vec![Vec3::ZERO; n];
    for tri in triangles {
        let [a, b, c] = tri.map(|i| i as usize);
        let (e1, e2) = (positions[b] - positions[a], positions[c] - positions[a]);
        let (d1, d2) = (uvs[b] - uvs[a], uvs[c] - uvs[a]);
        let det = d1.perp_dot(d2);
        if det.abs() <= MIN_UV_SINE * d1.length() * d2.length() {
            continue;
        }
        let su = (e1 * d2.y - e2 * d1.y) / det;
        let sv = (e2 * d1.x - e1 * d2.x) / det;
        for i in [a, b, c] {
            dp_du[i] += su;
            dp_dv[i] += sv;
        }
    }

    (0..n)
        .map(|i| {
            let len = normals[i].length();
            if len < MIN_NORMAL_LENGTH {
                return Err(BtfError::InvalidParameter {
                    what: "tangent_frames",
                    name: "normals",
                    value: format!("vertex {i}: {}", normals[i]),
                    reason: "a normal must have non-zero length",
                });
            }
            let normal = normals[i] / len;
            let t = dp_du[i] - normal * normal.dot(dp_du[i]);
            let len = t.length();
            if !len.is_finite() || len == 0.0 || len <= MIN_TANGENT_SINE * dp_du[i].length() {
                return Ok(normal.any_orthonormal_vector().extend(1.0));
            }
            let t = t.normalize();
            let w = if normal.cross(t).dot(dp_dv[i]) < 0.0 {
                -1.0
            } else {
                1.0
            };
            Ok(t.extend(w))
        })
        .collect()
}
