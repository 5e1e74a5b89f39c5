//! NumPy `.npy` arrays: reading f32/f64 arrays (either byte order, C or Fortran order) and
//! writing f32 arrays atomically, plus `[F, V, 3]` arrays as animations.
//!
//! Format: <https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html> — magic
//! `\x93NUMPY`, version, header length (u16 for 1.0, u32 for 2.0/3.0), a Python dict literal
//! `{'descr': '<f4', 'fortran_order': False, 'shape': (F, V, 3), }`, then the raw data. The
//! declared size is checked against the file length before the data is converted.

use std::io::Write;
use std::path::Path;

use glam::Vec3;

use crate::validate::finish_animation;
use crate::{
    Animation, AnimationOptions, LoadOptions, LoadReport, MeshIoError, SourceFormat, load_mesh,
};

const MAGIC: &[u8] = b"\x93NUMPY";

/// A dense f32 array in C (row-major) order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NpyArray {
    /// Extent of each axis.
    pub shape: Vec<usize>,
    /// `shape.iter().product()` values, last axis fastest.
    pub data: Vec<f32>,
}

fn npy_error(path: &Path, message: impl Into<String>) -> MeshIoError {
    MeshIoError::Npy {
        path: path.to_path_buf(),
        message: message.into(),
    }
}

fn header_error(path: &Path, message: impl Into<String>) -> MeshIoError {
    MeshIoError::InvalidHeader {
        path: path.to_path_buf(),
        line: None,
        message: message.into(),
    }
}

/// A value of the header dict.
#[derive(Debug, PartialEq)]
enum PyValue {
    Str(String),
    Bool(bool),
    Tuple(Vec<u64>),
}

/// Parses the header dict (a small subset of Python literal syntax).
fn parse_dict(text: &str) -> Option<Vec<(String, PyValue)>> {
    let mut s = text.trim_start().strip_prefix('{')?;
    let mut entries = Vec::new();
    loop {
        s = s.trim_start();
        if let Some(rest) = s.strip_prefix('}') {
            return rest.trim().is_empty().then_some(entries);
        }
        let (key, rest) = parse_string(s)?;
        let rest = rest.trim_start().strip_prefix(':')?.trim_start();
        let (value, rest) = if rest.starts_with(['\'', '"']) {
            let (v, r) = parse_string(rest)?;
            (PyValue::Str(v), r)
        } else if let Some(r) = rest.strip_prefix("True") {
            (PyValue::Bool(true), r)
        } else if let Some(r) = rest.strip_prefix("False") {
            (PyValue::Bool(false), r)
        } else {
            let inner = rest.strip_prefix('(')?;
            let end = inner.find(')')?;
            let dims = inner[..end]
                .split(',')
                .map(str::trim)
                .filter(|d| !d.is_empty())
                .map(|d| d.trim_end_matches('L').parse().ok())
                .collect::<Option<Vec<u64>>>()?;
            (PyValue::Tuple(dims), &inner[end + 1..])
        };
        entries.push((key, value));
        s = rest.trim_start();
        s = s.strip_prefix(',').unwrap_or(s);
    }
}

fn parse_string(s: &str) -> Option<(String, &str)> {
    let quote = s.chars().next().filter(|c| *c == '\'' || *c == '"')?;
    let body = &s[1..];
    let end = body.find(quote)?;
    Some((body[..end].to_string(), &body[end + 1..]))
}

/// Reads a `.npy` array of `float32` or `float64` (converted to f32), little- or big-endian,
/// C or Fortran order (returned in C order).
///
/// # Errors
/// [`MeshIoError::InvalidHeader`] for a bad magic or header dict, [`MeshIoError::Npy`] for an
/// unsupported dtype or a data length that differs from the declared shape.
pub fn read_npy_f32(path: &Path) -> Result<NpyArray, MeshIoError> {
    let bytes = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    if bytes.len() < 10 || !bytes.starts_with(MAGIC) {
        return Err(header_error(
            path,
            "missing the \\x93NUMPY magic; not a .npy file",
        ));
    }
    let (len_bytes, start) = match bytes[6] {
        1 => (2, 10),
        2 | 3 => (4, 12),
        v => {
            return Err(header_error(
                path,
                format!("unsupported .npy version {v}.{}", bytes[7]),
            ));
        }
    };
    let Some(len_field) = bytes.get(8..8 + len_bytes) else {
        return Err(header_error(
            path,
            "the file ends inside the header length field",
        ));
    };
    let header_len = len_field
        .iter()
        .rev()
        .fold(0usize, |acc, &b| (acc << 8) | usize::from(b));
    let Some(header) = bytes.get(start..start + header_len) else {
        return Err(header_error(
            path,
            format!(
                "header length {header_len} exceeds the file ({} bytes)",
                bytes.len()
            ),
        ));
    };
    let text = std::str::from_utf8(header).map_err(|_| header_error(path, "header is not text"))?;
    let dict = parse_dict(text)
        .ok_or_else(|| header_error(path, format!("cannot parse header dict {:?}", text.trim())))?;
    let get = |key: &str| dict.iter().find(|(k, _)| k == key).map(|(_, v)| v);
    let (Some(PyValue::Str(descr)), Some(PyValue::Bool(fortran)), Some(PyValue::Tuple(shape))) =
        (get("descr"), get("fortran_order"), get("shape"))
    else {
        return Err(header_error(
            path,
            format!(
                "header needs 'descr', 'fortran_order' and 'shape': {:?}",
                text.trim()
            ),
        ));
    };
    let little = cfg!(target_endian = "little");
    let (big, item) = match descr.as_str() {
        "<f4" => (false, 4),
        ">f4" => (true, 4),
        "=f4" => (!little, 4),
        "<f8" => (false, 8),
        ">f8" => (true, 8),
        "=f8" => (!little, 8),
        other => {
            return Err(npy_error(
                path,
                format!("dtype {other:?} is not supported; save the array as float32 or float64"),
            ));
        }
    };
    let data = &bytes[start + header_len..];
    let count = shape.iter().try_fold(1u64, |acc, &d| acc.checked_mul(d));
    let needed = count.and_then(|c| c.checked_mul(item));
    if needed != Some(data.len() as u64) {
        return Err(npy_error(
            path,
            format!(
                "header declares shape {shape:?} of {item}-byte values ({} bytes), but {} bytes follow the header; the file is truncated or corrupt",
                needed.map_or("more than 2^64".into(), |n| n.to_string()),
                data.len()
            ),
        ));
    }
    let values: Vec<f32> = match (item, big) {
        (4, false) => data
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        (4, true) => data
            .chunks_exact(4)
            .map(|c| f32::from_be_bytes([c[0], c[1], c[2], c[3]]))
            .collect(),
        (_, false) => data
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(to8(c)) as f32)
            .collect(),
        (_, true) => data
            .chunks_exact(8)
            .map(|c| f64::from_be_bytes(to8(c)) as f32)
            .collect(),
    };
    // The data length equals the product, so every dimension fits in usize.
    let shape: Vec<usize> = shape.iter().map(|&d| d as usize).collect();
    let data = if *fortran {
        fortran_to_c(&shape, &values)
    } else {
        values
    };
    Ok(NpyArray { shape, data })
}

fn to8(c: &[u8]) -> [u8; 8] {
    [c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]
}

/// Reorders column-major (`fortran_order`) data to row-major.
fn fortran_to_c(shape: &[usize], values: &[f32]) -> Vec<f32> {
    if shape.len() < 2 {
        return values.to_vec();
    }
    // Column-major stride of axis k: product of the extents before it.
    let strides: Vec<usize> = shape
        .iter()
        .scan(1, |acc, &d| Some(std::mem::replace(acc, *acc * d)))
        .collect();
    let mut index = vec![0usize; shape.len()];
    let mut out = Vec::with_capacity(values.len());
    for _ in 0..values.len() {
        out.push(
            values[index
                .iter()
                .zip(&strides)
                .map(|(i, s)| i * s)
                .sum::<usize>()],
        );
        // Increment the row-major multi-index (last axis fastest).
        for k in (0..shape.len()).rev() {
            index[k] += 1;
            if index[k] < shape[k] {
                break;
            }
            index[k] = 0;
        }
    }
    out
}

/// Writes `data` (row-major, `shape`) as a little-endian float32 `.npy` file, atomically
/// (temporary file beside `path`, then rename; see [`atomic_out::write_with`]).
///
/// # Errors
/// [`MeshIoError::ShapeMismatch`] when `shape`'s product differs from `data.len()`;
/// [`MeshIoError::Io`] when writing fails (then `path` is untouched).
///
/// # Examples
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("a.npy");
/// meshio::write_npy_f32(&path, &[2, 3], &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
/// let back = meshio::read_npy_f32(&path).unwrap();
/// assert_eq!(back.shape, vec![2, 3]);
/// assert_eq!(back.data[4], 4.0);
/// ```
pub fn write_npy_f32(path: &Path, shape: &[usize], data: &[f32]) -> Result<(), MeshIoError> {
    let expected = shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d));
    if expected != Some(data.len()) {
        return Err(MeshIoError::ShapeMismatch {
            path: path.to_path_buf(),
            shape: shape.to_vec(),
            expected,
            actual: data.len(),
        });
    }
    let header = npy_header(shape);
    atomic_out::write_with(path, |w| {
        w.write_all(&header)?;
        for value in data {
            w.write_all(&value.to_le_bytes())?;
        }
        Ok(())
    })?;
    Ok(())
}

/// Writes an animation as a `[F, V, 3]` f32 array, one frame at a time from `frames`, so a
/// caller that produces frames lazily (a decoder) never holds the whole clip. The file appears
/// complete or not at all.
///
/// # Errors
/// [`MeshIoError::ShapeMismatch`] when a frame does not hold `vertex_count` positions or the
/// iterator does not yield exactly `frame_count` frames (nothing is left behind);
/// [`MeshIoError::Io`] naming `path` when writing fails.
pub fn write_npy_frames<I>(
    path: &Path,
    frame_count: usize,
    vertex_count: usize,
    frames: I,
) -> Result<(), MeshIoError>
where
    I: IntoIterator,
    I::Item: AsRef<[Vec3]>,
{
    let shape = [frame_count, vertex_count, 3];
    let header = npy_header(&shape);
    let mut mismatch = None;
    let result = atomic_out::write_with(path, |w| {
        w.write_all(&header)?;
        let mut written = 0usize;
        for frame in frames {
            let frame = frame.as_ref();
            if frame.len() != vertex_count || written == frame_count {
                mismatch = Some(written * vertex_count * 3 + frame.len() * 3);
                return Err(std::io::Error::other("frame shape"));
            }
            for p in frame {
                for v in p.to_array() {
                    w.write_all(&v.to_le_bytes())?;
                }
            }
            written += 1;
        }
        if written != frame_count {
            mismatch = Some(written * vertex_count * 3);
            return Err(std::io::Error::other("frame count"));
        }
        Ok(())
    });
    if let Some(actual) = mismatch {
        return Err(MeshIoError::ShapeMismatch {
            path: path.to_path_buf(),
            shape: shape.to_vec(),
            expected: frame_count.checked_mul(vertex_count * 3),
            actual,
        });
    }
    result?;
    Ok(())
}

/// Magic, version, length and dict, padded with spaces and a newline to a multiple of 64 bytes
/// (the alignment NumPy itself uses).
fn npy_header(shape: &[usize]) -> Vec<u8> {
    const ALIGN: usize = 64;
    let dims = match shape {
        [] => "()".to_string(),
        [d] => format!("({d},)"),
        _ => format!(
            "({})",
            shape
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    let v1 = 10 + dict.len() < u16::MAX as usize - ALIGN;
    let preamble = if v1 { 10 } else { 12 };
    let total = (preamble + dict.len() + 1).div_ceil(ALIGN) * ALIGN;
    let header_len = total - preamble;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    if v1 {
        out.extend_from_slice(&[1, 0]);
        out.extend_from_slice(&(header_len as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&[2, 0]);
        out.extend_from_slice(&(header_len as u32).to_le_bytes());
    }
    out.extend_from_slice(dict.as_bytes());
    out.resize(total - 1, b' ');
    out.push(b'\n');
    out
}

/// Loads a `[F, V, 3]` array as an animation; triangles (and UVs) come from
/// `options.topology`, or are empty with [`LoadReport::topology_missing`] set.
/// Triangles and per-vertex UVs (when the mesh has them).
pub(crate) type Connectivity = (Vec<[u32; 3]>, Option<Vec<glam::Vec2>>);

/// The triangles and UVs of `options.topology` for a point-cache animation (`.npy`, PC2,
/// MDD) of `vertex_count` vertices stored in `path`, noted in `report`; none (and
/// `report.topology_missing`) without one.
pub(crate) fn attach_topology(
    path: &Path,
    options: &AnimationOptions,
    vertex_count: usize,
    report: &mut LoadReport,
) -> Result<Connectivity, MeshIoError> {
    match &options.topology {
        Some(topology) => {
            let (mesh, _) = load_mesh(topology, &LoadOptions::default())?;
            if mesh.vertex_count() != vertex_count {
                return Err(MeshIoError::TopologyMismatch {
                    path: path.to_path_buf(),
                    topology: topology.clone(),
                    topology_vertices: mesh.vertex_count(),
                    animation_vertices: vertex_count,
                });
            }
            report
                .notes
                .push(format!("triangles from {}", topology.display()));
            Ok((mesh.triangles, mesh.uvs))
        }
        None => {
            report.topology_missing = true;
            report.notes.push(
                "no topology given (AnimationOptions::topology, --topology MESH): the \
                 animation has no triangles"
                    .into(),
            );
            Ok((Vec::new(), None))
        }
    }
}

pub(crate) fn load_npy_animation(
    path: &Path,
    options: &AnimationOptions,
) -> Result<(Animation, LoadReport), MeshIoError> {
    options.validate(path)?;
    let array = read_npy_f32(path)?;
    let [frame_count, vertex_count, 3] = array.shape[..] else {
        return Err(npy_error(
            path,
            format!(
                "expected shape (frames, vertices, 3), found {:?}; reshape the array before saving",
                array.shape
            ),
        ));
    };
    if frame_count == 0 || vertex_count == 0 {
        // Checked before anything is allocated: a (2^40, 0, 3) header holds no data, and one
        // empty Vec per frame would still take 24 bytes each (hard case C2).
        return Err(npy_error(
            path,
            format!(
                "shape {:?} has no {}; an animation needs at least one frame of one vertex",
                array.shape,
                if frame_count == 0 {
                    "frames"
                } else {
                    "vertices"
                }
            ),
        ));
    }
    let mut report = LoadReport::new(path, SourceFormat::Npy);
    let (triangles, uvs) = attach_topology(path, options, vertex_count, &mut report)?;
    let frames: Vec<Vec<Vec3>> = array
        .data
        .chunks_exact(vertex_count * 3)
        .map(|frame| {
            frame
                .chunks_exact(3)
                .map(|p| Vec3::new(p[0], p[1], p[2]))
                .collect()
        })
        .collect();
    let animation = Animation {
        triangles,
        frames,
        frame_rate: options.frame_rate,
        uvs,
    };
    finish_animation(path, animation, true, report)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_dict_parses_numpy_output() {
        let dict =
            parse_dict("{'descr': '<f8', 'fortran_order': True, 'shape': (170, 3030, 3), }   \n")
                .unwrap();
        assert_eq!(dict[0], ("descr".into(), PyValue::Str("<f8".into())));
        assert_eq!(dict[1], ("fortran_order".into(), PyValue::Bool(true)));
        assert_eq!(
            dict[2],
            ("shape".into(), PyValue::Tuple(vec![170, 3030, 3]))
        );
        assert_eq!(
            parse_dict("{'shape': (5,)}").unwrap()[0].1,
            PyValue::Tuple(vec![5])
        );
        assert_eq!(
            parse_dict("{'shape': ()}").unwrap()[0].1,
            PyValue::Tuple(vec![])
        );
        assert!(parse_dict("{'shape': (5,}").is_none());
    }

    #[test]
    fn headers_are_aligned_and_end_with_newline() {
        for shape in [&[][..], &[7], &[2, 3], &[170, 3030, 3]] {
            let h = npy_header(shape);
            assert_eq!(h.len() % 64, 0);
            assert_eq!(*h.last().unwrap(), b'\n');
            assert_eq!(u16::from_le_bytes([h[8], h[9]]) as usize + 10, h.len());
        }
    }

    #[test]
    fn fortran_order_is_transposed() {
        // 2×3 matrix [[0,1,2],[3,4,5]] stored column-major.
        assert_eq!(
            fortran_to_c(&[2, 3], &[0.0, 3.0, 1.0, 4.0, 2.0, 5.0]),
            vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]
        );
    }
}
