//! The rendered image: linear RGB plus coverage, tone mapped to 8-bit sRGB for PNG.

use std::path::Path;

use crate::error::Result;
use crate::io::{linear_to_srgb8, write_png_srgb8};

/// A rendered image: linear RGB per pixel (row-major, top row first) and which pixels a
/// triangle covers (the rest show [`RenderParams::background`](super::RenderParams)).
#[derive(Clone, Debug, PartialEq)]
pub struct RenderedImage {
    width: u32,
    height: u32,
    pixels: Vec<[f32; 3]>,
    coverage: Vec<bool>,
}

impl RenderedImage {
    /// Assembles an image; the two buffers hold width · height entries.
    pub(crate) fn new(width: u32, height: u32, pixels: Vec<[f32; 3]>, coverage: Vec<bool>) -> Self {
        let n = width as usize * height as usize;
        assert!(
            pixels.len() == n && coverage.len() == n,
            "image buffers of {} and {} entries for {width} × {height}",
            pixels.len(),
            coverage.len()
        );
        Self {
            width,
            height,
            pixels,
            coverage,
        }
    }

    /// Linear RGBA pixels, row-major, top row first, alpha 1 where a triangle covers the
    /// pixel and 0 elsewhere: the layout of the workspace's linear image
    /// (`gpu_context::HdrImage::new(width, height, image.to_rgba())`).
    pub fn to_rgba(&self) -> Vec<[f32; 4]> {
        self.pixels
            .iter()
            .zip(&self.coverage)
            .map(|(p, &c)| [p[0], p[1], p[2], if c { 1.0 } else { 0.0 }])
            .collect()
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Linear RGB of every pixel, row-major, top row first.
    pub fn pixels(&self) -> &[[f32; 3]] {
        &self.pixels
    }

    /// Whether each pixel is covered by a triangle, row-major.
    pub fn coverage(&self) -> &[bool] {
        &self.coverage
    }

    /// Linear RGB of pixel (x, y), y from the top.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn pixel(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[self.index(x, y)]
    }

    /// Whether pixel (x, y) is covered by a triangle.
    ///
    /// # Panics
    /// If (x, y) is outside the image.
    pub fn covered(&self, x: u32, y: u32) -> bool {
        self.coverage[self.index(x, y)]
    }

    fn index(&self, x: u32, y: u32) -> usize {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside {} × {}",
            self.width,
            self.height
        );
        y as usize * self.width as usize + x as usize
    }

    /// The image tone mapped for display: each linear value clamped to [0, 1] and sRGB
    /// encoded to 8 bits ([`crate::linear_to_srgb8`]).
    pub fn to_srgb8(&self) -> Vec<[u8; 3]> {
        self.pixels.iter().map(|p| p.map(linear_to_srgb8)).collect()
    }

    /// Writes the image as an 8-bit sRGB PNG (tone mapped as [`RenderedImage::to_srgb8`]),
    /// atomically (a temporary file renamed into place).
    ///
    /// # Errors
    /// [`BtfError::Codec`](crate::BtfError::Codec) if encoding fails,
    /// [`BtfError::Io`](crate::BtfError::Io) if the file cannot be written.
    pub fn write_png(&self, path: &Path) -> Result<()> {
        write_png_srgb8(
            path,
            self.width as usize,
            self.height as usize,
            &self.pixels,
        )
    }
}
