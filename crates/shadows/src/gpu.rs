//! The stencil pipeline: z-fail shadow volumes counted in a depth-stencil buffer, and the
//! ground mask seen by an orthographic camera from above (the `cloth-vis shadows` command).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{GpuContext, RenderPipelineDesc, pipeline};
use wgpu::util::DeviceExt;

use crate::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams, VolumeStats};
use crate::{GroundGrid, Light, ShadowError, ground_extrusion};

/// WGSL of the stencil passes (after the render crate's `view.wgsl`).
pub const SHADOWS_SHADER: &str = include_str!("shadows.wgsl");

const MASK_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Unorm;

/// How the stencil counts volume faces along a pixel's ray.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Counting {
    /// Carmack's reverse (Bilodeau & Songy 1999): count the faces *behind* the surface —
    /// back faces +1, front faces −1 on depth fail. Right wherever the eye is, as long as the
    /// volumes are closed and nothing clips their far side (caps at infinity in a
    /// reversed-infinite frame).
    #[default]
    ZFail,
    /// Heidmann 1991: count the faces *in front of* the surface — front faces +1, back faces
    /// −1 on depth pass. Needs no back caps but is wrong when the eye is inside a volume or the
    /// near plane cuts one (thesis T 3231–3236); kept to show exactly that.
    ZPass,
}

/// Depth-stencil state of a volume draw: depth tested, never written; the stencil counts
/// faces by `counting` (wrapping), so a surface point ends at the number of volumes containing
/// it. Volumes are pushed back by a constant bias of a few units of depth precision: a cap
/// lying on the surface it came from, or a caster face coplanar with a receiver, then counts as
/// behind it, and that surface is lit. (A slope-scaled bias would push the steep side quads of
/// a slanted volume behind receivers they pass in front of.)
pub fn volume_stencil_state(
    format: wgpu::TextureFormat,
    compare: wgpu::CompareFunction,
    counting: Counting,
) -> wgpu::DepthStencilState {
    use wgpu::StencilOperation::{DecrementWrap, IncrementWrap, Keep};
    let face = |on_pass, on_fail| wgpu::StencilFaceState {
        compare: wgpu::CompareFunction::Always,
        fail_op: Keep,
        depth_fail_op: on_fail,
        pass_op: on_pass,
    };
    let (front, back) = match counting {
        Counting::ZFail => (face(Keep, DecrementWrap), face(Keep, IncrementWrap)),
        Counting::ZPass => (face(IncrementWrap, Keep), face(DecrementWrap, Keep)),
    };
    let away = if compare == wgpu::CompareFunction::Greater {
        -1
    } else {
        1
    };
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(false),
        depth_compare: Some(compare),
        stencil: wgpu::StencilState {
            front,
            back,
            read_mask: 0xff,
            write_mask: 0xff,
        },
        bias: wgpu::DepthBiasState {
            constant: away * 8,
            slope_scale: 0.0,
            clamp: 0.0,
        },
    }
}

/// Depth-stencil state of a pass drawn only where the stencil `compare`s against the
/// reference (set with `set_stencil_reference`), depth untouched.
pub fn stencil_test_state(
    format: wgpu::TextureFormat,
    depth_compare: wgpu::CompareFunction,
    compare: wgpu::CompareFunction,
) -> wgpu::DepthStencilState {
    let face = wgpu::StencilFaceState {
        compare,
        fail_op: wgpu::StencilOperation::Keep,
        depth_fail_op: wgpu::StencilOperation::Keep,
        pass_op: wgpu::StencilOperation::Keep,
    };
    wgpu::DepthStencilState {
        format,
        depth_write_enabled: Some(false),
        depth_compare: Some(depth_compare),
        stencil: wgpu::StencilState {
            front: face,
            back: face,
            read_mask: 0xff,
            write_mask: 0,
        },
        bias: wgpu::DepthBiasState::default(),
    }
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ViewUniform {
    clip_from_world: [[f32; 4]; 4],
    world_from_clip: [[f32; 4]; 4],
    eye: [f32; 4],
    viewport: [f32; 4],
}

/// The ground-mask renderer: pipelines built once, a mask per call.
#[derive(Debug)]
pub struct MaskRenderer {
    depth_format: wgpu::TextureFormat,
    view_layout: wgpu::BindGroupLayout,
    ground: wgpu::RenderPipeline,
    volume: wgpu::RenderPipeline,
    mark: wgpu::RenderPipeline,
}

impl MaskRenderer {
    /// Build the three pipelines (ground depth, volume stencil, mark) for `device`.
    pub fn new(device: &wgpu::Device) -> Self {
        let depth_format = if device
            .features()
            .contains(wgpu::Features::DEPTH32FLOAT_STENCIL8)
        {
            wgpu::TextureFormat::Depth32FloatStencil8
        } else {
            wgpu::TextureFormat::Depth24PlusStencil8
        };
        let view_layout = bind_group_layout(
            device,
            "shadow mask view",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[binding::uniform()],
        );
        let source = format!("{}\n{}", render::VIEW_SHADER, SHADOWS_SHADER);
        let module = pipeline::shader_module(device, "shadows.wgsl", &source);
        let layout = pipeline::pipeline_layout(device, "shadow mask", &[&view_layout]);
        let target = |write_mask| wgpu::ColorTargetState {
            format: MASK_FORMAT,
            blend: None,
            write_mask,
        };
        let less = wgpu::CompareFunction::Less;
        let desc = |label, vertex, fragment, buffers, write, depth_stencil| RenderPipelineDesc {
            label,
            layout: &layout,
            module: &module,
            vertex,
            fragment: Some(fragment),
            buffers,
            color: Some(target(write)),
            depth_stencil: Some(depth_stencil),
            samples: 1,
            cull_mode: None,
        };
        let ground = desc(
            "shadow mask ground",
            "vs_receiver",
            "fs_none",
            &[wgpu::VertexBufferLayout {
                array_stride: 12,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3],
            }],
            wgpu::ColorWrites::empty(),
            wgpu::DepthStencilState {
                format: depth_format,
                depth_write_enabled: Some(true),
                depth_compare: Some(less),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            },
        )
        .build(device);
        let volume = desc(
            "shadow volume (z-fail)",
            "vs_volume",
            "fs_none",
            &[wgpu::VertexBufferLayout {
                array_stride: 16,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x4],
            }],
            wgpu::ColorWrites::empty(),
            volume_stencil_state(depth_format, less, Counting::ZFail),
        )
        .build(device);
        let mark = desc(
            "shadow mask mark",
            "vs_fullscreen",
            "fs_mark",
            &[],
            wgpu::ColorWrites::ALL,
            stencil_test_state(
                depth_format,
                wgpu::CompareFunction::Always,
                wgpu::CompareFunction::NotEqual,
            ),
        )
        .build(device);
        Self {
            depth_format,
            view_layout,
            ground,
            volume,
            mark,
        }
    }

    /// The stencil mask of `grid` under `volume` (built with `origin` = the grid's centre and
    /// a finite extrusion), row-major, 1 = shadowed.
    ///
    /// # Errors
    /// [`ShadowError::Gpu`] when the grid exceeds the device's texture size or read-back fails.
    pub fn render(
        &self,
        gpu: &GpuContext,
        volume: &ShadowVolume,
        grid: &GroundGrid,
    ) -> Result<Vec<f32>, ShadowError> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let n = u32::try_from(grid.n).unwrap_or(u32::MAX);
        let maximum = device.limits().max_texture_dimension_2d;
        if n > maximum {
            return Err(gpu_context::GpuError::SizeOutOfRange {
                what: "shadow mask grid",
                value: n,
                maximum,
            }
            .into());
        }
        let [x0, z0, x1, z1] = grid.extent;
        let (hx, hz) = (((x1 - x0) / 2.0) as f32, ((z1 - z0) / 2.0) as f32);
        let ground: [[f32; 3]; 6] = {
            let c = [
                [-hx, 0.0, -hz],
                [hx, 0.0, -hz],
                [hx, 0.0, hz],
                [-hx, 0.0, hz],
            ];
            [c[0], c[2], c[1], c[0], c[3], c[2]]
        };
        // Depth spans everything drawn, so nothing meets a clipping plane.
        let (mut lo, mut hi) = (0.0f32, 0.0f32);
        for v in volume.vertices() {
            lo = lo.min(v[1]);
            hi = hi.max(v[1]);
        }
        // Relative to the grid, not absolute: a floor of 1e-6 units flattened a caster 10⁻²¹
        // across into one depth value.
        let margin = (hi - lo).max(1e-6 * hx.max(hz)) * 0.01;
        let (top, bottom) = (hi + margin, lo - margin);
        // x → columns, z → rows (row 0 at z0, the top of the image), height → depth 0 at `top`.
        let clip_from_world = Mat4::from_cols_array(&[
            1.0 / hx,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            -1.0 / (top - bottom),
            0.0,
            0.0,
            -1.0 / hz,
            0.0,
            0.0,
            0.0,
            0.0,
            top / (top - bottom),
            1.0,
        ]);
        let uniform = ViewUniform {
            clip_from_world: clip_from_world.to_cols_array_2d(),
            world_from_clip: clip_from_world.inverse().to_cols_array_2d(),
            eye: [0.0, top, 0.0, 1.0],
            viewport: [n as f32, n as f32, 1.0, 0.0],
        };
        let view_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow mask view"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let view_group = bind_group(
            device,
            "shadow mask view",
            &self.view_layout,
            &[view_buffer.as_entire_binding()],
        );
        let ground_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shadow mask ground"),
            contents: bytemuck::cast_slice(&ground),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let volume_buffer = (!volume.vertices().is_empty()).then(|| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("shadow volume"),
                contents: bytemuck::cast_slice(volume.vertices()),
                usage: wgpu::BufferUsages::VERTEX,
            })
        });
        let size = wgpu::Extent3d {
            width: n,
            height: n,
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
        let color = texture(
            "shadow mask",
            MASK_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let depth = texture(
            "shadow mask depth",
            self.depth_format,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let color_view = color.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("shadow mask"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &color_view,
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
                    stencil_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0),
                        store: wgpu::StoreOp::Discard,
                    }),
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_bind_group(0, &view_group, &[]);
            pass.set_pipeline(&self.ground);
            pass.set_vertex_buffer(0, ground_buffer.slice(..));
            pass.draw(0..6, 0..1);
            if let Some(buffer) = &volume_buffer {
                pass.set_pipeline(&self.volume);
                pass.set_vertex_buffer(0, buffer.slice(..));
                pass.draw(0..volume.vertices().len() as u32, 0..1);
            }
            pass.set_pipeline(&self.mark);
            pass.set_stencil_reference(0);
            pass.draw(0..3, 0..1);
        }
        queue.submit([encoder.finish()]);
        let bytes = gpu_context::read_texture(device, queue, &color, 1, wgpu::TextureAspect::All)?;
        Ok(bytes
            .iter()
            .map(|&b| f32::from(u8::from(b > 127)))
            .collect())
    }
}

/// The stencil mask of a caster over `grid` in one call: topology, volume (finite extrusion,
/// relative to the grid's centre), pipelines, draw, read-back.
///
/// # Errors
/// As [`CasterTopology::new`], [`ShadowVolume::build`] and [`MaskRenderer::render`].
pub fn stencil_ground_mask(
    gpu: &GpuContext,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    sides: Sides,
    grid: &GroundGrid,
) -> Result<(Vec<f32>, VolumeStats), ShadowError> {
    let topology = CasterTopology::new(positions.len(), triangles)?;
    let mut volume = ShadowVolume::new();
    let params = VolumeParams {
        sides,
        extrusion: Extrusion::Finite(ground_extrusion(positions, grid)),
        origin: grid.centre(),
        ..Default::default()
    };
    let stats = volume.build(&topology, positions, light, &params)?;
    let mask = MaskRenderer::new(&gpu.device).render(gpu, &volume, grid)?;
    Ok((mask, stats))
}
