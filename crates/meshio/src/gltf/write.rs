//! glTF 2.0 binary (`.glb`) output: a static mesh with optional colours and application-specific
//! scalar attributes ([`write_glb`]), and an animation as one morph target per frame
//! ([`write_glb_animation`]).
//!
//! Layout (glTF 2.0 §4.4 "GLB File Format Specification"): a 12-byte header (`glTF`, version 2,
//! total length), a JSON chunk padded with spaces, a BIN chunk padded with zeros; every chunk
//! and every buffer view starts on a 4-byte boundary. Each accessor has its own tightly packed
//! buffer view (no `byteStride`), so every accessor is 4-byte aligned. Vertex data is `FLOAT`,
//! indices `UNSIGNED_INT`.
//!
//! What is written:
//! - `POSITION` (`VEC3` float) with `min`/`max` (required by the spec, also for morph targets);
//! - `NORMAL` (`VEC3` float, unit length) when given;
//! - `COLOR_0` as **`VEC3` float, linear** RGB in \[0, 1\] (the spec's colour space for vertex
//!   colours: viewers multiply it with the base colour and apply the display encoding
//!   themselves, so do not pass gamma-encoded values);
//! - application-specific scalar attributes, e.g. `_AO`: `SCALAR` float, named with a leading
//!   underscore as the spec requires for custom semantics (§3.7.2.1);
//! - `indices` as `u32` triangles (mode 4), no material (the viewer's default material).
//!
//! The spec forbids NaN and infinity in accessor data, so every value must be finite: a writer
//! that has "no value" for some vertex must encode it (cloth-vis writes `_AO = -1`).
//!
//! Animations: frame 0 is the base mesh, frame f ≥ 1 is morph target f − 1 holding the
//! `POSITION` (and `NORMAL`) deltas `p_f − p_0`; one clip drives the node's morph weights with
//! `STEP` interpolation at keyframe times `t_f = f / frame_rate`, the weights of keyframe f
//! being one-hot on target f − 1 (all zero for f = 0). [`crate::load_animation`] sampling at the
//! same frame rate reads back the frames (up to the f32 rounding of `p_0 + (p_f − p_0)`). The
//! weight output is a sparse accessor (F − 1 ones over F·(F − 1) zeros), so the file grows
//! linearly with F (≈ 2× the `.npy` of the positions: position and normal deltas); readers
//! expand the weights to F·(F − 1) floats, so this layout suits clips of up to a few thousand
//! frames.

use std::io::Write as _;
use std::path::Path;

use glam::Vec3;
use serde_json::{Value, json};

use super::stream::{GlbClip, write_glb_animation_with};
use crate::{Animation, MeshIoError};

/// `"glTF"` as a little-endian u32.
const GLB_MAGIC: u32 = 0x4654_6C67;
/// GLB container version.
const GLB_VERSION: u32 = 2;
/// Chunk type `JSON`.
const CHUNK_JSON: u32 = 0x4E4F_534A;
/// Chunk type `BIN\0`.
const CHUNK_BIN: u32 = 0x004E_4942;
/// `bufferView.target` for vertex attributes.
pub(super) const TARGET_ARRAY_BUFFER: u32 = 34_962;
/// `bufferView.target` for indices.
pub(super) const TARGET_ELEMENT_ARRAY_BUFFER: u32 = 34_963;
/// `accessor.componentType` FLOAT.
pub(super) const COMPONENT_FLOAT: u32 = 5126;
/// `accessor.componentType` UNSIGNED_INT.
pub(super) const COMPONENT_UNSIGNED_INT: u32 = 5125;
/// Largest accepted deviation of a normal's length from 1. f32 normalisation leaves ~1e-7;
/// viewers and the Khronos validator expect unit normals.
pub const NORMAL_UNIT_TOLERANCE: f32 = 1e-4;
/// Written as `asset.generator`.
const GENERATOR: &str = concat!("cloth-vis meshio ", env!("CARGO_PKG_VERSION"));

/// A static triangle mesh to write with [`write_glb`], borrowing its data.
///
/// # Examples
/// ```
/// use glam::Vec3;
/// let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
/// let triangles = [[0u32, 1, 2]];
/// let ao = [1.0f32, 0.5, 0.25];
/// let mesh = meshio::GlbMesh::new(&positions, &triangles).with_attribute("_AO", &ao);
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("tri.glb");
/// meshio::write_glb(&path, &mesh).unwrap();
/// let (loaded, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).unwrap();
/// assert_eq!(loaded.positions, positions);
/// ```
#[derive(Clone, Debug)]
pub struct GlbMesh<'a> {
    /// Vertex positions (`POSITION`).
    pub positions: &'a [Vec3],
    /// Unit vertex normals (`NORMAL`), one per position.
    pub normals: Option<&'a [Vec3]>,
    /// Linear RGB vertex colours in \[0, 1\] (`COLOR_0`, float `VEC3`), one per position.
    pub colors: Option<&'a [Vec3]>,
    /// Application-specific scalar attributes `(name, values)`; names start with `_`.
    pub attributes: Vec<(&'a str, &'a [f32])>,
    /// Triangles, counter-clockwise seen from the front.
    pub triangles: &'a [[u32; 3]],
}

impl<'a> GlbMesh<'a> {
    /// A mesh with positions and triangles only.
    pub fn new(positions: &'a [Vec3], triangles: &'a [[u32; 3]]) -> Self {
        Self {
            positions,
            normals: None,
            colors: None,
            attributes: Vec::new(),
            triangles,
        }
    }

    /// Adds `NORMAL`.
    #[must_use]
    pub fn with_normals(mut self, normals: &'a [Vec3]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// Adds `COLOR_0` (linear RGB in \[0, 1\]).
    #[must_use]
    pub fn with_colors(mut self, colors: &'a [Vec3]) -> Self {
        self.colors = Some(colors);
        self
    }

    /// Adds an application-specific scalar float attribute; `name` must start with `_`
    /// (e.g. `"_AO"`).
    #[must_use]
    pub fn with_attribute(mut self, name: &'a str, values: &'a [f32]) -> Self {
        self.attributes.push((name, values));
        self
    }
}

/// Writes `mesh` as a glTF 2.0 binary file, atomically (see [`atomic_out::write_with`]).
///
/// # Errors
/// [`MeshIoError::InvalidWriteInput`] (nothing is written) when the mesh has no vertex or no
/// triangle, more than `u32::MAX` vertices, an index out of range, a per-vertex array whose
/// length differs from the vertex count, a NaN or infinite value, a normal that is not unit
/// length, a colour outside \[0, 1\], an attribute name not of the form `_NAME` (ASCII letters,
/// digits, `_`) or used twice; [`MeshIoError::Io`] when the file cannot be written.
pub fn write_glb(path: &Path, mesh: &GlbMesh<'_>) -> Result<(), MeshIoError> {
    let n = mesh.positions.len();
    check_topology(path, n, mesh.triangles)?;
    check_vec3(path, "POSITION", mesh.positions, n)?;
    if let Some(normals) = mesh.normals {
        check_vec3(path, "NORMAL", normals, n)?;
        check_unit(path, "NORMAL", normals)?;
    }
    if let Some(colors) = mesh.colors {
        check_vec3(path, "COLOR_0", colors, n)?;
        if let Some((i, c)) = colors
            .iter()
            .enumerate()
            .find(|(_, c)| c.min_element() < 0.0 || c.max_element() > 1.0)
        {
            return Err(invalid(
                path,
                format!("COLOR_0 of vertex {i}"),
                format!("{c} is outside [0, 1]; clamp or tone-map linear colours first"),
            ));
        }
    }
    for (k, (name, values)) in mesh.attributes.iter().enumerate() {
        check_attribute_name(path, name)?;
        if mesh.attributes[..k].iter().any(|(other, _)| other == name) {
            return Err(invalid(
                path,
                format!("attribute {name}"),
                "is given twice; attribute names must be unique".into(),
            ));
        }
        check_len(path, name, values.len(), n)?;
        check_finite(path, name, values.iter().copied())?;
    }

    let mut b = Builder::default();
    let mut attributes = serde_json::Map::new();
    attributes.insert("POSITION".into(), b.vec3(mesh.positions, true).into());
    if let Some(normals) = mesh.normals {
        attributes.insert("NORMAL".into(), b.vec3(normals, false).into());
    }
    if let Some(colors) = mesh.colors {
        attributes.insert("COLOR_0".into(), b.vec3(colors, false).into());
    }
    for (name, values) in &mesh.attributes {
        attributes.insert(
            (*name).into(),
            b.scalars(values, TARGET_ARRAY_BUFFER).into(),
        );
    }
    let indices = b.indices(mesh.triangles);
    let meshes = json!([{
        "name": "mesh",
        "primitives": [{ "attributes": attributes, "indices": indices, "mode": 4 }],
    }]);
    b.finish(path, meshes, None)
}

/// Writes `animation` as a glTF 2.0 binary file with one morph target per frame after the
/// first and a `STEP` weights clip at `animation.frame_rate` (module docs), atomically.
///
/// Normals are computed per frame ([`crate::compute_normals`], angle-weighted) and written as
/// `NORMAL` and morph-target normal deltas; a vertex no face uses gets the normal +Y so that
/// every normal is unit length. UVs, when present, are written as `TEXCOORD_0`. A single-frame
/// animation is written as a static mesh (no clip).
///
/// Frames go through [`write_glb_animation_with`], the streamed writer, which
/// `anim decompress` feeds from the decoder one frame at a time.
///
/// # Errors
/// As [`write_glb`], plus: no frame, more than [`super::MAX_GLB_ANIMATION_FRAMES`], a frame
/// with a different vertex count than frame 0, a non-finite or non-positive frame rate.
pub fn write_glb_animation(path: &Path, animation: &Animation) -> Result<(), MeshIoError> {
    let Some(first) = animation.frames.first() else {
        return Err(invalid(
            path,
            "animation".into(),
            "has no frame; an animation needs at least one".into(),
        ));
    };
    let n = first.len();
    let clip = GlbClip {
        triangles: &animation.triangles,
        uvs: animation.uvs.as_deref(),
        frame_rate: animation.frame_rate,
        frames: animation.frames.len(),
        vertices: n,
    };
    write_glb_animation_with(path, &clip, |f, out: &mut [Vec3]| {
        let frame = &animation.frames[f];
        check_vec3(path, &format!("frame {f} POSITION"), frame, n)?;
        out.copy_from_slice(frame);
        Ok(())
    })
}

pub(super) fn invalid(path: &Path, element: String, problem: String) -> MeshIoError {
    MeshIoError::InvalidWriteInput {
        path: path.to_path_buf(),
        element,
        problem,
    }
}

pub(super) fn check_len(
    path: &Path,
    element: &str,
    len: usize,
    n: usize,
) -> Result<(), MeshIoError> {
    if len == n {
        return Ok(());
    }
    Err(invalid(
        path,
        element.into(),
        format!("has {len} values but the mesh has {n} vertices; give one per vertex"),
    ))
}

pub(super) fn check_finite(
    path: &Path,
    element: &str,
    values: impl Iterator<Item = f32>,
) -> Result<(), MeshIoError> {
    match values.enumerate().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((i, v)) => Err(invalid(
            path,
            format!("{element} value {i}"),
            format!("{v} is not finite; glTF forbids NaN and infinity in accessors"),
        )),
    }
}

pub(super) fn check_vec3(
    path: &Path,
    element: &str,
    values: &[Vec3],
    n: usize,
) -> Result<(), MeshIoError> {
    check_len(path, element, values.len(), n)?;
    match values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        None => Ok(()),
        Some((i, v)) => Err(invalid(
            path,
            format!("{element} of vertex {i}"),
            format!("{v} is not finite; glTF forbids NaN and infinity in accessors"),
        )),
    }
}

fn check_unit(path: &Path, element: &str, normals: &[Vec3]) -> Result<(), MeshIoError> {
    match normals
        .iter()
        .enumerate()
        .find(|(_, v)| (v.length() - 1.0).abs() > NORMAL_UNIT_TOLERANCE)
    {
        None => Ok(()),
        Some((i, v)) => Err(invalid(
            path,
            format!("{element} of vertex {i}"),
            format!(
                "{v} has length {}; normals must be unit length (give any unit vector to a \
                 vertex no face uses)",
                v.length()
            ),
        )),
    }
}

pub(crate) fn check_topology(
    path: &Path,
    n: usize,
    triangles: &[[u32; 3]],
) -> Result<(), MeshIoError> {
    if n == 0 || triangles.is_empty() {
        return Err(invalid(
            path,
            "mesh".into(),
            format!(
                "has {n} vertices and {} triangles; a mesh needs at least one of each",
                triangles.len()
            ),
        ));
    }
    if u32::try_from(n).is_err() {
        return Err(invalid(
            path,
            "mesh".into(),
            format!("has {n} vertices; u32 indices address at most {}", u32::MAX),
        ));
    }
    for (t, tri) in triangles.iter().enumerate() {
        if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
            return Err(invalid(
                path,
                format!("triangle {t}"),
                format!("{tri:?} has index {i}, but only {n} vertices are given"),
            ));
        }
    }
    Ok(())
}

fn check_attribute_name(path: &Path, name: &str) -> Result<(), MeshIoError> {
    let valid = name.len() > 1
        && name.starts_with('_')
        && name.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_');
    if valid {
        return Ok(());
    }
    Err(invalid(
        path,
        format!("attribute {name:?}"),
        "is not a valid application-specific name; use `_NAME` with ASCII letters, digits \
         and `_` (e.g. `_AO`)"
            .into(),
    ))
}

/// Collects the BIN chunk, buffer views and accessors.
#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends `bytes` as a new buffer view starting on a 4-byte boundary; `target` 0 = none.
    fn view(&mut self, bytes: impl IntoIterator<Item = [u8; 4]>, target: u32) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let offset = self.bin.len();
        self.bin.extend(bytes.into_iter().flatten());
        let mut view = json!({
            "buffer": 0,
            "byteOffset": offset,
            "byteLength": self.bin.len() - offset,
        });
        if target != 0 {
            view["target"] = json!(target);
        }
        self.views.push(view);
        self.views.len() - 1
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn vec3(&mut self, data: &[Vec3], min_max: bool) -> usize {
        let view = self.view(
            data.iter().flat_map(|v| v.to_array()).map(f32::to_le_bytes),
            TARGET_ARRAY_BUFFER,
        );
        let mut acc = json!({
            "bufferView": view,
            "componentType": COMPONENT_FLOAT,
            "count": data.len(),
            "type": "VEC3",
        });
        if min_max {
            let lo = data.iter().fold(Vec3::INFINITY, |a, v| a.min(*v));
            let hi = data.iter().fold(Vec3::NEG_INFINITY, |a, v| a.max(*v));
            // f64 so that the JSON numbers are the f32 values exactly.
            acc["min"] = json!(lo.as_dvec3().to_array());
            acc["max"] = json!(hi.as_dvec3().to_array());
        }
        self.accessor(acc)
    }

    fn scalars(&mut self, data: &[f32], target: u32) -> usize {
        let view = self.view(data.iter().map(|v| v.to_le_bytes()), target);
        self.accessor(json!({
            "bufferView": view,
            "componentType": COMPONENT_FLOAT,
            "count": data.len(),
            "type": "SCALAR",
        }))
    }

    fn indices(&mut self, triangles: &[[u32; 3]]) -> usize {
        let view = self.view(
            triangles.iter().flatten().map(|i| i.to_le_bytes()),
            TARGET_ELEMENT_ARRAY_BUFFER,
        );
        self.accessor(json!({
            "bufferView": view,
            "componentType": COMPONENT_UNSIGNED_INT,
            "count": triangles.len() * 3,
            "type": "SCALAR",
        }))
    }

    /// Assembles the document around `meshes` (mesh 0 is instantiated by node 0) and writes
    /// the container.
    fn finish(
        mut self,
        path: &Path,
        meshes: Value,
        animations: Option<Value>,
    ) -> Result<(), MeshIoError> {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let root = glb_root(
            meshes,
            self.accessors,
            self.views,
            self.bin.len(),
            animations,
        );
        write_container(path, &root, self.bin.len(), |w| w.write_all(&self.bin))
    }
}

/// The glTF document of one mesh on node 0 of scene 0, over one buffer of `bin_len` bytes.
pub(super) fn glb_root(
    meshes: Value,
    accessors: Vec<Value>,
    views: Vec<Value>,
    bin_len: usize,
    animations: Option<Value>,
) -> Value {
    let mut root = json!({
        "asset": { "version": "2.0", "generator": GENERATOR },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "mesh": 0 }],
        "meshes": meshes,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": bin_len }],
    });
    if let Some(animations) = animations {
        root["animations"] = animations;
    }
    root
}

/// Writes the GLB container atomically: header, the JSON chunk (`root`, padded with spaces)
/// and the BIN chunk, whose `bin_len` bytes (a multiple of 4) `write_bin` writes.
pub(super) fn write_container(
    path: &Path,
    root: &Value,
    bin_len: usize,
    write_bin: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<(), MeshIoError> {
    debug_assert_eq!(bin_len % 4, 0);
    let text = serde_json::to_vec(root).map_err(|e| {
        invalid(
            path,
            "glTF JSON".into(),
            format!("cannot be serialized: {e}"),
        )
    })?;
    let padding = text.len().next_multiple_of(4) - text.len();
    let too_large = || {
        invalid(
            path,
            "GLB container".into(),
            "would exceed the format's 4 GiB limit; write fewer frames or vertices".into(),
        )
    };
    let total = 12 + 8 + text.len() + padding + 8 + bin_len;
    let total = u32::try_from(total).map_err(|_| too_large())?;
    let json_len = u32::try_from(text.len() + padding).map_err(|_| too_large())?;
    let bin_len = u32::try_from(bin_len).map_err(|_| too_large())?;
    atomic_out::write_with(path, |w| {
        for word in [GLB_MAGIC, GLB_VERSION, total, json_len, CHUNK_JSON] {
            w.write_all(&word.to_le_bytes())?;
        }
        w.write_all(&text)?;
        w.write_all(&b"   "[..padding])?;
        w.write_all(&bin_len.to_le_bytes())?;
        w.write_all(&CHUNK_BIN.to_le_bytes())?;
        write_bin(w)
    })?;
    Ok(())
}
