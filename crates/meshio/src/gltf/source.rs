//! Opening a glTF 2.0 file (`.gltf` JSON or `.glb` container): the document, validated, and
//! its buffers (GLB `BIN` chunk, base64 `data:` URIs, or files beside the document).
//!
//! The `gltf` crate's own importer is not used: it also decodes every image (slow and not
//! needed here), and it panics on some malformed input (an invalid percent-escape in a buffer
//! URI; a `POSITION` accessor index out of range during validation), which must be errors.

use std::path::{Path, PathBuf};

use gltf::json::validation::Validate;

use crate::MeshIoError;

/// The decoded bytes any glTF may expand to, whatever its size (resource policy,
/// ARCHITECTURE.md): 192 MiB.
pub const GLTF_DECODE_FLOOR: u64 = 192 << 20;

/// Beyond [`GLTF_DECODE_FLOOR`], decoded bytes allowed per byte of the file and its buffers.
/// Accessors decode to at most 3× their bytes (f32 from 8-bit normalised data); repeated
/// instances and viewless (sparse) accessors are what this bounds.
pub const GLTF_DECODE_PER_INPUT_BYTE: u64 = 16;

/// A parsed document and its buffer contents.
pub(crate) struct GltfSource {
    pub path: PathBuf,
    pub document: gltf::Document,
    pub buffers: Vec<Vec<u8>>,
    pub is_glb: bool,
    /// Bytes that decoding may still allocate (see [`GltfSource::charge`]).
    budget: std::sync::atomic::AtomicU64,
    /// The whole budget, for the message.
    budget_total: u64,
}

impl GltfSource {
    /// An error about `element` of this file.
    pub(crate) fn error(
        &self,
        element: impl Into<String>,
        message: impl Into<String>,
    ) -> MeshIoError {
        gltf_error(&self.path, element, message)
    }

    /// Takes `bytes` from the decode budget before they are allocated. Nothing in a glTF
    /// bounds what an accessor without a buffer view, a mesh instantiated by many nodes or
    /// hundreds of empty morph targets expand to, so the budget does: the floor plus a multiple
    /// of the input's size.
    ///
    /// # Errors
    /// [`MeshIoError::Gltf`] naming `element`, the bytes asked and the budget.
    pub(crate) fn charge(&self, element: &str, bytes: u64) -> Result<(), MeshIoError> {
        use std::sync::atomic::Ordering;
        let taken = self
            .budget
            .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |left| {
                left.checked_sub(bytes)
            });
        taken.map(|_| ()).map_err(|_| {
            self.error(
                element,
                format!(
                    "decoding it would exceed the {} MB this file may decode to ({} MB, plus \
                     {GLTF_DECODE_PER_INPUT_BYTE} bytes per byte of the file and its buffers); \
                     repeated mesh instances, morph targets or accessors without a buffer \
                     view expand to more than a real asset does",
                    self.budget_total >> 20,
                    GLTF_DECODE_FLOOR >> 20
                ),
            )
        })
    }
}

pub(crate) fn gltf_error(
    path: &Path,
    element: impl Into<String>,
    message: impl Into<String>,
) -> MeshIoError {
    MeshIoError::Gltf {
        path: path.to_path_buf(),
        element: element.into(),
        message: message.into(),
    }
}

/// Reads and validates `path` and loads its buffers.
pub(crate) fn open(path: &Path) -> Result<GltfSource, MeshIoError> {
    let bytes = input_guard::read_regular(path).map_err(|e| MeshIoError::io(path, "read", e))?;
    let is_glb = bytes.starts_with(b"glTF");
    let gltf = gltf::Gltf::from_slice_without_validation(&bytes)
        .map_err(|e| gltf_error(path, "file", format!("cannot parse: {e}; is it glTF 2.0?")))?;
    validate(path, gltf.document.as_json())?;
    // The raw JSON, for what the `gltf` crate does not model (the meshopt extensions), parsed
    // only when the file uses one of them.
    let compressed = gltf
        .document
        .extensions_used()
        .any(|e| super::meshopt::EXTENSIONS.contains(&e));
    let raw: serde_json::Value = if compressed {
        let json_bytes = if is_glb {
            glb_json_chunk(&bytes).unwrap_or_default()
        } else {
            &bytes[..]
        };
        serde_json::from_slice(json_bytes).unwrap_or_default()
    } else {
        serde_json::Value::Null
    };
    let fallbacks = super::meshopt::fallback_buffers(&raw);
    let fallback_bytes: u64 = fallbacks.iter().map(|(_, len)| *len as u64).sum();
    let fallback_budget = GLTF_DECODE_FLOOR
        .saturating_add((bytes.len() as u64).saturating_mul(GLTF_DECODE_PER_INPUT_BYTE));
    if fallback_bytes > fallback_budget {
        return Err(gltf_error(
            path,
            "buffers",
            format!(
                "meshopt compression's fallback buffers declare {fallback_bytes} bytes, more \
                 than this file may decode to ({fallback_budget})"
            ),
        ));
    }
    let mut blob = gltf.blob;
    let base = path.parent().unwrap_or(Path::new("."));
    let mut buffers = Vec::new();
    for buffer in gltf.document.buffers() {
        let element = format!("buffer {}", buffer.index());
        if let Some((_, len)) = fallbacks.iter().find(|(i, _)| *i == buffer.index()) {
            // Filled by the decoder below; a fallback buffer carries no data of its own.
            buffers.push(vec![0; *len]);
            continue;
        }
        let data = match buffer.source() {
            gltf::buffer::Source::Bin => blob.take().ok_or_else(|| {
                gltf_error(
                    path,
                    &element,
                    "refers to the GLB binary chunk, but there is none",
                )
            })?,
            gltf::buffer::Source::Uri(uri) => read_uri(path, base, &element, uri)?,
        };
        if data.len() < buffer.length() {
            return Err(gltf_error(
                path,
                element,
                format!(
                    "declares {} bytes but its data has {}; the file is truncated",
                    buffer.length(),
                    data.len()
                ),
            ));
        }
        buffers.push(data);
    }
    super::meshopt::decode_views(path, &raw, &mut buffers)?;
    let input_bytes = bytes.len() as u64 + buffers.iter().map(|b| b.len() as u64).sum::<u64>();
    let budget_total =
        GLTF_DECODE_FLOOR.saturating_add(input_bytes.saturating_mul(GLTF_DECODE_PER_INPUT_BYTE));
    Ok(GltfSource {
        path: path.to_path_buf(),
        document: gltf.document,
        buffers,
        is_glb,
        budget: std::sync::atomic::AtomicU64::new(budget_total),
        budget_total,
    })
}

/// Required extensions this reader decodes beyond what the `gltf` crate validates.
pub const SUPPORTED_REQUIRED: [&str; 3] = [
    "KHR_mesh_quantization",
    "EXT_meshopt_compression",
    "KHR_meshopt_compression",
];

/// Runs the `gltf` crate's validation, after the checks that keep it from panicking.
fn validate(path: &Path, root: &gltf::json::Root) -> Result<(), MeshIoError> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= root.accessors.len() {
                    return Err(gltf_error(
                        path,
                        format!("mesh {m} primitive {p}"),
                        format!(
                            "attribute {semantic:?} refers to accessor {}, but there are {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    for (i, extension) in root.extensions_required.iter().enumerate() {
        let what = match extension.as_str() {
            "KHR_draco_mesh_compression" => {
                "Draco-compressed geometry, which is not decoded here: export the file \
                 without Draco compression (Blender's glTF exporter: Compression off)"
            }
            _ => continue,
        };
        return Err(gltf_error(
            path,
            format!("extensionsRequired[{i}]"),
            format!("the file requires {extension}: {what}"),
        ));
    }
    // Extensions this reader handles although the `gltf` crate's validation does not know
    // them: KHR_mesh_quantization only widens the accessor types of attributes, which the
    // accessor reader decodes (normalised or not), and node transforms dequantize.
    let handled: Vec<String> = root
        .extensions_required
        .iter()
        .enumerate()
        .filter(|(_, e)| SUPPORTED_REQUIRED.contains(&e.as_str()))
        .map(|(i, _)| format!("extensionsRequired[{i}]"))
        .collect();
    let mut problems = Vec::new();
    root.validate(root, gltf::json::Path::new, &mut |where_, error| {
        let at = where_().to_string();
        // The path reads `extensionsRequired[i] = "NAME"`.
        if !handled.iter().any(|h| at.starts_with(h.as_str())) {
            problems.push(format!("{at}: {error}"));
        }
    });
    if problems.is_empty() {
        return Ok(());
    }
    let shown = problems
        .iter()
        .take(5)
        .cloned()
        .collect::<Vec<_>>()
        .join("; ");
    Err(gltf_error(
        path,
        "document",
        format!("{} validation problem(s): {shown}", problems.len()),
    ))
}

/// Loads a buffer URI: a base64 `data:` URI (bounded by the document's own size) or a path
/// relative to the document that stays inside its folder.
pub(super) fn read_uri(
    path: &Path,
    base: &Path,
    element: &str,
    uri: &str,
) -> Result<Vec<u8>, MeshIoError> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err(gltf_error(
                path,
                element,
                "data URI is not base64 (expected \"data:…;base64,…\")",
            ));
        };
        return decode_base64(payload.as_bytes())
            .ok_or_else(|| gltf_error(path, element, "data URI holds invalid base64"));
    }
    if uri.contains("://") {
        return Err(gltf_error(
            path,
            element,
            format!("URI {uri:?} is not a local file; download it first"),
        ));
    }
    let relative = percent_decode(uri).ok_or_else(|| {
        gltf_error(
            path,
            element,
            format!("URI {uri:?} has an invalid %-escape"),
        )
    })?;
    // Only files inside the asset's folder: `/etc/passwd` or `../../x` must not be read
    // into vertex positions, nor `/dev/zero` read until memory runs out.
    let file = input_guard::confined_join(base, &relative)
        .map_err(|e| gltf_error(path, element, e.to_string()))?;
    input_guard::read_regular(&file).map_err(|e| MeshIoError::io(&file, "read", e))
}

/// The bytes of a GLB's JSON chunk; `None` when the header or chunk is cut.
pub(super) fn glb_json_chunk(raw: &[u8]) -> Option<&[u8]> {
    let len = u32::from_le_bytes(raw.get(12..16)?.try_into().ok()?) as usize;
    raw.get(20..20usize.checked_add(len)?)
}

/// Decodes `%XX` escapes; `None` for a malformed escape or non-UTF-8 result.
pub(super) fn percent_decode(s: &str) -> Option<String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// Decodes standard base64 (RFC 4648 alphabet, `=` padding optional, no whitespace).
pub(crate) fn decode_base64(input: &[u8]) -> Option<Vec<u8>> {
    fn sextet(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    }
    let trimmed = input
        .strip_suffix(b"==")
        .or_else(|| input.strip_suffix(b"="))
        .unwrap_or(input);
    if trimmed.len() % 4 == 1 {
        return None;
    }
    let mut out = Vec::with_capacity(trimmed.len() / 4 * 3 + 2);
    for chunk in trimmed.chunks(4) {
        let mut acc = 0u32;
        for &c in chunk {
            acc = (acc << 6) | sextet(c)?;
        }
        acc <<= 6 * (4 - chunk.len() as u32);
        let bytes = acc.to_be_bytes();
        out.extend_from_slice(&bytes[1..chunk.len()]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trips_known_vectors() {
        assert_eq!(decode_base64(b"").unwrap(), b"");
        assert_eq!(decode_base64(b"Zg==").unwrap(), b"f");
        assert_eq!(decode_base64(b"Zm8=").unwrap(), b"fo");
        assert_eq!(decode_base64(b"Zm9v").unwrap(), b"foo");
        assert_eq!(decode_base64(b"Zm9vYmFy").unwrap(), b"foobar");
        assert!(decode_base64(b"Zm9v!").is_none());
    }

    #[test]
    fn percent_escapes() {
        assert_eq!(percent_decode("a%20b.bin").unwrap(), "a b.bin");
        assert!(percent_decode("bad%FF").is_none());
        assert!(percent_decode("cut%2").is_none());
    }
}
