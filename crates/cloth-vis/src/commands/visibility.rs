//! `cloth-vis visibility`: the visibility matrix M and the ambient term a_i of a mesh or of every
//! frame of an animation (paper 000), written as `.npy` arrays, a coloured `.ply` or a `.glb`,
//! and optionally rendered to a PNG or EXR image.
//!
//! Arrays keep the input's vertex order and count; a vertex used by no face has a zero normal
//! and gets a_i = NaN (and an all-zero row of M). Only the visibility computation is timed.
//!
//! Colours and images show the vertex radiance of a white Lambertian surface,
//! c_i = (1/π) Σ_j M_ij I_j ω_j (paper 000 §3.3 with the solid-angle weights of
//! [`lightsphere::Lightsphere::light_weights`]), so that a constant unit environment gives
//! c_i = a_i; without an environment the grey a_i is shown.
//!
//! Environment rotation (paper 000 §5, thesis §4.4.5: "When the environment map is rotated
//! relative to the object, the light directions are multiplied by the same rotation matrix to
//! obtain the new look-up positions"): rotating the environment by R about +Y reads I_j at the
//! look-up direction R⁻¹·l_j ([`light_radiance`]); M is not recomputed. A quarter turn maps the
//! octahedral directions onto each other, so it only permutes the I_j.
//!
//! Outputs by extension:
//! - `.npy`: a_i as f32 `[N]` (`[F, N]` for several frames), or M as `[N, k]` / `[F, N, k]`;
//! - `.ply` (one frame): positions, normals, gamma-encoded 8-bit colour, float `ao` = a_i (NaN
//!   for unused vertices);
//! - `.glb` (one frame, [`meshio::write_glb`]): positions, normals (+Y for unused vertices,
//!   glTF wants unit normals), `COLOR_0` as float linear RGB (the display colour before gamma:
//!   glTF viewers apply the display encoding), and the float attribute `_AO` = a_i, with
//!   **−1 for unused vertices** because glTF forbids NaN in accessor data;
//! - `--render FILE.png|FILE.exr`: the last frame drawn by the shared frame of crate `render` (Gouraud, both
//!   sides with c_i, the environment as backdrop when one is given) from an automatically
//!   framed camera; PNG tone-mapped with `2^EV` exposure (default: the 90th percentile of the
//!   used vertices' luminance maps to 0.8) and gamma, EXR linear. Needs a GPU adapter
//!   (lavapipe is fine).

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{DQuat, Quat, Vec3};
use gpu_context::{GpuContext, HdrImage};
use occlusion_gpu::{Backend, DepthParams, VisibilityEngine, VisibilityParams};
use render::tone::{Display, ToneCurve};
use render::{Backdrop, Background, DrawMesh, FrameFormat, Renderer, bounding_sphere};

use crate::Error;
use crate::scene::CameraDesc;

/// Where automatic exposure puts the 90th percentile of the used vertices' luminance.
const AUTO_EXPOSURE_KEY: f32 = render::tone::AUTO_EXPOSURE_KEY;
/// Default display gamma of `--render` PNGs and of `.ply` colours.
pub const DEFAULT_GAMMA: f32 = 2.2;
/// Default `--render` image size (width, height).
pub const DEFAULT_RENDER_SIZE: [u32; 2] = [768, 768];
/// `_AO` value of a vertex used by no face in a `.glb` (glTF forbids NaN).
pub const GLB_UNUSED_AO: f32 = -1.0;

/// What `cloth-vis visibility` was asked to do.
#[derive(Clone, Debug)]
pub struct VisibilityRequest {
    /// A mesh, or an animation (folder of numbered OBJ, `.npy`, animated glTF).
    pub input: PathBuf,
    /// Lightsphere level.
    pub level: u32,
    /// Backend; `None` = depth on a hardware GPU, cpu otherwise.
    pub backend: Option<Backend>,
    /// Depth-map side for the depth backend.
    pub depth_resolution: u32,
    /// Environment for colours and renders (`None` = grey ambient a_i).
    pub environment: Option<lightsphere::Environment>,
    /// Rotation of the environment about +Y relative to the object, degrees (right-handed;
    /// applied by rotated look-ups, see [`light_radiance`]). Needs `environment`.
    pub env_rotation_deg: f32,
    /// Output file: `.npy` (a_i, or M with `matrix`), `.ply` or `.glb` (mesh with colour and
    /// ambient term).
    pub out: Option<PathBuf>,
    /// Write M [N, k] instead of a_i.
    pub matrix: bool,
    /// Frames `start..end` of an animation (default all).
    pub frames: Option<(usize, usize)>,
    /// Render the last frame to this `.png` (tone-mapped) or `.exr` (linear) image.
    pub render: Option<PathBuf>,
    /// PNG exposure in stops: the multiplier is 2^EV; `None` = automatic (the 90th percentile
    /// of the used vertices' luminance maps to 0.8).
    pub exposure_ev: Option<f32>,
    /// PNG display gamma.
    pub gamma: f32,
    /// Rendered image size `[width, height]` in pixels.
    pub render_size: [u32; 2],
}

impl VisibilityRequest {
    /// A request for `input` with the command line's defaults: level 3, automatic backend,
    /// default depth resolution, no environment, no output, all frames, no render.
    pub fn new(input: PathBuf) -> Self {
        Self {
            input,
            level: 3,
            backend: None,
            depth_resolution: occlusion_gpu::DEFAULT_DEPTH_RESOLUTION,
            environment: None,
            env_rotation_deg: 0.0,
            out: None,
            matrix: false,
            frames: None,
            render: None,
            exposure_ev: None,
            gamma: DEFAULT_GAMMA,
            render_size: DEFAULT_RENDER_SIZE,
        }
    }
}

/// What was computed.
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilitySummary {
    /// Light directions k.
    pub directions: usize,
    /// Vertices per frame N.
    pub vertices: usize,
    /// Frames computed.
    pub frames: usize,
    /// Time of the visibility computation alone, all frames (ms).
    pub millis: f64,
    /// The backend that ran.
    pub backend: Backend,
}

impl VisibilitySummary {
    /// The one summary line: `visibility: K directions x N vertices in T ms (BACKEND)`.
    pub fn line(&self) -> String {
        let frames = if self.frames > 1 {
            format!(" x {} frames", self.frames)
        } else {
            String::new()
        };
        format!(
            "visibility: {} directions x {} vertices{frames} in {:.1} ms ({})",
            self.directions,
            self.vertices,
            self.millis,
            self.backend.name()
        )
    }
}

fn invalid(path: &Path, message: String) -> Error {
    Error::Request {
        path: path.to_owned(),
        message,
    }
}

/// What the output path's extension asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutKind {
    Npy,
    Ply,
    Glb,
}

/// What `--render`'s extension asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ImageKind {
    Png,
    Exr,
}

fn lower_extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// Checks everything that can be checked before loading or computing.
fn check_request(
    request: &VisibilityRequest,
    gpu: Option<&GpuContext>,
) -> Result<(Option<OutKind>, Option<ImageKind>), Error> {
    let out_kind = match &request.out {
        None => None,
        Some(p) => match (lower_extension(p).as_deref(), request.matrix) {
            (Some("npy"), _) => Some(OutKind::Npy),
            (Some("ply"), false) => Some(OutKind::Ply),
            (Some("glb"), false) => Some(OutKind::Glb),
            (Some(ext @ ("ply" | "glb")), true) => {
                return Err(invalid(
                    p,
                    format!("--matrix writes M as .npy; a .{ext} holds a_i and colours"),
                ));
            }
            _ => {
                return Err(invalid(
                    p,
                    "--out must end in .npy (a_i, or M with --matrix), .ply or .glb (mesh with \
                     colour and ambient term)"
                        .to_owned(),
                ));
            }
        },
    };
    let image_kind = match &request.render {
        None => None,
        Some(p) => {
            let kind = match lower_extension(p).as_deref() {
                Some("png") => ImageKind::Png,
                Some("exr") => ImageKind::Exr,
                _ => {
                    return Err(invalid(
                        p,
                        "--render must end in .png (tone-mapped) or .exr (linear radiance)"
                            .to_owned(),
                    ));
                }
            };
            if gpu.is_none() {
                return Err(invalid(
                    p,
                    "--render needs a GPU adapter and none was found; a software one is fine \
                     (Mesa's lavapipe: apt-get install mesa-vulkan-drivers)"
                        .to_owned(),
                ));
            }
            let [w, h] = request.render_size;
            if w == 0 || h == 0 || w > MAX_RENDER_SIDE || h > MAX_RENDER_SIDE {
                return Err(invalid(
                    p,
                    format!("--render-size {w}x{h}: each side must be 1..={MAX_RENDER_SIDE}"),
                ));
            }
            if !(request.gamma.is_finite() && request.gamma > 0.0) {
                return Err(invalid(
                    p,
                    format!("--gamma {} must be finite and > 0", request.gamma),
                ));
            }
            let ev = request.exposure_ev.unwrap_or(0.0);
            if !(ev.is_finite() && ev.abs() <= MAX_EXPOSURE_EV) {
                return Err(invalid(
                    p,
                    format!("--exposure {ev} must be finite, within ±{MAX_EXPOSURE_EV} stops"),
                ));
            }
            Some(kind)
        }
    };
    let rotation = request.env_rotation_deg;
    if !rotation.is_finite() {
        return Err(invalid(
            &request.input,
            format!("--env-rotation {rotation} must be finite (degrees)"),
        ));
    }
    if rotation != 0.0 && request.environment.is_none() {
        return Err(invalid(
            &request.input,
            format!("--env-rotation {rotation} rotates an environment: pass --env FILE or --sky"),
        ));
    }
    Ok((out_kind, image_kind))
}

/// Largest `--render-size` side (wgpu's guaranteed 2D texture limit).
const MAX_RENDER_SIDE: u32 = 8192;
/// Largest `--exposure` magnitude in stops (2^±64 covers every f32 radiance range).
const MAX_EXPOSURE_EV: f32 = 64.0;

/// Run the request. `gpu` is needed for the depth backend and for `render`.
///
/// # Errors
/// Loader, engine and output errors, naming the file; an unsupported output or image
/// extension, a frame range outside the animation, a multi-frame `.ply`/`.glb`, `render`
/// without a GPU adapter and `env_rotation_deg` without an environment are refused before any
/// computation.
pub fn run_visibility(
    request: &VisibilityRequest,
    gpu: Option<&GpuContext>,
) -> Result<VisibilitySummary, Error> {
    let input = &request.input;
    let (out_kind, image_kind) = check_request(request, gpu)?;
    let sphere = lightsphere::Lightsphere::new(request.level)?;
    let (frames, triangles) = load_frames(input)?;
    let (start, end) = request.frames.unwrap_or((0, frames.len()));
    if start >= end || end > frames.len() {
        return Err(invalid(
            input,
            format!(
                "--frames {start}..{end} is outside the {} frames (0..{})",
                frames.len(),
                frames.len()
            ),
        ));
    }
    let one_frame_ext = match out_kind {
        Some(OutKind::Ply) => Some("ply"),
        Some(OutKind::Glb) => Some("glb"),
        _ => None,
    };
    if let Some(ext) = one_frame_ext.filter(|_| end - start != 1) {
        return Err(invalid(
            input,
            format!("a .{ext} output holds one frame: pass --frames A..A+1"),
        ));
    }
    let backend = request.backend.unwrap_or(match gpu {
        Some(g) if !g.summary().is_software => Backend::Depth,
        _ => Backend::Cpu,
    });
    let params = VisibilityParams::default()
        .with_depth(DepthParams::default().with_resolution(request.depth_resolution));
    let mut engine = match (backend, gpu) {
        (Backend::Cpu, _) => VisibilityEngine::cpu(params),
        (other, Some(g)) => VisibilityEngine::with_gpu(&g.device, &g.queue, other, params),
        (other, None) => {
            return Err(invalid(
                input,
                format!(
                    "backend {} needs a GPU adapter; use --backend cpu",
                    other.name()
                ),
            ));
        }
    };
    let n = frames[0].len();
    let mut ambient = Vec::with_capacity((end - start) * n);
    let mut matrices = Vec::new();
    let mut last = None;
    let mut millis = 0.0;
    for positions in &frames[start..end] {
        let normals =
            meshio::compute_normals(positions, &triangles, meshio::NormalWeighting::Angle);
        let scene = occlusion_gpu::Scene::single(positions.clone(), normals, triangles.clone())?;
        let t = Instant::now();
        let m = engine.compute(&scene, &sphere)?;
        millis += t.elapsed().as_secs_f64() * 1e3;
        ambient.extend(m.ambient());
        if request.matrix {
            matrices.extend(m.to_dense());
        }
        last = Some((positions, m));
    }
    let count = end - start;
    let k = sphere.len();
    let Some((positions, m)) = last else {
        unreachable!("the frame range is non-empty");
    };
    let last_ambient = &ambient[(count - 1) * n..];
    let radiance = match (&request.environment, out_kind, image_kind) {
        (_, Some(OutKind::Npy) | None, None) => None,
        (Some(env), _, _) => {
            let light = light_radiance(env, &sphere, request.env_rotation_deg)?;
            Some(vertex_radiance(&m, &sphere, &light)?)
        }
        (None, _, _) => Some(
            last_ambient
                .iter()
                .map(|a| Vec3::splat(if a.is_finite() { *a } else { 0.0 }))
                .collect::<Vec<_>>(),
        ),
    };
    match (out_kind, &request.out, &radiance) {
        (Some(OutKind::Npy), Some(path), _) => {
            if request.matrix {
                let shape: Vec<usize> = if count > 1 {
                    vec![count, n, k]
                } else {
                    vec![n, k]
                };
                meshio::write_npy_f32(path, &shape, &matrices)?;
            } else {
                let shape: Vec<usize> = if count > 1 { vec![count, n] } else { vec![n] };
                meshio::write_npy_f32(path, &shape, &ambient)?;
            }
        }
        (Some(OutKind::Ply), Some(path), Some(c)) => {
            let colours = display_colours(c);
            write_ply(
                path,
                positions,
                m.normals(),
                &triangles,
                &colours,
                last_ambient,
            )?;
        }
        (Some(OutKind::Glb), Some(path), Some(c)) => {
            write_glb(path, positions, m.normals(), &triangles, c, last_ambient)?;
        }
        _ => {}
    }
    if let (Some(kind), Some(path), Some(gpu), Some(c)) =
        (image_kind, &request.render, gpu, &radiance)
    {
        let image = render_vertices(request, gpu, positions, &triangles, c)?;
        match kind {
            ImageKind::Png => {
                let exposure_ev = match request.exposure_ev {
                    Some(ev) => ev,
                    None => auto_exposure(c, m.normals()).log2(),
                };
                // `--gamma` keeps the seed's clamp-then-gamma mapping for this command.
                let display = Display {
                    exposure_ev,
                    curve: ToneCurve::Clamp {
                        gamma: request.gamma,
                    },
                };
                render::output::write_png(&image, path, &display, Background::Environment)?;
            }
            ImageKind::Exr => render::output::write_exr(&image, path, Background::Environment)?,
        }
    }
    Ok(VisibilitySummary {
        directions: k,
        vertices: n,
        frames: count,
        millis,
        backend,
    })
}

/// Radiance per light direction I_j of `env` rotated by `env_rotation_deg` about +Y relative
/// to the object (on top of the environment's own `world_from_env`), by rotated look-ups:
/// I_j is the environment's cell mean ([`lightsphere::RadianceMethod::CellMean`]) around the
/// look-up direction R⁻¹·l_j, with R = rotation about +Y by `env_rotation_deg` (the seed's
/// "light directions are multiplied by the same rotation matrix"). Equals
/// `env.with_rotation(R · env.world_from_env()).radiance_per_direction(sphere, CellMean)` up
/// to rounding, and the visibility matrix M (indexed by the unrotated l_j) is reused as is.
///
/// # Errors
/// [`Error::Light`] for a non-finite angle.
pub fn light_radiance(
    env: &lightsphere::Environment,
    sphere: &lightsphere::Lightsphere,
    env_rotation_deg: f32,
) -> Result<Vec<Vec3>, Error> {
    let lookup = if env_rotation_deg == 0.0 {
        sphere.clone()
    } else {
        sphere.try_rotated(env_rotation(env_rotation_deg).inverse())?
    };
    Ok(env.radiance_per_direction(&lookup, lightsphere::RadianceMethod::CellMean)?)
}

/// `world_from_rotated_env`: the rotation by `deg` about +Y, built in f64 so that quarter turns
/// map the octahedral directions onto each other to f64 rounding.
pub fn env_rotation(deg: f32) -> Quat {
    DQuat::from_rotation_y(f64::from(deg).to_radians()).as_quat()
}

/// Vertex radiance of a white Lambertian surface: c_i = (1/π) Σ_j M_ij I_j ω_j (NaN for
/// vertices used by no face).
///
/// # Errors
/// When `light` does not have one value per direction of `sphere`.
pub fn vertex_radiance(
    m: &occlusion_gpu::VisibilityMatrix,
    sphere: &lightsphere::Lightsphere,
    light: &[Vec3],
) -> Result<Vec<Vec3>, Error> {
    let weights = sphere.light_weights(light)?;
    Ok(m.radiance(&weights)?
        .into_iter()
        .map(|c| c / std::f32::consts::PI)
        .collect())
}

/// Draw one frame with per-vertex radiance `c` (both sides) over the environment backdrop.
fn render_vertices(
    request: &VisibilityRequest,
    gpu: &GpuContext,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    c: &[Vec3],
) -> Result<HdrImage, Error> {
    let used: Vec<Vec3> = triangles
        .iter()
        .flatten()
        .map(|&i| positions[i as usize])
        .collect();
    let (centre, radius) = bounding_sphere(&used).unwrap_or((Vec3::ZERO, 1.0));
    let desc = CameraDesc {
        width: request.render_size[0],
        height: request.render_size[1],
        ..CameraDesc::default()
    };
    let camera = crate::camera::resolve(&desc, centre, radius);
    let colours: Vec<Vec3> = c
        .iter()
        .map(|v| if v.is_finite() { *v } else { Vec3::ZERO })
        .collect();
    let mesh = DrawMesh {
        positions,
        triangles,
        front: &colours,
        back: &colours,
    };
    let backdrop = request.environment.as_ref().map(|env| Backdrop {
        width: env.width(),
        height: env.height(),
        texels: env.texels(),
        world_from_env: env_rotation(request.env_rotation_deg) * env.world_from_env(),
    });
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(gpu));
    let background = if backdrop.is_some() {
        Background::Environment
    } else {
        Background::Color([0.0; 3])
    };
    renderer.backdrop.set_environment(&gpu.device, backdrop);
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, &[mesh])?;
    Ok(renderer.render(&gpu.device, &gpu.queue, &camera, background, &[])?)
}

type Frames = (Vec<Vec<Vec3>>, Vec<[u32; 3]>);

fn load_frames(input: &Path) -> Result<Frames, Error> {
    let ext = |e: &str| input.extension().is_some_and(|x| x.eq_ignore_ascii_case(e));
    if input.is_dir() || ext("npy") || ext("glb") || ext("gltf") {
        if let Ok((anim, _)) = meshio::load_animation(input, &meshio::AnimationOptions::default()) {
            if !anim.triangles.is_empty() {
                return Ok((anim.frames, anim.triangles));
            }
            return Err(invalid(
                input,
                "an .npy animation has no triangles; pass a mesh as the input instead".to_owned(),
            ));
        }
    }
    let (mesh, _) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
    Ok((vec![mesh.positions], mesh.triangles))
}

/// The exposure multiplier that maps the 90th percentile of the luminance of `c` over used
/// vertices (non-zero normal) to [`AUTO_EXPOSURE_KEY`]; 1 when no vertex is lit.
fn auto_exposure(c: &[Vec3], normals: &[Vec3]) -> f32 {
    let lum = c
        .iter()
        .zip(normals)
        .filter(|(_, n)| **n != Vec3::ZERO)
        .map(|(v, _)| render::tone::luminance(v.to_array()));
    render::tone::auto_exposure_ev(
        lum,
        render::tone::AUTO_EXPOSURE_PERCENTILE,
        AUTO_EXPOSURE_KEY,
    )
    .map_or(1.0, f32::exp2)
}

/// Linear display colours: radiance scaled so that the 90th percentile of luminance is 0.8,
/// clamped to [0, 1]; black for non-finite radiance (unused vertices).
fn linear_display_colours(c: &[Vec3]) -> Vec<Vec3> {
    let lum = c.iter().map(|v| render::tone::luminance(v.to_array()));
    let scale = render::tone::auto_exposure_ev(
        lum,
        render::tone::AUTO_EXPOSURE_PERCENTILE,
        AUTO_EXPOSURE_KEY,
    )
    .map_or(1.0, f32::exp2);
    c.iter()
        .map(|v| {
            if v.is_finite() {
                (*v * scale).clamp(Vec3::ZERO, Vec3::ONE)
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Map radiance to display colours: the 90th percentile of luminance to 0.8, gamma 2.2.
fn display_colours(c: &[Vec3]) -> Vec<Vec3> {
    linear_display_colours(c)
        .into_iter()
        .map(|v| v.powf(1.0 / DEFAULT_GAMMA))
        .collect()
}

/// glTF binary with positions, normals (+Y for unused vertices), linear `COLOR_0` and `_AO`
/// (−1 for unused vertices), written atomically.
fn write_glb(
    path: &Path,
    positions: &[Vec3],
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    c: &[Vec3],
    ambient: &[f32],
) -> Result<(), Error> {
    let normals: Vec<Vec3> = normals
        .iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect();
    let colours = linear_display_colours(c);
    let ao: Vec<f32> = ambient
        .iter()
        .map(|a| if a.is_finite() { *a } else { GLB_UNUSED_AO })
        .collect();
    let mesh = meshio::GlbMesh::new(positions, triangles)
        .with_normals(&normals)
        .with_colors(&colours)
        .with_attribute("_AO", &ao);
    meshio::write_glb(path, &mesh)?;
    Ok(())
}

/// Binary little-endian PLY with positions, normals, 8-bit colour and a float `ao`, written
/// atomically.
fn write_ply(
    path: &Path,
    positions: &[Vec3],
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    colours: &[Vec3],
    ambient: &[f32],
) -> Result<(), Error> {
    meshio::write_atomic(path, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment cloth-vis visibility: ao = a_i (NaN: vertex used by no face)\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float ao\n\
             element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            positions.len(),
            triangles.len()
        )?;
        for i in 0..positions.len() {
            for v in positions[i]
                .to_array()
                .into_iter()
                .chain(normals[i].to_array())
            {
                w.write_all(&v.to_le_bytes())?;
            }
            let c = colours[i]
                .to_array()
                .map(|x| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8);
            w.write_all(&c)?;
            w.write_all(&ambient[i].to_le_bytes())?;
        }
        for t in triangles {
            w.write_all(&[3u8])?;
            for v in t {
                w.write_all(&v.to_le_bytes())?;
            }
        }
        Ok(())
    })?;
    Ok(())
}
