//! OBJ texture seams kept: a vertex whose face corners carry different `vt` values (a UV seam,
//! as on every sewing-pattern garment) is split into one vertex per distinct value, so that a
//! renderer gets per-vertex UVs, with a map back to the file's vertices ([`SeamSplit`]).

use std::collections::HashMap;
use std::path::Path;

use glam::{Vec2, Vec3};

use super::parse::{NO_INDEX, parse_obj};
use crate::validate::{RawMesh, finish_mesh};
use crate::{LoadOptions, LoadReport, Mesh, MeshIoError, SourceFormat};

/// A mesh whose seam vertices were split so that every vertex has one texture coordinate.
///
/// Vertices `0..source_count` are the file's vertices in the file's order (each with the UV of
/// its first corner); the split copies follow, and `source[i]` names the file vertex of vertex
/// i (`source[i] == i` below `source_count`). Per-vertex results computed on the split mesh map
/// back by taking the first `source_count` entries; results on the file's vertices map onto the
/// split mesh by `source`.
#[derive(Clone, Debug, PartialEq)]
pub struct SeamSplit {
    /// The split mesh: positions copied at seams, one UV per vertex, triangles re-indexed,
    /// normals those of the file's (welded) vertices, so seams do not show in the shading.
    pub mesh: Mesh,
    /// For every vertex of [`SeamSplit::mesh`], the file vertex it copies.
    pub source: Vec<u32>,
    /// Vertices of the file.
    pub source_count: usize,
}

/// Loads a mesh with one UV per vertex: an OBJ whose UVs differ between the corners of a vertex
/// has those vertices split ([`SeamSplit`]); a corner without `vt` gets (0, 0). Any other mesh
/// (or an OBJ without seams) loads as [`crate::load_mesh`] does, with `source` the identity.
///
/// # Errors
/// As [`crate::load_mesh`].
pub fn load_mesh_split_seams(
    path: &Path,
    options: &LoadOptions,
) -> Result<(SeamSplit, LoadReport), MeshIoError> {
    let is_obj = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("obj"));
    let (mesh, report) = crate::load_mesh(path, options)?;
    let unsplit = |mesh: Mesh, report| {
        let n = mesh.positions.len();
        let source = (0..n as u32).collect();
        Ok((
            SeamSplit {
                mesh,
                source,
                source_count: n,
            },
            report,
        ))
    };
    if !(is_obj && mesh.uvs.is_none() && !options.remove_unreferenced) {
        return unsplit(mesh, report);
    }
    let data = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let mut split_report = LoadReport::new(path, SourceFormat::Obj);
    let obj = parse_obj(path, &data, &mut split_report)?;
    let Some(corner_tex) = &obj.corner_tex else {
        // No `vt` at all: nothing to split.
        return unsplit(mesh, report);
    };
    let n = obj.positions.len();
    let uv_of = |i: u32| {
        if i == NO_INDEX {
            Vec2::ZERO
        } else {
            obj.tex_coords[i as usize]
        }
    };
    let key = |uv: Vec2| {
        uv.to_array()
            .map(|x| if x == 0.0 { 0 } else { x.to_bits() })
    };
    let mut first_uv: Vec<Option<Vec2>> = vec![None; n];
    let mut copies: HashMap<(u32, [u32; 2]), u32> = HashMap::new();
    let mut positions = obj.positions.clone();
    let mut source: Vec<u32> = (0..n as u32).collect();
    let mut extra_uvs = Vec::new();
    let mut triangles = obj.triangles.clone();
    for (tri, corners) in triangles.iter_mut().zip(corner_tex) {
        for (v, &t) in tri.iter_mut().zip(corners) {
            let uv = uv_of(t);
            match first_uv[*v as usize] {
                None => first_uv[*v as usize] = Some(uv),
                Some(first) if key(first) == key(uv) => {}
                Some(_) => {
                    let next = positions.len() as u32;
                    let copy = *copies.entry((*v, key(uv))).or_insert(next);
                    if copy == next {
                        positions.push(obj.positions[*v as usize]);
                        source.push(*v);
                        extra_uvs.push(uv);
                    }
                    *v = copy;
                }
            }
        }
    }
    let mut uvs: Vec<Vec2> = first_uv.iter().map(|uv| uv.unwrap_or_default()).collect();
    uvs.extend(extra_uvs);
    let extra = positions.len() - n;
    split_report.notes.push(format!(
        "{extra} vertices added at UV seams (per-corner texture coordinates kept; vertices \
         0..{n} are the file's, in its order)"
    ));
    let raw = RawMesh {
        positions,
        normals: None,
        uvs: Some(uvs),
        triangles,
    };
    let (mut split, split_report) = finish_mesh(path, raw, options, split_report)?;
    // Shading must not see the seams: the normals of the file's welded vertices.
    split.normals = source
        .iter()
        .map(|&s| mesh.normals[s as usize])
        .collect::<Vec<Vec3>>();
    Ok((
        SeamSplit {
            mesh: split,
            source,
            source_count: n,
        },
        split_report,
    ))
}
