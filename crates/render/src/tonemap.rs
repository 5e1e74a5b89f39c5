//! The last pass of the frame: tone mapping on the GPU, from the resolved HDR colour to
//! display values in an 8-bit target — what an interactive viewer presents each frame without
//! reading the HDR frame back. It computes what [`crate::output::to_rgba8`] computes on the
//! CPU from the read-back image (exposure 2^EV, [`ToneCurve`], un-premultiplied colour and
//! the coverage alpha over a transparent background), within one 8-bit code; a test holds
//! the two together.

use bytemuck::{Pod, Zeroable};
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};

use crate::output::Background;
use crate::tone::{Display, ToneCurve};

/// WGSL of the pass.
pub const TONEMAP_SHADER: &str = include_str!("tonemap.wgsl");

/// The 8-bit target [`crate::Renderer::render_display`] tone-maps into (display-encoded
/// values, so not an `*Srgb` format).
pub const DISPLAY_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ToneUniform {
    scale: f32,
    curve: u32,
    gamma: f32,
    transparent: u32,
}

/// The tone-map pipeline for one output format, and its parameters.
#[derive(Debug)]
pub struct ToneMapPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniform: wgpu::Buffer,
}

impl ToneMapPass {
    /// Build the pipeline writing `output` (any non-sRGB colour format a surface offers:
    /// `Rgba8Unorm`, `Bgra8Unorm`, …; the shader encodes).
    pub fn new(device: &wgpu::Device, output: wgpu::TextureFormat) -> Self {
        let module = pipeline::shader_module(device, "tonemap.wgsl", TONEMAP_SHADER);
        let layout = bind_group_layout(
            device,
            "tone map",
            wgpu::ShaderStages::FRAGMENT,
            &[
                binding::texture(
                    wgpu::TextureSampleType::Float { filterable: false },
                    wgpu::TextureViewDimension::D2,
                ),
                binding::uniform(),
            ],
        );
        let pipeline_layout = pipeline::pipeline_layout(device, "tone map", &[&layout]);
        let pipeline = RenderPipelineDesc {
            label: "tone map",
            layout: &pipeline_layout,
            module: &module,
            vertex: "vs_tonemap",
            fragment: Some("fs_tonemap"),
            buffers: &[],
            color: Some(wgpu::ColorTargetState {
                format: output,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            }),
            depth_stencil: None,
            samples: 1,
            cull_mode: None,
        }
        .build(device);
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("tone map parameters"),
            size: std::mem::size_of::<ToneUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            pipeline,
            layout,
            uniform,
        }
    }

    /// The binding of an HDR frame (a single-sample `Rgba32Float` view with
    /// `TEXTURE_BINDING`, such as [`crate::Renderer::hdr_view`]); build it once per target.
    pub fn bind(&self, device: &wgpu::Device, hdr: &wgpu::TextureView) -> wgpu::BindGroup {
        bind_group(
            device,
            "tone map",
            &self.layout,
            &[
                wgpu::BindingResource::TextureView(hdr),
                self.uniform.as_entire_binding(),
            ],
        )
    }

    /// Write `display` and `background` into the parameters and record the pass drawing the
    /// frame bound by `group` into `out` (same size as the frame).
    pub fn record(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        group: &wgpu::BindGroup,
        display: &Display,
        background: Background,
        out: &wgpu::TextureView,
    ) {
        let (curve, gamma) = match display.curve {
            ToneCurve::AcesFitted => (0, 1.0),
            ToneCurve::Clamp { gamma } => (1, gamma),
            ToneCurve::ClampSrgb => (2, 1.0),
        };
        let params = ToneUniform {
            scale: display.scale(),
            curve,
            gamma,
            transparent: u32::from(background.is_transparent()),
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&params));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("tone map"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: out,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..3, 0..1);
    }
}
