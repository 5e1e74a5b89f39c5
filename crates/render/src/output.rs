//! What a frame becomes for a person: background choice, automatic exposure from the objects
//! only, and PNG / EXR files with a real alpha matte, written atomically.

use std::path::Path;

use gpu_context::{GpuError, HdrImage};

use crate::tone::{self, Display};

/// What is behind the objects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Background {
    /// Nothing: PNG and EXR carry the objects' coverage as alpha.
    Transparent,
    /// A constant linear colour (black is `[0, 0, 0]`); opaque output.
    Color([f32; 3]),
    /// The environment map (the backdrop pass); opaque output.
    Environment,
}

impl Background {
    /// Whether output files carry the coverage matte as alpha.
    pub fn is_transparent(self) -> bool {
        self == Background::Transparent
    }
}

/// The objects' brightest channel ([`tone::peak`]): the pixels they cover entirely (alpha 1).
/// Edge pixels are left out — under MSAA they mix in the backdrop's samples, and a sun behind
/// an edge would set the exposure. The backdrop never counts.
pub fn object_peaks(image: &HdrImage) -> impl Iterator<Item = f32> + '_ {
    image
        .pixels()
        .iter()
        .filter(|p| p[3] >= 1.0)
        .map(|p| tone::peak([p[0], p[1], p[2]]))
}

/// The exposure (EV) that puts the objects' [`tone::AUTO_EXPOSURE_PERCENTILE`] brightest
/// channel at [`tone::AUTO_EXPOSURE_KEY`]; 0 when no object is visible.
pub fn auto_exposure(image: &HdrImage) -> f32 {
    tone::auto_exposure_ev(
        object_peaks(image),
        tone::AUTO_EXPOSURE_PERCENTILE,
        tone::AUTO_EXPOSURE_KEY,
    )
    .unwrap_or(0.0)
}

/// 8-bit RGBA: with a transparent background, straight (un-premultiplied) colour and the
/// coverage as alpha; otherwise opaque.
pub fn to_rgba8(image: &HdrImage, display: &Display, background: Background) -> Vec<u8> {
    let mut out = Vec::with_capacity(image.pixels().len() * 4);
    for p in image.pixels() {
        let (rgb, alpha) = if background.is_transparent() {
            let a = if p[3].is_nan() {
                0.0
            } else {
                p[3].clamp(0.0, 1.0)
            };
            let inv = if a > 0.0 { 1.0 / a } else { 0.0 };
            ([p[0] * inv, p[1] * inv, p[2] * inv], a)
        } else {
            ([p[0], p[1], p[2]], 1.0)
        };
        out.extend_from_slice(&[
            display.map_u8(rgb[0]),
            display.map_u8(rgb[1]),
            display.map_u8(rgb[2]),
            tone::to_u8(alpha),
        ]);
    }
    out
}

/// Write a tone-mapped 8-bit RGBA PNG ([`to_rgba8`]). The file appears complete or not at all.
///
/// # Errors
/// [`GpuError::Write`] naming the path.
pub fn write_png(
    image: &HdrImage,
    path: &Path,
    display: &Display,
    background: Background,
) -> Result<(), GpuError> {
    let rgba = to_rgba8(image, display, background);
    gpu_context::write_rgba8_png(path, &rgba, image.width(), image.height())
}

/// Write linear 32-bit float RGBA OpenEXR: with a transparent background, premultiplied
/// radiance and the coverage as alpha (EXR's convention); otherwise alpha 1. The file appears
/// complete or not at all.
///
/// # Errors
/// [`GpuError::Write`] naming the path.
pub fn write_exr(image: &HdrImage, path: &Path, background: Background) -> Result<(), GpuError> {
    if background.is_transparent() {
        return image.write_exr(path);
    }
    let opaque: Vec<[f32; 4]> = image
        .pixels()
        .iter()
        .map(|p| [p[0], p[1], p[2], 1.0])
        .collect();
    HdrImage::new(image.width(), image.height(), opaque)?.write_exr(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image() -> HdrImage {
        // Background (alpha 0, sky colour), a full object pixel, a half-covered edge that
        // mixes in the sky.
        HdrImage::new(
            3,
            1,
            vec![
                [5.0, 5.0, 5.0, 0.0],
                [0.2, 0.2, 0.2, 1.0],
                [2.6, 2.6, 2.6, 0.5],
            ],
        )
        .unwrap()
    }

    #[test]
    fn transparent_png_unpremultiplies_and_keeps_coverage() {
        let d = Display::default();
        let rgba = to_rgba8(&image(), &d, Background::Transparent);
        assert_eq!(rgba[3], 0);
        assert_eq!(rgba[7], 255);
        assert_eq!(rgba[11], 128);
        // Straight alpha: the edge pixel's colour divided by its coverage.
        assert_eq!(rgba[8], Display::default().map_u8(5.2));
        let opaque = to_rgba8(&image(), &d, Background::Environment);
        assert!(opaque.chunks(4).all(|p| p[3] == 255));
    }

    #[test]
    fn auto_exposure_keys_a_saturated_colour_on_its_strongest_channel() {
        // A red object, albedo (0.9, 0.3, 0.2) under unit light: keyed on its luminance
        // (0.42) its red channel would land at 1.71 after exposure, deep in the curve's
        // shoulder, and the picture would show pale pink; keyed on red it lands at 0.8.
        let red = HdrImage::new(1, 1, vec![[0.9, 0.3, 0.2, 1.0]]).unwrap();
        let ev = auto_exposure(&red);
        assert!((ev - (0.8f32 / 0.9).log2()).abs() < 1e-6, "{ev}");
        let d = Display {
            exposure_ev: ev,
            ..Display::default()
        };
        let [r, g, b] = [0.9f32, 0.3, 0.2].map(|c| d.map_u8(c));
        assert!(r > g && g > b && r - b > 60, "{r} {g} {b}");
    }

    #[test]
    fn auto_exposure_ignores_the_backdrop() {
        // Neither the bright backdrop pixel (alpha 0) nor the edge that mixes it in counts.
        let ev = auto_exposure(&image());
        assert!((ev - (0.8f32 / 0.2).log2()).abs() < 1e-5, "{ev}");
    }
}
