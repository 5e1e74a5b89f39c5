//! Readers for the PLY elements this crate uses (`vertex`, `face`, `tristrips`) and a skipper
//! for all others, generic over the [`Source`] encoding.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::header::{Element, Kind, Scalar};
use super::source::{ReadError, Source};
use crate::{LoadReport, MeshIoError};

/// Adds the path and element description to a low-level read error.
pub(crate) fn read_error(path: &Path, element: String, err: ReadError) -> MeshIoError {
    let path = path.to_path_buf();
    match err {
        ReadError::Eof { line } => MeshIoError::UnexpectedEof {
            path,
            line: Some(line),
            element,
        },
        ReadError::Malformed {
            line,
            token,
            expected,
        } => MeshIoError::Malformed {
            path,
            line: Some(line),
            element,
            token,
            expected,
        },
        ReadError::Truncated {
            offset,
            needed,
            len,
        } => MeshIoError::Truncated {
            path,
            element,
            offset,
            bytes_needed: needed,
            file_len: len,
        },
    }
}

/// Reads a list's count and checks it against the remaining data before anything is allocated.
fn list_len<S: Source>(
    path: &Path,
    src: &mut S,
    count: Scalar,
    item: Scalar,
    element: impl Fn() -> String,
) -> Result<usize, MeshIoError> {
    let line = src.line();
    let n = src.int(count).map_err(|e| read_error(path, element(), e))?;
    if n < 0 {
        return Err(MeshIoError::Malformed {
            path: path.to_path_buf(),
            line,
            element: element(),
            token: n.to_string(),
            expected: "a non-negative list length",
        });
    }
    src.check_list(n as u64, item)
        .map_err(|e| read_error(path, format!("{} (a list of {n})", element()), e))?;
    Ok(n as usize)
}

/// Skips one property value (scalar or whole list).
fn skip_property<S: Source>(
    path: &Path,
    src: &mut S,
    kind: Kind,
    element: impl Fn() -> String,
) -> Result<(), MeshIoError> {
    match kind {
        Kind::Scalar(ty) => src.skip(ty).map_err(|e| read_error(path, element(), e)),
        Kind::List { count, item } => {
            let n = list_len(path, src, count, item, &element)?;
            for _ in 0..n {
                src.skip(item).map_err(|e| read_error(path, element(), e))?;
            }
            Ok(())
        }
    }
}

/// Skips every row of an element the loader does not use.
pub(crate) fn skip_element<S: Source>(
    path: &Path,
    element: &Element,
    src: &mut S,
) -> Result<(), MeshIoError> {
    if element.properties.is_empty() {
        return Ok(());
    }
    for row in 0..element.count {
        for p in &element.properties {
            skip_property(path, src, p.kind, || {
                format!("{} {row} property {}", element.name, p.name)
            })?;
        }
    }
    Ok(())
}

/// Slots of a vertex row: x y z, nx ny nz, u v.
const SLOTS: usize = 8;
const UV_NAMES: [(&str, &str); 4] = [
    ("u", "v"),
    ("s", "t"),
    ("texture_u", "texture_v"),
    ("texture_s", "texture_t"),
];

/// Per-vertex data of the `vertex` element.
pub(crate) struct Vertices {
    pub positions: Vec<Vec3>,
    pub normals: Option<Vec<Vec3>>,
    pub uvs: Option<Vec<Vec2>>,
}

/// Reads the `vertex` element: `x y z` required, `nx ny nz` and a UV pair optional, anything
/// else skipped (and listed in the report).
pub(crate) fn read_vertices<S: Source>(
    path: &Path,
    element: &Element,
    src: &mut S,
    report: &mut LoadReport,
) -> Result<Vertices, MeshIoError> {
    let find = |name: &str| {
        element
            .properties
            .iter()
            .position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
    };
    let mut slot_of = vec![None; element.properties.len()];
    for (slot, name) in ["x", "y", "z"].iter().enumerate() {
        let Some(i) = find(name) else {
            return Err(MeshIoError::InvalidHeader {
                path: path.to_path_buf(),
                line: None,
                message: format!(
                    "element vertex has no scalar property {name}; x, y and z are required"
                ),
            });
        };
        slot_of[i] = Some(slot);
    }
    let normal_props = [find("nx"), find("ny"), find("nz")];
    let has_normals = normal_props.iter().all(Option::is_some);
    if has_normals {
        for (k, i) in normal_props.iter().flatten().enumerate() {
            slot_of[*i] = Some(3 + k);
        }
    }
    let uv_props = UV_NAMES
        .iter()
        .find_map(|(u, v)| Some((find(u)?, find(v)?)));
    if let Some((u, v)) = uv_props {
        slot_of[u] = Some(6);
        slot_of[v] = Some(7);
    }
    for (p, slot) in element.properties.iter().zip(&slot_of) {
        if slot.is_none() {
            report.skipped_properties.push(format!("vertex.{}", p.name));
        }
    }
    // The header check bounds `count` by the file length, so this allocation is bounded too.
    let count = element.count as usize;
    let mut positions = Vec::with_capacity(count);
    let mut normals = has_normals.then(|| Vec::with_capacity(count));
    let mut uvs = uv_props.map(|_| Vec::with_capacity(count));
    let mut row_values = [0f32; SLOTS];
    for row in 0..count {
        let line = src.line();
        for (p, slot) in element.properties.iter().zip(&slot_of) {
            match (slot, p.kind) {
                (Some(slot), Kind::Scalar(ty)) => {
                    row_values[*slot] = src.f32(ty).map_err(|e| {
                        read_error(path, format!("vertex {row} property {}", p.name), e)
                    })?;
                }
                _ => skip_property(path, src, p.kind, || {
                    format!("vertex {row} property {}", p.name)
                })?,
            }
        }
        let position = Vec3::new(row_values[0], row_values[1], row_values[2]);
        if let Some(axis) = (0..3).find(|&k| !position[k].is_finite()) {
            return Err(MeshIoError::NonFinite {
                path: path.to_path_buf(),
                line,
                element: format!("vertex {row}"),
                component: ["x", "y", "z"][axis],
                value: f64::from(position[axis]),
            });
        }
        positions.push(position);
        if let Some(normals) = &mut normals {
            normals.push(Vec3::new(row_values[3], row_values[4], row_values[5]));
        }
        if let Some(uvs) = &mut uvs {
            uvs.push(Vec2::new(row_values[6], row_values[7]));
        }
    }
    Ok(Vertices {
        positions,
        normals,
        uvs,
    })
}

/// Finds the index list of a `face` or `tristrips` element.
fn index_list(path: &Path, element: &Element) -> Result<(usize, Scalar, Scalar), MeshIoError> {
    let found = element
        .properties
        .iter()
        .position(|p| p.name == "vertex_indices" || p.name == "vertex_index");
    let header_error = |message: String| MeshIoError::InvalidHeader {
        path: path.to_path_buf(),
        line: None,
        message,
    };
    let Some(i) = found else {
        return Err(header_error(format!(
            "element {} has no property vertex_indices (or vertex_index)",
            element.name
        )));
    };
    match element.properties[i].kind {
        Kind::List { count, item } if item.is_integer() => Ok((i, count, item)),
        _ => Err(header_error(format!(
            "property {}.{} must be a list of integers, e.g. \"property list uchar int vertex_indices\"",
            element.name, element.properties[i].name
        ))),
    }
}

/// Calls `row_fn(row, line, indices)` for every row of a `face` or `tristrips` element, with
/// the row's index list; other properties are skipped.
pub(crate) fn for_each_index_list<S: Source>(
    path: &Path,
    element: &Element,
    src: &mut S,
    mut row_fn: impl FnMut(u64, Option<usize>, &[i64]) -> Result<(), MeshIoError>,
) -> Result<(), MeshIoError> {
    let (list, count_ty, item_ty) = index_list(path, element)?;
    let mut items: Vec<i64> = Vec::new();
    for row in 0..element.count {
        let mut line = src.line();
        for (i, p) in element.properties.iter().enumerate() {
            let describe = || format!("{} {row} property {}", element.name, p.name);
            if i != list {
                skip_property(path, src, p.kind, describe)?;
                continue;
            }
            line = src.line();
            let n = list_len(path, src, count_ty, item_ty, describe)?;
            items.clear();
            items.reserve(n);
            for _ in 0..n {
                items.push(
                    src.int(item_ty)
                        .map_err(|e| read_error(path, describe(), e))?,
                );
            }
        }
        row_fn(row, line, &items)?;
    }
    Ok(())
}
