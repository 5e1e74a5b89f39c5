//! The Gouraud pass: per-vertex linear radiance, interpolated, two-sided (front faces are
//! counter-clockwise). Meshes stay on the GPU between frames; an animation frame rewrites
//! their vertex buffers in place.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use gpu_context::{RenderPipelineDesc, pipeline};
use wgpu::util::DeviceExt;

use crate::RenderError;
use crate::frame::PassContext;

/// WGSL of the pass (after `view.wgsl`).
pub const GOURAUD_SHADER: &str = include_str!("gouraud.wgsl");

/// One object to draw: world-space positions, triangles and per-vertex linear radiance for the
/// front and back faces.
#[derive(Clone, Copy, Debug)]
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

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Vertex {
    position: [f32; 3],
    front: [f32; 3],
    back: [f32; 3],
}

#[derive(Debug)]
struct GpuMesh {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    vertex_count: usize,
    triangles: Vec<[u32; 3]>,
}

/// The Gouraud pass and the meshes it draws.
#[derive(Debug)]
pub struct GouraudPass {
    pipeline: wgpu::RenderPipeline,
    meshes: Vec<Option<GpuMesh>>,
    uploads: u64,
}

impl GouraudPass {
    pub(crate) fn new(device: &wgpu::Device, ctx: &PassContext<'_>) -> Self {
        let source = format!("{}\n{}", crate::VIEW_SHADER, GOURAUD_SHADER);
        let module = pipeline::shader_module(device, "gouraud.wgsl", &source);
        let layout = pipeline::pipeline_layout(device, "gouraud", &[ctx.view_layout]);
        let pipeline = RenderPipelineDesc {
            label: "gouraud",
            layout: &layout,
            module: &module,
            vertex: "vs_mesh",
            fragment: Some("fs_mesh"),
            buffers: &[wgpu::VertexBufferLayout {
                array_stride: std::mem::size_of::<Vertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3],
            }],
            color: Some(ctx.format.color_target()),
            depth_stencil: Some(ctx.format.opaque_depth()),
            samples: ctx.format.samples,
            cull_mode: None,
        }
        .build(device);
        Self {
            pipeline,
            meshes: Vec::new(),
            uploads: 0,
        }
    }

    /// Set the meshes drawn by the next frames: mesh `i` replaces slot `i`. A slot whose
    /// vertex count and triangles are unchanged is rewritten in place (one `write_buffer`, no
    /// allocation on the GPU); others get new buffers. Slots beyond `meshes.len()` are dropped.
    ///
    /// # Errors
    /// [`RenderError::Mesh`] when a mesh's slices differ in length or a triangle names a
    /// vertex that does not exist.
    pub fn set_meshes(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        meshes: &[DrawMesh<'_>],
    ) -> Result<(), RenderError> {
        for (i, m) in meshes.iter().enumerate() {
            validate(i, m)?;
        }
        self.meshes.resize_with(meshes.len(), || None);
        for (slot, m) in self.meshes.iter_mut().zip(meshes) {
            let vertices: Vec<Vertex> = (0..m.positions.len())
                .map(|i| Vertex {
                    position: m.positions[i].to_array(),
                    front: m.front[i].to_array(),
                    back: m.back[i].to_array(),
                })
                .collect();
            if m.triangles.is_empty() {
                *slot = None;
                continue;
            }
            match slot {
                Some(g) if g.vertex_count == vertices.len() && g.triangles == m.triangles => {
                    queue.write_buffer(&g.vertices, 0, bytemuck::cast_slice(&vertices));
                }
                _ => {
                    self.uploads += 1;
                    *slot = Some(GpuMesh {
                        vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("gouraud vertices"),
                            contents: bytemuck::cast_slice(&vertices),
                            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                        }),
                        indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                            label: Some("gouraud indices"),
                            contents: bytemuck::cast_slice(m.triangles),
                            usage: wgpu::BufferUsages::INDEX,
                        }),
                        vertex_count: vertices.len(),
                        triangles: m.triangles.to_vec(),
                    });
                }
            }
        }
        Ok(())
    }

    /// How many times a mesh was (re)allocated on the GPU rather than rewritten in place.
    pub fn allocations(&self) -> u64 {
        self.uploads
    }

    pub(crate) fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_pipeline(&self.pipeline);
        for m in self.meshes.iter().flatten() {
            pass.set_vertex_buffer(0, m.vertices.slice(..));
            pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
            // ≤ u32::MAX: `validate` bounds indices by u32 and wgpu bounds buffer sizes.
            pass.draw_indexed(0..(m.triangles.len() * 3) as u32, 0, 0..1);
        }
    }
}

fn validate(index: usize, m: &DrawMesh<'_>) -> Result<(), RenderError> {
    let n = m.positions.len();
    if m.front.len() != n || m.back.len() != n {
        return Err(RenderError::Mesh {
            index,
            reason: format!(
                "{n} positions but {} front and {} back radiances",
                m.front.len(),
                m.back.len()
            ),
        });
    }
    if let Some((t, tri)) = m
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(RenderError::Mesh {
            index,
            reason: format!("triangle {t} = {tri:?} names a vertex ≥ {n}"),
        });
    }
    Ok(())
}
