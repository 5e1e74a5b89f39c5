//! `cloth-vis hemicube`: static self-shadowing from per-vertex visibility maps (thesis §4.3,
//! crate `hemicube`).
//!
//! Builds one map per vertex in the chosen model (hemicube, single plane, hemisphere grid) by
//! the GPU atlas or by exact rays, then writes per vertex either the cosine-weighted open
//! fraction Σ_p V_p ΔF_p (no light; 1 = fully open, the convention of `visibility`'s a_i) or the
//! radiance of a white Lambertian surface, L_o = Σ_p V_p ΔF_p L_env(dir_p) plus point lights
//! (eqs. 4.4–4.7). Only the map build is timed in the summary line.
//!
//! Outputs by extension: `.npy` (f32 `[N]` open fraction, or `[N, 3]` radiance with a light;
//! NaN for vertices used by no face), `.ply` (colour + float `ao`), `.glb` (linear `COLOR_0` +
//! `_AO`, −1 for unused vertices), and `--render FILE.png|.exr` (the shared frame).
//! `--up-axis` turns the environment's zenith and the camera's up onto a Z-up (or other)
//! asset's up axis, as `visibility`'s does; the maps and outputs stay in the input's frame.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use super::invalid;
use super::up_axis::{UpAxis, turn_camera};
use super::visibility::{
    DEFAULT_GAMMA, DEFAULT_RENDER_SIZE, check_render, display_colours, display_scene,
    lower_extension, turned_environment, write_glb, write_ply,
};
use cloth_vis::Error;
use cloth_vis::run::render_still_image;
use cloth_vis::scene::Scene;
use glam::Vec3;
use gpu_context::GpuContext;
use hemicube::lighting::{PointLighting, add_point_lights, environment_radiance};
use hemicube::{
    BuildParams, EnvLookup, FormFactorRule, GpuBuilder, Model, PixelLayout, PointLight,
    PointVisibility, RingSpacing, VisibilityMaps,
};
use occlusion_gpu::RayCaster;

/// Largest total size of the maps (1 bit per pixel) the command builds.
const MAX_MAP_BYTES: u64 = 2 << 30;

/// Which builder makes the maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Builder {
    /// The wgpu atlas (HC and SP).
    Gpu,
    /// Exact rays through the BVH (every model).
    Cpu,
}

impl Builder {
    fn name(self) -> &'static str {
        match self {
            Builder::Gpu => "gpu",
            Builder::Cpu => "cpu",
        }
    }
}

/// What `cloth-vis hemicube` was asked to do.
#[derive(Clone, Debug)]
pub struct HemicubeRequest {
    /// A mesh, or an animation (its frame `frame` is used).
    pub input: PathBuf,
    /// Triangles for a point-cache input.
    pub topology: Option<PathBuf>,
    /// Frame of an animation.
    pub frame: usize,
    /// Model and resolution.
    pub model: Model,
    /// ΔF rule.
    pub rule: FormFactorRule,
    /// Builder; `None` = GPU on a hardware adapter with clip distances for HC/SP, rays
    /// otherwise.
    pub builder: Option<Builder>,
    /// Preselection distance (rays only), units of the mesh's largest side.
    pub max_distance: Option<f32>,
    /// Environment (already loaded).
    pub environment: Option<lightsphere::Environment>,
    /// Rotation of the environment about the up axis, degrees.
    pub rotation_deg: f32,
    /// The input's up axis: the environment's zenith and the render camera's up turn onto it;
    /// the maps and outputs stay in the input's frame.
    pub up_axis: UpAxis,
    /// Environment look-up.
    pub lookup: EnvLookup,
    /// Point lights.
    pub point_lights: Vec<PointLight>,
    /// How point lights are tested.
    pub light_test: PointVisibility,
    /// Output file.
    pub out: Option<PathBuf>,
    /// Rendered image.
    pub render: Option<PathBuf>,
    /// PNG exposure in stops (`None` = automatic).
    pub exposure_ev: Option<f32>,
    /// Rendered image size.
    pub render_size: [u32; 2],
    /// Show the bar over the map build (stderr, terminals only).
    pub progress: bool,
}

/// What was computed.
#[derive(Clone, Debug, PartialEq)]
pub struct HemicubeSummary {
    /// The model and resolution.
    pub model: Model,
    /// Vertices.
    pub vertices: usize,
    /// Build time (ms), maps only.
    pub millis: f64,
    /// The builder that ran.
    pub builder: Builder,
    /// Storage per vertex.
    pub bytes_per_vertex: usize,
}

impl HemicubeSummary {
    /// `hemicube: MODEL RES x N vertices in T ms (BUILDER), B bytes per vertex`.
    pub fn line(&self) -> String {
        format!(
            "hemicube: {} x {} vertices in {:.1} ms ({}), {} bytes per vertex",
            self.model.label(),
            self.vertices,
            self.millis,
            self.builder.name(),
            self.bytes_per_vertex
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OutKind {
    Npy,
    Ply,
    Glb,
}

/// Checks what can be checked before loading.
fn check_request(
    request: &HemicubeRequest,
    gpu: Option<&GpuContext>,
) -> Result<Option<OutKind>, Error> {
    let input = &request.input;
    request
        .model
        .validate()
        .map_err(|e| invalid(input, e.to_string()))?;
    let out = match &request.out {
        None => None,
        Some(p) => Some(match lower_extension(p).as_deref() {
            Some("npy") => OutKind::Npy,
            Some("ply") => OutKind::Ply,
            Some("glb") => OutKind::Glb,
            _ => {
                return Err(invalid(
                    p,
                    "--out must end in .npy (open fraction [N], or radiance [N, 3] with a light), \
                     .ply or .glb"
                        .to_owned(),
                ));
            }
        }),
    };
    if let Some(p) = &request.render {
        check_render(
            p,
            gpu,
            request.render_size,
            DEFAULT_GAMMA,
            request.exposure_ev,
        )?;
    }
    if !request.rotation_deg.is_finite() {
        return Err(invalid(
            input,
            format!(
                "--rotation {} must be finite (degrees)",
                request.rotation_deg
            ),
        ));
    }
    if request.rotation_deg != 0.0 && request.environment.is_none() {
        return Err(invalid(
            input,
            format!(
                "--rotation {} rotates an environment: pass --env FILE or --sky",
                request.rotation_deg
            ),
        ));
    }
    for (i, light) in request.point_lights.iter().enumerate() {
        let bad_position = !light.position.is_finite()
            || light.position.abs().max_element() > cloth_vis::inputs::MAX_WORLD_COORDINATE;
        let bad_intensity = !light.intensity.is_finite() || light.intensity.min_element() < 0.0;
        if bad_position || bad_intensity {
            return Err(invalid(
                input,
                format!(
                    "--point-light #{} ({}, {}): the position must be finite (|x| <= 1e15) and \
                     the intensity finite and >= 0",
                    i + 1,
                    light.position,
                    light.intensity
                ),
            ));
        }
    }
    if let Some(d) = request.max_distance {
        if request.builder == Some(Builder::Gpu) {
            return Err(invalid(
                input,
                "--max-distance is the ray builder's triangle preselection: add --builder cpu"
                    .to_owned(),
            ));
        }
        if !(d.is_finite() && d > 0.0) {
            return Err(invalid(
                input,
                format!(
                    "--max-distance {d} must be finite and > 0 (units of the mesh's largest side)"
                ),
            ));
        }
    }
    if request.builder == Some(Builder::Gpu) && !request.model.is_planar() {
        return Err(invalid(
            input,
            "the hemisphere model cannot be rasterised (§4.3.4): use --builder cpu".to_owned(),
        ));
    }
    Ok(out)
}

/// The one-object scene for loading and rendering: the input as a white object, clamp-then-gamma
/// PNGs, the environment as backdrop.
fn one_object_scene(request: &HemicubeRequest) -> Result<Scene, Error> {
    let mut scene = display_scene(
        &request.input,
        request.topology.as_deref(),
        "cloth-vis hemicube",
        request.render_size,
        request.exposure_ev,
        DEFAULT_GAMMA,
    )?;
    turn_camera(&mut scene.camera, request.up_axis);
    Ok(scene)
}

/// Builds the maps with the chosen builder.
fn build_maps(
    request: &HemicubeRequest,
    caster: &RayCaster,
    layout: Arc<PixelLayout>,
    builder: Builder,
    gpu: Option<&GpuContext>,
) -> Result<VisibilityMaps, Error> {
    let mut params = BuildParams::default();
    params.max_distance = request.max_distance;
    // A bar on stderr (hidden when it is not a terminal) for builds over a second.
    let bar = cloth_vis::run::progress_bar(
        request.progress,
        caster.receiver_count() as u64,
        "visibility maps",
    );
    let progress = |n: u64| bar.inc(n);
    let maps = match (builder, gpu) {
        (Builder::Gpu, Some(gpu)) => {
            GpuBuilder::new(gpu, layout)?
                .build_with_progress(gpu, caster, &params, &progress)?
                .0
        }
        (Builder::Gpu, None) => {
            return Err(invalid(
                &request.input,
                "--builder gpu needs a GPU adapter and none was found (lavapipe is fine: \
                 apt-get install mesa-vulkan-drivers); or use --builder cpu"
                    .to_owned(),
            ));
        }
        (Builder::Cpu, _) => hemicube::build_with_progress(caster, layout, &params, &progress).0,
    };
    bar.finish_and_clear();
    Ok(maps)
}

/// Runs the request.
///
/// # Errors
/// Bad flags before any work; loader, builder, GPU and output errors naming the file.
pub fn run_hemicube(
    request: &HemicubeRequest,
    gpu: Option<&GpuContext>,
) -> Result<HemicubeSummary, Error> {
    let input = &request.input;
    for output in request.out.iter().chain(&request.render) {
        super::check_output_file(output, &[input])?;
    }
    let out_kind = check_request(request, gpu)?;
    let builder = request.builder.unwrap_or(match gpu {
        Some(g)
            if !g.summary().is_software
                && request.model.is_planar()
                && GpuBuilder::is_supported(g) =>
        {
            Builder::Gpu
        }
        _ => Builder::Cpu,
    });
    let scene = one_object_scene(request)?;
    let (mut objects, _) = cloth_vis::inputs::load_geometry(&scene, false)?;
    if objects[0].triangles.is_empty() {
        return Err(invalid(
            input,
            "the input has no triangles (a point cache carries none): add --topology MESH"
                .to_owned(),
        ));
    }
    let frames = objects[0].frame_count();
    if request.frame >= frames {
        return Err(invalid(
            input,
            format!(
                "--frame {} is outside the {frames} frames (0..{frames})",
                request.frame
            ),
        ));
    }
    objects[0].pose(request.frame);
    let object = &objects[0];
    let map_bytes =
        object.positions.len() as u64 * request.model.pixel_count().div_ceil(64) as u64 * 8;
    if map_bytes > MAX_MAP_BYTES {
        return Err(invalid(
            input,
            format!(
                "{} maps of {} vertices would take {:.1} GiB, more than the {} GiB this command \
                 holds: lower --res",
                request.model.label(),
                object.positions.len(),
                map_bytes as f64 / (1u64 << 30) as f64,
                MAX_MAP_BYTES >> 30
            ),
        ));
    }
    let occ = occlusion_gpu::Scene::single(
        object.positions.clone(),
        object.normals.clone(),
        object.triangles.clone(),
    )?;
    let layout = Arc::new(PixelLayout::new(request.model, request.rule)?);
    let caster = RayCaster::new(&occ)?;
    let t = Instant::now();
    let maps = build_maps(request, &caster, layout, builder, gpu)?;
    let millis = t.elapsed().as_secs_f64() * 1e3;
    let open = maps.open_fraction();
    let environment = request
        .environment
        .clone()
        .map(|env| turned_environment(env, request.up_axis, request.rotation_deg));
    let lit = environment.is_some() || !request.point_lights.is_empty();
    let radiance: Vec<Vec3> = if lit {
        let mut c = match &environment {
            Some(env) => environment_radiance(&maps, env, Vec3::ONE, request.lookup),
            None => open
                .iter()
                .map(|a| if a.is_finite() { Vec3::ZERO } else { Vec3::NAN })
                .collect(),
        };
        add_point_lights(
            &mut c,
            &maps,
            &object.positions,
            Vec3::ONE,
            &PointLighting {
                lights: &request.point_lights,
                visibility: request.light_test,
                caster: Some(&caster),
                offset_relative: BuildParams::default().offset_relative,
            },
        );
        c
    } else {
        open.iter().map(|a| Vec3::splat(*a)).collect()
    };
    let normals = &object.normals;
    match (out_kind, &request.out) {
        (Some(OutKind::Npy), Some(path)) => {
            if lit {
                let flat: Vec<f32> = radiance.iter().flat_map(|c| c.to_array()).collect();
                meshio::write_npy_f32(path, &[radiance.len(), 3], &flat)?;
            } else {
                meshio::write_npy_f32(path, &[open.len()], &open)?;
            }
        }
        (Some(OutKind::Ply), Some(path)) => write_ply(
            path,
            "cloth-vis hemicube: ao = open fraction sum V dF (NaN: vertex used by no face)",
            &object.positions,
            normals,
            &object.triangles,
            &display_colours(&radiance),
            &open,
        )?,
        (Some(OutKind::Glb), Some(path)) => write_glb(
            path,
            &object.positions,
            normals,
            &object.triangles,
            &radiance,
            &open,
        )?,
        _ => {}
    }
    if let (Some(path), Some(gpu)) = (&request.render, gpu) {
        let shown: Vec<Vec3> = radiance
            .iter()
            .map(|v| if v.is_finite() { *v } else { Vec3::ZERO })
            .collect();
        objects[0].front = Some(shown.clone());
        objects[0].back = Some(shown);
        let (image, display, background) =
            render_still_image(&scene, gpu, &objects, environment.as_ref())?;
        if lower_extension(path).as_deref() == Some("exr") {
            render::output::write_exr(&image, path, background)?;
        } else {
            render::output::write_png(&image, path, &display, background)?;
        }
    }
    Ok(HemicubeSummary {
        model: request.model,
        vertices: maps.len(),
        millis,
        builder,
        bytes_per_vertex: maps.bytes_per_vertex(),
    })
}

/// Parses `X,Y,Z,R,G,B`.
fn parse_point_light(s: &str) -> Result<PointLight, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>().map_err(|e| format!("{x:?}: {e}")))
        .collect::<Result<_, _>>()?;
    if v.len() != 6 {
        return Err(format!(
            "{s:?}: expected X,Y,Z,R,G,B (position and intensity), got {} numbers",
            v.len()
        ));
    }
    Ok(PointLight {
        position: Vec3::new(v[0], v[1], v[2]),
        intensity: Vec3::new(v[3], v[4], v[5]),
    })
}

/// Parses `N` or `AxB` (HS: φ bins x θ rings).
fn parse_resolution(s: &str) -> Result<(u32, Option<u32>), String> {
    let parse = |x: &str| {
        x.trim()
            .parse::<u32>()
            .map_err(|e| format!("{x:?} is not a resolution: {e}"))
    };
    match s.split_once(['x', 'X']) {
        Some((a, b)) => Ok((parse(a)?, Some(parse(b)?))),
        None => Ok((parse(s)?, None)),
    }
}

/// `cloth-vis hemicube`: the flags of a [`HemicubeRequest`].
#[derive(clap::Args)]
pub struct HemicubeArgs {
    /// A mesh (.ply .obj .gltf .glb), an animation (its --frame is used) or synth:cloth.
    input: PathBuf,
    /// Triangles for a point-cache input (.npy, .pc2, .mdd).
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// Frame of an animation.
    #[arg(long, default_value_t = 0)]
    frame: usize,
    /// Model: hc (hemicube), sp (single plane), hs (hemisphere grid).
    #[arg(long, default_value = "hc", value_parser = ["hc", "sp", "hs"])]
    model: String,
    /// Resolution: N for hc (top NxN, sides NxN/2) and sp (NxN); PHIxTHETA for hs (N alone:
    /// N x N/4).
    #[arg(long, default_value = "64", value_parser = parse_resolution)]
    res: (u32, Option<u32>),
    /// Single-plane aperture in degrees.
    #[arg(long, value_name = "DEG", default_value_t = hemicube::DEFAULT_APERTURE_DEG)]
    aperture: f64,
    /// Hemisphere rings: equal-theta or equal-area (equal solid angle).
    #[arg(long, default_value = "equal-theta", value_parser = ["equal-theta", "equal-area"])]
    rings: String,
    /// Delta form factors: exact (integrated over each pixel) or midpoint (the seed's
    /// Cohen–Greenberg formulas).
    #[arg(long = "form-factors", default_value = "exact", value_parser = ["exact", "midpoint"])]
    form_factors: String,
    /// Builder: gpu (wgpu atlas; hc and sp) or cpu (exact rays); default gpu on a hardware
    /// adapter for hc/sp, cpu otherwise.
    #[arg(long, value_parser = ["gpu", "cpu"])]
    builder: Option<String>,
    /// The seed's triangle preselection: ignore occluders farther than D units of the mesh's
    /// largest side (cpu builder).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    max_distance: Option<f32>,
    /// HDR environment (.hdr/.exr).
    #[arg(long, conflicts_with = "sky")]
    env: Option<PathBuf>,
    /// The procedural sky as environment.
    #[arg(long)]
    sky: bool,
    /// Rotate the environment by DEG about the up axis (the maps are not rebuilt).
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    rotation: f32,
    /// The input's up axis: the environment's zenith and the render camera's up turn onto it
    /// (z for Blender/CAD exports and the Berkeley garments); the maps and outputs stay in
    /// the input's frame.
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    up_axis: UpAxis,
    /// Environment look-up: cube (power-conserving cube map, the seed's) or exact (per pixel
    /// direction).
    #[arg(long, default_value = "cube", value_parser = ["cube", "exact"])]
    lookup: String,
    /// A point light X,Y,Z,R,G,B (world position, intensity); repeatable.
    #[arg(long = "point-light", value_name = "X,Y,Z,R,G,B", value_parser = parse_point_light, allow_negative_numbers = true)]
    point_lights: Vec<PointLight>,
    /// Point-light visibility: map (the seed's look-up; wrong for a light closer than its
    /// occluder) or ray (exact).
    #[arg(long, default_value = "map", value_parser = ["map", "ray"])]
    light_test: String,
    /// Output: .npy, .ply or .glb.
    #[arg(long, short = 'o')]
    out: Option<PathBuf>,
    /// Render FILE.png (tone-mapped) or FILE.exr (linear). Needs a GPU adapter.
    #[arg(long, value_name = "FILE")]
    render: Option<PathBuf>,
    /// PNG exposure in stops; default automatic.
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// Rendered image size.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = DEFAULT_RENDER_SIZE)]
    render_size: [u32; 2],
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

impl HemicubeArgs {
    /// The request these flags describe.
    fn request(self) -> anyhow::Result<HemicubeRequest> {
        let (a, b) = self.res;
        let model = match (self.model.as_str(), b) {
            ("hs", b) => Model::Hemisphere {
                phi: a,
                theta: b.unwrap_or((a / 4).max(1)),
                spacing: if self.rings == "equal-area" {
                    RingSpacing::EqualSolidAngle
                } else {
                    RingSpacing::EqualTheta
                },
            },
            (m, Some(b)) if a != b => anyhow::bail!(
                "--res {a}x{b}: the {m} model is square (--res N); PHIxTHETA is for --model hs"
            ),
            ("sp", _) => Model::SinglePlane {
                res: a,
                aperture_deg: self.aperture,
            },
            _ => Model::Hemicube { res: a },
        };
        let environment = match (&self.env, self.sky) {
            (Some(path), _) => Some(lightsphere::Environment::load(path)?),
            (None, true) => {
                let s = synth::sky(&synth::SkyParams::default())?;
                Some(lightsphere::Environment::from_latlong(
                    s.width, s.height, s.texels,
                )?)
            }
            (None, false) => None,
        };
        Ok(HemicubeRequest {
            input: self.input,
            topology: self.topology,
            frame: self.frame,
            model,
            rule: if self.form_factors == "midpoint" {
                FormFactorRule::Midpoint
            } else {
                FormFactorRule::Exact
            },
            builder: self.builder.as_deref().map(|b| {
                if b == "gpu" {
                    Builder::Gpu
                } else {
                    Builder::Cpu
                }
            }),
            max_distance: self.max_distance,
            environment,
            rotation_deg: self.rotation,
            up_axis: self.up_axis,
            lookup: if self.lookup == "exact" {
                EnvLookup::Exact
            } else {
                EnvLookup::CubeMap
            },
            point_lights: self.point_lights,
            light_test: if self.light_test == "ray" {
                PointVisibility::Ray
            } else {
                PointVisibility::Map
            },
            out: self.out,
            render: self.render,
            exposure_ev: self.exposure,
            render_size: self.render_size,
            progress: !self.quiet,
        })
    }

    /// Build, light, write; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let request = self.request()?;
        let gpu = match (&request.render, request.builder) {
            (Some(path), _) => Some(super::required_gpu(path, "--render")?),
            (None, Some(Builder::Gpu)) => {
                Some(GpuContext::new(&gpu_context::GpuOptions::default())?)
            }
            (None, Some(Builder::Cpu)) => None,
            (None, None) => super::optional_gpu(),
        };
        let line = run_hemicube(&request, gpu.as_ref())?.line();
        let outputs = [&request.out, &request.render];
        super::print_summary(&line, outputs.into_iter().flatten().map(PathBuf::as_path))
    }
}
