//! Stencil shadows in the shared frame (render crate, [`Phase::DepthReading`]).
//!
//! The opaque passes have drawn every object with its ambient/environment radiance (Gouraud)
//! and left the depth. Then, per light, inside the frame's one render pass:
//!
//! 1. the stencil is reset to 0 by a full-screen triangle (`Replace`, depth `Always`);
//! 2. the light's volumes are drawn z-fail ([`crate::volume_stencil_state`]): behind the stored depth,
//!    back faces +1 and front faces −1, so a pixel ends at the number of volumes containing
//!    its surface point, whatever the eye's position — correct with the eye inside a volume
//!    and where the near plane cuts one (z-pass is wrong in both);
//! 3. the receivers are drawn again with depth `Equal` and stencil `Equal 0`, adding the
//!    light's direct term ρ/π · E · max(n·l, 0) · tex(u) (eq. 5.6's boundary texture when the
//!    light asks for it, on receivers that cast) — lit ⇔ stencil = 0, so the ambient and
//!    environment terms stay and only the light's own term is masked.
//!
//! Volumes are extruded to infinity (w = 0), so the frame must use
//! [`render::DepthConvention::ReversedInfinite`]: points at infinity land on depth 0, in
//! front of nothing, and no far plane clips a back cap.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};
use render::{DepthConvention, FramePass, PassContext, Phase};
use wgpu::util::DeviceExt;

use crate::Counting;
use crate::boundary::{BoundaryMode, BoundaryTexture, boundary_u};
use crate::volume::ShadowVolume;
use crate::{Light, ShadowError};

/// A receiver of direct light: the same positions and triangles the opaque pass drew, with
/// per-vertex normals and diffuse albedo ρ (linear RGB).
#[derive(Clone, Copy, Debug)]
pub struct Receiver<'a> {
    /// World-space positions (as drawn by the opaque pass).
    pub positions: &'a [Vec3],
    /// Vertex normals (front side; the back side uses the negation).
    pub normals: &'a [Vec3],
    /// Diffuse albedo per vertex.
    pub albedo: &'a [Vec3],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// Whether this surface also casts (its own volume's silhouette edges run along it): only
    /// such a receiver takes eq. 5.6's smooth boundary. One that casts nothing — a ground
    /// plane — has no zig-zag to hide, and the term would only black out wherever light grazes
    /// it at under α (a ground under a sun 12° up rendered without any shadow at α = 15°).
    pub casts: bool,
}

/// The smooth boundary of eq. 5.6 on a light's casting receivers ([`Receiver::casts`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothBoundary {
    /// Offset α in degrees (the thesis's 15°).
    pub alpha_deg: f64,
    /// Eq. 5.6 or the prose's angle-linear reading.
    pub mode: BoundaryMode,
}

/// One light of the frame: what it is, how bright, and the volume its casters throw (built
/// with [`crate::volume::Extrusion::Infinite`] and origin 0, this frame's positions).
#[derive(Clone, Copy, Debug)]
pub struct FrameLight<'a> {
    /// Position or direction.
    pub light: Light,
    /// Radiant intensity (point, W/sr) or irradiance at normal incidence (directional), RGB.
    pub intensity: Vec3,
    /// The volume of every caster for this light (several casters: build each and
    /// [`ShadowVolume::append`] them, or one volume of a merged caster).
    pub volume: &'a ShadowVolume,
    /// Eq. 5.6 on the receivers, or `None` for the bare stencil result.
    pub boundary: Option<SmoothBoundary>,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct LightUniform {
    position: [f32; 4],
    intensity: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct LitVertex {
    position: [f32; 3],
    normal: [f32; 3],
    albedo: [f32; 3],
}

#[derive(Debug)]
struct GpuReceiver {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    casts: bool,
}

#[derive(Debug)]
struct GpuLight {
    uniform: wgpu::Buffer,
    group: wgpu::BindGroup,
    volume: Option<wgpu::Buffer>,
    volume_vertices: u32,
    /// Per receiver: eq. 5.6's (front, back) u per vertex.
    u: Vec<wgpu::Buffer>,
}

/// The stencil-shadow effect: pipelines built once, receivers and lights set per frame.
#[derive(Debug)]
pub struct StencilShadows {
    clear: wgpu::RenderPipeline,
    volume: wgpu::RenderPipeline,
    lit: wgpu::RenderPipeline,
    light_layout: wgpu::BindGroupLayout,
    boundary: wgpu::Buffer,
    receivers: Vec<GpuReceiver>,
    lights: Vec<GpuLight>,
}

impl StencilShadows {
    /// Build the pipelines against the frame, counting volumes by `counting` (z-fail unless
    /// demonstrating z-pass's failures), and upload `texture` as the boundary texture.
    ///
    /// # Errors
    /// [`ShadowError::Parameter`] when the frame's depth is not reversed-infinite or the
    /// device cannot blend `Rgba32Float` (the light's term is added).
    pub fn new(
        device: &wgpu::Device,
        ctx: &PassContext<'_>,
        texture: &BoundaryTexture,
        counting: Counting,
    ) -> Result<Self, ShadowError> {
        if ctx.format.depth != DepthConvention::ReversedInfinite {
            return Err(crate::error::bad_parameter(
                "frame depth",
                format!("{:?}", ctx.format.depth),
                "shadow volumes extruded to infinity need DepthConvention::ReversedInfinite",
            ));
        }
        if !device
            .features()
            .contains(wgpu::Features::FLOAT32_BLENDABLE)
        {
            return Err(crate::error::bad_parameter(
                "adapter",
                "no FLOAT32_BLENDABLE",
                "the light's term is blended into the Rgba32Float frame",
            ));
        }
        let fmt = ctx.format;
        let light_layout = bind_group_layout(
            device,
            "shadow light",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[binding::uniform(), binding::storage_read()],
        );
        let source = format!("{}\n{}", render::VIEW_SHADER, crate::SHADOWS_SHADER);
        let module = pipeline::shader_module(device, "shadows.wgsl", &source);
        let view_only = pipeline::pipeline_layout(device, "shadow volumes", &[ctx.view_layout]);
        let with_light =
            pipeline::pipeline_layout(device, "shadow light", &[ctx.view_layout, &light_layout]);
        let silent = wgpu::ColorTargetState {
            format: fmt.color,
            blend: None,
            write_mask: wgpu::ColorWrites::empty(),
        };
        let replace = wgpu::StencilFaceState {
            compare: wgpu::CompareFunction::Always,
            fail_op: wgpu::StencilOperation::Replace,
            depth_fail_op: wgpu::StencilOperation::Replace,
            pass_op: wgpu::StencilOperation::Replace,
        };
        let clear = RenderPipelineDesc {
            label: "shadow stencil clear",
            layout: &view_only,
            module: &module,
            vertex: "vs_fullscreen",
            fragment: Some("fs_none"),
            buffers: &[],
            color: Some(silent.clone()),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: fmt.depth_stencil,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: wgpu::StencilState {
                    front: replace,
                    back: replace,
                    read_mask: 0xff,
                    write_mask: 0xff,
                },
                bias: wgpu::DepthBiasState::default(),
            }),
            samples: fmt.samples,
            cull_mode: None,
        }
        .build(device);
        let volume = RenderPipelineDesc {
            label: "shadow volumes (z-fail)",
            layout: &view_only,
            module: &module,
            vertex: "vs_volume",
            fragment: Some("fs_none"),
            buffers: &[wgpu::VertexBufferLayout {
                array_stride: 16,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x4],
            }],
            color: Some(silent),
            depth_stencil: Some(crate::volume_stencil_state(
                fmt.depth_stencil,
                fmt.depth_compare(),
                counting,
            )),
            samples: fmt.samples,
            cull_mode: None,
        }
        .build(device);
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let keep_alpha = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        let lit = RenderPipelineDesc {
            label: "shadow light term",
            layout: &with_light,
            module: &module,
            vertex: "vs_lit",
            fragment: Some("fs_lit"),
            buffers: &[
                wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<LitVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3],
                },
                wgpu::VertexBufferLayout {
                    array_stride: 8,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![3 => Float32x2],
                },
            ],
            color: Some(wgpu::ColorTargetState {
                format: fmt.color,
                blend: Some(wgpu::BlendState {
                    color: add,
                    alpha: keep_alpha,
                }),
                write_mask: wgpu::ColorWrites::ALL,
            }),
            depth_stencil: Some(crate::stencil_test_state(
                fmt.depth_stencil,
                wgpu::CompareFunction::Equal,
                wgpu::CompareFunction::Equal,
            )),
            samples: fmt.samples,
            cull_mode: None,
        }
        .build(device);
        let boundary = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow boundary texture"),
            contents: bytemuck::cast_slice(texture.texels()),
            usage: wgpu::BufferUsages::STORAGE,
        });
        Ok(Self {
            clear,
            volume,
            lit,
            light_layout,
            boundary,
            receivers: Vec::new(),
            lights: Vec::new(),
        })
    }

    /// Set the receivers of direct light (replacing the previous ones).
    ///
    /// # Errors
    /// [`ShadowError::Mesh`] when a receiver's slices differ in length or a triangle names a
    /// missing vertex.
    pub fn set_receivers(
        &mut self,
        device: &wgpu::Device,
        receivers: &[Receiver<'_>],
    ) -> Result<(), ShadowError> {
        self.receivers.clear();
        for (r, m) in receivers.iter().enumerate() {
            let n = m.positions.len();
            if m.normals.len() != n || m.albedo.len() != n {
                return Err(ShadowError::Mesh(format!(
                    "receiver {r}: {n} positions, {} normals, {} albedos",
                    m.normals.len(),
                    m.albedo.len()
                )));
            }
            if let Some(t) = m
                .triangles
                .iter()
                .find(|t| t.iter().any(|&v| v as usize >= n))
            {
                return Err(ShadowError::Mesh(format!(
                    "receiver {r}: triangle {t:?} names a vertex ≥ {n}"
                )));
            }
            let vertices: Vec<LitVertex> = (0..n)
                .map(|i| LitVertex {
                    position: m.positions[i].to_array(),
                    normal: m.normals[i].to_array(),
                    albedo: m.albedo[i].to_array(),
                })
                .collect();
            self.receivers.push(GpuReceiver {
                vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("shadow receiver"),
                    contents: bytemuck::cast_slice(&vertices),
                    usage: wgpu::BufferUsages::VERTEX,
                }),
                indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("shadow receiver indices"),
                    contents: bytemuck::cast_slice(m.triangles),
                    usage: wgpu::BufferUsages::INDEX,
                }),
                index_count: u32::try_from(m.triangles.len() * 3)
                    .map_err(|_| ShadowError::Mesh(format!("receiver {r}: too many triangles")))?,
                positions: m.positions.to_vec(),
                normals: m.normals.to_vec(),
                casts: m.casts,
            });
        }
        // Per-light u buffers follow the receivers.
        self.lights.clear();
        Ok(())
    }

    /// Set this frame's lights and their volumes. Buffers of an unchanged light count are
    /// rewritten in place; a volume larger than any before grows its buffer.
    ///
    /// # Errors
    /// [`ShadowError::Light`] for an invalid light; [`ShadowError::Parameter`] for α out of
    /// [0°, 90°).
    pub fn set_lights(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        lights: &[FrameLight<'_>],
    ) -> Result<(), ShadowError> {
        if self.lights.len() != lights.len() {
            self.lights.clear();
        }
        for (k, l) in lights.iter().enumerate() {
            let light = l.light.validated()?;
            let position = match light {
                Light::Point(p) => p.as_vec3().extend(1.0),
                Light::Directional(d) => d.as_vec3().extend(0.0),
            };
            let uniform = LightUniform {
                position: position.to_array(),
                intensity: l
                    .intensity
                    .extend(f32::from(u8::from(l.boundary.is_some())))
                    .to_array(),
            };
            if self.lights.len() <= k {
                let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("shadow light"),
                    contents: bytemuck::bytes_of(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                });
                let group = bind_group(
                    device,
                    "shadow light",
                    &self.light_layout,
                    &[
                        buffer.as_entire_binding(),
                        self.boundary.as_entire_binding(),
                    ],
                );
                let u = self
                    .receivers
                    .iter()
                    .map(|r| {
                        device.create_buffer(&wgpu::BufferDescriptor {
                            label: Some("shadow boundary u"),
                            size: (r.positions.len().max(1) * 8) as u64,
                            usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                            mapped_at_creation: false,
                        })
                    })
                    .collect();
                self.lights.push(GpuLight {
                    uniform: buffer,
                    group,
                    volume: None,
                    volume_vertices: 0,
                    u,
                });
            }
            let gpu = &mut self.lights[k];
            queue.write_buffer(&gpu.uniform, 0, bytemuck::bytes_of(&uniform));
            let vertices = l.volume.vertices();
            let bytes = std::mem::size_of_val(vertices) as u64;
            if gpu.volume.as_ref().is_none_or(|b| b.size() < bytes) {
                gpu.volume = (bytes > 0).then(|| {
                    device.create_buffer(&wgpu::BufferDescriptor {
                        label: Some("shadow volume"),
                        size: bytes.next_power_of_two(),
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                        mapped_at_creation: false,
                    })
                });
            }
            if let Some(buffer) = &gpu.volume {
                queue.write_buffer(buffer, 0, bytemuck::cast_slice(vertices));
            }
            gpu.volume_vertices = u32::try_from(vertices.len()).unwrap_or(u32::MAX);
            for (r, buffer) in self.receivers.iter().zip(&gpu.u) {
                let mut pairs: Vec<[f32; 2]> = vec![[1.0, 1.0]; r.positions.len()];
                // Eq. 5.6 per vertex for the front side and the back side (normal negated), on
                // a surface that casts.
                if let Some(b) = l.boundary {
                    crate::boundary::check_alpha(b.alpha_deg)?;
                    let alpha = b.alpha_deg.to_radians();
                    let vertices = r.positions.iter().zip(&r.normals);
                    for (pair, (p, n)) in pairs.iter_mut().zip(vertices).filter(|_| r.casts) {
                        let (n, l) = (n.as_dvec3(), light.to_light(p.as_dvec3()));
                        *pair = [
                            boundary_u(n, l, alpha, b.mode) as f32,
                            boundary_u(-n, l, alpha, b.mode) as f32,
                        ];
                    }
                }
                queue.write_buffer(buffer, 0, bytemuck::cast_slice(&pairs));
            }
        }
        Ok(())
    }
}

impl FramePass for StencilShadows {
    fn phase(&self) -> Phase {
        Phase::DepthReading
    }

    fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        for light in &self.lights {
            pass.set_stencil_reference(0);
            pass.set_pipeline(&self.clear);
            pass.draw(0..3, 0..1);
            if let Some(volume) = &light.volume
                && light.volume_vertices > 0
            {
                pass.set_pipeline(&self.volume);
                pass.set_vertex_buffer(0, volume.slice(..));
                pass.draw(0..light.volume_vertices, 0..1);
            }
            pass.set_pipeline(&self.lit);
            pass.set_bind_group(1, &light.group, &[]);
            for (r, u) in self.receivers.iter().zip(&light.u) {
                pass.set_vertex_buffer(0, r.vertices.slice(..));
                pass.set_vertex_buffer(1, u.slice(..));
                pass.set_index_buffer(r.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..r.index_count, 0, 0..1);
            }
        }
    }
}
