//! Headless render targets: an HDR colour texture plus a depth texture, read back to the CPU.

use crate::{GpuError, HdrImage};

/// Colour format of offscreen targets: linear HDR, read back exactly.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
/// Depth format: `Depth32Float`, so depth can be read back or sampled in compute.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// An offscreen colour + depth target of a fixed size.
#[derive(Debug)]
pub struct OffscreenTarget {
    color: wgpu::Texture,
    depth: wgpu::Texture,
    width: u32,
    height: u32,
}

impl OffscreenTarget {
    /// Create a `width × height` target.
    ///
    /// # Errors
    /// [`GpuError::SizeOutOfRange`] when a side is zero or above the device's 2-D texture limit.
    pub fn new(device: &wgpu::Device, width: u32, height: u32) -> Result<Self, GpuError> {
        let maximum = device.limits().max_texture_dimension_2d;
        for (what, value) in [("offscreen width", width), ("offscreen height", height)] {
            if value == 0 || value > maximum {
                return Err(GpuError::SizeOutOfRange {
                    what,
                    value,
                    maximum,
                });
            }
        }
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let make = |label, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let color = make(
            "offscreen colour",
            COLOR_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = make(
            "offscreen depth",
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        Ok(Self {
            color,
            depth,
            width,
            height,
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

    /// A view of the colour texture, for a render pass attachment.
    pub fn color_view(&self) -> wgpu::TextureView {
        self.color
            .create_view(&wgpu::TextureViewDescriptor::default())
    }

    /// A view of the depth texture, for a render pass attachment.
    pub fn depth_view(&self) -> wgpu::TextureView {
        self.depth
            .create_view(&wgpu::TextureViewDescriptor::default())
    }

    /// Copy the colour texture to the CPU (blocking) as a linear HDR image, top row first.
    ///
    /// # Errors
    /// [`GpuError::Readback`] when mapping fails or the device is lost.
    pub fn read_color(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<HdrImage, GpuError> {
        read_hdr_image(device, queue, &self.color)
    }

    /// Copy the depth texture to the CPU (blocking), row-major, top row first.
    ///
    /// # Errors
    /// [`GpuError::Readback`] when mapping fails or the device is lost.
    pub fn read_depth(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f32>, GpuError> {
        let bytes = read_texture(
            device,
            queue,
            &self.depth,
            4,
            wgpu::TextureAspect::DepthOnly,
        )?;
        Ok(bytemuck::cast_slice(&bytes).to_vec())
    }
}

/// Copy a whole `Rgba32Float` texture (`COPY_SRC` usage) to the CPU as a linear HDR image,
/// top row first.
///
/// # Errors
/// [`GpuError::Readback`] when mapping fails or the device is lost.
pub fn read_hdr_image(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<HdrImage, GpuError> {
    const TEXEL_BYTES: u32 = 16;
    let bytes = read_texture(
        device,
        queue,
        texture,
        TEXEL_BYTES,
        wgpu::TextureAspect::All,
    )?;
    let floats: &[f32] = bytemuck::cast_slice(&bytes);
    let pixels = floats
        .chunks_exact(4)
        .map(|p| [p[0], p[1], p[2], p[3]])
        .collect();
    HdrImage::new(texture.width(), texture.height(), pixels)
}

/// Copy a whole 2-D texture (one aspect, `texel_bytes` per texel, `COPY_SRC` usage) into
/// tightly packed bytes, row-major, top row first (row padding removed).
///
/// # Errors
/// [`GpuError::Readback`] when mapping fails or the device is lost.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
    texel_bytes: u32,
    aspect: wgpu::TextureAspect,
) -> Result<Vec<u8>, GpuError> {
    let (width, height) = (texture.width(), texture.height());
    let row_bytes = width * texel_bytes;
    let padded_row =
        row_bytes.div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read-back"),
        size: u64::from(padded_row) * u64::from(height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("read-back"),
    });
    encoder.copy_texture_to_buffer(
        wgpu::TexelCopyTextureInfo {
            texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect,
        },
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded_row),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([encoder.finish()]);
    let mapped = map_read(device, &buffer)?;
    let mut out = Vec::with_capacity(row_bytes as usize * height as usize);
    for row in mapped.chunks_exact(padded_row as usize) {
        out.extend_from_slice(&row[..row_bytes as usize]);
    }
    Ok(out)
}

/// Copy the first `size` bytes of `buffer` (which needs `COPY_SRC` usage) to the CPU: one copy
/// into a staging buffer, one map, one blocking wait.
///
/// # Errors
/// [`GpuError::Readback`] when mapping fails or the device is lost;
/// [`GpuError::Validation`] when the device reported a validation error since the last check.
pub fn read_buffer(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    buffer: &wgpu::Buffer,
    size: u64,
) -> Result<Vec<u8>, GpuError> {
    if size == 0 {
        return Ok(Vec::new());
    }
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("read-back"),
        size,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("read-back"),
    });
    encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
    queue.submit([encoder.finish()]);
    map_read(device, &staging)
}

/// Map a `MAP_READ` buffer whose copy has been submitted, wait, and return its bytes.
fn map_read(device: &wgpu::Device, buffer: &wgpu::Buffer) -> Result<Vec<u8>, GpuError> {
    let slice = buffer.slice(..);
    let (sender, receiver) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |result| {
        // The receiver lives until recv() below returns; a failed send is impossible.
        let _ = sender.send(result);
    });
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    receiver
        .recv()
        .map_err(|e| GpuError::Readback(e.to_string()))?
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let mapped = slice
        .get_mapped_range()
        .map_err(|e| GpuError::Readback(e.to_string()))?;
    let bytes = mapped.to_vec();
    drop(mapped);
    buffer.unmap();
    // Work that failed validation leaves zeros behind: report the error, not the zeros.
    crate::adapter::check_device_errors()?;
    Ok(bytes)
}
