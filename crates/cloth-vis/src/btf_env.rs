//! A BTF object under environment light (thesis §5.5.2; crate `btf`, module `env`): the
//! environment binned onto the BTF's 81 measured light directions per vertex (W, eq. 5.10 with
//! the solid angle), through the object's own self-shadowing, then γ* (eq. 5.11) and the frame.
//!
//! Two visibilities, the same integral:
//! * **the visibility matrix M** (crate `occlusion-gpu`, k lightsphere directions per vertex):
//!   recomputed per frame, so a deforming garment self-shadows while it moves — what the
//!   thesis could not do (it lit only static meshes by an environment);
//! * **static visibility maps** (crate `hemicube`, one bit per pixel, built once in each
//!   vertex's texture tangent frame): the thesis's own path, per-pixel directions and solid
//!   angles.
//!
//! Turning the environment about the up axis is a new W; with [`Decompose`] it is instead the
//! decomposition of eq. 5.13 ([`btf::env::EnvDecomposition`]): W for A turns, PCA to e
//! components, and any turn by an e-term sum per vertex.

use std::time::Instant;

use btf::BtfPca;
use btf::env::{EnvDecomposition, EnvLightWeights, EnvTransfer};
use btf::render::{GpuBtfRenderer, RenderParams};
use glam::{Quat, Vec3};
use gpu_context::{GpuContext, HdrImage};
use render::{Background, Camera, FrameFormat, Renderer};

use crate::Error;
use crate::btf_stage::{btf_mesh, tangents_of};
use crate::object::WorldObject;

/// Most turns a decomposition samples (1° apart).
pub const MAX_TURNS: usize = 360;

/// Most bytes the A samples of W may hold (A × vertices × 81 × 3 × 4 bytes, kept twice while
/// the PCA runs): 2 GB, e.g. 30 turns of 70,000 vertices.
pub const MAX_DECOMPOSITION_BYTES: u64 = 2_000_000_000;

/// Bytes of W per vertex and turn, counted twice (the samples and their flattened copy).
const BYTES_PER_VERTEX_TURN: u64 = 2 * 81 * 3 * 4;

/// Whose visibility shadows the environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvVisibility {
    /// occlusion-gpu's visibility matrix M at this lightsphere level (the environment's
    /// cell-mean radiance I_j per direction).
    Matrix {
        /// Lightsphere level (3: 258 directions).
        level: u32,
    },
    /// Static per-vertex maps of this model (exact rays), in each vertex's tangent frame; the
    /// environment looked up per open pixel in a power-conserving cube map (the seed's).
    Maps {
        /// The map model (e.g. hemicube 32²).
        model: hemicube::Model,
    },
}

/// The environment decomposition of eq. 5.13: `turns` (A) samples, `components` (e) kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decompose {
    /// A: turns sampled over 360° (the thesis: 30, every 12°).
    pub turns: usize,
    /// e: components kept (the thesis: 5).
    pub components: usize,
}

/// How a BTF object is lit by an environment.
#[derive(Clone, Debug)]
pub struct EnvLighting<'a> {
    /// The environment, already turned onto the object's up axis.
    pub env: &'a lightsphere::Environment,
    /// The world up axis the environment turns about.
    pub up: Vec3,
    /// The turn in degrees (right-handed about `up`).
    pub rotation_deg: f32,
    /// The visibility.
    pub visibility: EnvVisibility,
    /// Turn through the decomposition instead of a direct update.
    pub decompose: Option<Decompose>,
}

/// What lighting a BTF object by an environment cost ([`render_env`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvCost {
    /// Environment directions per vertex: lightsphere directions k, or map pixels.
    pub directions: usize,
    /// Vertices lit.
    pub vertices: usize,
    /// Milliseconds of the visibility (M, or the maps).
    pub visibility_ms: f64,
    /// Milliseconds of the per-vertex transfer T_i (M only; once per frame of a deforming
    /// mesh).
    pub transfer_ms: f64,
    /// Milliseconds of the environment update: W_i and γ* of the four view slots (what a new
    /// map or a turned map costs; through the decomposition, the e-term sum).
    pub update_ms: f64,
    /// Milliseconds of the frame (draw and read-back; the CPU reference without a GPU).
    pub render_ms: f64,
    /// The decomposition, when asked for.
    pub decomposition: Option<DecompositionCost>,
}

/// What the decomposition cost and how close it came.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecompositionCost {
    /// A.
    pub turns: usize,
    /// e kept.
    pub components: usize,
    /// Milliseconds of the A direct updates U_a.
    pub samples_ms: f64,
    /// Milliseconds of the PCA.
    pub build_ms: f64,
    /// Milliseconds of one turn: W from the e components (the runtime cost of a rotation).
    pub turn_ms: f64,
    /// Relative RMS error of that W against the direct update at the same turn.
    pub error: f64,
    /// Bytes held (mean, components, coefficients).
    pub bytes: usize,
}

/// The environment binned per vertex for one object and visibility: built once (visibility,
/// transfer, cube map), then W for any turn of the environment ([`EnvBinner::weights`]) or
/// the decomposition of all turns ([`EnvBinner::decompose`]) without recomputing visibility.
/// It owns what a turn needs (a viewer keeps one per pose and turns it every frame).
pub struct EnvBinner {
    update: Box<dyn Fn(f32) -> Result<Vec<EnvLightWeights>, Error> + Send>,
    cost: EnvCost,
}

impl std::fmt::Debug for EnvBinner {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvBinner")
            .field("cost", &self.cost)
            .finish()
    }
}

impl EnvBinner {
    /// The visibility of `object` (with UVs) by `visibility`, in the tangent frames of its UVs,
    /// for `env` (already on the object's up axis) turning about `up`.
    ///
    /// # Errors
    /// An object without UVs; lightsphere, visibility and hemicube errors.
    pub fn new(
        pca: &BtfPca,
        object: &WorldObject,
        env: &lightsphere::Environment,
        up: Vec3,
        visibility: EnvVisibility,
    ) -> Result<Self, Error> {
        let (tangents, _) = tangents_of(object)?;
        let frames: Vec<[Vec3; 3]> = tangents
            .iter()
            .zip(&object.normals)
            .map(|(t, n)| {
                let n = n.normalize_or_zero();
                let t3 = (t.truncate() - n * n.dot(t.truncate())).normalize_or_zero();
                [t3, t.w * n.cross(t3), n]
            })
            .collect();
        let scene = occlusion_gpu::Scene::single(
            object.positions.clone(),
            object.normals.clone(),
            object.triangles.clone(),
        )?;
        let turn = move |deg: f32| Quat::from_axis_angle(up, deg.to_radians());
        let start = Instant::now();
        let mut cost = EnvCost {
            directions: 0,
            vertices: object.positions.len(),
            visibility_ms: 0.0,
            transfer_ms: 0.0,
            update_ms: 0.0,
            render_ms: 0.0,
            decomposition: None,
        };
        let update: Box<dyn Fn(f32) -> Result<Vec<EnvLightWeights>, Error> + Send> =
            match visibility {
                EnvVisibility::Matrix { level } => {
                    let sphere = lightsphere::Lightsphere::new(level)?;
                    let mut engine = occlusion_gpu::VisibilityEngine::cpu(
                        occlusion_gpu::VisibilityParams::default(),
                    );
                    let m = engine.compute(&scene, &sphere)?;
                    cost.visibility_ms = start.elapsed().as_secs_f64() * 1e3;
                    cost.directions = sphere.len();
                    let omegas: Vec<f32> =
                        sphere.solid_angles().iter().map(|&w| w as f32).collect();
                    let start = Instant::now();
                    let transfer = EnvTransfer::build(
                        pca.sampling(),
                        &frames,
                        sphere.directions(),
                        &omegas,
                        |i, j| m.is_visible(i, j),
                    );
                    cost.transfer_ms = start.elapsed().as_secs_f64() * 1e3;
                    let env = env.clone();
                    Box::new(move |deg| {
                        let lookup = if deg == 0.0 {
                            sphere.clone()
                        } else {
                            sphere.try_rotated(turn(deg).inverse())?
                        };
                        let radiance = env.radiance_per_direction(
                            &lookup,
                            lightsphere::RadianceMethod::CellMean,
                        )?;
                        let mut w = Vec::new();
                        transfer.update(&radiance, &mut w);
                        Ok(w)
                    })
                }
                EnvVisibility::Maps { model } => {
                    let layout = std::sync::Arc::new(hemicube::PixelLayout::new(
                        model,
                        hemicube::FormFactorRule::Exact,
                    )?);
                    let caster = occlusion_gpu::RayCaster::new(&scene)?;
                    let map_frames = frames
                        .iter()
                        .map(|[t, _, n]| {
                            (*n != Vec3::ZERO)
                                .then(|| hemicube::VertexFrame::from_normal_tangent(*n, *t))
                        })
                        .collect();
                    let (maps, _) = hemicube::build_with_frames(
                        &caster,
                        layout,
                        &hemicube::BuildParams::default(),
                        map_frames,
                        &|_| {},
                    );
                    cost.visibility_ms = start.elapsed().as_secs_f64() * 1e3;
                    cost.directions = maps.layout().len();
                    let channel = hemicube::BtfLightChannel::new(maps.layout(), pca.sampling());
                    let mirrored: Vec<bool> = tangents.iter().map(|t| t.w < 0.0).collect();
                    // The seed's look-up: a power-conserving cube map matched to the maps (the
                    // resolution `hemicube` measured best), turned by rotating the look-up.
                    let cube = hemicube::CubeMap::from_environment(
                        env,
                        hemicube::lighting::matched_cube_resolution(&maps),
                    );
                    Box::new(move |deg| {
                        let back = turn(deg).inverse();
                        Ok(channel.light_weights(&maps, &mirrored, |d| cube.lookup(back * d)))
                    })
                }
            };
        Ok(Self { update, cost })
    }

    /// What the visibility and transfer cost (update and frame times 0).
    pub fn cost(&self) -> EnvCost {
        self.cost
    }

    /// W of every vertex with the environment turned by `deg` degrees about the up axis.
    ///
    /// # Errors
    /// A non-finite angle; lightsphere errors.
    pub fn weights(&self, deg: f32) -> Result<Vec<EnvLightWeights>, Error> {
        if !deg.is_finite() {
            return Err(Error::Request {
                path: std::path::PathBuf::from("rotation"),
                message: format!("the environment's turn {deg}° must be finite"),
            });
        }
        (self.update)(deg)
    }

    /// The decomposition of eq. 5.13 over `d.turns` turns every 360°/A, keeping `d.components`;
    /// with the milliseconds of the A updates and of the PCA.
    ///
    /// # Errors
    /// As [`EnvBinner::weights`]; decomposition errors (A < 2); [`Error::Request`] for more
    /// than [`MAX_TURNS`] turns or samples that would hold more than [`MAX_DECOMPOSITION_BYTES`].
    pub fn decompose(
        &self,
        d: Decompose,
        centred: bool,
    ) -> Result<(EnvDecomposition, f64, f64), Error> {
        let bytes = (d.turns as u64)
            .saturating_mul(self.cost.vertices as u64)
            .saturating_mul(BYTES_PER_VERTEX_TURN);
        if d.turns > MAX_TURNS || bytes > MAX_DECOMPOSITION_BYTES {
            return Err(Error::Request {
                path: std::path::PathBuf::from("decompose"),
                message: format!(
                    "{} turns of {} vertices need {:.1} GB of samples; at most {MAX_TURNS} turns \
                     and {:.0} GB (the thesis: 30 turns)",
                    d.turns,
                    self.cost.vertices,
                    bytes as f64 / 1e9,
                    MAX_DECOMPOSITION_BYTES as f64 / 1e9
                ),
            });
        }
        let start = Instant::now();
        let samples = (0..d.turns)
            .map(|a| self.weights(360.0 * a as f32 / d.turns as f32))
            .collect::<Result<Vec<_>, _>>()?;
        let samples_ms = start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let dec = EnvDecomposition::build(&samples, d.components, centred)?;
        Ok((dec, samples_ms, start.elapsed().as_secs_f64() * 1e3))
    }
}

/// W of every vertex of `object` under `lighting` (see the [module docs](self)) and its cost
/// (without the frame and γ*); through the (centred) decomposition when asked, with its error
/// against the direct update at the same turn.
///
/// # Errors
/// An object without UVs; lightsphere, visibility, hemicube and decomposition errors.
pub fn env_weights(
    pca: &BtfPca,
    object: &WorldObject,
    lighting: &EnvLighting,
) -> Result<(Vec<EnvLightWeights>, EnvCost), Error> {
    let binner = EnvBinner::new(pca, object, lighting.env, lighting.up, lighting.visibility)?;
    let mut cost = binner.cost();
    let w = match lighting.decompose {
        None => {
            let start = Instant::now();
            let w = binner.weights(lighting.rotation_deg)?;
            cost.update_ms = start.elapsed().as_secs_f64() * 1e3;
            w
        }
        Some(d) => {
            let (dec, samples_ms, build_ms) = binner.decompose(d, true)?;
            let start = Instant::now();
            let mut w = Vec::new();
            dec.weights_at(lighting.rotation_deg.to_radians(), &mut w);
            let turn_ms = start.elapsed().as_secs_f64() * 1e3;
            cost.update_ms = turn_ms;
            let direct = binner.weights(lighting.rotation_deg)?;
            cost.decomposition = Some(DecompositionCost {
                turns: d.turns,
                components: dec.components(),
                samples_ms,
                build_ms,
                turn_ms,
                error: btf::env::relative_error(&w, &direct),
                bytes: dec.bytes(),
            });
            w
        }
    };
    Ok((w, cost))
}

/// Renders `object` (with UVs) with `pca` under `lighting` ([`env_weights`]), the frame with
/// RGB γ* — on the GPU when `gpu` is given, else the CPU reference.
///
/// # Errors
/// As [`env_weights`]; rendering errors.
pub fn render_env(
    gpu: Option<&GpuContext>,
    pca: &BtfPca,
    object: &WorldObject,
    lighting: &EnvLighting,
    camera: &Camera,
    params: &RenderParams,
) -> Result<(HdrImage, EnvCost), Error> {
    let (w, mut cost) = env_weights(pca, object, lighting)?;
    let (tangents, uvs) = tangents_of(object)?;
    let mesh = btf_mesh(object, &tangents, uvs);
    let start = Instant::now();
    let (image, gamma_ms) = match gpu {
        Some(g) => {
            let mut renderer = Renderer::new(&g.device, FrameFormat::single_sample(&g.device));
            let btf =
                GpuBtfRenderer::for_frame(&g.device, &g.queue, pca, &renderer.pass_context())?;
            let t = Instant::now();
            let draw = btf.prepare_env(&mesh, &w, camera, params)?;
            let gamma_ms = t.elapsed().as_secs_f64() * 1e3;
            let background = Background::Color(params.background.to_array());
            (
                renderer.render(&g.device, &g.queue, camera, background, &[&draw])?,
                gamma_ms,
            )
        }
        None => {
            let image = btf::render::render_cpu_env(pca, &mesh, &w, camera, params)?;
            (
                HdrImage::new(camera.width, camera.height, image.to_rgba())?,
                0.0,
            )
        }
    };
    cost.render_ms = start.elapsed().as_secs_f64() * 1e3 - gamma_ms;
    cost.update_ms += gamma_ms;
    Ok((image, cost))
}
