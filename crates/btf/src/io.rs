//! Image files of a BTF folder: header reads, decoding to linear RGB, and the PNG writer.
//!
//! 8-bit and 16-bit PNG and JPEG images are sRGB-encoded (the Bonn normtextures are 8-bit sRGB
//! JPEGs; thesis §5.3.3, "the common 8-bit RGB texture format") and are decoded through the
//! sRGB transfer function; float images (EXR, 32-bit float PNG/TIFF-like buffers) are taken as
//! linear. Grey images are replicated to RGB; alpha is dropped.

use std::path::Path;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

use image::{DynamicImage, ImageEncoder};
use rayon::prelude::*;

use crate::dataset::{image_file_name, pair_count};
use crate::error::{BtfError, Result};
use crate::sampling::{DIRECTIONS, Sampling};

/// Image kinds a BTF folder may hold, decided by the file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Kind {
    /// PNG or JPEG through the `image` crate.
    Raster,
    /// OpenEXR through the `exr` crate.
    Exr,
}

/// The kind of an image file from its (case-insensitive) extension.
pub(crate) fn kind_of(ext: &str) -> Option<Kind> {
    match ext.to_ascii_lowercase().as_str() {
        "png" | "jpg" | "jpeg" => Some(Kind::Raster),
        "exr" => Some(Kind::Exr),
        _ => None,
    }
}

fn kind_of_path(path: &Path) -> Kind {
    path.extension()
        .and_then(|e| e.to_str())
        .and_then(kind_of)
        .unwrap_or(Kind::Raster)
}

/// sRGB-encoded value in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Linear value to sRGB-encoded, clamped to [0, 1] (the workspace's one sRGB encoder,
/// [`render::tone::srgb_encode`]).
pub fn linear_to_srgb(l: f32) -> f32 {
    ::render::tone::srgb_encode(l)
}

/// Linear value to an 8-bit sRGB code (clamped, rounded).
pub fn linear_to_srgb8(l: f32) -> u8 {
    (linear_to_srgb(l) * 255.0).round() as u8
}

/// The 256 linear values of the 8-bit sRGB codes.
pub(crate) fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|c| srgb_to_linear(c as f32 / 255.0)))
}

/// An image reader over the regular file `path` (a FIFO named like an image would block).
fn open_image(path: &Path) -> Result<image::ImageReader<std::io::BufReader<std::fs::File>>> {
    let file = input_guard::open_regular(path).map_err(|e| BtfError::io(path, "open", e))?;
    let mut reader = image::ImageReader::new(std::io::BufReader::new(file));
    // The extension's format, as `ImageReader::open` would set it; the content's signature,
    // when recognised, takes precedence (`with_guessed_format`).
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    Ok(reader)
}

/// Width and height from the file's header only (no pixel data is decoded).
pub(crate) fn read_dimensions(path: &Path) -> Result<(usize, usize)> {
    match kind_of_path(path) {
        Kind::Raster => {
            let reader = open_image(path)?
                .with_guessed_format()
                .map_err(|e| BtfError::io(path, "read", e))?;
            let (w, h) = reader
                .into_dimensions()
                .map_err(|e| BtfError::codec(path, "read the header of", e))?;
            Ok((w as usize, h as usize))
        }
        Kind::Exr => {
            // The exr crate opens by path: refuse a FIFO or a device first.
            input_guard::open_regular(path).map_err(|e| BtfError::io(path, "open", e))?;
            let meta = exr::meta::MetaData::read_from_file(path, false)
                .map_err(|e| BtfError::codec(path, "read the header of", e))?;
            let header = meta
                .headers
                .iter()
                .find(|h| {
                    ["R", "G", "B"]
                        .iter()
                        .all(|n| h.channels.list.iter().any(|c| c.name.to_string() == *n))
                })
                .ok_or_else(|| {
                    BtfError::codec(
                        path,
                        "read the header of",
                        "no layer with R, G and B channels",
                    )
                })?;
            Ok((header.layer_size.width(), header.layer_size.height()))
        }
    }
}

/// Decodes `path` into `out` (3·width·height linear RGB floats, row-major), checking that the
/// image is `width` × `height`.
pub(crate) fn decode_into(path: &Path, width: usize, height: usize, out: &mut [f32]) -> Result<()> {
    debug_assert_eq!(out.len(), 3 * width * height);
    match kind_of_path(path) {
        Kind::Raster => decode_raster(path, width, height, out),
        Kind::Exr => decode_exr(path, width, height, out),
    }
}

fn size_error(path: &Path, width: usize, height: usize, w: usize, h: usize) -> BtfError {
    BtfError::SizeMismatch {
        path: path.to_path_buf(),
        reference: path.to_path_buf(),
        expected_w: width,
        expected_h: height,
        found_w: w,
        found_h: h,
    }
}

fn decode_raster(path: &Path, width: usize, height: usize, out: &mut [f32]) -> Result<()> {
    let mut reader = open_image(path)?
        .with_guessed_format()
        .map_err(|e| BtfError::io(path, "read", e))?;
    // The decoder allocates from the header, which `BtfDir::open` checked: bound it by the
    // size found then, in case the file changed since.
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(u32::try_from(width).unwrap_or(u32::MAX));
    limits.max_image_height = Some(u32::try_from(height).unwrap_or(u32::MAX));
    reader.limits(limits);
    let img = reader
        .decode()
        .map_err(|e| BtfError::codec(path, "decode", e))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    if (w, h) != (width, height) {
        return Err(size_error(path, width, height, w, h));
    }
    match img {
        DynamicImage::ImageLuma8(_)
        | DynamicImage::ImageLumaA8(_)
        | DynamicImage::ImageRgb8(_)
        | DynamicImage::ImageRgba8(_) => {
            let table = srgb8_table();
            let rgb = img.into_rgb8();
            out.iter_mut()
                .zip(rgb.as_raw())
                .for_each(|(o, &c)| *o = table[c as usize]);
        }
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            let rgb = img.into_rgb32f();
            out.copy_from_slice(rgb.as_raw());
        }
        _ => {
            let rgb = img.into_rgb16();
            out.iter_mut()
                .zip(rgb.as_raw())
                .for_each(|(o, &c)| *o = srgb_to_linear(f32::from(c) / 65535.0));
        }
    }
    Ok(())
}

fn decode_exr(path: &Path, width: usize, height: usize, out: &mut [f32]) -> Result<()> {
    // The header was checked by `BtfDir::open`; check again (the file may have changed) before
    // writing into `out`, and allocate nothing per pixel.
    let (w, h) = read_dimensions(path)?;
    if (w, h) != (width, height) {
        return Err(size_error(path, width, height, w, h));
    }
    // The reader's closures must be 'static, so the pixels go to an owned buffer, allocated
    // only when the layer has the size already validated.
    struct Pixels {
        data: Vec<f32>,
        width: usize,
        size: (usize, usize),
    }
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        move |res, _| {
            let size = (res.width(), res.height());
            let data = if size == (width, height) {
                vec![0.0; 3 * width * height]
            } else {
                Vec::new()
            };
            Pixels { data, width, size }
        },
        |p: &mut Pixels, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let i = 3 * (pos.y() * p.width + pos.x());
            if let Some(px) = p.data.get_mut(i..i + 3) {
                px.copy_from_slice(&[r, g, b]);
            }
        },
    )
    .map_err(|e| BtfError::codec(path, "decode", e))?;
    let pixels = image.layer_data.channel_data.pixels;
    if pixels.size != (width, height) {
        return Err(size_error(
            path,
            width,
            height,
            pixels.size.0,
            pixels.size.1,
        ));
    }
    out.copy_from_slice(&pixels.data);
    Ok(())
}

/// Writes linear RGB texels as an 8-bit sRGB PNG, atomically (temporary file + rename).
///
/// The file is not fsync'ed: a BTF folder has 6,561 files and one fsync each cost 30 s on the
/// development machine's disk (5 ms per file, against < 0.1 ms to encode a 16² image). A
/// reader never sees a half-written file under its final name; after a system crash a file may
/// be empty, which [`crate::BtfDir::open`] reports naming the file.
///
/// # Errors
/// [`BtfError::LengthMismatch`] if `texels.len() ≠ width·height`, [`BtfError::Codec`] if it
/// cannot be encoded, [`BtfError::Io`] if it cannot be written.
pub fn write_png_srgb8(
    path: &Path,
    width: usize,
    height: usize,
    texels: &[[f32; 3]],
) -> Result<()> {
    if texels.len() != width * height || width == 0 || height == 0 {
        return Err(BtfError::LengthMismatch {
            what: "write_png_srgb8 texels",
            expected: width * height,
            found: texels.len(),
            hint: "pass width · height (> 0) RGB texels, row-major",
        });
    }
    let bytes: Vec<u8> = texels.iter().flat_map(|t| t.map(linear_to_srgb8)).collect();
    let mut encoded = Vec::with_capacity(bytes.len() / 2 + 64);
    image::codecs::png::PngEncoder::new_with_quality(
        &mut encoded,
        image::codecs::png::CompressionType::Fast,
        image::codecs::png::FilterType::Adaptive,
    )
    .write_image(
        &bytes,
        width as u32,
        height as u32,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| BtfError::codec(path, "encode", e))?;
    atomic_out::write_bytes(path, &encoded)?;
    Ok(())
}

/// Writes a complete BTF folder in the UBO2003 naming (`tl{θl:03} pl{φl:03} tv{θv:03}
/// pv{φv:03}.png`, [`crate::image_file_name`]): for every view slot `v` and light `l` of
/// `sampling`, `image(v, l)` returns the `res` × `res` linear RGB texels (row-major), written as
/// an 8-bit sRGB PNG (values clamped to [0, 1]), each file atomically. Files are produced in
/// parallel, in view-major order (each thread takes a contiguous run of pairs, so a generator
/// that caches per-view work benefits); `progress(done, total)` is called after every file.
///
/// For generators with expensive per-view setup, [`write_btf_view`] writes one view slot at a
/// time.
///
/// # Errors
/// [`BtfError::InvalidParameter`] for `res = 0`, [`BtfError::Io`] if the folder cannot be
/// created, [`BtfError::LengthMismatch`] if `image` returns the wrong number of texels,
/// [`BtfError::Io`] if a file cannot be written.
///
/// # Examples
/// ```
/// use btf::{BtfDir, Sampling, write_btf_dir};
/// let dir = tempfile::tempdir().unwrap();
/// write_btf_dir(dir.path(), Sampling::H2, 2, |v, l| vec![[0.01 * (v + l) as f32; 3]; 4], None)
///     .unwrap();
/// let btf = BtfDir::open(dir.path()).unwrap();
/// assert_eq!((btf.sampling(), btf.width(), btf.height()), (Sampling::H2, 2, 2));
/// ```
pub fn write_btf_dir<F>(
    dir: &Path,
    sampling: Sampling,
    res: usize,
    image: F,
    progress: Option<&(dyn Fn(usize, usize) + Sync)>,
) -> Result<()>
where
    F: Fn(usize, usize) -> Vec<[f32; 3]> + Sync,
{
    check_res(res)?;
    std::fs::create_dir_all(dir).map_err(|e| BtfError::io(dir, "create", e))?;
    let total = pair_count();
    let done = AtomicUsize::new(0);
    (0..total).into_par_iter().try_for_each(|pair| {
        let (view, light) = (pair / DIRECTIONS, pair % DIRECTIONS);
        write_one(dir, sampling, res, view, light, &image(view, light))?;
        let d = done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(p) = progress {
            p(d, total);
        }
        Ok(())
    })
}

/// Writes the 81 light images of one view slot (see [`write_btf_dir`]); `image(l)` returns
/// light `l`'s `res` × `res` linear RGB texels. Lights are written in parallel.
///
/// # Errors
/// As [`write_btf_dir`]; [`BtfError::IndexOutOfRange`] for `view ≥ 81`.
pub fn write_btf_view<F>(
    dir: &Path,
    sampling: Sampling,
    res: usize,
    view: usize,
    image: F,
) -> Result<()>
where
    F: Fn(usize) -> Vec<[f32; 3]> + Sync,
{
    check_res(res)?;
    if view >= DIRECTIONS {
        return Err(BtfError::IndexOutOfRange {
            what: "write_btf_view view slot",
            index: view,
            len: DIRECTIONS,
        });
    }
    std::fs::create_dir_all(dir).map_err(|e| BtfError::io(dir, "create", e))?;
    (0..DIRECTIONS)
        .into_par_iter()
        .try_for_each(|light| write_one(dir, sampling, res, view, light, &image(light)))
}

fn check_res(res: usize) -> Result<()> {
    if res == 0 || res > u32::MAX as usize / 4 {
        return Err(BtfError::InvalidParameter {
            what: "write_btf_dir",
            name: "res",
            value: res.to_string(),
            reason: "the normtexture resolution must be at least 1 (and fit a PNG)",
        });
    }
    Ok(())
}

fn write_one(
    dir: &Path,
    sampling: Sampling,
    res: usize,
    view: usize,
    light: usize,
    texels: &[[f32; 3]],
) -> Result<()> {
    if texels.len() != res * res {
        return Err(BtfError::LengthMismatch {
            what: "write_btf_dir image(view, light)",
            expected: res * res,
            found: texels.len(),
            hint: "return res × res RGB texels, row-major",
        });
    }
    let path = dir.join(image_file_name(sampling, view, light, "png"));
    write_png_srgb8(&path, res, res, texels)
}
