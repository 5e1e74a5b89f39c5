//! Wavefront OBJ parsing: `v`, `vt`, `vn` and `f` (corners `v`, `v/vt`, `v//vn`, `v/vt/vn`,
//! 1-based or negative relative indices, polygons fan-triangulated) and `usemtl` (the material
//! of each face, for per-face materials). Every other keyword is
//! skipped and counted (the ARCSim garment files carry `vv` and `t` lines). Line continuations
//! (`\` at the end of a line) are not supported.

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::text::{Lines, parse_f32, parse_i64, tokens};
use crate::{LoadReport, MeshIoError};

/// Marks a corner without a `vt` or `vn` index.
pub(crate) const NO_INDEX: u32 = u32::MAX;

/// The parsed content of an OBJ file.
#[derive(Debug, Default)]
pub(crate) struct ObjData {
    pub positions: Vec<Vec3>,
    pub tex_coords: Vec<Vec2>,
    pub normals: Vec<Vec3>,
    /// Position indices, fan-triangulated.
    pub triangles: Vec<[u32; 3]>,
    /// `vt` index per triangle corner (present once any face has `vt`).
    pub corner_tex: Option<Vec<[u32; 3]>>,
    /// `vn` index per triangle corner (present once any face has `vn`).
    pub corner_normals: Option<Vec<[u32; 3]>>,
    /// `usemtl` names in order of first use.
    pub material_names: Vec<String>,
    /// Per triangle, the index into `material_names` of the `usemtl` in force, or
    /// [`NO_INDEX`] before the first one.
    pub triangle_material: Vec<u32>,
}

/// An index that points past what was defined when its face was read; checked at the end.
struct ForwardRef {
    line: usize,
    face: usize,
    kind: usize,
    written: i64,
    resolved: u64,
}

const KIND_NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];

fn malformed(
    path: &Path,
    line: usize,
    element: String,
    token: &[u8],
    expected: &'static str,
) -> MeshIoError {
    MeshIoError::Malformed {
        path: path.to_path_buf(),
        line: Some(line),
        element,
        token: if token.is_empty() {
            "<end of line>".into()
        } else {
            crate::error::token_text(token)
        },
        expected,
    }
}

/// Reads `N` floats from `words` (`min` of them required, the rest default to 0).
fn floats<'a, const N: usize>(
    path: &Path,
    line: usize,
    element: impl Fn() -> String,
    words: &mut impl Iterator<Item = &'a [u8]>,
    min: usize,
) -> Result<[f32; N], MeshIoError> {
    let mut out = [0f32; N];
    for (k, slot) in out.iter_mut().enumerate() {
        match words.next() {
            Some(token) => {
                *slot = parse_f32(token)
                    .ok_or_else(|| malformed(path, line, element(), token, "a number"))?
            }
            None if k < min => {
                return Err(malformed(path, line, element(), b"", "another coordinate"));
            }
            None => break,
        }
    }
    Ok(out)
}

fn check_finite(
    path: &Path,
    line: usize,
    element: impl Fn() -> String,
    values: &[f32],
    names: [&'static str; 3],
) -> Result<(), MeshIoError> {
    match values.iter().position(|v| !v.is_finite()) {
        Some(k) => Err(MeshIoError::NonFinite {
            path: path.to_path_buf(),
            line: Some(line),
            element: element(),
            component: names[k],
            value: f64::from(values[k]),
        }),
        None => Ok(()),
    }
}

/// Parses OBJ bytes; skipped keywords are counted in `report`.
pub(crate) fn parse_obj(
    path: &Path,
    data: &[u8],
    report: &mut LoadReport,
) -> Result<ObjData, MeshIoError> {
    let mut obj = ObjData::default();
    let mut corners: Vec<[u32; 3]> = Vec::new();
    let mut forward: Vec<ForwardRef> = Vec::new();
    let mut face = 0usize;
    let mut material = NO_INDEX;
    for (line, text) in Lines::new(data, 1) {
        let mut words = tokens(text);
        let Some(keyword) = words.next() else {
            continue;
        };
        match keyword {
            b"v" => {
                let element = || format!("vertex {}", obj.positions.len());
                let p = floats::<3>(path, line, element, &mut words, 3)?;
                check_finite(path, line, element, &p, ["x", "y", "z"])?;
                obj.positions.push(Vec3::from_array(p));
            }
            b"vt" => {
                let element = || format!("texture coordinate {}", obj.tex_coords.len());
                let t = floats::<2>(path, line, element, &mut words, 1)?;
                check_finite(
                    path,
                    line,
                    element,
                    &t,
                    ["texture u", "texture v", "texture w"],
                )?;
                obj.tex_coords.push(Vec2::from_array(t));
            }
            b"vn" => {
                let element = || format!("normal {}", obj.normals.len());
                let n = floats::<3>(path, line, element, &mut words, 3)?;
                check_finite(
                    path,
                    line,
                    element,
                    &n,
                    ["normal x", "normal y", "normal z"],
                )?;
                obj.normals.push(Vec3::from_array(n));
            }
            b"usemtl" => {
                let name = words
                    .map(|w| String::from_utf8_lossy(w).into_owned())
                    .collect::<Vec<_>>()
                    .join(" ");
                material = match obj.material_names.iter().position(|n| *n == name) {
                    Some(i) => i as u32,
                    None => {
                        obj.material_names.push(name);
                        (obj.material_names.len() - 1) as u32
                    }
                };
            }
            b"f" => {
                corners.clear();
                for word in words {
                    let counts = [obj.positions.len(), obj.tex_coords.len(), obj.normals.len()];
                    let corner = parse_corner(path, line, face, word, counts, &mut forward)?;
                    corners.push(corner);
                }
                if corners.len() < 3 {
                    return Err(MeshIoError::ShortFace {
                        path: path.to_path_buf(),
                        line: Some(line),
                        element: format!("face {face}"),
                        corners: corners.len(),
                    });
                }
                push_fan(&mut obj, &corners);
                let fan = corners.len() - 2;
                obj.triangle_material
                    .extend(std::iter::repeat_n(material, fan));
                if corners.len() > 3 {
                    report.polygons_triangulated += 1;
                }
                face += 1;
            }
            _ if keyword.starts_with(b"#") => {}
            _ => report.skip_keyword(keyword),
        }
    }
    report.file_face_count = face;
    let counts = [obj.positions.len(), obj.tex_coords.len(), obj.normals.len()];
    if let Some(bad) = forward.iter().find(|r| r.resolved >= counts[r.kind] as u64) {
        return Err(out_of_range(
            path,
            bad.line,
            bad.face,
            bad.kind,
            bad.written,
            counts[bad.kind],
        ));
    }
    Ok(obj)
}

fn out_of_range(
    path: &Path,
    line: usize,
    face: usize,
    kind: usize,
    written: i64,
    count: usize,
) -> MeshIoError {
    MeshIoError::IndexOutOfRange {
        path: path.to_path_buf(),
        line: Some(line),
        element: format!(
            "face {face} ({} index, 1-based or negative)",
            KIND_NAMES[kind]
        ),
        index: written,
        vertex_count: count,
    }
}

/// Parses `v`, `v/vt`, `v//vn` or `v/vt/vn` into 0-based indices (`NO_INDEX` when absent).
fn parse_corner(
    path: &Path,
    line: usize,
    face: usize,
    word: &[u8],
    counts: [usize; 3],
    forward: &mut Vec<ForwardRef>,
) -> Result<[u32; 3], MeshIoError> {
    let mut out = [NO_INDEX; 3];
    let mut parts = word.split(|&b| b == b'/');
    for (kind, slot) in out.iter_mut().enumerate() {
        let Some(part) = parts.next() else { break };
        if part.is_empty() && kind > 0 {
            continue;
        }
        let written = parse_i64(part).ok_or_else(|| {
            malformed(
                path,
                line,
                format!("face {face} corner {:?}", crate::error::token_text(word)),
                part,
                "an integer index",
            )
        })?;
        let resolved = match written {
            w if w > 0 => (w - 1) as u64,
            w if w < 0 && counts[kind] as i64 + w >= 0 => (counts[kind] as i64 + w) as u64,
            w => return Err(out_of_range(path, line, face, kind, w, counts[kind])),
        };
        if resolved >= u64::from(NO_INDEX) {
            return Err(out_of_range(path, line, face, kind, written, counts[kind]));
        }
        if resolved >= counts[kind] as u64 {
            forward.push(ForwardRef {
                line,
                face,
                kind,
                written,
                resolved,
            });
        }
        *slot = resolved as u32;
    }
    if parts.next().is_some() {
        return Err(malformed(
            path,
            line,
            format!("face {face}"),
            word,
            "a corner v, v/vt, v//vn or v/vt/vn",
        ));
    }
    Ok(out)
}

/// Appends the fan triangulation of one face, with its per-corner attribute indices.
fn push_fan(obj: &mut ObjData, corners: &[[u32; 3]]) {
    let has_tex = corners.iter().any(|c| c[1] != NO_INDEX);
    let has_normal = corners.iter().any(|c| c[2] != NO_INDEX);
    let before = obj.triangles.len();
    if has_tex && obj.corner_tex.is_none() {
        obj.corner_tex = Some(vec![[NO_INDEX; 3]; before]);
    }
    if has_normal && obj.corner_normals.is_none() {
        obj.corner_normals = Some(vec![[NO_INDEX; 3]; before]);
    }
    let c0 = corners[0];
    for pair in corners[1..].windows(2) {
        let tri = [c0, pair[0], pair[1]];
        obj.triangles.push(tri.map(|c| c[0]));
        if let Some(tex) = &mut obj.corner_tex {
            tex.push(tri.map(|c| c[1]));
        }
        if let Some(normals) = &mut obj.corner_normals {
            normals.push(tri.map(|c| c[2]));
        }
    }
}
