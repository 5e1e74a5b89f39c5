//! Linear HDR images and atomic PNG/EXR output (through [`atomic_out::write_via_path`]). Tone
//! mapping for display lives in one place, `render::tone` and `render::output`.

use std::path::Path;

use crate::GpuError;

/// A linear RGBA image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 4]>,
}

impl HdrImage {
    /// Wrap pixels.
    ///
    /// # Errors
    /// [`GpuError::ImageSize`] when `pixels.len() != width · height`.
    pub fn new(width: u32, height: u32, pixels: Vec<[f32; 4]>) -> Result<Self, GpuError> {
        let expected = width as usize * height as usize;
        if pixels.len() != expected {
            return Err(GpuError::ImageSize {
                width,
                height,
                expected,
                actual: pixels.len(),
            });
        }
        Ok(Self {
            width,
            height,
            pixels,
        })
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Pixels, row-major, top row first.
    pub fn pixels(&self) -> &[[f32; 4]] {
        &self.pixels
    }

    /// Write a linear 32-bit float RGBA OpenEXR file. The file appears complete or not at all.
    ///
    /// # Errors
    /// [`GpuError::Write`] naming the path.
    pub fn write_exr(&self, path: &Path) -> Result<(), GpuError> {
        let width = self.width as usize;
        atomic_write(path, |tmp| {
            exr::prelude::write_rgba_file(tmp, width, self.height as usize, |x, y| {
                let p = self.pixels[y * width + x];
                (p[0], p[1], p[2], p[3])
            })
            .map_err(|e| e.to_string())
        })
    }
}

/// Write 8-bit RGBA pixels (row-major, top row first) as a PNG. The file appears complete or
/// not at all.
///
/// # Errors
/// [`GpuError::Write`] naming the path (also when `rgba` is not `4 · width · height` bytes).
pub fn write_rgba8_png(path: &Path, rgba: &[u8], width: u32, height: u32) -> Result<(), GpuError> {
    // The encoder asserts on a wrong length; say it as an error instead of panicking.
    let expected = 4 * u64::from(width) * u64::from(height);
    if rgba.len() as u64 != expected {
        return Err(GpuError::Write {
            path: path.to_owned(),
            reason: format!(
                "{} bytes of RGBA for a {width} × {height} image, which needs {expected}",
                rgba.len()
            ),
        });
    }
    atomic_write(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            rgba,
            width,
            height,
            image::ColorType::Rgba8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    })
}

/// Runs the encoder `write` on a temporary path beside `path` with
/// [`atomic_out::write_via_path`], then renames it into place; on failure nothing is left.
fn atomic_write(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), GpuError> {
    atomic_out::write_via_path(path, write).map_err(|e| GpuError::Write {
        path: path.to_owned(),
        reason: match e {
            atomic_out::AtomicError::File(e) => format!("cannot {} it: {}", e.op, e.source),
            atomic_out::AtomicError::Writer(reason) => reason,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_size_is_checked() {
        assert!(matches!(
            HdrImage::new(2, 2, vec![[0.0; 4]; 3]),
            Err(GpuError::ImageSize {
                expected: 4,
                actual: 3,
                ..
            })
        ));
    }

    #[test]
    fn exr_round_trips_and_failed_writes_leave_nothing() {
        let dir = std::env::temp_dir().join(format!("gpu-context-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let pixels = (0..6).map(|i| [i as f32 * 10.5, -1.0, 1e4, 1.0]).collect();
        let img = HdrImage::new(3, 2, pixels).unwrap();
        let path = dir.join("x.exr");
        img.write_exr(&path).unwrap();
        let read = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |res, _| vec![[0.0f32; 4]; res.width() * res.height()],
            |buf: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                buf[pos.y() * 3 + pos.x()] = [r, g, b, a];
            },
        )
        .unwrap();
        assert_eq!(read.layer_data.channel_data.pixels, img.pixels);
        // A file where a folder should be: error names the path, no file left behind.
        let bad = path.join("below").join("y.png");
        let err = write_rgba8_png(&bad, &[0; 24], 3, 2).unwrap_err();
        assert!(err.to_string().contains("y.png"), "{err}");
        assert!(!bad.exists());
        // A folder that does not exist is created, as by every writer.
        write_rgba8_png(&dir.join("new-dir").join("z.png"), &[0; 24], 3, 2).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
