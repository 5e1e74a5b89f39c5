//! Reading `.hdr` / `.exr` lat-long maps and writing `.exr`.
//!
//! Every reader checks the size from the header against [`super::MAX_ENV_DIMENSION`] and
//! [`super::MAX_ENV_TEXELS`] before the pixel buffer is allocated, so a header claiming
//! 2^40 texels is an error, not an allocation.

use super::{Environment, check_size};
use crate::LightsphereError;
use image::ImageDecoder;
use std::io::{BufRead as _, BufReader, Read as _};
use std::path::Path;

/// The longest first line a Radiance file may start with before its program name is judged
/// not to be a signature.
const SIGNATURE_MAX: u64 = 64;

const HDR: &str = "Radiance HDR";
const EXR: &str = "OpenEXR";

pub(super) fn load(path: &Path) -> Result<Environment, LightsphereError> {
    let extension = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match extension.as_str() {
        "hdr" | "rgbe" => load_hdr(path),
        "exr" => load_exr(path),
        _ => Err(LightsphereError::UnsupportedFormat {
            path: path.to_path_buf(),
            extension,
        }),
    }
}

fn io_error(path: &Path, operation: &'static str, source: std::io::Error) -> LightsphereError {
    LightsphereError::Io {
        path: path.to_path_buf(),
        operation,
        source,
    }
}

fn decode_error(
    path: &Path,
    format: &'static str,
    source: impl std::error::Error + Send + Sync + 'static,
) -> LightsphereError {
    LightsphereError::Decode {
        path: path.to_path_buf(),
        format,
        source: Box::new(source),
    }
}

fn load_hdr(path: &Path) -> Result<Environment, LightsphereError> {
    let file = input_guard::open_regular(path).map_err(|e| io_error(path, "open", e))?;
    let bytes_in_file = file
        .metadata()
        .map_err(|e| io_error(path, "stat", e))?
        .len();
    // Radiance files open with "#?" and the writing program's name: `#?RADIANCE` from most
    // tools, `#?RGBE` from Mitsuba and others (stb_image reads both). The decoder knows only
    // the first, so any other program name is read as if it were RADIANCE.
    let mut reader = BufReader::new(file);
    let mut first = Vec::new();
    reader
        .by_ref()
        .take(SIGNATURE_MAX)
        .read_until(b'\n', &mut first)
        .map_err(|e| io_error(path, "read", e))?;
    let program = first.strip_prefix(b"#?").map(|p| p.trim_ascii_end());
    if program.is_some_and(|p| !p.is_empty() && p.iter().all(u8::is_ascii_alphanumeric)) {
        first = b"#?RADIANCE\n".to_vec();
    }
    // Reads and parses the header only.
    let decoder = image::codecs::hdr::HdrDecoder::new(std::io::Cursor::new(first).chain(reader))
        .map_err(|e| decode_error(path, HDR, e))?;
    let (width, height) = decoder.dimensions();
    let (width, height) = (width as usize, height as usize);
    check_size(Some(path), width, height)?;
    let texels = (width as u64).saturating_mul(height as u64);
    let backed = super::HDR_TEXELS_FLOOR
        .saturating_add(bytes_in_file.saturating_mul(super::HDR_TEXELS_PER_BYTE));
    if texels > backed {
        return Err(LightsphereError::HdrHeaderTooLarge {
            path: path.to_path_buf(),
            width,
            height,
            bytes: bytes_in_file,
            per_byte: super::HDR_TEXELS_PER_BYTE,
            floor: super::HDR_TEXELS_FLOOR,
        });
    }
    let mut bytes = vec![0u8; width * height * 12];
    decoder
        .read_image(&mut bytes)
        .map_err(|e| decode_error(path, HDR, e))?;
    let texels = bytes
        .chunks_exact(12)
        .map(|px| {
            let channel = |i: usize| {
                f32::from_ne_bytes([px[4 * i], px[4 * i + 1], px[4 * i + 2], px[4 * i + 3]])
            };
            [channel(0), channel(1), channel(2)]
        })
        .collect();
    drop(bytes);
    Environment::from_texels(Some(path), width, height, texels)
}

/// Pixel storage for the EXR reader; `oversized` flags a layer that the header check did not
/// see (then nothing is allocated and loading fails).
struct ExrPixels {
    width: usize,
    texels: Vec<[f32; 3]>,
    oversized: Option<(usize, usize)>,
}

fn load_exr(path: &Path) -> Result<Environment, LightsphereError> {
    // The exr crate opens by path: refuse a FIFO or a device first.
    input_guard::open_regular(path).map_err(|e| io_error(path, "open", e))?;
    // Headers only: validate every RGB layer's size before decoding.
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| exr_error(path, e))?;
    let mut names = Vec::new();
    let mut has_rgb = false;
    for header in &meta.headers {
        let channel_names: Vec<String> = header
            .channels
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        let has = |n: &str| channel_names.iter().any(|c| c == n);
        if has("R") && has("G") && has("B") {
            has_rgb = true;
            let size = header.layer_size;
            check_size(Some(path), size.width(), size.height())?;
        }
        names.extend(channel_names);
    }
    if !has_rgb {
        return Err(LightsphereError::ExrMissingRgb {
            path: path.to_path_buf(),
            channels: names.join(", "),
        });
    }
    let image = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |resolution, _| {
            let (width, height) = (resolution.width(), resolution.height());
            if check_size(None, width, height).is_err() {
                ExrPixels {
                    width,
                    texels: Vec::new(),
                    oversized: Some((width, height)),
                }
            } else {
                ExrPixels {
                    width,
                    texels: vec![[0.0; 3]; width * height],
                    oversized: None,
                }
            }
        },
        |pixels: &mut ExrPixels, position, (r, g, b, _a): (f32, f32, f32, f32)| {
            let index = position.y() * pixels.width + position.x();
            if let Some(t) = pixels.texels.get_mut(index) {
                *t = [r, g, b];
            }
        },
    )
    .map_err(|e| exr_error(path, e))?;
    let size = image.layer_data.size;
    let pixels = image.layer_data.channel_data.pixels;
    if let Some((width, height)) = pixels.oversized {
        check_size(Some(path), width, height)?;
    }
    Environment::from_texels(Some(path), size.width(), size.height(), pixels.texels)
}

fn exr_error(path: &Path, error: exr::error::Error) -> LightsphereError {
    match error {
        // A file that ends early is a decoding problem (truncated), not an I/O failure.
        exr::error::Error::Io(e) if e.kind() != std::io::ErrorKind::UnexpectedEof => {
            io_error(path, "read", e)
        }
        other => decode_error(path, EXR, other),
    }
}

/// Writes `env` as float RGB OpenEXR, atomically ([`atomic_out::write_via_path`]: the `exr`
/// encoder writes a temporary file beside `path`, which is renamed over it).
pub(super) fn write_exr(env: &Environment, path: &Path) -> Result<(), LightsphereError> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    let width = env.width;
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let t = env.texels[y * width + x];
        (t[0], t[1], t[2])
    });
    let image = Image::from_channels((env.width, env.height), channels);
    atomic_out::write_via_path(path, |temporary| {
        image.write().to_file(temporary).map_err(|e| match e {
            exr::error::Error::Io(e) => io_error(path, "write", e),
            other => LightsphereError::Encode {
                path: path.to_path_buf(),
                source: Box::new(other),
            },
        })
    })
    .map_err(|e| match e {
        atomic_out::AtomicError::File(e) => io_error(&e.path, e.op, e.source),
        atomic_out::AtomicError::Writer(e) => e,
    })
}
