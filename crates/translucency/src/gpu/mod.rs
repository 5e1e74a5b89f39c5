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
//!    surface, `light_map_size`² per face (512² default): for a point light within 1.5
//!    bounding radii, the six 90° faces around it that the box reaches (so a light inside the
//!    box works); farther out, one perspective face fitted to the bounding sphere (a 90° face
//!    spans 2D at distance D, so an object of radius R covered size · R / D texels — 3.4 of
//!    512 at 150 R, where the bunny's whole body read as thin and glowed); beyond 10⁴ radii,
//!    where f32 distances from the
//!    light no longer resolve the object, the directional map from its direction; for a
//!    directional light, one orthographic face;
//! 4. **one peeled layer** (TR 155): the nearest surface farther than the first by ε;
//! 5. **separable Gaussian** on the first layer (9 taps, σ = 2 texels, empty texels left out);
//!
//! and [`FramePass::record`] (phase [`Phase::DepthReading`]) draws the surfaces again with
//! depth `Equal`, adding eq. 12 per pixel: r = refract(−ω_out, n, 1/η), the shift fix by a
//! ray–box intersection, B = s̃ᵀ M s̃ clamped at 0, d = dist(x) − first layer ≥ 0 with
//! A(d) clamped at the longest transport mean free path, no scattering where x lies behind
//! the second layer.

use bytemuck::{Pod, Zeroable};
use glam::{DVec3, Vec3};
use render::{FramePass, Phase};

use crate::error::{TranslucencyError, bad_parameter};
use crate::sh::Window;

mod build;
mod frame;
mod readback;

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
    /// The sizes and switches this pass was built with.
    #[must_use]
    pub fn params(&self) -> &PipelineParams {
        &self.params
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
