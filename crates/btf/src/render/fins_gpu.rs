//! Fins in the shared frame (thesis §5.7.3, Fig. 5.22): the compressed fin BTF uploaded once,
//! each frame's fins drawn in two passes ([`Phase::Blended`], after the opaque surface and the
//! backdrop, depth tested against them and never written).
//!
//! # Two passes, independent of the order
//! Fig. 5.22 draws all fins with blending (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) and depth writes
//! off, then all fins again with depth writes on, so that without sorting the nearest fins end
//! on top. Both passes of that reading depend on the order the fins arrive in wherever fins
//! overlap ("over" is not commutative, and in pass 2 the first fin drawn at a pixel decides
//! which others pass the depth test), and pass 2 blends every nearest fin a second time. Here
//! the two passes split the "over" operator into its two commutative halves:
//!
//! 1. **absorb**: dst.rgb ← (1 − α) · dst.rgb, dst.α ← α + (1 − α) · dst.α — every fin
//!    attenuates what lies behind it (the surface, the backdrop, the background);
//! 2. **emit**: dst.rgb ← dst.rgb + c — every fin adds its premultiplied colour.
//!
//! A single fin over a background gives exactly c + (1 − α) · dst, the premultiplied "over";
//! n overlapping fins give Π(1 − α_i) · dst + Σ c_i in any order, up to float rounding
//! (tested with shuffled fins). The price: fins do not hide each other — where two overlap,
//! the nearer one's (1 − α) does not dim the farther one's colour, an error of α_near · c_far,
//! second order in the fibres' coverage — except where many fins pile up on one spot: a
//! silhouette that zig-zags across the fan of a UV sphere's pole stacks dozens of short fins,
//! and their summed light shows as a bright spot that "over" would have capped at one fin's
//! colour (`cargo xtask repro fins`, Fig. 5.23). The colour is treated as premultiplied (the images
//! are fibres over black, so coverage is already in them) rather than multiplied by alpha a
//! second time as SRC_ALPHA does. Fins test depth against the opaque surface, so the mesh
//! hides the fins behind it.

use ::render::{FramePass, PassContext, Phase};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use gpu_context::layout::{bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline};
use wgpu::util::DeviceExt;

use super::fin_shade::{FinShading, fin_gammas};
use super::gpu::{buffer, check_buffer, storage_init};
use super::mesh::Light;
use crate::error::Result;
use crate::fin_pca::FinPca;
use crate::fins::FinMesh;

const SHADER: &str = include_str!("fins.wgsl");

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FinUniform {
    radiance: [f32; 4],
    dims: [u32; 4],
    params: [f32; 4],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct FinVertex {
    position: [f32; 3],
    end_weight: f32,
    st: [f32; 2],
    _pad: [f32; 2],
}

/// A compressed fin BTF resident on the GPU, drawing each frame's fins into the shared frame.
///
/// ```no_run
/// # fn demo(gpu: &gpu_context::GpuContext, renderer: &mut render::Renderer,
/// #     fins: &btf::fin_pca::FinPca, mesh: &btf::fins::FinMesh, positions: &[glam::Vec3],
/// #     normals: &[glam::Vec3], light: &btf::render::Light, camera: &render::Camera)
/// #     -> Result<(), Box<dyn std::error::Error>> {
/// use btf::render::{FinShading, GpuFinRenderer};
/// let fin_renderer = GpuFinRenderer::for_frame(&gpu.device, fins, &renderer.pass_context())?;
/// let draw = fin_renderer.prepare(mesh, positions, normals, light, camera.eye,
///     &FinShading::default())?;
/// let image = renderer.render(&gpu.device, &gpu.queue, camera,
///     render::Background::Transparent, &[&draw])?;
/// # Ok(()) }
/// ```
#[derive(Debug)]
pub struct GpuFinRenderer {
    device: wgpu::Device,
    fins: FinPca,
    images: wgpu::Buffer,
    layout: wgpu::BindGroupLayout,
    absorb: wgpu::RenderPipeline,
    emit: wgpu::RenderPipeline,
    gammas: std::sync::Mutex<Vec<f32>>,
}

/// One frame's fins, ready to record ([`Phase::Blended`]).
#[derive(Debug)]
pub struct FinDraw {
    absorb: wgpu::RenderPipeline,
    emit: wgpu::RenderPipeline,
    bind_group: wgpu::BindGroup,
    vertices: u32,
}

impl FinDraw {
    /// Fins in the draw.
    pub fn fins(&self) -> usize {
        self.vertices as usize / 6
    }
}

impl FramePass for FinDraw {
    fn phase(&self) -> Phase {
        Phase::Blended
    }

    fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        if self.vertices > 0 {
            pass.set_bind_group(1, &self.bind_group, &[]);
            pass.set_pipeline(&self.absorb);
            pass.draw(0..self.vertices, 0..1);
            pass.set_pipeline(&self.emit);
            pass.draw(0..self.vertices, 0..1);
        }
    }
}

impl GpuFinRenderer {
    /// Uploads the mean and eigen-images of `fins` (as f32) and builds both pipelines for
    /// the frame of `ctx`.
    ///
    /// # Errors
    /// [`crate::BtfError::GpuLimit`] when the images exceed the device's storage-buffer
    /// limit.
    pub fn for_frame(device: &wgpu::Device, fins: &FinPca, ctx: &PassContext<'_>) -> Result<Self> {
        let slot = fins.slot();
        let values = 3 * fins.width() * fins.height();
        check_buffer(
            device,
            "fin image bytes",
            ((slot.components() + 1) * values * 4) as u64,
        )?;
        let mut data = Vec::with_capacity((slot.components() + 1) * values);
        for k in 0..=slot.components() {
            data.extend(slot.texture(k).dequantize());
        }
        let images = storage_init(device, "fin images", bytemuck::cast_slice(&data));
        let (layout, absorb, emit) = make_pipelines(device, ctx);
        Ok(Self {
            device: device.clone(),
            fins: fins.clone(),
            images,
            layout,
            absorb,
            emit,
            gammas: std::sync::Mutex::new(Vec::new()),
        })
    }

    /// Lights the fins of one frame (γ at both ends of every fin, [`fin_gammas`]) for `light`
    /// seen from `eye` and uploads them with the fin vertices.
    ///
    /// # Errors
    /// As [`fin_gammas`]; [`crate::BtfError::InvalidParameter`] for a bad `shading`;
    /// [`crate::BtfError::GpuLimit`] when a buffer exceeds the device's limit.
    pub fn prepare(
        &self,
        mesh: &FinMesh,
        positions: &[Vec3],
        normals: &[Vec3],
        light: &Light,
        eye: Vec3,
        shading: &FinShading,
    ) -> Result<FinDraw> {
        shading.validate()?;
        let device = &self.device;
        let n = mesh.len();
        check_buffer(device, "fin vertex bytes", (4 * n * 32) as u64)?;
        let gamma_len = self.fins.gamma_len();
        check_buffer(device, "fin γ bytes", (2 * n * gamma_len * 4) as u64)?;
        let mut gammas = self
            .gammas
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        fin_gammas(
            &self.fins,
            mesh,
            positions,
            normals,
            light,
            eye,
            &mut gammas,
        )?;
        let vertices: Vec<FinVertex> = mesh
            .positions
            .iter()
            .zip(&mesh.texcoords)
            .zip(&mesh.end_weight)
            .map(|((p, st), &w)| FinVertex {
                position: p.to_array(),
                end_weight: w,
                st: st.to_array(),
                _pad: [0.0; 2],
            })
            .collect();
        let uniform = FinUniform {
            radiance: light.radiance().extend(0.0).to_array(),
            dims: [
                self.fins.width() as u32,
                self.fins.height() as u32,
                gamma_len as u32,
                0,
            ],
            params: [shading.alpha_cut, 0.0, 0.0, 0.0],
        };
        let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fin frame"),
            contents: bytemuck::bytes_of(&uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let vertex_buffer = storage_init(device, "fin vertices", bytemuck::cast_slice(&vertices));
        let gamma_buffer = storage_init(device, "fin gammas", bytemuck::cast_slice(&gammas));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("fins"),
            layout: &self.layout,
            entries: &[
                buffer(0, &uniform),
                buffer(1, &vertex_buffer),
                buffer(2, &gamma_buffer),
                buffer(3, &self.images),
            ],
        });
        Ok(FinDraw {
            absorb: self.absorb.clone(),
            emit: self.emit.clone(),
            bind_group,
            // ≤ u32::MAX: the vertex buffer was checked above.
            vertices: 6 * n as u32,
        })
    }
}

fn make_pipelines(
    device: &wgpu::Device,
    ctx: &PassContext<'_>,
) -> (
    wgpu::BindGroupLayout,
    wgpu::RenderPipeline,
    wgpu::RenderPipeline,
) {
    let source = format!("{}\n{}", ::render::VIEW_SHADER, SHADER);
    let module = pipeline::shader_module(device, "fins.wgsl", &source);
    let layout = bind_group_layout(
        device,
        "fins",
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[
            binding::uniform(),
            binding::storage_read(),
            binding::storage_read(),
            binding::storage_read(),
        ],
    );
    let pipeline_layout = pipeline::pipeline_layout(device, "fins", &[ctx.view_layout, &layout]);
    let absorb_blend = wgpu::BlendState {
        color: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
            operation: wgpu::BlendOperation::Add,
        },
        alpha: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
            operation: wgpu::BlendOperation::Add,
        },
    };
    let emit_blend = wgpu::BlendState {
        color: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        },
        alpha: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        },
    };
    let build = |label, fragment, blend| {
        RenderPipelineDesc {
            label,
            layout: &pipeline_layout,
            module: &module,
            vertex: "vs_main",
            fragment: Some(fragment),
            buffers: &[],
            color: Some(ctx.format.blended_color_target(blend)),
            depth_stencil: Some(ctx.format.blended_depth()),
            samples: ctx.format.samples,
            cull_mode: None,
        }
        .build(device)
    };
    let absorb = build("fins absorb", "fs_absorb", absorb_blend);
    let emit = build("fins emit", "fs_emit", emit_blend);
    (layout, absorb, emit)
}
