//! Baking per-vertex values into the user's own glTF ([`write_gltf_with`]): the input as it was,
//! every node, mesh, material, texture, skin, animation and extension kept, plus new vertex
//! attributes on the primitives the scene instantiates.
//!
//! How the input is carried over (glTF 2.0 §4.4 "GLB File Format Specification"):
//! - the JSON is edited as a `serde_json` tree, so members this crate does not model
//!   (extensions, extras) pass through untouched;
//! - every buffer (the GLB `BIN` chunk, `data:` URIs, files beside a `.gltf`) is copied into the
//!   output's single `BIN` chunk at a 16-byte aligned offset and the buffer views are re-pointed
//!   at it; their bytes are unchanged;
//! - images given by URI (a file beside the input, or a `data:` URI) are embedded as buffer
//!   views with their `mimeType` (from the extension or the data URI), so the output is one
//!   self-contained `.glb` wherever it is written — or, for a `.gltf` output, the JSON file and
//!   one `.bin` of the same name beside it ([`text_gltf_buffer`]);
//! - a mesh instantiated by several nodes is duplicated for the second and later nodes (sharing
//!   every existing accessor), because each instance bakes to different values and a glTF
//!   primitive has one set of attributes.
//!
//! What is added per baked primitive: the chosen colour channel ([`ColourChannel`]: `COLOR_0`
//! RGB, `COLOR_0` alpha over the existing RGB, or `COLOR_1`) as linear float, and any named
//! float attributes (application-specific semantics start with `_`, §3.7.2.1). A primitive
//! without a material gets one non-metallic, fully rough default material (glTF's implicit
//! default is metallic, which hides baked colour); materials are set double-sided per
//! [`DoubleSided`].

use std::collections::{HashMap, HashSet};
use std::path::Path;

use glam::Vec3;
use serde_json::{Value, json};

use super::rig::Rig;
use super::source::{self, GltfSource, gltf_error};
use super::write::{COMPONENT_FLOAT, TARGET_ARRAY_BUFFER, write_container};
use crate::MeshIoError;

/// Alignment of every buffer and buffer view copied or added (covers every component size and
/// the 16-byte alignment some GPU loaders prefer).
const ALIGN: usize = 16;

/// Where the baked scalar (ambient occlusion) goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColourChannel {
    /// `COLOR_0` as `VEC3` float (a, a, a), replacing an existing `COLOR_0`: Blender's
    /// bake-to-colour-attribute and MeshLab's vertex colour.
    Color0,
    /// `COLOR_0` as `VEC4` float: the existing `COLOR_0` RGB (white without one), alpha = a.
    Color0Alpha,
    /// `COLOR_1` as `VEC3` float (a, a, a), leaving `COLOR_0` alone.
    Color1,
}

impl ColourChannel {
    /// The name users type: `COLOR_0`, `COLOR_0.a`, `COLOR_1`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Color0 => "COLOR_0",
            Self::Color0Alpha => "COLOR_0.a",
            Self::Color1 => "COLOR_1",
        }
    }
}

/// Which baked primitives' materials become double-sided.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DoubleSided {
    /// Leave `doubleSided` as the input has it.
    Keep,
    /// Every baked primitive's material.
    All,
    /// Primitives with a border edge (an open surface such as cloth, whose back faces would
    /// otherwise vanish); edges are compared by position, so UV seams of a closed mesh do not
    /// count.
    Open,
}

/// Per-vertex values of a named float attribute, in [`crate::load_mesh`]'s vertex order.
#[derive(Clone, Copy, Debug)]
pub enum BakeValues<'a> {
    /// `SCALAR` float.
    Scalar(&'a [f32]),
    /// `VEC3` float.
    Vec3(&'a [Vec3]),
}

impl BakeValues<'_> {
    fn len(&self) -> usize {
        match self {
            Self::Scalar(v) => v.len(),
            Self::Vec3(v) => v.len(),
        }
    }
}

/// What [`write_gltf_with`] adds.
#[derive(Clone, Debug)]
pub struct GltfBake<'a> {
    /// The colour value per vertex (AO in \[0, 1\]; clamped, non-finite → 1) and its channel.
    pub colour: Option<(ColourChannel, &'a [f32])>,
    /// Named float attributes (`_AO`, `_RADIANCE`, `_BENT_NORMAL` …); every value must be
    /// finite (the spec forbids NaN in accessors).
    pub attributes: Vec<(String, BakeValues<'a>)>,
    /// Which materials become double-sided.
    pub double_sided: DoubleSided,
}

/// What [`write_gltf_with`] did, for the user.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct GltfBakeReport {
    /// Primitives that received the baked attributes.
    pub primitives: usize,
    /// Meshes duplicated because several nodes instantiate them.
    pub meshes_duplicated: usize,
    /// Images embedded from URIs.
    pub images_embedded: usize,
    /// Materials set double-sided (existing ones, plus the default one when it is).
    pub materials_double_sided: usize,
    /// Whether the default material was added for primitives without one.
    pub default_material_added: bool,
    /// Primitives whose existing `COLOR_0` was replaced ([`ColourChannel::Color0`]).
    pub colours_replaced: usize,
}

/// Writes `output` — a `.glb`, or a `.gltf` with its one buffer in [`text_gltf_buffer`] beside
/// it — the glTF `input` with the values of `bake` added to every primitive
/// its scene instantiates. Values are in the merged vertex order of [`crate::load_mesh`] on the
/// same file (instances in scene order, then primitives, then vertices), so whatever was
/// computed on the loaded mesh is written back where it belongs. Written atomically.
///
/// # Errors
/// The loader's errors for `input`; [`MeshIoError::Gltf`] when a value array does not have one
/// entry per vertex, a named attribute holds a non-finite value or its name does not start with
/// `_`, or an image URI cannot be read; [`MeshIoError::Io`] for the output.
pub fn write_gltf_with(
    input: &Path,
    output: &Path,
    bake: &GltfBake<'_>,
) -> Result<GltfBakeReport, MeshIoError> {
    let src = source::open(input)?;
    let rig = Rig::build(&src)?;
    check_values(&src, &rig, bake)?;
    let raw = input_guard::read_regular(input).map_err(|e| MeshIoError::io(input, "read", e))?;
    let json_bytes = if src.is_glb {
        source::glb_json_chunk(&raw)
            .ok_or_else(|| gltf_error(input, "file", "GLB JSON chunk is cut"))?
    } else {
        &raw[..]
    };
    let mut root: Value = serde_json::from_slice(json_bytes)
        .map_err(|e| gltf_error(input, "file", format!("cannot parse the JSON: {e}")))?;
    let mut out = Output::default();
    merge_buffers(&src, &mut root, &mut out);
    out.report.images_embedded = embed_images(&src, &mut root, &mut out)?;
    bake_primitives(&src, &rig, &mut root, bake, &mut out)?;
    let bin_len = out.bin.len().next_multiple_of(4);
    out.bin.resize(bin_len, 0);
    if is_text_gltf(output) {
        write_text(input, output, &mut root, &out.bin)?;
    } else {
        root["buffers"] = json!([{ "byteLength": bin_len }]);
        write_container(output, &root, bin_len, |w| w.write_all(&out.bin))?;
    }
    Ok(out.report)
}

/// Whether `path` names a JSON `.gltf` (else a `.glb` is written).
fn is_text_gltf(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf"))
}

/// The buffer file a `.gltf` output `output` gets: its name with `.bin`, every character
/// outside `A–Z a–z 0–9 . _ -` replaced by `_`, so that its URI needs no percent-encoding
/// (readers differ on decoding it: trimesh does not).
pub fn text_gltf_buffer(output: &Path) -> std::path::PathBuf {
    let stem = output
        .file_stem()
        .map(|s| s.to_string_lossy())
        .unwrap_or_default();
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '_' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect();
    output.with_file_name(format!("{safe}.bin"))
}

/// Writes `root` as `output` (`.gltf`, JSON) with its one buffer `bin` in
/// [`text_gltf_buffer`]`(output)` beside it, the buffer first so that
/// the JSON never names a missing file; both atomically, the buffer removed again when the
/// JSON cannot be written. Refused when the buffer file is one the input reads (its own buffer
/// or an image), which the bake would destroy.
fn write_text(
    input: &Path,
    output: &Path,
    root: &mut Value,
    bin: &[u8],
) -> Result<(), MeshIoError> {
    let bin_path = text_gltf_buffer(output);
    let name = bin_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Ok(target) = std::fs::canonicalize(&bin_path) {
        let base = input.parent().unwrap_or(Path::new("."));
        let json = source_json(input)?;
        for list in ["buffers", "images"] {
            for (i, uri) in referenced_files(&json, list) {
                let file = base.join(uri);
                if std::fs::canonicalize(&file).is_ok_and(|f| f == target) {
                    return Err(gltf_error(
                        output,
                        format!("{list}[{i}].uri"),
                        format!(
                            "the output's buffer {} is a file the input reads; name the output \
                             differently",
                            bin_path.display()
                        ),
                    ));
                }
            }
        }
    }
    root["buffers"] = json!([{ "byteLength": bin.len(), "uri": name }]);
    let text = serde_json::to_vec_pretty(root)
        .map_err(|e| gltf_error(output, "file", format!("cannot serialize the JSON: {e}")))?;
    atomic_out::write_bytes(&bin_path, bin)?;
    if let Err(e) = atomic_out::write_bytes(output, &text) {
        let _ = std::fs::remove_file(&bin_path);
        return Err(e.into());
    }
    Ok(())
}

/// The input's JSON (a `.gltf` file, or a `.glb`'s JSON chunk) as a tree.
fn source_json(input: &Path) -> Result<Value, MeshIoError> {
    let raw = input_guard::read_regular(input).map_err(|e| MeshIoError::io(input, "read", e))?;
    let bytes = source::glb_json_chunk(&raw)
        .filter(|_| raw.starts_with(b"glTF"))
        .unwrap_or(&raw[..]);
    serde_json::from_slice(bytes)
        .map_err(|e| gltf_error(input, "file", format!("cannot parse the JSON: {e}")))
}

/// The decoded relative file URIs of the top-level array `list` (`buffers`, `images`), with
/// their indices; `data:` URIs skipped.
fn referenced_files(root: &Value, list: &str) -> Vec<(usize, String)> {
    root.get(list)
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
        .enumerate()
        .filter_map(|(i, item)| {
            let uri = item.get("uri")?.as_str()?;
            (!uri.starts_with("data:"))
                .then(|| source::percent_decode(uri))
                .flatten()
                .map(|u| (i, u))
        })
        .collect()
}

use std::io::Write as _;

/// The output's BIN chunk and what was done.
#[derive(Default)]
struct Output {
    bin: Vec<u8>,
    report: GltfBakeReport,
}

impl Output {
    /// Appends `bytes` at an aligned offset; returns the offset.
    fn append(&mut self, bytes: &[u8]) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(ALIGN), 0);
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        offset
    }

    /// Appends `bytes` as a new buffer view; returns its index.
    fn view(&mut self, root: &mut Value, bytes: &[u8], target: Option<u32>) -> usize {
        let offset = self.append(bytes);
        let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        push(root, "bufferViews", view)
    }

    /// Appends float data as a new accessor of `kind` (`SCALAR`, `VEC3`, `VEC4`).
    fn accessor(&mut self, root: &mut Value, floats: &[f32], kind: &str, count: usize) -> usize {
        let bytes: Vec<u8> = floats.iter().flat_map(|f| f.to_le_bytes()).collect();
        let view = self.view(root, &bytes, Some(TARGET_ARRAY_BUFFER));
        push(
            root,
            "accessors",
            json!({ "bufferView": view, "componentType": COMPONENT_FLOAT, "count": count,
                    "type": kind }),
        )
    }
}

/// Pushes `value` onto the top-level array `key` (created when absent); returns its index.
fn push(root: &mut Value, key: &str, value: Value) -> usize {
    if !root[key].is_array() {
        root[key] = json!([]);
    }
    let array = root[key].as_array_mut().expect("made an array above");
    array.push(value);
    array.len() - 1
}

fn check_values(src: &GltfSource, rig: &Rig, bake: &GltfBake<'_>) -> Result<(), MeshIoError> {
    let n = rig.vertex_count;
    let colour = bake.colour.map(|(c, v)| (c.name().to_owned(), v.len()));
    let named = bake.attributes.iter().map(|(k, v)| (k.clone(), v.len()));
    for (name, len) in colour.into_iter().chain(named) {
        if len != n {
            return Err(src.error(
                name,
                format!("has {len} values for the scene's {n} vertices"),
            ));
        }
    }
    for (name, values) in &bake.attributes {
        if !name.starts_with('_') {
            return Err(src.error(
                name,
                "an application-specific attribute must start with '_' (glTF §3.7.2.1)",
            ));
        }
        let finite = match values {
            BakeValues::Scalar(v) => v.iter().all(|x| x.is_finite()),
            BakeValues::Vec3(v) => v.iter().all(|x| x.is_finite()),
        };
        if !finite {
            return Err(src.error(name, "holds a NaN or infinite value, which glTF forbids"));
        }
    }
    Ok(())
}

/// Copies every buffer into the output's BIN and re-points the buffer views at buffer 0.
/// Meshopt-compressed views (EXT or KHR) were decoded into their fallback buffer on loading:
/// they are written decoded (the extension dropped; gltfpack compresses the result again if
/// wanted).
fn merge_buffers(src: &GltfSource, root: &mut Value, out: &mut Output) {
    let offsets: Vec<usize> = src.buffers.iter().map(|b| out.append(b)).collect();
    for list in ["extensionsUsed", "extensionsRequired"] {
        if let Some(names) = root.get_mut(list).and_then(Value::as_array_mut) {
            names.retain(|n| !super::meshopt::EXTENSIONS.iter().any(|e| n == e));
            if names.is_empty() {
                root.as_object_mut().map(|o| o.remove(list));
            }
        }
    }
    if let Some(views) = root.get_mut("bufferViews").and_then(Value::as_array_mut) {
        for view in views {
            if let Some(extensions) = view.get_mut("extensions").and_then(Value::as_object_mut) {
                for name in super::meshopt::EXTENSIONS {
                    extensions.remove(name);
                }
                if extensions.is_empty() {
                    view.as_object_mut().map(|o| o.remove("extensions"));
                }
            }
            let buffer = view["buffer"].as_u64().unwrap_or(0) as usize;
            let old = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            view["buffer"] = json!(0);
            view["byteOffset"] = json!(old + offsets.get(buffer).copied().unwrap_or(0));
        }
    }
}

/// Embeds images given by URI as buffer views; returns how many.
fn embed_images(
    src: &GltfSource,
    root: &mut Value,
    out: &mut Output,
) -> Result<usize, MeshIoError> {
    let base = src.path.parent().unwrap_or(Path::new("."));
    let count = root["images"].as_array().map_or(0, Vec::len);
    let mut embedded = 0;
    for i in 0..count {
        let Some(uri) = root["images"][i]["uri"].as_str().map(str::to_owned) else {
            continue;
        };
        let element = format!("images[{i}].uri");
        let mime = root["images"][i]["mimeType"]
            .as_str()
            .map(str::to_owned)
            .or_else(|| mime_type(&uri))
            .ok_or_else(|| {
                src.error(
                    &element,
                    format!("{uri:?}: cannot tell the image type (png, jpeg, webp, ktx2)"),
                )
            })?;
        let bytes = source::read_uri(&src.path, base, &element, &uri)?;
        let view = out.view(root, &bytes, None);
        let image = &mut root["images"][i];
        if let Some(object) = image.as_object_mut() {
            object.remove("uri");
        }
        image["bufferView"] = json!(view);
        image["mimeType"] = json!(mime);
        embedded += 1;
    }
    Ok(embedded)
}

/// The MIME type of an image URI, from a `data:` header or the file extension.
fn mime_type(uri: &str) -> Option<String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        return rest.split(';').next().map(str::to_owned);
    }
    let ext = uri.rsplit('.').next()?.to_ascii_lowercase();
    Some(
        match ext.as_str() {
            "png" => "image/png",
            "jpg" | "jpeg" => "image/jpeg",
            "webp" => "image/webp",
            "ktx2" => "image/ktx2",
            _ => return None,
        }
        .to_owned(),
    )
}

/// Adds the baked attributes to every instantiated primitive.
fn bake_primitives(
    src: &GltfSource,
    rig: &Rig,
    root: &mut Value,
    bake: &GltfBake<'_>,
    out: &mut Output,
) -> Result<(), MeshIoError> {
    let mut used_meshes = HashSet::new();
    let mut default_material = None;
    let mut double_sided_materials = HashSet::new();
    let mut first_vertex = 0usize;
    let mut first_triangle = 0usize;
    for instance in &rig.instances {
        let node = src
            .document
            .nodes()
            .nth(instance.node)
            .expect("rig nodes exist");
        let source_mesh = node.mesh().expect("instances have meshes");
        let mut mesh = source_mesh.index();
        if !used_meshes.insert(mesh) {
            let copy = root["meshes"][mesh].clone();
            mesh = push(root, "meshes", copy);
            root["nodes"][instance.node]["mesh"] = json!(mesh);
            out.report.meshes_duplicated += 1;
        }
        for (p, (prim, gltf_prim)) in instance
            .primitives
            .iter()
            .zip(source_mesh.primitives())
            .enumerate()
        {
            let vertices = first_vertex..first_vertex + prim.positions.len();
            let triangles = first_triangle..first_triangle + prim.triangle_count;
            first_vertex = vertices.end;
            first_triangle = triangles.end;
            let mut attributes = Vec::new();
            if let Some((channel, values)) = bake.colour {
                let values = &values[vertices.clone()];
                let a = |x: f32| {
                    if x.is_finite() {
                        x.clamp(0.0, 1.0)
                    } else {
                        1.0
                    }
                };
                let (name, kind, floats) = match channel {
                    ColourChannel::Color0 | ColourChannel::Color1 => {
                        let floats: Vec<f32> = values.iter().flat_map(|x| [a(*x); 3]).collect();
                        (channel.name().replace(".a", ""), "VEC3", floats)
                    }
                    ColourChannel::Color0Alpha => {
                        let reader =
                            gltf_prim.reader(|b| src.buffers.get(b.index()).map(|v| &v[..]));
                        let existing: Option<Vec<[f32; 4]>> =
                            reader.read_colors(0).map(|c| c.into_rgba_f32().collect());
                        let floats = values
                            .iter()
                            .enumerate()
                            .flat_map(|(v, x)| {
                                let rgb = existing
                                    .as_ref()
                                    .and_then(|e| e.get(v))
                                    .map_or([1.0; 3], |c| [c[0], c[1], c[2]]);
                                [rgb[0], rgb[1], rgb[2], a(*x)]
                            })
                            .collect();
                        ("COLOR_0".to_owned(), "VEC4", floats)
                    }
                };
                if channel == ColourChannel::Color0
                    && root["meshes"][mesh]["primitives"][p]["attributes"]["COLOR_0"].is_number()
                {
                    out.report.colours_replaced += 1;
                }
                attributes.push((name, kind, floats));
            }
            for (name, values) in &bake.attributes {
                let (kind, floats): (&str, Vec<f32>) = match values {
                    BakeValues::Scalar(v) => ("SCALAR", v[vertices.clone()].to_vec()),
                    BakeValues::Vec3(v) => (
                        "VEC3",
                        v[vertices.clone()]
                            .iter()
                            .flat_map(|x| x.to_array())
                            .collect(),
                    ),
                };
                attributes.push((name.clone(), kind, floats));
            }
            let count = vertices.len();
            for (name, kind, floats) in attributes {
                let accessor = out.accessor(root, &floats, kind, count);
                root["meshes"][mesh]["primitives"][p]["attributes"][name] = json!(accessor);
            }
            let two_sided = match bake.double_sided {
                DoubleSided::Keep => false,
                DoubleSided::All => true,
                DoubleSided::Open => {
                    has_border_edge(&prim.positions, &rig.triangles[triangles], vertices.start)
                }
            };
            let material = match root["meshes"][mesh]["primitives"][p]["material"].as_u64() {
                Some(m) => m as usize,
                None => {
                    let m = *default_material.get_or_insert_with(|| {
                        out.report.default_material_added = true;
                        push(
                            root,
                            "materials",
                            json!({ "name": "cloth-vis bake default (non-metallic, rough)",
                                    "pbrMetallicRoughness":
                                        { "metallicFactor": 0.0, "roughnessFactor": 1.0 } }),
                        )
                    });
                    root["meshes"][mesh]["primitives"][p]["material"] = json!(m);
                    m
                }
            };
            if two_sided && double_sided_materials.insert(material) {
                root["materials"][material]["doubleSided"] = json!(true);
            }
            out.report.primitives += 1;
        }
    }
    out.report.materials_double_sided = double_sided_materials.len();
    Ok(())
}

/// Whether the primitive's triangles (merged indices, `first` its first merged vertex) have an
/// edge used once, with vertices identified by position (UV seams split vertices, not edges).
fn has_border_edge(positions: &[Vec3], triangles: &[[u32; 3]], first: usize) -> bool {
    let mut ids: HashMap<[u32; 3], u32> = HashMap::new();
    let weld: Vec<u32> = positions
        .iter()
        .map(|p| {
            let next = ids.len() as u32;
            *ids.entry(p.to_array().map(f32::to_bits)).or_insert(next)
        })
        .collect();
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    for t in triangles {
        let t = t.map(|i| weld[i as usize - first]);
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            if a != b {
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
    }
    edges.values().any(|&uses| uses == 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn border_edges_are_found_by_position_not_index() {
        // Two triangles of a square: open.
        let square = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        assert!(has_border_edge(&square, &[[0, 1, 2], [0, 2, 3]], 0));
        // A tetrahedron whose vertex 0 is split into two copies (a UV seam): closed.
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO];
        let tris = [[10, 12, 11], [10, 11, 13], [14, 13, 12], [11, 12, 13]];
        assert!(!has_border_edge(&p, &tris, 10));
    }

    #[test]
    fn mime_types_from_uris() {
        assert_eq!(mime_type("tex/a.PNG").as_deref(), Some("image/png"));
        assert_eq!(mime_type("b.jpeg").as_deref(), Some("image/jpeg"));
        assert_eq!(
            mime_type("data:image/webp;base64,AAAA").as_deref(),
            Some("image/webp")
        );
        assert_eq!(mime_type("noext"), None);
    }
}
