//! The per-frame GPU pipeline of seed 004 (SEED-NOTES §5.2) and its evaluation in the render
//! crate's shared frame.
//!
//! Per frame, [`TranslucencyPass::prepare`] records, with nothing precomputed but the Y_lm·Δω
//! table of the cube map's texels:
//!
//! 1. **external cube map** (TR 75–84): the lit object's transmitted irradiance E_t (F_t(η)
//!    already applied per vertex, [`crate::model::transmitted_irradiance`]) seen from the
//!    accumulation point along the box axes, the box scaled to a cube (the "blindness" fix),
//!    six faces of `cube_size`² (64² default, TR 164) stacked in one texture; the farthest
//!    surface wins (depth `Greater`), so a concave object shows its outer skin;
//! 2. **SH projection** (TR 143): a two-level reduction in compute, then eq. 10's three 4×4
//!    matrices (window applied) — they stay on the GPU;
//! 3. **light distance map** (TR 131): the linear distance along the light's ray to the nearest
//!    surface (six faces around a point light — so a light inside the box works — or one
//!    orthographic face for a directional light), `light_map_size`² per face (512² default);
//! 4. **one peeled layer** (TR 155): the nearest surface farther than the first by ε;
//! 5. **separable Gaussian** on the first layer (9 taps, σ = 2 texels, empty texels left out);
//!
//! and [`FramePass::record`] (phase [`Phase::DepthReading`]) draws the surfaces again with
//! depth `Equal`, adding eq. 12 per pixel: r = refract(−ω_out, n, 1/η), the shift fix by a
//! ray–box intersection, B = s̃ᵀ M s̃ clamped at 0, d = dist(x) − first layer ≥ 0 with
//! A(d) clamped at one mean free path, no scattering where x lies behind the second layer.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};
use gpu_context::layout::{bind_group, bind_group_layout, binding};
use gpu_context::{RenderPipelineDesc, pipeline, read_buffer, read_texture};
use render::{FramePass, PassContext, Phase};
use std::time::Instant;
use wgpu::util::DeviceExt;

use crate::cube::{self, CubeMap};
use crate::error::{TranslucencyError, bad_parameter};
use crate::material::Material;
use crate::model::{AccumulationFrame, Light};
use crate::sh::{SH_COUNT, Sh9, Window};

/// WGSL of the pipeline's render passes (without `common.wgsl`).
pub const PIPELINE_SHADER: &str = include_str!("translucency.wgsl");
/// WGSL of the parameters shared by every pass.
pub const COMMON_SHADER: &str = include_str!("common.wgsl");
/// WGSL of the SH reduction.
pub const REDUCE_SHADER: &str = include_str!("reduce.wgsl");
/// WGSL of the Gaussian blur.
pub const BLUR_SHADER: &str = include_str!("blur.wgsl");
/// WGSL of the evaluation in the frame (without `view.wgsl` and `common.wgsl`).
pub const EVAL_SHADER: &str = include_str!("eval.wgsl");

/// Workgroups of the first reduction level (reduce.wgsl: GROUPS).
const REDUCE_GROUPS: u64 = 64;

/// Sizes and switches of the pipeline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PipelineParams {
    /// Cube-map face size (TR 164: 64²; 128² and 256² "did not significantly change" E_lm).
    pub cube_size: u32,
    /// Light distance map face size (TR 164: 512²).
    pub light_map_size: u32,
    /// Window on the SH bands.
    pub window: Window,
    /// The peeled-layer test for concave objects.
    pub peel: bool,
    /// A multiplier on L^e (1 = eq. 12 as written).
    pub intensity: f64,
}

impl Default for PipelineParams {
    fn default() -> Self {
        Self {
            cube_size: 64,
            light_map_size: 512,
            window: Window::None,
            peel: true,
            intensity: 1.0,
        }
    }
}

impl PipelineParams {
    fn validate(&self, device: &wgpu::Device) -> Result<(), TranslucencyError> {
        let max = device.limits().max_texture_dimension_2d;
        for (name, v) in [
            ("cube size", self.cube_size),
            ("light map size", self.light_map_size),
        ] {
            if v < 4 || v.saturating_mul(6) > max {
                return Err(bad_parameter(
                    name,
                    v,
                    "must be ≥ 4 and six faces must fit the device's texture limit",
                ));
            }
        }
        if !self.intensity.is_finite() || self.intensity < 0.0 {
            return Err(bad_parameter(
                "intensity",
                self.intensity,
                "must be finite and ≥ 0",
            ));
        }
        self.window.validate().map(|_| ())
    }
}

/// One frame's translucent object: world positions (f64, so an offset mesh keeps its detail
/// in the centred passes), normals, triangles and the transmitted irradiance E_t per vertex.
#[derive(Clone, Copy, Debug)]
pub struct TranslucentMesh<'a> {
    /// World positions.
    pub positions: &'a [DVec3],
    /// Vertex normals.
    pub normals: &'a [Vec3],
    /// Triangles.
    pub triangles: &'a [[u32; 3]],
    /// E_t per vertex (linear RGB), what the cube map stores.
    pub irradiance: &'a [[f32; 3]],
}

/// Wall-clock milliseconds of each pass (with [`TranslucencyPass::prepare`]'s `timed`, each
/// pass is submitted and waited for; otherwise only `total`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassTimes {
    /// Vertex upload and uniforms.
    pub upload: f64,
    /// Pass 1, the external cube map.
    pub cube_map: f64,
    /// Pass 2, the SH reduction and eq. 10's matrices.
    pub sh_projection: f64,
    /// Passes 3 and 4, the light distance map and its peeled layer.
    pub light_map: f64,
    /// The separable Gaussian.
    pub blur: f64,
    /// Everything [`TranslucencyPass::prepare`] did.
    pub total: f64,
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct Vertex {
    world: [f32; 3],
    centred: [f32; 3],
    normal: [f32; 3],
    irradiance: [f32; 3],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct BlurUniform {
    size: [f32; 4],
    faces: [[u32; 4]; 2],
}

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct ParamsUniform {
    half_extent: [f32; 4],
    light: [f32; 4],
    eye: [f32; 4],
    sigma_tr: [f32; 4],
    sigma_t: [f32; 4],
    misc: [f32; 4],
    maps: [f32; 4],
    window: [f32; 4],
    light_faces: [[f32; 4]; 18],
}

/// Stacked face textures: six faces of `size`² one above the other.
fn stacked(
    device: &wgpu::Device,
    label: &str,
    size: u32,
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d {
            width: size,
            height: 6 * size,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
}

fn view(t: &wgpu::Texture) -> wgpu::TextureView {
    t.create_view(&wgpu::TextureViewDescriptor::default())
}

const RENDER: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);
const STORAGE: wgpu::TextureUsages = wgpu::TextureUsages::STORAGE_BINDING
    .union(wgpu::TextureUsages::TEXTURE_BINDING)
    .union(wgpu::TextureUsages::COPY_SRC);

/// The textures and the bind groups that read them (rebuilt only when sizes change).
#[derive(Debug)]
struct Targets {
    cube: wgpu::Texture,
    cube_depth: wgpu::Texture,
    first: wgpu::Texture,
    blurred: wgpu::Texture,
    second: wgpu::Texture,
    light_depth: wgpu::Texture,
    sh_group: wgpu::BindGroup,
    peel_group: wgpu::BindGroup,
    blur_h_group: wgpu::BindGroup,
    blur_v_group: wgpu::BindGroup,
    eval_group: wgpu::BindGroup,
}

#[derive(Debug)]
struct MeshBuffers {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    vertex_count: usize,
    index_count: u32,
}

/// Seed 004's translucency: pipelines built once, the mesh and light set every frame.
#[derive(Debug)]
pub struct TranslucencyPass {
    params: PipelineParams,
    cube_pipeline: wgpu::RenderPipeline,
    distance_pipeline: wgpu::RenderPipeline,
    peel_pipeline: wgpu::RenderPipeline,
    sh_partial: wgpu::ComputePipeline,
    sh_final: wgpu::ComputePipeline,
    blur_h: wgpu::ComputePipeline,
    blur_v: wgpu::ComputePipeline,
    eval: wgpu::RenderPipeline,
    params_buffer: wgpu::Buffer,
    params_group: wgpu::BindGroup,
    window_buffer: wgpu::Buffer,
    coefficients: wgpu::Buffer,
    sh_final_group: wgpu::BindGroup,
    blur_uniform: wgpu::Buffer,
    targets: Targets,
    mesh: Option<MeshBuffers>,
    /// The light-map faces drawn this frame (slots of the stacked textures).
    light_faces: Vec<u32>,
}

impl TranslucencyPass {
    /// Build every pipeline and texture for the frame `ctx` and the sizes in `params`.
    ///
    /// # Errors
    /// Sizes beyond the device's limits, a bad window, or a device that cannot blend the
    /// frame's `Rgba32Float` colour (L^e is added).
    pub fn new(
        device: &wgpu::Device,
        ctx: &PassContext<'_>,
        params: PipelineParams,
    ) -> Result<Self, TranslucencyError> {
        params.validate(device)?;
        if !device
            .features()
            .contains(wgpu::Features::FLOAT32_BLENDABLE)
        {
            return Err(bad_parameter(
                "adapter",
                "no FLOAT32_BLENDABLE",
                "L^e is blended into the Rgba32Float frame",
            ));
        }
        let vis = wgpu::ShaderStages::VERTEX_FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let unfilterable = binding::texture(
            wgpu::TextureSampleType::Float { filterable: false },
            wgpu::TextureViewDimension::D2,
        );
        let params_layout =
            bind_group_layout(device, "translucency params", vis, &[binding::uniform()]);
        let peel_layout = bind_group_layout(device, "translucency peel", vis, &[unfilterable]);
        let sh_layout = bind_group_layout(
            device,
            "translucency sh",
            wgpu::ShaderStages::COMPUTE,
            &[unfilterable, binding::storage_read(), binding::storage_rw()],
        );
        let sh_final_layout = bind_group_layout(
            device,
            "translucency sh final",
            wgpu::ShaderStages::COMPUTE,
            &[binding::uniform(), binding::storage_rw()],
        );
        let storage_r32 = wgpu::BindingType::StorageTexture {
            access: wgpu::StorageTextureAccess::WriteOnly,
            format: wgpu::TextureFormat::R32Float,
            view_dimension: wgpu::TextureViewDimension::D2,
        };
        let blur_layout = bind_group_layout(
            device,
            "translucency blur",
            wgpu::ShaderStages::COMPUTE,
            &[unfilterable, storage_r32, binding::uniform()],
        );
        let eval_layout = bind_group_layout(
            device,
            "translucency eval",
            wgpu::ShaderStages::VERTEX_FRAGMENT,
            &[
                binding::uniform(),
                binding::storage_read(),
                unfilterable,
                unfilterable,
            ],
        );

        let module = pipeline::shader_module(
            device,
            "translucency.wgsl",
            &format!("{COMMON_SHADER}\n{PIPELINE_SHADER}"),
        );
        let vertex_layout = [wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<Vertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Float32x3],
        }];
        let only_params = pipeline::pipeline_layout(device, "translucency", &[&params_layout]);
        let with_peel =
            pipeline::pipeline_layout(device, "translucency peel", &[&params_layout, &peel_layout]);
        let offscreen = |label, layout, vertex, fragment, format, compare| {
            RenderPipelineDesc {
                label,
                layout,
                module: &module,
                vertex,
                fragment: Some(fragment),
                buffers: &vertex_layout,
                color: Some(wgpu::ColorTargetState {
                    format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                }),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: wgpu::TextureFormat::Depth32Float,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(compare),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                samples: 1,
                cull_mode: None,
            }
            .build(device)
        };
        let cube_pipeline = offscreen(
            "translucency cube map",
            &only_params,
            "vs_cube",
            "fs_cube",
            wgpu::TextureFormat::Rgba32Float,
            wgpu::CompareFunction::Greater,
        );
        let distance_pipeline = offscreen(
            "translucency light distance",
            &only_params,
            "vs_light",
            "fs_distance",
            wgpu::TextureFormat::R32Float,
            wgpu::CompareFunction::Less,
        );
        let peel_pipeline = offscreen(
            "translucency peel",
            &with_peel,
            "vs_light",
            "fs_peel",
            wgpu::TextureFormat::R32Float,
            wgpu::CompareFunction::Less,
        );

        let reduce = pipeline::shader_module(device, "reduce.wgsl", REDUCE_SHADER);
        let sh_partial = pipeline::compute_pipeline(
            device,
            "translucency sh partial",
            &pipeline::pipeline_layout(device, "sh partial", &[&sh_layout]),
            &reduce,
            "sh_partial",
        );
        let sh_final = pipeline::compute_pipeline(
            device,
            "translucency sh final",
            &pipeline::pipeline_layout(device, "sh final", &[&sh_layout, &sh_final_layout]),
            &reduce,
            "sh_final",
        );
        let blur_module = pipeline::shader_module(device, "blur.wgsl", BLUR_SHADER);
        let blur_pl = pipeline::pipeline_layout(device, "blur", &[&blur_layout]);
        let blur_h = pipeline::compute_pipeline(device, "blur h", &blur_pl, &blur_module, "blur_h");
        let blur_v = pipeline::compute_pipeline(device, "blur v", &blur_pl, &blur_module, "blur_v");

        let eval_module = pipeline::shader_module(
            device,
            "translucency eval",
            &format!("{}\n{COMMON_SHADER}\n{EVAL_SHADER}", render::VIEW_SHADER),
        );
        let eval = RenderPipelineDesc {
            label: "translucency eval",
            layout: &pipeline::pipeline_layout(
                device,
                "translucency eval",
                &[ctx.view_layout, &eval_layout],
            ),
            module: &eval_module,
            vertex: "vs_eval",
            fragment: Some("fs_eval"),
            buffers: &vertex_layout,
            color: Some(wgpu::ColorTargetState {
                format: ctx.format.color,
                blend: Some(wgpu::BlendState {
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
                }),
                write_mask: wgpu::ColorWrites::ALL,
            }),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: ctx.format.depth_stencil,
                depth_write_enabled: Some(false),
                depth_compare: Some(wgpu::CompareFunction::Equal),
                stencil: wgpu::StencilState::default(),
                bias: wgpu::DepthBiasState::default(),
            }),
            samples: ctx.format.samples,
            cull_mode: None,
        }
        .build(device);

        let params_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency params"),
            size: std::mem::size_of::<ParamsUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_group = bind_group(
            device,
            "translucency params",
            &params_layout,
            &[params_buffer.as_entire_binding()],
        );
        let window_buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency window"),
            size: 16,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let coefficients = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency E_lm and M"),
            size: (27 + 48) * 4,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let sh_final_group = bind_group(
            device,
            "translucency sh final",
            &sh_final_layout,
            &[
                window_buffer.as_entire_binding(),
                coefficients.as_entire_binding(),
            ],
        );
        let blur_size = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency blur faces"),
            size: std::mem::size_of::<BlurUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });

        // Textures and the groups reading them.
        let cube = stacked(
            device,
            "translucency cube map",
            params.cube_size,
            wgpu::TextureFormat::Rgba32Float,
            RENDER | wgpu::TextureUsages::COPY_DST,
        );
        let cube_depth = stacked(
            device,
            "translucency cube depth",
            params.cube_size,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let ls = params.light_map_size;
        let first = stacked(
            device,
            "translucency first layer",
            ls,
            wgpu::TextureFormat::R32Float,
            RENDER,
        );
        let blurred_tmp = stacked(
            device,
            "translucency blur tmp",
            ls,
            wgpu::TextureFormat::R32Float,
            STORAGE,
        );
        let blurred = stacked(
            device,
            "translucency first layer blurred",
            ls,
            wgpu::TextureFormat::R32Float,
            STORAGE,
        );
        let second = stacked(
            device,
            "translucency second layer",
            ls,
            wgpu::TextureFormat::R32Float,
            RENDER,
        );
        let light_depth = stacked(
            device,
            "translucency light depth",
            ls,
            wgpu::TextureFormat::Depth32Float,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        );
        let weights: Vec<f32> = cube::projection_weights(params.cube_size as usize)
            .iter()
            .flat_map(|w| w.map(|v| v as f32))
            .collect();
        let weights = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("translucency Y_lm·Δω"),
            contents: bytemuck::cast_slice(&weights),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let partials = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("translucency partial sums"),
            size: REDUCE_GROUPS * 27 * 4,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let (cube_v, first_v, tmp_v, blurred_v, second_v) = (
            view(&cube),
            view(&first),
            view(&blurred_tmp),
            view(&blurred),
            view(&second),
        );
        let sh_group = bind_group(
            device,
            "translucency sh",
            &sh_layout,
            &[
                wgpu::BindingResource::TextureView(&cube_v),
                weights.as_entire_binding(),
                partials.as_entire_binding(),
            ],
        );
        let peel_group = bind_group(
            device,
            "translucency peel",
            &peel_layout,
            &[wgpu::BindingResource::TextureView(&first_v)],
        );
        let blur_h_group = bind_group(
            device,
            "translucency blur h",
            &blur_layout,
            &[
                wgpu::BindingResource::TextureView(&first_v),
                wgpu::BindingResource::TextureView(&tmp_v),
                blur_size.as_entire_binding(),
            ],
        );
        let blur_v_group = bind_group(
            device,
            "translucency blur v",
            &blur_layout,
            &[
                wgpu::BindingResource::TextureView(&tmp_v),
                wgpu::BindingResource::TextureView(&blurred_v),
                blur_size.as_entire_binding(),
            ],
        );
        let eval_group = bind_group(
            device,
            "translucency eval",
            &eval_layout,
            &[
                params_buffer.as_entire_binding(),
                coefficients.as_entire_binding(),
                wgpu::BindingResource::TextureView(&blurred_v),
                wgpu::BindingResource::TextureView(&second_v),
            ],
        );
        Ok(Self {
            params,
            cube_pipeline,
            distance_pipeline,
            peel_pipeline,
            sh_partial,
            sh_final,
            blur_h,
            blur_v,
            eval,
            params_buffer,
            params_group,
            window_buffer,
            coefficients,
            sh_final_group,
            blur_uniform: blur_size,
            targets: Targets {
                cube,
                cube_depth,
                first,
                blurred,
                second,
                light_depth,
                sh_group,
                peel_group,
                blur_h_group,
                blur_v_group,
                eval_group,
            },
            mesh: None,
            light_faces: Vec::new(),
        })
    }

    /// The sizes and switches this pass was built with.
    #[must_use]
    pub fn params(&self) -> &PipelineParams {
        &self.params
    }
}

/// The faces of a point light's six-face map that the object's box can reach: a face is left
/// out when all eight box corners lie outside one of its pyramid's four side planes
/// (conservative: a face drawn in vain costs time, a face missed would lose the thickness).
/// A light inside the box needs all six.
fn needed_faces(light: DVec3, frame: &AccumulationFrame) -> Vec<u32> {
    let corners: Vec<DVec3> = (0..8)
        .map(|i| {
            let s = DVec3::new(
                if i & 1 == 0 { -1.0 } else { 1.0 },
                if i & 2 == 0 { -1.0 } else { 1.0 },
                if i & 4 == 0 { -1.0 } else { 1.0 },
            );
            frame.centre + s * frame.half_extent - light
        })
        .collect();
    (0..6u32)
        .filter(|&f| {
            let [fwd, right, up] = cube::FACES[f as usize];
            [fwd - right, fwd + right, fwd - up, fwd + up]
                .iter()
                .all(|n| corners.iter().any(|v| v.dot(*n) >= 0.0))
        })
        .collect()
}

/// Orthonormal (forward, right, up) for a directional light's map: forward = −l.
fn directional_basis(l: DVec3) -> [DVec3; 3] {
    let forward = -l;
    let helper = if forward.y.abs() < 0.9 {
        DVec3::Y
    } else {
        DVec3::X
    };
    let right = forward.cross(helper).normalize();
    let up = right.cross(forward);
    [forward, right, up]
}

fn vec4(v: DVec3, w: f64) -> [f32; 4] {
    [v.x as f32, v.y as f32, v.z as f32, w as f32]
}

fn check_mesh(mesh: &TranslucentMesh<'_>) -> Result<(), TranslucencyError> {
    let n = mesh.positions.len();
    if mesh.normals.len() != n || mesh.irradiance.len() != n {
        return Err(TranslucencyError::Mesh(format!(
            "{n} positions, {} normals, {} irradiance values",
            mesh.normals.len(),
            mesh.irradiance.len()
        )));
    }
    if mesh.triangles.is_empty() {
        return Err(TranslucencyError::Mesh("no triangles".into()));
    }
    if let Some((i, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= n))
    {
        return Err(TranslucencyError::Mesh(format!(
            "triangle {i} = {t:?} names a vertex ≥ {n}"
        )));
    }
    if let Some(i) = (0..n).find(|&i| {
        !mesh.normals[i].is_finite()
            || mesh.irradiance[i]
                .iter()
                .any(|v| !v.is_finite() || *v < 0.0)
    }) {
        return Err(TranslucencyError::Mesh(format!(
            "vertex {i}: normal {} or irradiance {:?} is not finite (or negative)",
            mesh.normals[i], mesh.irradiance[i]
        )));
    }
    Ok(())
}

impl TranslucencyPass {
    /// Run passes 1–5 for this frame's mesh, light, material and eye (world), leaving the
    /// matrices and the light maps on the GPU for [`FramePass::record`]. With `timed`, each
    /// pass is submitted and waited for, so [`PassTimes`] holds per-pass times (the frame is
    /// then slower than with one submission).
    ///
    /// # Errors
    /// A mesh whose slices disagree, with an index out of range, non-finite values, or no
    /// extent; a bad light; a GPU failure.
    #[allow(clippy::too_many_arguments)]
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &TranslucentMesh<'_>,
        light: Light,
        material: &Material,
        eye: DVec3,
        timed: bool,
    ) -> Result<PassTimes, TranslucencyError> {
        let start = Instant::now();
        check_mesh(mesh)?;
        let light = light.validated()?;
        if !eye.is_finite() {
            return Err(bad_parameter("eye", eye, "must be finite"));
        }
        let frame = AccumulationFrame::of_points(mesh.positions.iter().copied())?;
        let c = frame.centre;
        let vertices: Vec<Vertex> = (0..mesh.positions.len())
            .map(|i| Vertex {
                world: mesh.positions[i].as_vec3().to_array(),
                centred: (mesh.positions[i] - c).as_vec3().to_array(),
                normal: mesh.normals[i].to_array(),
                irradiance: mesh.irradiance[i],
            })
            .collect();
        let index_count = u32::try_from(mesh.triangles.len() * 3)
            .map_err(|_| TranslucencyError::Mesh("too many triangles".into()))?;
        match &self.mesh {
            Some(m) if m.vertex_count == vertices.len() && m.index_count == index_count => {
                queue.write_buffer(&m.vertices, 0, bytemuck::cast_slice(&vertices));
                queue.write_buffer(&m.indices, 0, bytemuck::cast_slice(mesh.triangles));
            }
            _ => {
                self.mesh = Some(MeshBuffers {
                    vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("translucency vertices"),
                        contents: bytemuck::cast_slice(&vertices),
                        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                    }),
                    indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("translucency indices"),
                        contents: bytemuck::cast_slice(mesh.triangles),
                        usage: wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_DST,
                    }),
                    vertex_count: vertices.len(),
                    index_count,
                });
            }
        }
        let radius = frame.half_extent.length() * 1.01;
        let mut faces = [[0.0f32; 4]; 18];
        let (light_vec, near, far) = match light {
            Light::Point(p) => {
                for (f, axes) in cube::FACES.iter().enumerate() {
                    for (k, a) in axes.iter().enumerate() {
                        faces[3 * f + k] = vec4(*a, 0.0);
                    }
                }
                self.light_faces = needed_faces(p, &frame);
                let pc = p - c;
                let far = pc.length() + radius;
                (vec4(pc, 1.0), far * 1e-5, far)
            }
            Light::Directional(l) => {
                for (k, a) in directional_basis(l).iter().enumerate() {
                    faces[k] = vec4(*a, 0.0);
                }
                self.light_faces = vec![0];
                (vec4(l, 0.0), 0.0, 0.0)
            }
        };
        let (tr, tp) = (material.sigma_tr(), material.sigma_t_prime());
        let h = self.params.window.factors();
        let mut uniform = ParamsUniform {
            half_extent: vec4(frame.half_extent, 6.0),
            light: light_vec,
            eye: vec4(eye - c, 1.0),
            sigma_tr: [
                tr[0] as f32,
                tr[1] as f32,
                tr[2] as f32,
                material.mm_per_unit as f32,
            ],
            sigma_t: [
                tp[0] as f32,
                tp[1] as f32,
                tp[2] as f32,
                material.eta as f32,
            ],
            misc: [
                self.params.intensity as f32,
                (radius * 1e-4) as f32,
                near as f32,
                far as f32,
            ],
            maps: [
                self.params.cube_size as f32,
                self.params.light_map_size as f32,
                radius as f32,
                if self.params.peel { 1.0 } else { 0.0 },
            ],
            window: [
                h[0] as f32,
                h[1] as f32,
                h[2] as f32,
                material.clamp_distance() as f32,
            ],
            light_faces: faces,
        };
        // Instance i of the light passes draws face light_faces[i].
        for (i, &f) in self.light_faces.iter().enumerate() {
            uniform.light_faces[3 * i + 1][3] = f as f32;
        }
        let mut blur = BlurUniform {
            size: [self.params.light_map_size as f32, 0.0, 0.0, 0.0],
            faces: [[0; 4]; 2],
        };
        for (i, &f) in self.light_faces.iter().enumerate() {
            blur.faces[i / 4][i % 4] = f;
        }
        queue.write_buffer(&self.blur_uniform, 0, bytemuck::bytes_of(&blur));
        queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.window_buffer, 0, bytemuck::bytes_of(&uniform.window));
        let mut times = PassTimes::default();
        let wait = |device: &wgpu::Device| {
            device
                .poll(wgpu::PollType::wait_indefinitely())
                .map_err(|e| TranslucencyError::Gpu(gpu_context::GpuError::Readback(e.to_string())))
        };
        if timed {
            wait(device)?;
            times.upload = (Instant::now() - start).as_secs_f64() * 1e3;
        }
        let mut mark = Instant::now();
        let mut step = |device: &wgpu::Device, slot: &mut f64, encoder: wgpu::CommandEncoder| {
            queue.submit([encoder.finish()]);
            if timed {
                wait(device)?;
                let now = Instant::now();
                *slot = (now - mark).as_secs_f64() * 1e3;
                mark = now;
            }
            Ok::<(), TranslucencyError>(())
        };
        let new_encoder = |label| {
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) })
        };
        let m = self.mesh.as_ref().expect("uploaded above");

        // 1. The external cube map.
        let mut encoder = new_encoder("translucency cube map");
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.cube_pipeline,
            None,
            &self.targets.cube,
            &self.targets.cube_depth,
            0.0,
            6,
        );
        step(device, &mut times.cube_map, encoder)?;

        // 2. SH projection and eq. 10.
        let mut encoder = new_encoder("translucency sh");
        self.record_sh(&mut encoder);
        step(device, &mut times.sh_projection, encoder)?;

        // 3–4. The light distance map and its peeled layer.
        let mut encoder = new_encoder("translucency light map");
        let faces = self.light_faces.len() as u32;
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.distance_pipeline,
            None,
            &self.targets.first,
            &self.targets.light_depth,
            1.0,
            faces,
        );
        self.draw_offscreen(
            &mut encoder,
            m,
            &self.peel_pipeline,
            Some(&self.targets.peel_group),
            &self.targets.second,
            &self.targets.light_depth,
            1.0,
            faces,
        );
        step(device, &mut times.light_map, encoder)?;

        // 5. The separable Gaussian.
        let mut encoder = new_encoder("translucency blur");
        {
            let size = self.params.light_map_size;
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("translucency blur"),
                timestamp_writes: None,
            });
            for (pipe, group) in [
                (&self.blur_h, &self.targets.blur_h_group),
                (&self.blur_v, &self.targets.blur_v_group),
            ] {
                pass.set_pipeline(pipe);
                pass.set_bind_group(0, group, &[]);
                // Only the faces in use (one for a directional light).
                pass.dispatch_workgroups(size.div_ceil(8), size.div_ceil(8), faces);
            }
        }
        step(device, &mut times.blur, encoder)?;
        if timed {
            wait(device)?;
        }
        times.total = (Instant::now() - start).as_secs_f64() * 1e3;
        Ok(times)
    }

    /// One offscreen render pass over every face slot (instances = faces): colour cleared to
    /// 1e30 ("nothing") for distance maps or 0 for the cube map, depth to `clear_depth`.
    #[allow(clippy::too_many_arguments)]
    fn draw_offscreen(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        m: &MeshBuffers,
        pipeline: &wgpu::RenderPipeline,
        extra: Option<&wgpu::BindGroup>,
        color: &wgpu::Texture,
        depth: &wgpu::Texture,
        clear_depth: f32,
        faces: u32,
    ) {
        let clear = if clear_depth > 0.5 { 1e30 } else { 0.0 };
        let (cv, dv) = (view(color), view(depth));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("translucency offscreen"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &cv,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: clear,
                        g: 0.0,
                        b: 0.0,
                        a: 0.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &dv,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(clear_depth),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.params_group, &[]);
        if let Some(g) = extra {
            pass.set_bind_group(1, g, &[]);
        }
        pass.set_vertex_buffer(0, m.vertices.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.index_count, 0, 0..faces);
    }

    /// Read back this frame's cube map (pass 1) — for tests and pictures.
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_cube_map(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<CubeMap, TranslucencyError> {
        let bytes = read_texture(
            device,
            queue,
            &self.targets.cube,
            16,
            wgpu::TextureAspect::All,
        )?;
        let rgba: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        CubeMap::new(
            self.params.cube_size as usize,
            rgba.iter().map(|t| [t[0], t[1], t[2]]).collect(),
        )
    }

    /// Project any cube map of this pass's face size with the GPU reduction (pass 2 alone):
    /// what `cloth-vis sh --gpu` runs, and the check of the reduction against the f64 sum.
    /// It overwrites this frame's cube map.
    ///
    /// # Errors
    /// A face size other than [`PipelineParams::cube_size`]; a failed read-back.
    pub fn project_on_gpu(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cube: &CubeMap,
    ) -> Result<Sh9, TranslucencyError> {
        let size = self.params.cube_size;
        if cube.size() != size as usize {
            return Err(bad_parameter(
                "cube face size",
                cube.size(),
                "must equal the pass's cube_size",
            ));
        }
        let rgba: Vec<[f32; 4]> = cube
            .texels()
            .iter()
            .map(|t| [t[0], t[1], t[2], 1.0])
            .collect();
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &self.targets.cube,
                mip_level: 0,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            bytemuck::cast_slice(&rgba),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(16 * size),
                rows_per_image: Some(6 * size),
            },
            wgpu::Extent3d {
                width: size,
                height: 6 * size,
                depth_or_array_layers: 1,
            },
        );
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("translucency sh only"),
        });
        self.record_sh(&mut encoder);
        queue.submit([encoder.finish()]);
        self.read_coefficients(device, queue)
    }

    fn record_sh(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("translucency sh"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.sh_partial);
        pass.set_bind_group(0, &self.targets.sh_group, &[]);
        pass.dispatch_workgroups(REDUCE_GROUPS as u32, 1, 1);
        pass.set_pipeline(&self.sh_final);
        pass.set_bind_group(1, &self.sh_final_group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
    }

    /// Read back this frame's E_lm as the GPU reduced them (before the window).
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_coefficients(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Sh9, TranslucencyError> {
        let bytes = read_buffer(device, queue, &self.coefficients, 27 * 4)?;
        let v: &[f32] = bytemuck::cast_slice(&bytes);
        let mut sh = Sh9::default();
        for k in 0..SH_COUNT {
            for c in 0..3 {
                sh.coeffs[k][c] = f64::from(v[3 * k + c]);
            }
        }
        Ok(sh)
    }

    /// Read back the light map's layers — (first blurred, second), each `size` × 6·`size`,
    /// 1e30 where empty — for tests.
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_light_layers(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<(Vec<f32>, Vec<f32>), TranslucencyError> {
        let read = |t: &wgpu::Texture| {
            read_texture(device, queue, t, 4, wgpu::TextureAspect::All)
                .map(|b| bytemuck::cast_slice::<u8, f32>(&b).to_vec())
        };
        Ok((read(&self.targets.blurred)?, read(&self.targets.second)?))
    }

    /// The unblurred first layer (for tests of the blur).
    ///
    /// # Errors
    /// A failed read-back.
    pub fn read_first_layer_raw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
    ) -> Result<Vec<f32>, TranslucencyError> {
        let b = read_texture(
            device,
            queue,
            &self.targets.first,
            4,
            wgpu::TextureAspect::All,
        )?;
        Ok(bytemuck::cast_slice::<u8, f32>(&b).to_vec())
    }
}

impl FramePass for TranslucencyPass {
    fn phase(&self) -> Phase {
        Phase::DepthReading
    }

    fn record(&self, pass: &mut wgpu::RenderPass<'_>) {
        let Some(m) = &self.mesh else {
            return;
        };
        pass.set_pipeline(&self.eval);
        pass.set_bind_group(1, &self.targets.eval_group, &[]);
        pass.set_vertex_buffer(0, m.vertices.slice(..));
        pass.set_index_buffer(m.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..m.index_count, 0, 0..1);
    }
}
