//! Wavefront OBJ: single meshes ([`load_obj`]) and folders of numbered frames
//! ([`frames::load_obj_frames`]).

mod corners;
pub(crate) mod frames;
mod parse;
mod seams;

use std::path::Path;

use glam::{Vec2, Vec3};

use crate::validate::{RawMesh, finish_mesh};
use crate::{LoadOptions, LoadReport, Mesh, MeshIoError, SourceFormat};
pub(crate) use parse::{NO_INDEX, ObjData, parse_obj};
pub use seams::{SeamSplit, load_mesh_split_seams};

/// Loads an OBJ file.
pub(crate) fn load_obj(
    path: &Path,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshIoError> {
    let data = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let mut report = LoadReport::new(path, SourceFormat::Obj);
    let obj = parse_obj(path, &data, &mut report)?;
    let raw = into_raw(obj, &mut report);
    finish_mesh(path, raw, options, report)
}

/// Turns parsed OBJ data into a raw mesh, resolving per-corner UVs and normals to per-vertex
/// ones where they are consistent (see [`corners`]) and recording the outcome in `report`.
pub(crate) fn into_raw(obj: ObjData, report: &mut LoadReport) -> RawMesh {
    let ObjData {
        positions,
        tex_coords,
        normals,
        triangles,
        corner_tex,
        corner_normals,
        ..
    } = obj;
    let n = positions.len();
    let uvs = corner_tex.and_then(|idx| {
        corners::per_vertex(n, &triangles, &idx, &tex_coords, |a: &Vec2, b| corners::same_bits(a.to_array(), b.to_array()))
            .map_err(|status| {
                report.uvs = status;
                report.notes.push(format!(
                    "texture coordinates {status} (no single value per vertex without splitting vertices at the seams); positions are kept as in the file"
                ));
            })
            .ok()
    });
    let normals = corner_normals.and_then(|idx| {
        corners::per_vertex(n, &triangles, &idx, &normals, |a: &Vec3, b| corners::same_bits(a.to_array(), b.to_array()))
            .map_err(|status| {
                report.file_normals = status;
                report.notes.push(format!(
                    "file normals {status} (no single value per vertex without splitting vertices at the hard edges); normals are computed"
                ));
            })
            .ok()
    });
    RawMesh {
        positions,
        normals,
        uvs,
        triangles,
    }
}
