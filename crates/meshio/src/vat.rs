//! Vertex-animation textures (VAT): a deforming mesh as two images a game engine's vertex
//! shader samples — positions and normals per vertex per frame — plus a JSON sidecar
//! ([`write_vat_with`]).
//!
//! Layout (the soft-body layout of SideFX Labs' VAT and of OpenVAT, read by their Unity, Unreal
//! and Godot shaders): one texel per vertex along x, one row per frame. A mesh of N vertices
//! takes `rows_per_frame = ⌈N / width⌉` rows per frame, `width = min(N, 8192)`; vertex i of
//! frame f is texel `(i mod width, f·rows_per_frame + ⌊i / width⌋)`, row 0 being the image's
//! first (top) row. A shader samples texel centres with point filtering: u = (x + 0.5)/width,
//! v = (y + 0.5)/height (engines whose v runs bottom-up read v' = 1 − v). Vertex i is the i-th
//! vertex of the input mesh, whose order every cloth-vis output keeps.
//!
//! Encodings, by the extension of the positions file:
//! - `.exr`: 32-bit float RGBA; RGB = the object-space position, exactly;
//! - `.png`: 16-bit RGBA; RGB = (p − min) / (max − min) per axis over the whole clip, so
//!   p = min + v·(max − min), v = value/65535: within half a step (max − min)/131070 per axis.
//!
//! Alpha holds a per-vertex, per-frame scalar when one is given (cloth-vis bake: the ambient
//! term a_i of that frame), else 1. The normals image (`STEM-normals.EXT`) has the same layout
//! with RGB = n (EXR) or n·0.5 + 0.5 (PNG), angle-weighted normals of each frame (+Y for a
//! vertex used by no face). The sidecar `STEM.json` (for `clip.vat.exr`: `clip.vat.json`) holds
//! everything a shader needs: the sizes, the frame count and rate, the bounds, the encoding.

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde_json::json;

use crate::{MeshIoError, NormalWeighting, compute_normals};

/// Widest VAT image: the texture side every desktop GPU supports.
pub const VAT_MAX_WIDTH: usize = 8192;
/// Tallest VAT image (frames × rows per frame): the 2D texture limit of D3D11-class GPUs.
pub const VAT_MAX_HEIGHT: usize = 16384;

/// A clip to write as a VAT: everything but its frames.
#[derive(Clone, Copy, Debug)]
pub struct VatClip<'a> {
    /// Triangles (for the normals).
    pub triangles: &'a [[u32; 3]],
    /// Frames per second, finite and > 0.
    pub frame_rate: f32,
    /// F: frames the callback delivers.
    pub frames: usize,
    /// N: vertices per frame.
    pub vertices: usize,
}

/// What [`write_vat_with`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct VatReport {
    /// The positions image, the normals image and the JSON sidecar.
    pub files: [PathBuf; 3],
    /// Image width (texels per row).
    pub width: usize,
    /// Image height (rows).
    pub height: usize,
    /// Rows per frame.
    pub rows_per_frame: usize,
}

/// The encoding an output path asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Exr,
    Png16,
}

/// The normals image and the sidecar beside a VAT positions file `path`:
/// `STEM-normals.EXT` and `STEM.json`.
pub fn vat_companions(path: &Path) -> (PathBuf, PathBuf) {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let ext = path
        .extension()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    (
        path.with_file_name(format!("{stem}-normals.{ext}")),
        path.with_file_name(format!("{stem}.json")),
    )
}

/// Writes the clip whose frames `frame(f, positions, alpha)` fills (alpha pre-filled with 1)
/// as a VAT at `path` (`.exr` or `.png`), its normals image and its sidecar (see the module
/// documentation for the layout). Each file is written atomically; on error none is left.
///
/// # Errors
/// [`MeshIoError::InvalidOption`] for another extension, F = 0, a bad frame rate, or an image
/// above [`VAT_MAX_WIDTH`] × [`VAT_MAX_HEIGHT`]; [`MeshIoError::Gltf`]-free write errors as
/// [`MeshIoError::Io`]; a non-finite position; the callback's own error, unchanged.
pub fn write_vat_with<E: From<MeshIoError>>(
    path: &Path,
    clip: &VatClip<'_>,
    mut frame: impl FnMut(usize, &mut [Vec3], &mut [f32]) -> Result<(), E>,
) -> Result<VatReport, E> {
    let (encoding, width, rows) = check(path, clip)?;
    let (n, frames) = (clip.vertices, clip.frames);
    let height = frames * rows;
    let mut positions = vec![[0.0f32; 4]; width * height];
    let mut normals = vec![[0.0f32, 1.0, 0.0, 1.0]; width * height];
    let mut p = vec![Vec3::ZERO; n];
    let mut alpha = vec![1.0f32; n];
    let (mut lo, mut hi) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for f in 0..frames {
        alpha.fill(1.0);
        frame(f, &mut p, &mut alpha)?;
        if let Some(i) = p.iter().position(|v| !v.is_finite()) {
            return Err(E::from(invalid(
                path,
                "frame",
                f.to_string(),
                format!("frame {f} vertex {i} is {}", p[i]),
            )));
        }
        let nf = compute_normals(&p, clip.triangles, NormalWeighting::Angle);
        for i in 0..n {
            let texel = (f * rows + i / width) * width + i % width;
            positions[texel] = [p[i].x, p[i].y, p[i].z, alpha[i]];
            let nv = if nf[i] == Vec3::ZERO { Vec3::Y } else { nf[i] };
            normals[texel] = [nv.x, nv.y, nv.z, 1.0];
            lo = lo.min(p[i]);
            hi = hi.max(p[i]);
        }
    }
    let (normals_path, sidecar) = vat_companions(path);
    let files = [path.to_path_buf(), normals_path, sidecar];
    let result = (|| {
        match encoding {
            Encoding::Exr => {
                write_exr(&files[0], width, height, &positions)?;
                write_exr(&files[1], width, height, &normals)?;
            }
            Encoding::Png16 => {
                let extent = hi - lo;
                let scale = |v: f32, l: f32, e: f32| if e > 0.0 { (v - l) / e } else { 0.0 };
                let quantized: Vec<[f32; 4]> = positions
                    .iter()
                    .map(|t| {
                        [
                            scale(t[0], lo.x, extent.x),
                            scale(t[1], lo.y, extent.y),
                            scale(t[2], lo.z, extent.z),
                            t[3],
                        ]
                    })
                    .collect();
                write_png16(&files[0], width, height, &quantized)?;
                let mapped: Vec<[f32; 4]> = normals
                    .iter()
                    .map(|t| [t[0] * 0.5 + 0.5, t[1] * 0.5 + 0.5, t[2] * 0.5 + 0.5, 1.0])
                    .collect();
                write_png16(&files[1], width, height, &mapped)?;
            }
        }
        let name = |p: &Path| p.file_name().map(|s| s.to_string_lossy().into_owned());
        let doc = json!({
            "format": "cloth-vis vertex-animation texture 1",
            "positions": name(&files[0]),
            "normals": name(&files[1]),
            "encoding": match encoding {
                Encoding::Exr => "float32 RGBA: RGB = object-space position",
                Encoding::Png16 => "uint16 RGBA: RGB = (p - bounds_min) / (bounds_max - bounds_min), value / 65535",
            },
            "normals_encoding": match encoding {
                Encoding::Exr => "float32: RGB = unit normal",
                Encoding::Png16 => "uint16: RGB = n * 0.5 + 0.5, value / 65535",
            },
            "alpha": "per-vertex scalar of the frame (cloth-vis bake: ambient occlusion a_i), else 1",
            "vertex_count": n,
            "frame_count": frames,
            "fps": clip.frame_rate,
            "width": width,
            "height": height,
            "rows_per_frame": rows,
            "addressing": "vertex i of frame f is texel (i % width, f * rows_per_frame + i / width), row 0 at the top; sample texel centres with point filtering",
            "bounds_min": [lo.x, lo.y, lo.z],
            "bounds_max": [hi.x, hi.y, hi.z],
        });
        let text = serde_json::to_vec_pretty(&doc).expect("a JSON value serializes");
        atomic_out::write_with(&files[2], |w| std::io::Write::write_all(w, &text))?;
        Ok::<(), MeshIoError>(())
    })();
    if let Err(e) = result {
        for f in &files {
            let _ = std::fs::remove_file(f);
        }
        return Err(E::from(e));
    }
    Ok(VatReport {
        files,
        width,
        height,
        rows_per_frame: rows,
    })
}

fn invalid(path: &Path, option: &'static str, value: String, message: String) -> MeshIoError {
    MeshIoError::InvalidOption {
        path: path.to_path_buf(),
        option,
        value,
        message,
    }
}

/// The image size of a VAT of `frames` frames of `vertices` vertices at `path`:
/// `(width, height, rows_per_frame)`, or why it cannot be written (the extension, an empty
/// clip, more rows than [`VAT_MAX_HEIGHT`]) — for callers that check before their work.
///
/// # Errors
/// [`MeshIoError::InvalidOption`] naming the problem.
pub fn vat_layout(
    path: &Path,
    frames: usize,
    vertices: usize,
) -> Result<(usize, usize, usize), MeshIoError> {
    let (_, width, rows) = layout(path, frames, vertices)?;
    Ok((width, frames * rows, rows))
}

/// The encoding, width and rows per frame, or why the clip cannot be written.
fn check(path: &Path, clip: &VatClip<'_>) -> Result<(Encoding, usize, usize), MeshIoError> {
    let layout = layout(path, clip.frames, clip.vertices)?;
    if !(clip.frame_rate.is_finite() && clip.frame_rate > 0.0) {
        return Err(invalid(
            path,
            "frame_rate",
            clip.frame_rate.to_string(),
            "must be finite and > 0".into(),
        ));
    }
    crate::gltf::check_topology(path, clip.vertices, clip.triangles)?;
    Ok(layout)
}

fn layout(
    path: &Path,
    frames: usize,
    vertices: usize,
) -> Result<(Encoding, usize, usize), MeshIoError> {
    let encoding = match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("exr") => Encoding::Exr,
        Some("png") => Encoding::Png16,
        _ => {
            return Err(invalid(
                path,
                "out",
                path.display().to_string(),
                "a vertex-animation texture is .exr (float) or .png (16-bit)".into(),
            ));
        }
    };
    if frames == 0 || vertices == 0 {
        return Err(invalid(
            path,
            "frames",
            frames.to_string(),
            format!("a clip of {frames} frames of {vertices} vertices is empty"),
        ));
    }
    let width = vertices.min(VAT_MAX_WIDTH);
    let rows = vertices.div_ceil(width);
    let height = frames.saturating_mul(rows);
    if height > VAT_MAX_HEIGHT {
        return Err(invalid(
            path,
            "frames",
            frames.to_string(),
            format!(
                "{frames} frames x {rows} row(s) per frame is {height} rows, above the \
                 {VAT_MAX_HEIGHT} GPUs sample (meshio::VAT_MAX_HEIGHT); write fewer frames per \
                 texture"
            ),
        ));
    }
    Ok((encoding, width, rows))
}

fn write_exr(
    path: &Path,
    width: usize,
    height: usize,
    texels: &[[f32; 4]],
) -> Result<(), MeshIoError> {
    atomic_out::write_via_path(path, |tmp| {
        exr::prelude::write_rgba_file(tmp, width, height, |x, y| {
            let t = texels[y * width + x];
            (t[0], t[1], t[2], t[3])
        })
        .map_err(|e| e.to_string())
    })
    .map_err(|e| atomic_error(path, e))
}

fn write_png16(
    path: &Path,
    width: usize,
    height: usize,
    texels: &[[f32; 4]],
) -> Result<(), MeshIoError> {
    let data: Vec<u16> = texels
        .iter()
        .flatten()
        .map(|v| (v.clamp(0.0, 1.0) * 65535.0).round() as u16)
        .collect();
    let (w, h) = (width as u32, height as u32);
    atomic_out::write_via_path(path, |tmp| {
        let image = image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(w, h, data)
            .ok_or_else(|| "texel count does not match the size".to_owned())?;
        image
            .save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| e.to_string())
    })
    .map_err(|e| atomic_error(path, e))
}

fn atomic_error(path: &Path, e: atomic_out::AtomicError<String>) -> MeshIoError {
    match e {
        atomic_out::AtomicError::File(e) => MeshIoError::from(e),
        atomic_out::AtomicError::Writer(reason) => {
            MeshIoError::io(path, "write", std::io::Error::other(reason))
        }
    }
}
