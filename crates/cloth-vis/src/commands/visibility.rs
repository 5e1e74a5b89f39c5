//! `cloth-vis visibility`: the visibility matrix M and the ambient term a_i of a mesh or of every
//! frame of an animation (paper 000), written as `.npy` arrays, a coloured `.ply` or a `.glb`,
//! and optionally rendered to a PNG or EXR image.
//!
//! It is a one-object scene ([`Scene::one_object`]) run through the library's stages: the
//! geometry loader, the light directions, [`VisibilityStage`] (one engine for every frame),
//! [`shadowed_radiance`] and [`render_still_image`] — the same code `cloth-vis render` runs,
//! with this command's outputs on top.
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
//! look-up direction R⁻¹·l_j ([`cloth_vis::lighting::rotated_lookup_radiance`]); M is not
//! recomputed. The command rotates the environment itself by the same f64-built rotation
//! ([`environment_rotation`]), which equals the rotated look-ups to rounding (tested) and turns
//! the backdrop with it. A quarter turn maps the octahedral directions onto each other, so it
//! only permutes the I_j.
//!
//! Outputs by extension:
//! - `.npy`: a_i as f32 `[N]` (`[F, N]` for several frames; NaN for vertices no triangle
//!   uses, as in `.ply`), or M as `[N, k]` / `[F, N, k]` (rows of unused vertices 0);
//! - `.ply` (one frame): positions, normals, gamma-encoded 8-bit colour, float `ao` = a_i (NaN
//!   for unused vertices);
//! - `.glb` (one frame, [`meshio::write_glb`]): positions, normals (+Y for unused vertices,
//!   glTF wants unit normals), `COLOR_0` as float linear RGB (the display colour before gamma:
//!   glTF viewers apply the display encoding), and the float attribute `_AO` = a_i, with
//!   **−1 for unused vertices** because glTF forbids NaN in accessor data;
//! - `--render FILE.png|FILE.exr`: the last frame drawn by the shared frame of crate `render` (Gouraud, both
//!   sides with c_i, the environment as backdrop when one is given) from an automatically
//!   framed camera; PNG tone-mapped with `2^EV` exposure (default: automatic, the 90th
//!   percentile of the object's pixels' brightest channel maps to 0.8, the backdrop never
//!   counts) and
//!   clamp-then-gamma, EXR linear. Needs a GPU adapter
//!   (lavapipe is fine).

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use super::up_axis::{UpAxis, turn_camera, up_axis_rotation};
use super::{invalid, output_size};
use cloth_vis::Error;
use cloth_vis::lighting::{environment_rotation, shadowed_radiance};
use cloth_vis::run::{progress_bar, render_still_image};
use cloth_vis::scene::{
    AutoKeyword, BackgroundDesc, BackgroundKeyword, ExposureDesc, Scene, ToneDesc,
    VisibilityBackendDesc,
};
use cloth_vis::shadowing::VisibilityStage;
use glam::Vec3;
use gpu_context::GpuContext;
use occlusion_gpu::Backend;

/// Where the colours of `.ply`/`.glb` outputs put the 90th percentile of the vertices'
/// brightest channel.
const AUTO_EXPOSURE_KEY: f32 = render::tone::AUTO_EXPOSURE_KEY;
/// Default display gamma of `--render` PNGs and of `.ply` colours.
pub const DEFAULT_GAMMA: f32 = 2.2;
/// Default `--render-size` (width x height).
pub(super) const DEFAULT_RENDER_SIZE: &str = "768x768";
/// `_AO` value of a vertex used by no face in a `.glb` (glTF forbids NaN).
pub const GLB_UNUSED_AO: f32 = -1.0;

/// What `cloth-vis visibility` was asked to do.
#[derive(Clone, Debug)]
pub struct VisibilityRequest {
    /// A mesh, or an animation (folder of numbered OBJ, `.npy`, animated glTF).
    pub input: PathBuf,
    /// A mesh whose triangles a point-cache input (`.npy`, `.pc2`, `.mdd`) takes.
    pub topology: Option<PathBuf>,
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
    /// of the pixels' brightest channel maps to 0.8).
    pub exposure_ev: Option<f32>,
    /// PNG display gamma.
    pub gamma: f32,
    /// Rendered image size `[width, height]` in pixels.
    pub render_size: [u32; 2],
    /// The input's up axis (`+Y` for most tools, `+Z` for CAD and Blender exports): the
    /// environment's zenith and the render camera's up are turned onto it
    /// ([`up_axis_rotation`]); positions, normals, a_i and M stay in the input's frame.
    pub up_axis: UpAxis,
    /// A progress bar over the frames of an animation on stderr.
    pub progress: bool,
    /// Write an output estimated above [`output_size::REFUSE_BYTES`] anyway.
    pub force: bool,
}

#[cfg(test)]
impl VisibilityRequest {
    /// A request for `input` with the command line's defaults: level 3, automatic backend,
    /// default depth resolution, no environment, no output, all frames, no render.
    pub fn new(input: PathBuf) -> Self {
        Self {
            input,
            topology: None,
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
            render_size: super::parse::size(DEFAULT_RENDER_SIZE).expect("the default parses"),
            up_axis: UpAxis::PosY,
            progress: false,
            force: false,
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
    /// Vertices without a normal in the last frame — used by no triangle, or neither their
    /// triangles nor their neighbours give a direction (`meshio::compute_normals`): a_i is
    /// NaN for them (−1 in `.glb`), their rows of M 0.
    pub unused: usize,
    /// Frames computed.
    pub frames: usize,
    /// Time of the visibility computation alone, all frames (ms).
    pub millis: f64,
    /// The backend that ran.
    pub backend: Backend,
}

impl VisibilitySummary {
    /// The one summary line: `visibility: K directions x N vertices in T ms (BACKEND)`, and
    /// where some vertices have no normal, how many (their a_i is NaN).
    pub fn line(&self) -> String {
        let frames = if self.frames > 1 {
            format!(" x {} frames", self.frames)
        } else {
            String::new()
        };
        let unused = match self.unused {
            0 => String::new(),
            n => format!(
                "; {n} {} without a normal (used by no triangle, or neither their triangles nor \
                 their neighbours give a direction): a_i = NaN (-1 in .glb)",
                if n == 1 { "vertex" } else { "vertices" }
            ),
        };
        format!(
            "visibility: {} directions x {} vertices{frames} in {:.1} ms ({}){unused}",
            self.directions,
            self.vertices,
            self.millis,
            self.backend.name()
        )
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
pub(super) enum ImageKind {
    Png,
    Exr,
}

pub(super) fn lower_extension(path: &Path) -> Option<String> {
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
        Some(p) => Some(check_render(
            p,
            gpu,
            request.render_size,
            request.gamma,
            request.exposure_ev,
        )?),
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

/// Checks a `--render` request (`path`'s extension, an adapter, the size, gamma and exposure)
/// before any work; returns what the extension asks for.
pub(super) fn check_render(
    path: &Path,
    gpu: Option<&GpuContext>,
    [w, h]: [u32; 2],
    gamma: f32,
    exposure_ev: Option<f32>,
) -> Result<ImageKind, Error> {
    let kind = match lower_extension(path).as_deref() {
        Some("png") => ImageKind::Png,
        Some("exr") => ImageKind::Exr,
        _ => {
            return Err(invalid(
                path,
                "--render must end in .png (tone-mapped) or .exr (linear radiance)".to_owned(),
            ));
        }
    };
    if gpu.is_none() {
        return Err(invalid(
            path,
            "--render needs a GPU adapter and none was found; a software one is fine \
             (Mesa's lavapipe: apt-get install mesa-vulkan-drivers)"
                .to_owned(),
        ));
    }
    if w == 0 || h == 0 || w > MAX_RENDER_SIDE || h > MAX_RENDER_SIDE {
        return Err(invalid(
            path,
            format!("--render-size {w}x{h}: each side must be 1..={MAX_RENDER_SIDE}"),
        ));
    }
    if !(gamma.is_finite() && gamma > 0.0) {
        return Err(invalid(
            path,
            format!("--gamma {gamma} must be finite and > 0"),
        ));
    }
    let ev = exposure_ev.unwrap_or(0.0);
    if !(ev.is_finite() && ev.abs() <= MAX_EXPOSURE_EV) {
        return Err(invalid(
            path,
            format!("--exposure {ev} must be finite, within ±{MAX_EXPOSURE_EV} stops"),
        ));
    }
    Ok(kind)
}

/// Largest `--render-size` side (wgpu's guaranteed 2D texture limit).
const MAX_RENDER_SIDE: u32 = 8192;
/// Largest `--exposure` magnitude in stops (2^±64 covers every f32 radiance range).
const MAX_EXPOSURE_EV: f32 = 64.0;

/// The one-object scene the request describes: the input as a white one-sided object, the
/// lightsphere level, the visibility backend and depth resolution, an automatically framed
/// camera of the render size, and the display mapping of `--render` PNGs (the seed's
/// clamp-then-gamma with `--gamma`, exposure `--exposure` or automatic from the object's
/// pixels; the backdrop when an environment is given, else black).
fn one_object_scene(request: &VisibilityRequest) -> Result<Scene, Error> {
    let mut scene = display_scene(
        &request.input,
        request.topology.as_deref(),
        "cloth-vis visibility",
        request.render_size,
        request.exposure_ev,
        request.gamma,
    )?;
    scene.lighting.level = request.level;
    scene.visibility.backend = match request.backend {
        None => VisibilityBackendDesc::Auto,
        Some(Backend::Cpu) => VisibilityBackendDesc::Cpu,
        Some(Backend::Depth) => VisibilityBackendDesc::Depth,
        Some(Backend::Query) => VisibilityBackendDesc::Query,
        Some(Backend::Rays) => VisibilityBackendDesc::Rays,
    };
    scene.visibility.depth_resolution = request.depth_resolution;
    turn_camera(&mut scene.camera, request.up_axis);
    Ok(scene)
}

/// The one-object scene a per-vertex command displays: `input` (with `topology` for a point
/// cache) as a white object, an automatically framed camera of `render_size`, the seed's
/// clamp-then-gamma PNGs with exposure `exposure_ev` (automatic when `None`), the environment
/// as backdrop.
pub(super) fn display_scene(
    input: &Path,
    topology: Option<&Path>,
    origin: &str,
    render_size: [u32; 2],
    exposure_ev: Option<f32>,
    gamma: f32,
) -> Result<Scene, Error> {
    let mut scene = Scene::one_object(input, origin)?;
    if let Some(topology) = topology {
        scene.objects[0].topology = Some(
            topology
                .to_str()
                .ok_or_else(|| invalid(topology, "the path is not valid UTF-8".to_owned()))?
                .to_owned(),
        );
    }
    scene.camera.width = render_size[0];
    scene.camera.height = render_size[1];
    scene.output.exposure = match exposure_ev {
        Some(ev) => ExposureDesc::Fixed(ev),
        None => ExposureDesc::Auto(AutoKeyword::Auto),
    };
    scene.output.tone = ToneDesc::Clamp;
    scene.output.gamma = gamma;
    scene.output.background = BackgroundDesc::Named(BackgroundKeyword::Environment);
    Ok(scene)
}

/// Run the request as a one-object scene through the library's stages (geometry, light
/// directions, visibility, lighting, render). `gpu` is needed for the depth backend and for
/// `render`.
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
    for output in request.out.iter().chain(&request.render) {
        super::check_output_file(output, &[input])?;
    }
    let (out_kind, image_kind) = check_request(request, gpu)?;
    let scene = one_object_scene(request)?;
    let sphere = lightsphere::Lightsphere::new(request.level)?;
    let (mut objects, _) = cloth_vis::inputs::load_geometry(&scene, false)?;
    let object = &objects[0];
    if object.triangles.is_empty() {
        return Err(invalid(
            input,
            "the input has no triangles (a point cache — .npy, .pc2, .mdd — carries none): \
             add --topology MESH, a mesh with the same vertices"
                .to_owned(),
        ));
    }
    let total = object.frame_count();
    let (start, end) = request.frames.unwrap_or((0, total));
    if start >= end || end > total {
        return Err(invalid(
            input,
            format!("--frames {start}..{end} is outside the {total} frames (0..{total})"),
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
    let mut stage = VisibilityStage::new(&scene, gpu).map_err(|e| invalid(input, e.to_string()))?;
    // Rotating the environment turns its backdrop and its I_j alike; M is computed once.
    // With another up axis the zenith turns onto it and --env-rotation turns about it.
    let environment = request
        .environment
        .clone()
        .map(|env| turned_environment(env, request.up_axis, request.env_rotation_deg));
    let light = match &environment {
        Some(env) => Some(cloth_vis::inputs::light_directions(&scene, env)?.0.1),
        None => None,
    };
    let n = objects[0].positions.len();
    let k = sphere.len();
    let count = end - start;
    if let (Some(path), true) = (&request.out, request.matrix) {
        let bytes = (count * n) as u64 * k as u64 * 4;
        let levers = "lower --level or pass fewer --frames";
        if let Some(line) = output_size::check(path, "M", bytes, levers, request.force)? {
            eprintln!("{line}");
        }
    }
    let mut ambient = Vec::with_capacity(count * n);
    let mut matrices = Vec::new();
    let mut last = None;
    let mut millis = 0.0;
    let bar = progress_bar(request.progress && count > 1, count as u64, "frames");
    let what = format!(
        "visibility: {k} directions x {n} vertices ({})",
        stage.backend().name()
    );
    let step = super::engine_bar(request.progress && count == 1, &mut stage, what);
    for frame in start..end {
        objects[0].pose(frame);
        let t = Instant::now();
        let (visibility, _) = stage.compute(&objects, &sphere)?;
        millis += t.elapsed().as_secs_f64() * 1e3;
        ambient.extend(visibility.matrix().ambient());
        if request.matrix {
            matrices.extend(visibility.matrix().to_dense());
        }
        last = Some(visibility);
        bar.inc(1);
    }
    bar.finish_and_clear();
    step.finish_and_clear();
    let visibility = last.ok_or_else(|| invalid(input, "no frame to compute".to_owned()))?;
    let last_ambient = &ambient[(count - 1) * n..];
    // c_i = (1/π) Σ_j M_ij I_j ω_j of a white surface (NaN for unused vertices), or the grey
    // ambient term a_i without an environment.
    let radiance = match (&light, out_kind, image_kind) {
        (_, Some(OutKind::Npy) | None, None) => None,
        (Some(light), _, _) => Some(shadowed_radiance(visibility.matrix(), &sphere, light)?),
        (None, _, _) => Some(last_ambient.iter().map(|a| Vec3::splat(*a)).collect()),
    };
    let positions = &objects[0].positions;
    let normals = visibility.matrix().normals();
    let triangles = &objects[0].triangles;
    match (out_kind, &request.out, &radiance) {
        (Some(OutKind::Npy), Some(path), _) => {
            if request.matrix {
                let shape: Vec<usize> = if count > 1 {
                    vec![count, n, k]
                } else {
                    vec![n, k]
                };
                meshio::write_npy_f32(path, &shape, &matrices)?;
                // Beside M, what it needs outside the tool: l_j and ω_j (a_i = Σ_j M_ij ω_j / π).
                let (directions, weights) = matrix_sidecars(path);
                let dirs: Vec<f32> = sphere
                    .directions()
                    .iter()
                    .flat_map(|d| d.to_array())
                    .collect();
                meshio::write_npy_f32(&directions, &[k, 3], &dirs)?;
                let omega: Vec<f32> = sphere.solid_angles().iter().map(|w| *w as f32).collect();
                meshio::write_npy_f32(&weights, &[k], &omega)?;
            } else {
                let shape: Vec<usize> = if count > 1 { vec![count, n] } else { vec![n] };
                meshio::write_npy_f32(path, &shape, &ambient)?;
            }
        }
        (Some(OutKind::Ply), Some(path), Some(c)) => {
            let colours = display_colours(c);
            write_ply(
                path,
                "cloth-vis visibility: ao = a_i (NaN: vertex used by no face)",
                positions,
                normals,
                triangles,
                &colours,
                last_ambient,
            )?;
        }
        (Some(OutKind::Glb), Some(path), Some(c)) => {
            write_glb(path, positions, normals, triangles, c, last_ambient)?;
        }
        _ => {}
    }
    if let (Some(kind), Some(path), Some(gpu), Some(c)) =
        (image_kind, &request.render, gpu, &radiance)
    {
        let lit: Vec<Vec3> = c
            .iter()
            .map(|v| if v.is_finite() { *v } else { Vec3::ZERO })
            .collect();
        objects[0].front = Some(lit.clone());
        objects[0].back = Some(lit);
        let (image, display, background) =
            render_still_image(&scene, gpu, &objects, environment.as_ref())?;
        match kind {
            ImageKind::Png => render::output::write_png(&image, path, &display, background)?,
            ImageKind::Exr => render::output::write_exr(&image, path, background)?,
        }
    }
    Ok(VisibilitySummary {
        directions: k,
        vertices: n,
        unused: last_ambient.iter().filter(|a| a.is_nan()).count(),
        frames: count,
        millis,
        backend: stage.backend(),
    })
}

/// Linear display colours: radiance scaled so that the 90th percentile of the brightest
/// channel is 0.8 (as the pictures' automatic exposure), clamped to [0, 1]; black for
/// non-finite radiance (unused vertices).
pub(super) fn linear_display_colours(c: &[Vec3]) -> Vec<Vec3> {
    let peaks = c.iter().map(|v| render::tone::peak(v.to_array()));
    let scale = render::tone::auto_exposure_ev(
        peaks,
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

/// Map radiance to display colours: the 90th percentile of the brightest channel to 0.8,
/// gamma 2.2.
pub(super) fn display_colours(c: &[Vec3]) -> Vec<Vec3> {
    linear_display_colours(c)
        .into_iter()
        .map(|v| v.powf(1.0 / DEFAULT_GAMMA))
        .collect()
}

/// glTF binary with positions, normals (+Y for unused vertices), linear `COLOR_0` and `_AO`
/// (−1 for unused vertices), written atomically.
pub(super) fn write_glb(
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
pub(super) fn write_ply(
    path: &Path,
    comment: &str,
    positions: &[Vec3],
    normals: &[Vec3],
    triangles: &[[u32; 3]],
    colours: &[Vec3],
    ambient: &[f32],
) -> Result<(), Error> {
    atomic_out::write_with(path, |w| {
        write!(
            w,
            "ply\nformat binary_little_endian 1.0\ncomment {comment}\n\
             element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float ao\n\
             element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
            positions.len(),
            triangles.len(),
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

/// `cloth-vis visibility`: the flags of a [`VisibilityRequest`].
#[derive(clap::Args)]
pub struct VisibilityArgs {
    /// A mesh (.ply .obj .gltf .glb), an animation (folder of numbered .obj, .glb; point
    /// caches .npy, .pc2, .mdd with --topology) or synth:cloth (the demo's simulated drape).
    input: PathBuf,
    /// A mesh (.ply .obj .gltf .glb) whose triangles a point-cache input (.npy, .pc2, .mdd)
    /// takes; its vertex count must match.
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// Lightsphere level s (k = 2 + 4^(s+1) directions).
    #[arg(long, default_value_t = 3)]
    level: u32,
    /// Backend: depth (GPU depth maps), query (the published per-vertex occlusion
    /// queries; slow, N·k draws), cpu (exact ray casting) or rays (the same exact rays cast
    /// on the GPU); default depth on a hardware GPU, cpu otherwise.
    #[arg(long, value_parser = ["depth", "query", "cpu", "rays"])]
    backend: Option<String>,
    /// Depth-map side for the depth and query backends.
    #[arg(long, default_value_t = occlusion_gpu::DEFAULT_DEPTH_RESOLUTION)]
    depth_res: u32,
    #[command(flatten)]
    environment: super::env_args::EnvironmentArgs,
    /// Output: .npy (a_i as f32 [N] or [F, N], NaN for unused vertices; M as [N, k] or
    /// [F, N, k] with --matrix, rows of unused vertices 0), .ply (one frame: colour, float
    /// `ao` = a_i, NaN for unused vertices) or .glb (one frame: linear float COLOR_0, float
    /// `_AO` = a_i, -1 for unused vertices). Unused: without a normal, because no triangle
    /// uses them (the Stanford bunny has 1,113) or neither their triangles nor their
    /// neighbours give a direction.
    #[arg(long, short = 'o')]
    out: Option<PathBuf>,
    /// Write the matrix M (M_ij = n_i·l_j where vertex i sees direction j, else 0) instead of
    /// a_i (.npy only), with STEM.directions.npy (l_j, f32 [k, 3], world +Y up) and
    /// STEM.weights.npy (ω_j, f32 [k], summing to 4π) beside it: a_i = Σ_j M_ij ω_j / π.
    #[arg(long)]
    matrix: bool,
    /// Frames A..B of an animation (end exclusive).
    #[arg(long, value_parser = super::parse::range)]
    frames: Option<(usize, usize)>,
    /// Render the last frame with its vertex radiance: FILE.png (tone-mapped) or FILE.exr
    /// (linear HDR). Needs a GPU adapter (lavapipe is fine).
    #[arg(long, value_name = "FILE")]
    render: Option<PathBuf>,
    /// PNG exposure in stops (multiplier 2^EV); default: auto (the 90th percentile of the
    /// object's pixels' brightest channel maps to 0.8).
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// PNG display gamma.
    #[arg(long, value_name = "G", default_value_t = DEFAULT_GAMMA)]
    gamma: f32,
    /// Rendered image size.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = DEFAULT_RENDER_SIZE)]
    render_size: [u32; 2],
    /// Hide the progress bar over the frames of an animation.
    #[arg(long)]
    quiet: bool,
    /// Write a --matrix output estimated above 8 GiB anyway (one from 1 GiB on is announced).
    #[arg(long)]
    force: bool,
}

impl VisibilityArgs {
    /// Load the environment the flags name, compute, write; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let environment = self.environment.load()?;
        let backend = self.backend.as_deref().map(|b| match b {
            "cpu" => Backend::Cpu,
            "query" => Backend::Query,
            "rays" => Backend::Rays,
            _ => Backend::Depth,
        });
        let gpu = match backend {
            Some(Backend::Cpu) if self.render.is_none() => None,
            // A GPU backend without an adapter fails here, with gpu-context's advice.
            Some(Backend::Depth | Backend::Query | Backend::Rays) => {
                Some(GpuContext::new(&gpu_context::GpuOptions::default())?)
            }
            _ => match &self.render {
                Some(path) => Some(super::required_gpu(path, "--render")?),
                None => super::optional_gpu(),
            },
        };
        let request = VisibilityRequest {
            input: self.input,
            topology: self.topology,
            level: self.level,
            backend,
            depth_resolution: self.depth_res,
            environment,
            env_rotation_deg: self.environment.env_rotation,
            out: self.out,
            matrix: self.matrix,
            frames: self.frames,
            render: self.render,
            exposure_ev: self.exposure,
            gamma: self.gamma,
            render_size: self.render_size,
            up_axis: self.environment.up_axis,
            progress: !self.quiet,
            force: self.force,
        };
        let line = run_visibility(&request, gpu.as_ref())?.line();
        let outputs = [&request.out, &request.render];
        super::print_summary(&line, outputs.into_iter().flatten().map(PathBuf::as_path))
    }
}

/// `--env FILE` or `--sky` (the procedural sky), or no environment.
pub(super) fn load_environment(
    env: Option<&Path>,
    sky: bool,
) -> Result<Option<lightsphere::Environment>, Error> {
    Ok(match (env, sky) {
        (Some(path), _) => Some(lightsphere::Environment::load(path)?),
        (None, true) => {
            let s = synth::sky(&synth::SkyParams::default())?;
            Some(lightsphere::Environment::from_latlong(
                s.width, s.height, s.texels,
            )?)
        }
        (None, false) => None,
    })
}

/// `env` turned by `--env-rotation` about +Y, then with its zenith onto `--up-axis`.
pub(super) fn turned_environment(
    env: lightsphere::Environment,
    up_axis: UpAxis,
    rotation_deg: f32,
) -> lightsphere::Environment {
    let up = up_axis_rotation(up_axis).as_quat();
    let world_from_env = up * environment_rotation(rotation_deg) * env.world_from_env();
    env.with_rotation(world_from_env)
}

/// The sidecars of `--matrix` output `path`: STEM.directions.npy and STEM.weights.npy.
pub(crate) fn matrix_sidecars(path: &Path) -> (PathBuf, PathBuf) {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    (
        path.with_file_name(format!("{stem}.directions.npy")),
        path.with_file_name(format!("{stem}.weights.npy")),
    )
}
