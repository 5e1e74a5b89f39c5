//! Which triangles the camera sees: the input of the "todo" list T of paper 000 §4.1.
//!
//! > "In order to compute list T, we perform an algorithm similar to the one in Section 3,
//! > except that here we render triangles in the second pass and use perspective projection.
//! > More precisely, in the first pass, we render the unlit mesh into the depth buffer as seen
//! > from the new camera position. In the second pass, we render only the triangles still in
//! > list U, each with its own occlusion query."
//!
//! Deviation: instead of one occlusion query per triangle still in U, one pass renders every
//! triangle's id into an R32Uint target with a depth test ([`TriangleIdRenderer`],
//! `shaders/triangle_ids.wgsl`); after read-back, a triangle is visible iff it covers at least
//! one pixel centre. This is one draw instead of |U| queries, and exact at pixel granularity
//! (an occlusion query with polygon offset also counts pixels that tie in depth). A triangle
//! smaller than a pixel that covers no pixel centre is not visible, so it is neither computed
//! nor drawn at that resolution. Both faces are rasterised (cloth is seen from both sides).
//! [`super::raster::visible_triangles_cpu`] is the CPU reference (and the path without an
//! adapter): the same pixel-centre sampling with an inclusive edge rule instead of the GPU's
//! top-left rule, so the two may differ on triangles that only touch pixel centres with an
//! edge.

use glam::Vec3;
use wgpu::util::DeviceExt;

use super::camera::{Camera, prepare};
use super::triangle_set::TriangleSet;
use crate::{OcclusionError, Scene};

const ID_SHADER: &str = include_str!("triangle_ids.wgsl");

/// Render target of one size: triangle ids, depth, and a buffer for the read-back copy.
struct IdTarget {
    width: u32,
    height: u32,
    ids: wgpu::Texture,
    depth: wgpu::Texture,
    readback: wgpu::Buffer,
    padded_row_bytes: u32,
}

/// The GPU triangle-id pass (see the module docs): one draw of all triangles into an R32Uint
/// target with a depth test, then a read-back of the ids.
pub struct TriangleIdRenderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    target: Option<IdTarget>,
}

impl TriangleIdRenderer {
    /// Builds the pipeline on `device` (cloned handles are kept).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("triangle_ids.wgsl"),
            source: wgpu::ShaderSource::Wgsl(ID_SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("triangle ids"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("triangle ids"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("triangle ids"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 12,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3],
                })],
            },
            primitive: wgpu::PrimitiveState {
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: wgpu::TextureFormat::Depth32Float,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: wgpu::TextureFormat::R32Uint,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self {
            device: device.clone(),
            queue: queue.clone(),
            pipeline,
            layout,
            target: None,
        }
    }

    /// The triangles that cover at least one pixel of `camera`'s target after the depth test.
    ///
    /// # Errors
    /// An invalid camera or scene, a target larger than the device allows or a vertex buffer
    /// larger than its maximum ([`OcclusionError::GpuLimit`]), read-back failures.
    pub fn visible_triangles(
        &mut self,
        scene: &Scene,
        camera: &Camera,
    ) -> Result<TriangleSet, OcclusionError> {
        let total = scene.triangle_count();
        let Some((prepared, clip_from_centred)) = prepare(scene, camera)? else {
            return Ok(TriangleSet::empty(total));
        };
        let limits = self.device.limits();
        let max_side = limits.max_texture_dimension_2d;
        for (what, value) in [
            ("camera width", camera.width),
            ("camera height", camera.height),
        ] {
            if value > max_side {
                return Err(OcclusionError::GpuLimit {
                    what,
                    value: value.into(),
                    maximum: max_side.into(),
                });
            }
        }
        let expanded: Vec<Vec3> = prepared
            .triangles
            .iter()
            .flat_map(|t| t.map(|i| prepared.positions[i as usize]))
            .collect();
        let vertex_bytes = (expanded.len() * 12) as u64;
        if vertex_bytes > limits.max_buffer_size {
            return Err(OcclusionError::GpuLimit {
                what: "triangle-id vertex buffer bytes",
                value: vertex_bytes,
                maximum: limits.max_buffer_size,
            });
        }
        let target = id_target(&self.device, &mut self.target, camera.width, camera.height);
        let device = &self.device;
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangle id vertices"),
            contents: bytemuck::cast_slice(&expanded),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("triangle id camera"),
            contents: bytemuck::cast_slice(&clip_from_centred.to_cols_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("triangle ids"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform.as_entire_binding(),
            }],
        });
        let id_view = target.ids.create_view(&Default::default());
        let depth_view = target.depth.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("triangle ids"),
        });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("triangle ids"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &id_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.draw(0..expanded.len() as u32, 0..1);
        }
        encoder.copy_texture_to_buffer(
            wgpu::TexelCopyTextureInfo {
                texture: &target.ids,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            wgpu::TexelCopyBufferInfo {
                buffer: &target.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(target.padded_row_bytes),
                    rows_per_image: Some(target.height),
                },
            },
            wgpu::Extent3d {
                width: target.width,
                height: target.height,
                depth_or_array_layers: 1,
            },
        );
        self.queue.submit([encoder.finish()]);
        let size = u64::from(target.padded_row_bytes) * u64::from(target.height);
        let bytes = gpu_context::read_buffer(device, &self.queue, &target.readback, size)
            .map_err(|e| OcclusionError::Readback(e.to_string()))?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut set = TriangleSet::empty(total);
        let row_words = (target.padded_row_bytes / 4) as usize;
        for row in words.chunks_exact(row_words) {
            for &id in &row[..target.width as usize] {
                if id != 0 && (id as usize) <= total {
                    set.insert(id as usize - 1);
                }
            }
        }
        Ok(set)
    }
}

/// The id target of this size, (re)allocated when the size changed.
fn id_target<'a>(
    device: &wgpu::Device,
    slot: &'a mut Option<IdTarget>,
    width: u32,
    height: u32,
) -> &'a IdTarget {
    if slot
        .as_ref()
        .is_some_and(|t| t.width != width || t.height != height)
    {
        *slot = None;
    }
    slot.get_or_insert_with(|| {
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, usage| {
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
        let ids = texture(
            "triangle ids",
            wgpu::TextureFormat::R32Uint,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = texture(
            "triangle id depth",
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let padded_row_bytes = (width * 4).div_ceil(align) * align;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("triangle id copy"),
            size: u64::from(padded_row_bytes) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        IdTarget {
            width,
            height,
            ids,
            depth,
            readback,
            padded_row_bytes,
        }
    })
}
