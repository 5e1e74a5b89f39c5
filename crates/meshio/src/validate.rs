//! Checks shared by every loader: finite coordinates, index ranges, degenerate triangles,
//! unreferenced vertices, duplicate positions, and the optional clean-up.
//!
//! Problems that make the data unusable (NaN, out-of-range indices, empty meshes) are errors.
//! Problems that are merely untidy (degenerate triangles, unreferenced or duplicated vertices)
//! are reported in [`LoadReport`] and fixed only when [`LoadOptions`] asks for it, so that by
//! default per-vertex outputs line up with the file.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::{
    Animation, AttributeStatus, DegenerateKind, DegenerateTriangle, LoadOptions, LoadReport, Mesh,
    MeshIoError, compute_normals,
};

/// A triangle is [`DegenerateKind::ZeroArea`] when twice its area is at most this fraction of
/// its longest edge squared, i.e. its height is below f32 resolution relative to that edge:
/// its normal is then rounding noise. `f32::EPSILON` because positions are f32.
pub const ZERO_AREA_RELATIVE: f64 = f32::EPSILON as f64;

/// Finds triangles with a repeated index or (near-)zero area (see [`ZERO_AREA_RELATIVE`]).
///
/// Indices must be in range (loaders check this first); out-of-range triangles are skipped.
pub fn find_degenerate_triangles(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
) -> Vec<DegenerateTriangle> {
    let mut found = Vec::new();
    for (t, &[a, b, c]) in triangles.iter().enumerate() {
        let kind = if a == b || b == c || a == c {
            DegenerateKind::RepeatedIndex
        } else {
            let (Some(pa), Some(pb), Some(pc)) = (
                positions.get(a as usize),
                positions.get(b as usize),
                positions.get(c as usize),
            ) else {
                continue;
            };
            let (pa, pb, pc) = (pa.as_dvec3(), pb.as_dvec3(), pc.as_dvec3());
            let twice_area = (pb - pa).cross(pc - pa).length();
            let longest_sq = (pb - pa)
                .length_squared()
                .max((pc - pb).length_squared())
                .max((pa - pc).length_squared());
            if twice_area > ZERO_AREA_RELATIVE * longest_sq {
                continue;
            }
            DegenerateKind::ZeroArea
        };
        found.push(DegenerateTriangle {
            triangle: t as u32,
            kind,
        });
    }
    found
}

/// Indices of the vertices (out of `vertex_count`) that no triangle references, ascending.
pub fn find_unreferenced_vertices(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    let used = referenced_mask(vertex_count, triangles);
    (0..vertex_count as u32)
        .filter(|&v| !used[v as usize])
        .collect()
}

/// Vertex count minus the number of distinct positions (bitwise equality, `-0.0 == 0.0`).
pub fn count_duplicate_positions(positions: &[Vec3]) -> usize {
    let bits = |c: f32| if c == 0.0 { 0 } else { u128::from(c.to_bits()) };
    let mut keys: Vec<u128> = positions
        .iter()
        .map(|p| (bits(p.x) << 64) | (bits(p.y) << 32) | bits(p.z))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    positions.len() - keys.len()
}

/// Triangles that repeat an earlier triangle's three vertices: `repeated` with the same
/// winding (the same face twice), `back_to_back` pairs with opposite windings (a
/// zero-thickness flap, whose normals cancel: see [`crate::compute_normals`]). A set of
/// vertices written `e` times in one winding and `o` times in the other counts
/// p = `min(e, o)` pairs, and the e + o − 2p triangles left over (all of one winding) less the
/// first one, when no pair holds it already, as repeats; triangles with a repeated index are
/// left to [`find_degenerate_triangles`].
pub fn count_repeated_triangles(triangles: &[[u32; 3]]) -> RepeatedTriangles {
    let mut keys: Vec<([u32; 3], bool)> = triangles
        .iter()
        .filter(|&&[a, b, c]| a != b && b != c && a != c)
        .map(|&tri| {
            // Rotate the smallest index first (keeps the winding), then compare the others.
            let m = (0..3).min_by_key(|&i| tri[i]).unwrap_or(0);
            let [a, b, c] = [tri[m], tri[(m + 1) % 3], tri[(m + 2) % 3]];
            if b < c {
                ([a, b, c], true)
            } else {
                ([a, c, b], false)
            }
        })
        .collect();
    keys.sort_unstable();
    let mut found = RepeatedTriangles::default();
    for run in keys.chunk_by(|x, y| x.0 == y.0) {
        let even = run.iter().filter(|k| k.1).count();
        let pairs = even.min(run.len() - even);
        found.back_to_back += pairs;
        let left = run.len() - 2 * pairs;
        found.repeated += if pairs == 0 { left - 1 } else { left };
    }
    found
}

/// What [`count_repeated_triangles`] found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RepeatedTriangles {
    /// Triangles equal to another, winding included, beyond the pairs below and the first.
    pub repeated: usize,
    /// Pairs of triangles over the same vertices with opposite windings.
    pub back_to_back: usize,
}

fn referenced_mask(vertex_count: usize, triangles: &[[u32; 3]]) -> Vec<bool> {
    let mut used = vec![false; vertex_count];
    for &i in triangles.iter().flatten() {
        if let Some(flag) = used.get_mut(i as usize) {
            *flag = true;
        }
    }
    used
}

const AXES: [&str; 3] = ["x", "y", "z"];
const NORMAL_AXES: [&str; 3] = ["normal x", "normal y", "normal z"];

/// Errors on the first non-finite vector; `element(i)` names entry `i`.
pub(crate) fn check_finite3(
    path: &Path,
    values: &[Vec3],
    normals: bool,
    element: impl Fn(usize) -> String,
) -> Result<(), MeshIoError> {
    let names = if normals { NORMAL_AXES } else { AXES };
    for (i, v) in values.iter().enumerate() {
        if let Some(axis) = (0..3).find(|&k| !v[k].is_finite()) {
            return Err(MeshIoError::NonFinite {
                path: path.to_path_buf(),
                line: None,
                element: element(i),
                component: names[axis],
                value: f64::from(v[axis]),
            });
        }
    }
    Ok(())
}

fn check_finite_uvs(path: &Path, uvs: &[Vec2]) -> Result<(), MeshIoError> {
    for (i, uv) in uvs.iter().enumerate() {
        if let Some(axis) = (0..2).find(|&k| !uv[k].is_finite()) {
            return Err(MeshIoError::NonFinite {
                path: path.to_path_buf(),
                line: None,
                element: format!("vertex {i}"),
                component: ["texture u", "texture v"][axis],
                value: f64::from(uv[axis]),
            });
        }
    }
    Ok(())
}

/// Errors on the first triangle index `>= vertex_count`.
pub(crate) fn check_indices(
    path: &Path,
    triangles: &[[u32; 3]],
    vertex_count: usize,
) -> Result<(), MeshIoError> {
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= vertex_count) {
            return Err(MeshIoError::IndexOutOfRange {
                path: path.to_path_buf(),
                line: None,
                element: format!("triangle {t}"),
                index: i64::from(index),
                vertex_count,
            });
        }
    }
    Ok(())
}

/// A mesh as parsed, before validation and clean-up.
#[derive(Debug, Default)]
pub(crate) struct RawMesh {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
    pub triangles: Vec<[u32; 3]>,
}

/// Validates `raw`, fills the analysis part of `report`, applies the clean-up `options` ask
/// for and computes normals when needed.
pub(crate) fn finish_mesh(
    path: &Path,
    raw: RawMesh,
    options: &LoadOptions,
    mut report: LoadReport,
) -> Result<(Mesh, LoadReport), MeshIoError> {
    let RawMesh {
        mut positions,
        normals,
        mut uvs,
        mut triangles,
    } = raw;
    if positions.is_empty() {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the file has no vertices".into(),
        });
    }
    if triangles.is_empty() {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the file has no faces".into(),
        });
    }
    check_finite3(path, &positions, false, |i| format!("vertex {i}"))?;
    if normals.is_some() && report.file_normals == AttributeStatus::Absent {
        report.file_normals = AttributeStatus::Loaded;
    }
    if uvs.is_some() && report.uvs == AttributeStatus::Absent {
        report.uvs = AttributeStatus::Loaded;
    }
    let mut normals = match normals {
        Some(normals) if !options.recompute_normals => {
            check_finite3(path, &normals, true, |i| format!("vertex {i}"))?;
            Some(
                normals
                    .into_iter()
                    .map(Vec3::normalize_or_zero)
                    .collect::<Vec<_>>(),
            )
        }
        _ => None,
    };
    if let Some(uvs) = &uvs {
        check_finite_uvs(path, uvs)?;
    }
    check_indices(path, &triangles, positions.len())?;

    report.file_vertex_count = positions.len();
    report.file_triangle_count = triangles.len();
    report.degenerate_triangles = find_degenerate_triangles(&positions, &triangles);
    report.duplicate_positions = count_duplicate_positions(&positions);
    report.repeated_triangles = count_repeated_triangles(&triangles);
    if options.remove_degenerate && !report.degenerate_triangles.is_empty() {
        let mut degenerate = vec![false; triangles.len()];
        for d in &report.degenerate_triangles {
            degenerate[d.triangle as usize] = true;
        }
        let mut t = 0;
        triangles.retain(|_| {
            t += 1;
            !degenerate[t - 1]
        });
        report.removed_triangles = report.file_triangle_count - triangles.len();
    }
    report.unreferenced_vertices = find_unreferenced_vertices(positions.len(), &triangles);
    if options.remove_unreferenced {
        let remap = compact_vertices(
            &mut positions,
            normals.as_mut(),
            uvs.as_mut(),
            &mut triangles,
        );
        report.removed_vertices = report.file_vertex_count - positions.len();
        report.vertex_remap = Some(remap);
    }
    let normals = match normals {
        Some(normals) => normals,
        None => {
            report.normals_computed = true;
            compute_normals(&positions, &triangles, options.normals)
        }
    };
    if triangles.is_empty() {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "every triangle is degenerate, none is left after remove_degenerate".into(),
        });
    }
    Ok((
        Mesh {
            positions,
            normals,
            uvs,
            triangles,
        },
        report,
    ))
}

/// Removes vertices no triangle references, renumbering triangles; returns old → new.
fn compact_vertices(
    positions: &mut Vec<Vec3>,
    normals: Option<&mut Vec<Vec3>>,
    uvs: Option<&mut Vec<Vec2>>,
    triangles: &mut [[u32; 3]],
) -> Vec<Option<u32>> {
    let used = referenced_mask(positions.len(), triangles);
    let mut next = 0u32;
    let remap: Vec<Option<u32>> = used
        .iter()
        .map(|&u| {
            u.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    fn keep<T>(values: &mut Vec<T>, used: &[bool]) {
        let mut i = 0;
        values.retain(|_| {
            i += 1;
            used[i - 1]
        });
    }
    keep(positions, &used);
    if let Some(normals) = normals {
        keep(normals, &used);
    }
    if let Some(uvs) = uvs {
        keep(uvs, &used);
    }
    for index in triangles.iter_mut().flatten() {
        // Every index of a kept triangle is referenced, so it has a new number.
        *index = remap[*index as usize].unwrap_or(u32::MAX);
    }
    remap
}

/// Validates an animation's frames against its triangles and fills the frame-0 analysis of
/// `report`. `allow_no_triangles` is for `.npy` without topology.
pub(crate) fn finish_animation(
    path: &Path,
    animation: Animation,
    allow_no_triangles: bool,
    mut report: LoadReport,
) -> Result<(Animation, LoadReport), MeshIoError> {
    let Some(first) = animation.frames.first() else {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the animation has no frames".into(),
        });
    };
    let vertex_count = first.len();
    if vertex_count == 0 {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the frames have no vertices".into(),
        });
    }
    if animation.triangles.is_empty() && !allow_no_triangles {
        return Err(MeshIoError::EmptyMesh {
            path: path.to_path_buf(),
            what: "the animation has no triangles".into(),
        });
    }
    for (f, frame) in animation.frames.iter().enumerate() {
        // Loaders guarantee equal lengths; a mismatch here is an internal bug.
        assert_eq!(
            frame.len(),
            vertex_count,
            "frame {f} has a different vertex count"
        );
        check_finite3(path, frame, false, |i| format!("frame {f} vertex {i}"))?;
    }
    if let Some(uvs) = &animation.uvs {
        check_finite_uvs(path, uvs)?;
        if report.uvs == AttributeStatus::Absent {
            report.uvs = AttributeStatus::Loaded;
        }
    }
    check_indices(path, &animation.triangles, vertex_count)?;
    report.file_vertex_count = vertex_count;
    report.file_triangle_count = animation.triangles.len();
    report.degenerate_triangles = find_degenerate_triangles(first, &animation.triangles);
    report.unreferenced_vertices = if animation.triangles.is_empty() {
        Vec::new()
    } else {
        find_unreferenced_vertices(vertex_count, &animation.triangles)
    };
    report.duplicate_positions = count_duplicate_positions(first);
    report.repeated_triangles = count_repeated_triangles(&animation.triangles);
    report.normals_computed = false;
    Ok((animation, report))
}
