//! The wgpu renderer: Gouraud-interpolated per-vertex radiance over an environment backdrop,
//! headless into an HDR offscreen target (`shaders/mesh.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat, Vec3};
use gpu_context::{COLOR_FORMAT, DEPTH_FORMAT, GpuError, HdrImage, OffscreenTarget};
use wgpu::util::DeviceExt;

use crate::camera::Camera;

/// WGSL source of the renderer.
pub const MESH_SHADER: &str = include_str!("../../../shaders/mesh.wgsl");

/// Largest backdrop width uploaded; larger maps are box-downsampled (the backdrop is for looks;
/// lighting always uses the full map).
const MAX_BACKDROP_WIDTH: usize = 2048;

/// One object ready to draw: world-space positions, triangles and per-vertex linear radiance for
/// the front and back faces (front = counter-clockwise winding).
#[derive(Clone, Debug)]
pub struct DrawMesh<'a> {
    /// World-space positions.
    pub positions: &'a [Vec3],
    /// Triangles (indices into `positions`).
    pub triangles: &'a [[u32; 3]],
    /// Radiance seen on front faces.
    pub front: &'a [Vec3],
    /// Radiance seen on back faces.
    pub back: &'a [Vec3],
}

/// The environment drawn behind the objects.
#[derive(Clone, Copy, Debug)]
pub struct Backdrop<'a> {
    /// Lat-long width.
    pub width: usize,
    /// Lat-long height.
    pub height: usize,
    /// Linear texels, row-major.
    pub texels: &'a [[f32; 3]],
    /// Rotation of the environment relative to the world.
    pub world_from_env: Quat,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FrameUniform {
    clip_from_world: [[f32; 4]; 4],
    world_from_clip: [[f32; 4]; 4],
    env_from_world: [[f32; 4]; 4],
    eye: [f32; 4],
    env_size: [u32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Vertex {
    position: [f32; 3],
    front: [f32; 3],
    back: [f32; 3],
}

/// Render `meshes` seen by `camera` over `backdrop` (black when `None`).
///
/// # Errors
/// [`GpuError`] when the target cannot be created or read back.
pub fn render(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    camera: &Camera,
    meshes: &[DrawMesh<'_>],
    backdrop: Option<Backdrop<'_>>,
) -> Result<HdrImage, GpuError> {
    let target = OffscreenTarget::new(device, camera.width, camera.height)?;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("mesh.wgsl"),
        source: wgpu::ShaderSource::Wgsl(MESH_SHADER.into()),
    });

    let (env_width, env_height, env_texels) = match backdrop {
        Some(b) => {
            let (w, h, t) = downsample_for_backdrop(b.width, b.height, b.texels);
            (w, h, t)
        }
        None => (1, 1, vec![[0.0; 4]]),
    };
    let env_from_world = backdrop.map_or(Mat4::IDENTITY, |b| {
        Mat4::from_quat(b.world_from_env.inverse())
    });
    let uniform = FrameUniform {
        clip_from_world: camera.clip_from_world.to_cols_array_2d(),
        world_from_clip: camera.clip_from_world.inverse().to_cols_array_2d(),
        env_from_world: env_from_world.to_cols_array_2d(),
        eye: camera.eye.extend(1.0).to_array(),
        env_size: [
            env_width as u32,
            env_height as u32,
            u32::from(backdrop.is_some()),
            0,
        ],
    };
    let uniform_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("frame uniform"),
        contents: bytemuck::bytes_of(&uniform),
        usage: wgpu::BufferUsages::UNIFORM,
    });
    let env_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("environment texels"),
        contents: bytemuck::cast_slice(&env_texels),
        usage: wgpu::BufferUsages::STORAGE,
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("frame"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("frame"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: uniform_buffer.as_entire_binding(),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: env_buffer.as_entire_binding(),
            },
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("mesh"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let color_target = [Some(wgpu::ColorTargetState {
        format: COLOR_FORMAT,
        blend: None,
        write_mask: wgpu::ColorWrites::ALL,
    })];
    let depth_state = |write: bool, compare| wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(write),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState::default(),
        bias: wgpu::DepthBiasState::default(),
    };
    let pipeline = |label, vs, fs, buffers: &[Option<wgpu::VertexBufferLayout<'_>>], depth| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(vs),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(depth),
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &color_target,
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let vertex_layout = [Some(wgpu::VertexBufferLayout {
        array_stride: std::mem::size_of::<Vertex>() as u64,
        step_mode: wgpu::VertexStepMode::Vertex,
        attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3],
    })];
    let background = pipeline(
        "background",
        "vs_background",
        "fs_background",
        &[],
        depth_state(false, wgpu::CompareFunction::Always),
    );
    let mesh_pipeline = pipeline(
        "mesh",
        "vs_mesh",
        "fs_mesh",
        &vertex_layout,
        depth_state(true, wgpu::CompareFunction::Less),
    );

    let buffers: Vec<(wgpu::Buffer, wgpu::Buffer, u32)> = meshes
        .iter()
        .filter(|m| !m.triangles.is_empty())
        .map(|m| {
            let vertices: Vec<Vertex> = (0..m.positions.len())
                .map(|i| Vertex {
                    position: m.positions[i].to_array(),
                    front: m.front[i].to_array(),
                    back: m.back[i].to_array(),
                })
                .collect();
            let vb = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mesh vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            });
            let ib = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("mesh indices"),
                contents: bytemuck::cast_slice(m.triangles),
                usage: wgpu::BufferUsages::INDEX,
            });
            (vb, ib, (m.triangles.len() * 3) as u32)
        })
        .collect();

    let color_view = target.color_view();
    let depth_view = target.depth_view();
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("render"),
    });
    {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("scene"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &color_view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &depth_view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_bind_group(0, &bind_group, &[]);
        pass.set_pipeline(&background);
        pass.draw(0..3, 0..1);
        pass.set_pipeline(&mesh_pipeline);
        for (vb, ib, count) in &buffers {
            pass.set_vertex_buffer(0, vb.slice(..));
            pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..*count, 0, 0..1);
        }
    }
    queue.submit([encoder.finish()]);
    target.read_color(device, queue)
}

/// Box-downsample a lat-long map by powers of two until it is at most [`MAX_BACKDROP_WIDTH`]
/// wide, and pad texels to vec4 for the storage buffer.
fn downsample_for_backdrop(
    width: usize,
    height: usize,
    texels: &[[f32; 3]],
) -> (usize, usize, Vec<[f32; 4]>) {
    let mut factor = 1;
    while width / factor > MAX_BACKDROP_WIDTH && height / (factor * 2) >= 1 {
        factor *= 2;
    }
    let (w, h) = (width / factor, height / factor);
    let mut out = vec![[0.0f32; 4]; w * h];
    let norm = 1.0 / (factor * factor) as f32;
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
