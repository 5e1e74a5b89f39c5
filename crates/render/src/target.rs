//! The frame target: HDR colour (`Rgba32Float`), depth with stencil, MSAA where the adapter
//! offers it, resolved to one sample for read-back.

use gpu_context::{COLOR_FORMAT, GpuContext, GpuError};

use crate::camera::DepthConvention;

/// Samples per pixel the frame asks for when the adapter allows it (lavapipe does).
pub const PREFERRED_SAMPLES: u32 = 4;

/// What every pipeline drawing into a frame must match: colour and depth formats, sample
/// count and depth convention.
///
/// * Colour is always [`COLOR_FORMAT`] (`Rgba32Float`: a sun at 10⁴× the sky neither clips
///   nor quantises; ARCHITECTURE.md).
/// * Depth is `Depth32FloatStencil8` when the device has `DEPTH32FLOAT_STENCIL8` (Vulkan,
///   Metal, DX12 and lavapipe do) — float depth plus the stencil shadow volumes need — and
///   otherwise the always-available `Depth24PlusStencil8` (same stencil, 24-bit depth).
/// * MSAA: [`PREFERRED_SAMPLES`] when the adapter reports 4× multisampling *and* resolve for
///   `Rgba32Float` (an adapter-specific format feature, requested by `gpu-context` when
///   offered); otherwise 1 sample — edges are then aliased and the alpha matte is binary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameFormat {
    /// Colour format (always [`COLOR_FORMAT`]).
    pub color: wgpu::TextureFormat,
    /// Depth-stencil format.
    pub depth_stencil: wgpu::TextureFormat,
    /// Samples per pixel (1 or [`PREFERRED_SAMPLES`]).
    pub samples: u32,
    /// Depth mapping and comparison.
    pub depth: DepthConvention,
}

impl FrameFormat {
    /// The best format `ctx`'s adapter offers: 4× MSAA when supported, float depth with stencil
    /// when supported, the standard depth convention.
    pub fn for_context(ctx: &GpuContext) -> Self {
        let features = ctx.device.features();
        let color_features = ctx.adapter.get_texture_format_features(COLOR_FORMAT);
        let msaa = features.contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES)
            && color_features
                .flags
                .sample_count_supported(PREFERRED_SAMPLES)
            && color_features
                .flags
                .contains(wgpu::TextureFormatFeatureFlags::MULTISAMPLE_RESOLVE);
        Self {
            samples: if msaa { PREFERRED_SAMPLES } else { 1 },
            ..Self::single_sample(&ctx.device)
        }
    }

    /// One sample per pixel: what CPU references compare against pixel for pixel.
    pub fn single_sample(device: &wgpu::Device) -> Self {
        let depth_stencil = if device
            .features()
            .contains(wgpu::Features::DEPTH32FLOAT_STENCIL8)
        {
            wgpu::TextureFormat::Depth32FloatStencil8
        } else {
            wgpu::TextureFormat::Depth24PlusStencil8
        };
        Self {
            color: COLOR_FORMAT,
            depth_stencil,
            samples: 1,
            depth: DepthConvention::Standard,
        }
    }

    /// The same format with another depth convention.
    pub fn with_depth(self, depth: DepthConvention) -> Self {
        Self { depth, ..self }
    }

    /// The depth comparison of opaque geometry: `Less` (standard) or `Greater` (reversed).
    pub fn depth_compare(&self) -> wgpu::CompareFunction {
        match self.depth {
            DepthConvention::Standard => wgpu::CompareFunction::Less,
            DepthConvention::ReversedInfinite => wgpu::CompareFunction::Greater,
        }
    }

    /// Depth-stencil state of opaque geometry: test and write depth, stencil untouched.
    pub fn opaque_depth(&self) -> wgpu::DepthStencilState {
        wgpu::DepthStencilState {
            format: self.depth_stencil,
            depth_write_enabled: Some(true),
            depth_compare: Some(self.depth_compare()),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }
    }

    /// Depth-stencil state of blended geometry: test against the opaque depth, write nothing.
    pub fn blended_depth(&self) -> wgpu::DepthStencilState {
        wgpu::DepthStencilState {
            depth_write_enabled: Some(false),
            ..self.opaque_depth()
        }
    }

    /// Colour target state with `blend`.
    pub fn blended_color_target(&self, blend: wgpu::BlendState) -> wgpu::ColorTargetState {
        wgpu::ColorTargetState {
            format: self.color,
            blend: Some(blend),
            write_mask: wgpu::ColorWrites::ALL,
        }
    }

    /// Colour target state without blending.
    pub fn color_target(&self) -> wgpu::ColorTargetState {
        wgpu::ColorTargetState {
            format: self.color,
            blend: None,
            write_mask: wgpu::ColorWrites::ALL,
        }
    }
}

/// The textures of one frame size.
#[derive(Debug)]
pub(crate) struct FrameTarget {
    /// Multisampled colour (only when samples > 1).
    pub msaa_color: Option<wgpu::TextureView>,
    /// One-sample colour: the render target without MSAA, the resolve target with it.
    pub resolved: wgpu::Texture,
    pub resolved_view: wgpu::TextureView,
    /// The tone-mapped 8-bit frame ([`crate::tonemap::DISPLAY_FORMAT`]).
    pub display: wgpu::Texture,
    /// View of `display`.
    pub display_view: wgpu::TextureView,
    pub depth_view: wgpu::TextureView,
    pub width: u32,
    pub height: u32,
}

impl FrameTarget {
    pub fn new(
        device: &wgpu::Device,
        format: &FrameFormat,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        let maximum = device.limits().max_texture_dimension_2d;
        for (what, value) in [("frame width", width), ("frame height", height)] {
            if value == 0 || value > maximum {
                return Err(GpuError::SizeOutOfRange {
                    what,
                    value,
                    maximum,
                });
            }
        }
        let make = |label, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d {
                    width,
                    height,
                    depth_or_array_layers: 1,
                },
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let resolved = make(
            "frame colour",
            format.color,
            1,
            attach | wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::TEXTURE_BINDING,
        );
        let display = make(
            "frame display",
            crate::tonemap::DISPLAY_FORMAT,
            1,
            attach | wgpu::TextureUsages::COPY_SRC,
        );
        let msaa_color = (format.samples > 1).then(|| {
            make("frame colour (MSAA)", format.color, format.samples, attach)
                .create_view(&Default::default())
        });
        let depth = make(
            "frame depth-stencil",
            format.depth_stencil,
            format.samples,
            attach,
        );
        Ok(Self {
            msaa_color,
            resolved_view: resolved.create_view(&Default::default()),
            resolved,
            display_view: display.create_view(&Default::default()),
            display,
            depth_view: depth.create_view(&Default::default()),
            width,
            height,
        })
    }
}
