//! The environment backdrop: a lat-long map drawn where no object is, after the opaque passes
//! (the depth test passes only at the cleared far depth, so covered pixels cost nothing).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat};
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};
use wgpu::util::DeviceExt;

use crate::frame::PassContext;

/// WGSL of the pass (after `view.wgsl`).
pub const BACKDROP_SHADER: &str = include_str!("backdrop.wgsl");

/// Largest backdrop width uploaded; wider maps are box-downsampled by powers of two (the
/// backdrop is for looks; lighting always uses the full map).
pub const MAX_BACKDROP_WIDTH: usize = 2048;

/// A lat-long environment to draw behind the objects.
#[derive(Clone, Copy, Debug)]
pub struct Backdrop<'a> {
    /// Lat-long width.
    pub width: usize,
    /// Lat-long height.
    pub height: usize,
    /// Linear texels, row-major, top row (θ = 0, +Y) first.
    pub texels: &'a [[f32; 3]],
    /// Rotation of the environment relative to the world.
    pub world_from_env: Quat,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct EnvUniform {
    env_from_world: [[f32; 4]; 4],
    size: [u32; 4],
}

/// The backdrop pass and its uploaded map.
#[derive(Debug)]
pub struct BackdropPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    group: Option<wgpu::BindGroup>,
}

impl BackdropPass {
    pub(crate) fn new(device: &wgpu::Device, ctx: &PassContext<'_>) -> Self {
        let source = format!("{}\n{}", crate::VIEW_SHADER, BACKDROP_SHADER);
        let module = pipeline::shader_module(device, "backdrop.wgsl", &source);
        let layout = bind_group_layout(
            device,
            "backdrop",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[binding::uniform(), binding::storage_read()],
        );
        let pipeline_layout =
            pipeline::pipeline_layout(device, "backdrop", &[ctx.view_layout, &layout]);
        let pipeline = RenderPipelineDesc {
            label: "backdrop",
            layout: &pipeline_layout,
            module: &module,
            vertex: "vs_backdrop",
            fragment: Some("fs_backdrop"),
            buffers: &[],
            color: Some(ctx.format.color_target()),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: ctx.format.depth_stencil,
                depth_write_enabled: Some(false),
                // The triangle sits exactly at the cleared depth: equal passes, anything
                // nearer (an object) fails.
                depth_compare: Some(wgpu::CompareFunction::Equal),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            samples: ctx.format.samples,
            cull_mode: None,
        }
        .build(device);
        Self {
            pipeline,
            layout,
            group: None,
        }
    }

    /// Upload the map drawn by the next frames (`None`: no backdrop).
    pub fn set_environment(&mut self, device: &wgpu::Device, backdrop: Option<Backdrop<'_>>) {
        self.group = backdrop.map(|b| {
            let (w, h, texels) = downsample(b.width, b.height, b.texels);
            let uniform = EnvUniform {
                env_from_world: Mat4::from_quat(b.world_from_env.inverse()).to_cols_array_2d(),
                size: [w as u32, h as u32, 0, 0],
            };
            let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("backdrop uniform"),
                contents: bytemuck::bytes_of(&uniform),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let texels = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("backdrop texels"),
                contents: bytemuck::cast_slice(&texels),
                usage: wgpu::BufferUsages::STORAGE,
            });
            bind_group(
                device,
                "backdrop",
                &self.layout,
                &[uniform.as_entire_binding(), texels.as_entire_binding()],
            )
        });
    }

    /// Whether a map is uploaded.
    pub fn has_environment(&self) -> bool {
        self.group.is_some()
    }

    pub(crate) fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        if let Some(group) = &self.group {
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(1, group, &[]);
            pass.draw(0..3, 0..1);
        }
    }
}

/// Box-downsample a lat-long map by powers of two until it is at most [`MAX_BACKDROP_WIDTH`]
/// wide, padding texels to vec4 for the storage buffer. An empty map becomes one black texel.
fn downsample(width: usize, height: usize, texels: &[[f32; 3]]) -> (usize, usize, Vec<[f32; 4]>) {
    if width == 0 || height == 0 || texels.len() < width * height {
        return (1, 1, vec![[0.0; 4]]);
    }
    let mut factor = 1;
    while width / factor > MAX_BACKDROP_WIDTH && height / (factor * 2) >= 1 {
        factor *= 2;
    }
    let (w, h) = (width / factor, height / factor);
    let norm = 1.0 / (factor * factor) as f32;
    let mut out = vec![[0.0f32; 4]; w * h];
    for r in 0..h {
        for c in 0..w {
            let mut sum = [0.0f32; 3];
            for dr in 0..factor {
                for dc in 0..factor {
                    let t = texels[(r * factor + dr) * width + c * factor + dc];
                    for k in 0..3 {
                        sum[k] += t[k];
                    }
                }
            }
            out[r * w + c] = [sum[0] * norm, sum[1] * norm, sum[2] * norm, 0.0];
        }
    }
    (w, h, out)
}
