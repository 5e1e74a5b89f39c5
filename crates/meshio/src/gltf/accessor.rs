//! Reading glTF accessors with every offset, stride and count checked against the buffer
//! (glTF 2.0 §3.6.2 "Accessors", §3.6.2.4 "Sparse accessors", §3.11 normalised integers).
//!
//! All arithmetic is checked, so a corrupt count, offset or stride gives an error naming the
//! accessor instead of a panic or a huge allocation.

use glam::{Mat4, Vec2, Vec3};
use gltf::accessor::{DataType, Dimensions};

use super::source::GltfSource;
use crate::MeshIoError;

/// Upper bound on the element count of an accessor without a buffer view (all zeros, possibly
/// with sparse substitutions): nothing in the file bounds it, so this does. 2²⁸ elements is far
/// above any real attribute (BrainStem has 34 159 vertices).
pub const MAX_VIEWLESS_ELEMENTS: usize = 1 << 28;

/// Bounds-checked strided view of `count` elements.
struct Strided<'a> {
    bytes: &'a [u8],
    stride: usize,
    component: DataType,
}

fn component_size(component: DataType) -> usize {
    match component {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

impl Strided<'_> {
    /// Component `c` of element `i`, exactly (integers up to 32 bits fit in f64).
    #[inline]
    fn get(&self, i: usize, c: usize) -> f64 {
        let size = component_size(self.component);
        let at = i * self.stride + c * size;
        let b = &self.bytes[at..at + size];
        match self.component {
            DataType::I8 => f64::from(b[0] as i8),
            DataType::U8 => f64::from(b[0]),
            DataType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            DataType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            DataType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            DataType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        }
    }
}

/// Maps a normalised integer to [-1, 1] or [0, 1] (glTF 2.0 §3.11).
fn normalize(component: DataType, v: f64) -> f64 {
    match component {
        DataType::I8 => (v / 127.0).max(-1.0),
        DataType::U8 => v / 255.0,
        DataType::I16 => (v / 32767.0).max(-1.0),
        DataType::U16 => v / 65535.0,
        DataType::U32 => v / 4_294_967_295.0,
        DataType::F32 => v,
    }
}

/// A strided view of `count` elements of `components` values starting `offset` bytes into
/// buffer view `view`, after checking that it fits.
fn strided<'a>(
    src: &'a GltfSource,
    view: gltf::buffer::View<'_>,
    offset: usize,
    count: usize,
    component: DataType,
    components: usize,
    what: &str,
) -> Result<Strided<'a>, MeshIoError> {
    let buffer = src.buffers.get(view.buffer().index()).ok_or_else(|| {
        src.error(
            what,
            format!("buffer view {} refers to a missing buffer", view.index()),
        )
    })?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&end| end <= buffer.len());
    let Some(view_end) = view_end else {
        return Err(src.error(
            what,
            format!(
                "buffer view {} (offset {}, length {}) extends past its buffer ({} bytes)",
                view.index(),
                view.offset(),
                view.length(),
                buffer.len()
            ),
        ));
    };
    let element = components * component_size(component);
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(src.error(
            what,
            format!("byte stride {stride} is smaller than an element ({element} bytes)"),
        ));
    }
    let needed = match count {
        0 => Some(0),
        _ => (count - 1)
            .checked_mul(stride)
            .and_then(|n| n.checked_add(element))
            .and_then(|n| n.checked_add(offset)),
    };
    if needed.is_none_or(|n| n > view.length()) {
        return Err(src.error(
            what,
            format!(
                "{count} elements of {element} bytes (stride {stride}) from offset {offset} do not fit in buffer view {} ({} bytes); the file is corrupt",
                view.index(),
                view.length()
            ),
        ));
    }
    let start = (view.offset() + offset).min(view_end);
    Ok(Strided {
        bytes: &buffer[start..view_end],
        stride,
        component,
    })
}

/// Reads all values of an accessor exactly as f64 (normalised integers mapped per §3.11), with
/// sparse substitution; returns `count × components` values.
fn read_exact(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<f64>, MeshIoError> {
    let count = accessor.count();
    let component = accessor.data_type();
    let dims = accessor.dimensions();
    let components = dims.multiplicity();
    if matches!(dims, Dimensions::Mat2 | Dimensions::Mat3 | Dimensions::Mat4)
        && component != DataType::F32
    {
        return Err(src.error(
            what,
            "integer matrices (with column padding) are not supported; store FLOAT matrices",
        ));
    }
    // f64 values here, f32 in the caller: 12 bytes per value, taken before allocation.
    let values_bytes = (count as u64)
        .saturating_mul(components as u64)
        .saturating_mul(12);
    src.charge(what, values_bytes)?;
    let convert = |v: f64| {
        if accessor.normalized() {
            normalize(component, v)
        } else {
            v
        }
    };
    let mut values = match accessor.view() {
        Some(view) => {
            let data = strided(
                src,
                view,
                accessor.offset(),
                count,
                component,
                components,
                what,
            )?;
            let mut values = Vec::with_capacity(count * components);
            for i in 0..count {
                values.extend((0..components).map(|c| convert(data.get(i, c))));
            }
            values
        }
        None if count <= MAX_VIEWLESS_ELEMENTS => vec![0.0; count * components],
        None => {
            return Err(src.error(
                what,
                format!("{count} elements without a buffer view exceed the limit of {MAX_VIEWLESS_ELEMENTS}"),
            ));
        }
    };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        let indices = sparse.indices();
        let index_type = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => DataType::U8,
            gltf::accessor::sparse::IndexType::U16 => DataType::U16,
            gltf::accessor::sparse::IndexType::U32 => DataType::U32,
        };
        let index_data = strided(
            src,
            indices.view(),
            indices.offset(),
            n,
            index_type,
            1,
            what,
        )?;
        let value_data = strided(
            src,
            sparse.values().view(),
            sparse.values().offset(),
            n,
            component,
            components,
            what,
        )?;
        for j in 0..n {
            let target = index_data.get(j, 0) as usize;
            if target >= count {
                return Err(src.error(
                    what,
                    format!("sparse index {target} (entry {j}) is not below the count {count}"),
                ));
            }
            for c in 0..components {
                values[target * components + c] = convert(value_data.get(j, c));
            }
        }
    }
    Ok(values)
}

/// [`read_exact`] rounded to f32.
fn read_values(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<f32>, MeshIoError> {
    Ok(read_exact(src, accessor, what)?
        .into_iter()
        .map(|v| v as f32)
        .collect())
}

fn expect_dims(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
    allowed: &[Dimensions],
) -> Result<(), MeshIoError> {
    let dims = accessor.dimensions();
    if allowed.contains(&dims) {
        return Ok(());
    }
    Err(src.error(
        what,
        format!(
            "accessor {} has type {dims:?}, expected {allowed:?}",
            accessor.index()
        ),
    ))
}

/// VEC3 attribute (positions, normals, morph displacements).
pub(crate) fn read_vec3(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<Vec3>, MeshIoError> {
    expect_dims(src, accessor, what, &[Dimensions::Vec3])?;
    Ok(read_values(src, accessor, what)?
        .chunks_exact(3)
        .map(Vec3::from_slice)
        .collect())
}

/// VEC2 attribute (texture coordinates).
pub(crate) fn read_vec2(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<Vec2>, MeshIoError> {
    expect_dims(src, accessor, what, &[Dimensions::Vec2])?;
    Ok(read_values(src, accessor, what)?
        .chunks_exact(2)
        .map(Vec2::from_slice)
        .collect())
}

/// VEC4 attribute (skin weights).
pub(crate) fn read_vec4(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<[f32; 4]>, MeshIoError> {
    expect_dims(src, accessor, what, &[Dimensions::Vec4])?;
    Ok(read_values(src, accessor, what)?
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect())
}

/// MAT4 values (inverse bind matrices), column-major.
pub(crate) fn read_mat4(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<Vec<Mat4>, MeshIoError> {
    expect_dims(src, accessor, what, &[Dimensions::Mat4])?;
    Ok(read_values(src, accessor, what)?
        .chunks_exact(16)
        .map(Mat4::from_cols_slice)
        .collect())
}

/// Any float-convertible accessor as flat values plus its component count (animation outputs).
pub(crate) fn read_flat(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
) -> Result<(Vec<f32>, usize), MeshIoError> {
    let values = read_values(src, accessor, what)?;
    Ok((values, accessor.dimensions().multiplicity()))
}

/// Unsigned integer data (indices: SCALAR; joints: VEC4), exactly, as u32.
pub(crate) fn read_uints(
    src: &GltfSource,
    accessor: &gltf::Accessor<'_>,
    what: &str,
    dims: Dimensions,
) -> Result<Vec<u32>, MeshIoError> {
    expect_dims(src, accessor, what, &[dims])?;
    let component = accessor.data_type();
    if !matches!(component, DataType::U8 | DataType::U16 | DataType::U32) || accessor.normalized() {
        return Err(src.error(
            what,
            format!(
                "accessor {} has component type {component:?}; expected unsigned integers",
                accessor.index()
            ),
        ));
    }
    // Unsigned integers up to 32 bits are exact in f64 (not in f32).
    Ok(read_exact(src, accessor, what)?
        .into_iter()
        .map(|v| v as u32)
        .collect())
}
