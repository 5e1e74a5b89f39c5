//! PLY reader: ASCII and binary (both byte orders); `vertex` with `x y z` and optional normals
//! and UVs (other properties such as `confidence intensity` are skipped); polygons in `face`
//! (`vertex_indices` or `vertex_index`, any integer types, fan-triangulated) and strips in
//! `tristrips` (`-1` restarts, alternating winding). The header's counts are checked against
//! the file length before anything is allocated.

mod elements;
mod header;
mod source;
pub(crate) mod strips;

use std::path::Path;

use elements::{for_each_index_list, read_vertices, skip_element};
use header::{Encoding, Header, check_sizes, parse_header};
use source::{Ascii, Binary, Source};

use crate::validate::{RawMesh, finish_mesh};
use crate::{LoadOptions, LoadReport, Mesh, MeshIoError, SourceFormat};

/// Loads a PLY file.
pub(crate) fn load_ply(
    path: &Path,
    options: &LoadOptions,
) -> Result<(Mesh, LoadReport), MeshIoError> {
    let data = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let (raw, report) = parse_ply(path, &data)?;
    finish_mesh(path, raw, options, report)
}

/// Parses PLY bytes into an unvalidated mesh and a partial report.
pub(crate) fn parse_ply(path: &Path, data: &[u8]) -> Result<(RawMesh, LoadReport), MeshIoError> {
    let header = parse_header(path, data)?;
    let body = &data[header.body_start..];
    check_sizes(path, &header, body.len())?;
    let format = match header.encoding {
        Encoding::Ascii => SourceFormat::PlyAscii,
        Encoding::BinaryLittleEndian => SourceFormat::PlyBinaryLittleEndian,
        Encoding::BinaryBigEndian => SourceFormat::PlyBinaryBigEndian,
    };
    let mut report = LoadReport::new(path, format);
    let raw = match header.encoding {
        Encoding::Ascii => read_body(
            path,
            &header,
            Ascii::new(body, header.body_first_line),
            &mut report,
        ),
        Encoding::BinaryLittleEndian => read_body(
            path,
            &header,
            Binary::<false>::new(body, header.body_start),
            &mut report,
        ),
        Encoding::BinaryBigEndian => read_body(
            path,
            &header,
            Binary::<true>::new(body, header.body_start),
            &mut report,
        ),
    }?;
    Ok((raw, report))
}

fn read_body<S: Source>(
    path: &Path,
    header: &Header,
    mut src: S,
    report: &mut LoadReport,
) -> Result<RawMesh, MeshIoError> {
    let Some(vertex_element) = header.elements.iter().find(|e| e.name == "vertex") else {
        return Err(MeshIoError::InvalidHeader {
            path: path.to_path_buf(),
            line: None,
            message: "no \"element vertex\"; a mesh needs vertices".into(),
        });
    };
    let vertex_count = vertex_element.count;
    let mut raw = RawMesh::default();
    for element in &header.elements {
        match element.name.as_str() {
            "vertex" => {
                let v = read_vertices(path, element, &mut src, report)?;
                raw.positions = v.positions;
                raw.normals = v.normals;
                raw.uvs = v.uvs;
            }
            "face" => {
                // Only a row with properties occupies bytes, so only then does check_sizes bound
                // the count by the file; a property-less face element is refused below instead
                // of reserving 2^40 triangles (hard case C1).
                if !element.properties.is_empty() {
                    raw.triangles.reserve(element.count as usize);
                }
                report.file_face_count += element.count as usize;
                let triangles = &mut raw.triangles;
                let polygons = &mut report.polygons_triangulated;
                for_each_index_list(path, element, &mut src, |row, line, items| {
                    fan_triangulate(path, row, line, items, vertex_count, triangles, polygons)
                })?;
                note_skipped(report, element, &["vertex_indices", "vertex_index"]);
            }
            "tristrips" => {
                report.file_face_count += element.count as usize;
                let triangles = &mut raw.triangles;
                for_each_index_list(path, element, &mut src, |row, line, items| {
                    strips::decode_strip(items, vertex_count, triangles).map_err(|bad| {
                        MeshIoError::IndexOutOfRange {
                            path: path.to_path_buf(),
                            line,
                            element: format!("tristrips {row} entry {}", bad.position),
                            index: bad.value,
                            vertex_count: vertex_count as usize,
                        }
                    })
                })?;
                note_skipped(report, element, &["vertex_indices", "vertex_index"]);
            }
            _ => {
                skip_element(path, element, &mut src)?;
                report
                    .skipped_properties
                    .push(format!("element {} ({} rows)", element.name, element.count));
            }
        }
    }
    let trailing = src.trailing_bytes();
    if trailing > 0 {
        report.notes.push(format!(
            "{trailing} bytes after the last element were ignored"
        ));
    }
    Ok(raw)
}

/// Lists the properties of `element` other than `used` as skipped.
fn note_skipped(report: &mut LoadReport, element: &header::Element, used: &[&str]) {
    for p in &element.properties {
        if !used.contains(&p.name.as_str()) {
            report
                .skipped_properties
                .push(format!("{}.{}", element.name, p.name));
        }
    }
}

/// Checks a face's indices and appends its fan triangulation `(c0, ck, ck+1)`.
fn fan_triangulate(
    path: &Path,
    row: u64,
    line: Option<usize>,
    items: &[i64],
    vertex_count: u64,
    triangles: &mut Vec<[u32; 3]>,
    polygons: &mut usize,
) -> Result<(), MeshIoError> {
    if items.len() < 3 {
        return Err(MeshIoError::ShortFace {
            path: path.to_path_buf(),
            line,
            element: format!("face {row}"),
            corners: items.len(),
        });
    }
    if let Some(&bad) = items.iter().find(|&&i| i < 0 || i as u64 >= vertex_count) {
        return Err(MeshIoError::IndexOutOfRange {
            path: path.to_path_buf(),
            line,
            element: format!("face {row}"),
            index: bad,
            vertex_count: vertex_count as usize,
        });
    }
    if items.len() > 3 {
        *polygons += 1;
    }
    let first = items[0] as u32;
    for pair in items[1..].windows(2) {
        triangles.push([first, pair[0] as u32, pair[1] as u32]);
    }
    Ok(())
}
