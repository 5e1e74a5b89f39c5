//! `cloth-vis btf render`: a mesh textured by a compressed BTF under one light (thesis §5.5),
//! optionally with fins along its silhouette (§5.7) — the pictures of Figs. 5.16, 5.23 and
//! 5.24.

use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::BtfPca;
use glam::Vec3;

use super::invalid as request;
use cloth_vis::Error;
/// The light of `btf render`.
#[derive(Clone, Debug)]
pub enum RenderLight {
    /// A directional light: world-space direction towards the light.
    Direction(Vec3),
    /// A point light at this world-space position (no distance falloff, eq. 5.4).
    Position(Vec3),
    /// An environment (already turned onto the mesh's up axis), turned by `rotation_deg`
    /// about `up`, through the mesh's own visibility (§5.5.2).
    Environment {
        /// The map.
        env: Box<lightsphere::Environment>,
        /// The world up axis.
        up: Vec3,
        /// The turn about `up`, degrees.
        rotation_deg: f32,
        /// M at a lightsphere level, or static maps.
        visibility: cloth_vis::btf_env::EnvVisibility,
        /// Turn through the decomposition of eq. 5.13.
        decompose: Option<cloth_vis::btf_env::Decompose>,
    },
}

impl RenderLight {
    /// The environment lighting, when this is an environment.
    pub(super) fn env_lighting(&self) -> Option<cloth_vis::btf_env::EnvLighting<'_>> {
        match self {
            Self::Environment {
                env,
                up,
                rotation_deg,
                visibility,
                decompose,
            } => Some(cloth_vis::btf_env::EnvLighting {
                env,
                up: *up,
                rotation_deg: *rotation_deg,
                visibility: *visibility,
                decompose: *decompose,
            }),
            _ => None,
        }
    }
}

/// What `cloth-vis btf render` was asked to do.
#[derive(Clone, Debug)]
pub struct RenderRequest {
    /// A mesh file with per-vertex UVs (.obj, .ply, .gltf, .glb) or `synth:cloth` (the last
    /// frame of the synthetic drape).
    pub mesh: PathBuf,
    /// The `.btfpca` material.
    pub btf: PathBuf,
    /// The light.
    pub light: RenderLight,
    /// Linear RGB radiance g of the light.
    pub radiance: Vec3,
    /// Direction from the mesh towards the camera (the camera frames the mesh), in a Y-up frame
    /// turned onto `up_axis` with the camera's up.
    pub camera_direction: Vec3,
    /// The mesh's up axis (z for Blender/CAD exports such as the Berkeley garments); lights
    /// stay in the mesh's own coordinates.
    pub up_axis: super::up_axis::UpAxis,
    /// Image size in pixels.
    pub size: [u32; 2],
    /// Texture repeats across the mesh's UV range.
    pub uv_scale: f32,
    /// Draw plain texture mapping of the same material beside it (the thesis's Fig. 5.16).
    pub beside_plain: bool,
    /// Use the CPU reference renderer instead of the GPU.
    pub cpu: bool,
    /// Fins (§5.7): a `.finpca` file or `synth:wool`, with height (material units) and size
    /// (world length of a material unit; default a fraction of the mesh's radius).
    pub fins: Option<FinsRequest>,
    /// Frames A..B of an animated input (`synth:cloth`): `out` is then a folder of
    /// frame-NNNN.png, each lit with that frame's own visibility.
    pub frames: Option<(usize, usize)>,
    /// Garment parts (§5.6): faces of material NAME (OBJ `usemtl`, glTF material) wear the
    /// BTF of FILE; the other faces wear `btf`.
    pub parts: Vec<(String, PathBuf)>,
    /// The PNG to write (a folder with `frames`).
    pub out: PathBuf,
    /// Show a progress bar over frames.
    pub progress: bool,
}

/// The fins of `btf render`.
#[derive(Clone, Debug)]
pub struct FinsRequest {
    /// The fin material.
    pub source: cloth_vis::fins_stage::FinSource,
    /// Fin height in material units.
    pub height: Option<f32>,
    /// World length of one material unit.
    pub size: Option<f32>,
    /// Draw the mesh without fins on the left (Figs. 5.23/5.24).
    pub beside_without: bool,
}

/// What `render` did.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSummary {
    /// Vertices and triangles drawn.
    pub mesh: (usize, usize),
    /// Image size written.
    pub size: [u32; 2],
    /// `gpu` or `cpu`.
    pub backend: &'static str,
    /// Wall-clock seconds of rendering (not loading).
    pub seconds: f64,
    /// What the fins cost, when drawn.
    pub fins: Option<cloth_vis::btf_stage::FinCost>,
    /// What the environment light cost, when lit by one.
    pub env: Option<cloth_vis::btf_env::EnvCost>,
}

impl RenderSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        let mut line = format!(
            "btf render: {} vertices, {} triangles -> {}x{} ({}) in {:.2} s",
            self.mesh.0, self.mesh.1, self.size[0], self.size[1], self.backend, self.seconds
        );
        if let Some(e) = &self.env {
            line.push_str(&format!(
                "; environment: {} directions per vertex, visibility {:.0} ms, transfer {:.0} ms, \
                 environment update: {:.1} ms for {} vertices, frame {:.0} ms",
                e.directions, e.visibility_ms, e.transfer_ms, e.update_ms, e.vertices, e.render_ms
            ));
            if let Some(d) = &e.decomposition {
                line.push_str(&format!(
                    "; decomposition (eq. 5.13): {} turns in {:.0} ms, PCA {:.0} ms, {} components \
                     ({:.1} MB), turn {:.1} ms, error against the direct update {:.2} %",
                    d.turns,
                    d.samples_ms,
                    d.build_ms,
                    d.components,
                    d.bytes as f64 / 1e6,
                    d.turn_ms,
                    100.0 * d.error
                ));
            }
        }
        if let Some(f) = &self.fins {
            line.push_str(&format!(
                "; fins: {} fins, extraction {:.2} ms, lighting {:.2} ms, frame {:.1} ms with \
                 and {:.1} ms without ({:+.0} %)",
                f.fins,
                f.extract_ms,
                f.prepare_ms,
                f.frame_ms,
                f.frame_without_ms,
                100.0 * (f.frame_ms / f.frame_without_ms.max(1e-9) - 1.0)
            ));
        }
        line
    }
}

/// The mesh of `btf render` as a world object with UVs.
fn render_mesh(path: &Path) -> Result<cloth_vis::object::WorldObject, Error> {
    let (positions, triangles, uvs, normals) = if path == Path::new("synth:cloth") {
        let anim = synth::simulate_cloth(&synth::ClothParams::default())?;
        let last = anim.frames.len() - 1;
        let normals = meshio::compute_normals(
            &anim.frames[last],
            &anim.triangles,
            meshio::NormalWeighting::Angle,
        );
        (
            anim.frames[last].clone(),
            anim.triangles,
            Some(anim.uvs),
            normals,
        )
    } else if path == Path::new("synth:sphere") {
        let (positions, triangles, uvs) = cloth_vis::object::uv_sphere(48, 96);
        let normals = positions.clone();
        (positions, triangles, Some(uvs), normals)
    } else {
        // UV seams (sewing-pattern garments) split into vertex copies; the normals stay those
        // of the welded mesh, so the seams do not show in the shading.
        let options = meshio::LoadOptions {
            recompute_normals: true,
            ..meshio::LoadOptions::default()
        };
        let (split, _) = meshio::load_mesh_split_seams(path, &options)?;
        let mesh = split.mesh;
        (mesh.positions, mesh.triangles, mesh.uvs, mesh.normals)
    };
    if uvs.is_none() {
        return Err(request(
            path,
            "has no texture coordinates (no vt/TEXCOORD_0), and a BTF is looked up by them"
                .to_owned(),
        ));
    }
    Ok(cloth_vis::object::WorldObject::textured(
        path.display().to_string(),
        positions,
        normals,
        triangles,
        uvs,
    ))
}

/// Runs `btf render`: the mesh textured by the compressed BTF under one light (thesis §5.5),
/// on the GPU (`gpu`) or the CPU reference (`request.cpu`).
///
/// # Errors
/// An output that is not `.png` or a size of 0 (refused before loading); a mesh without UVs;
/// a missing GPU without `--cpu`; file, tangent and rendering errors. Nothing is written on
/// error.
pub fn run_render(
    request_: &RenderRequest,
    gpu: Option<&gpu_context::GpuContext>,
) -> Result<RenderSummary, Error> {
    let png = request_
        .out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !png && request_.frames.is_none() {
        return Err(request(
            &request_.out,
            "the image is written as .png".to_owned(),
        ));
    }
    if request_.frames.is_none() {
        super::check_output_file(&request_.out, &[&request_.btf, &request_.mesh])?;
    }
    let [w, h] = request_.size;
    if !(1..=cloth_vis::scene::MAX_IMAGE_SIDE).contains(&w)
        || !(1..=cloth_vis::scene::MAX_IMAGE_SIDE).contains(&h)
    {
        return Err(request(
            &request_.out,
            format!(
                "--size {w}x{h}: each side must be 1..={}",
                cloth_vis::scene::MAX_IMAGE_SIDE
            ),
        ));
    }
    if !(request_.uv_scale.is_finite() && request_.uv_scale > 0.0) {
        return Err(request(
            &request_.out,
            format!("--uv-scale {}: must be finite and > 0", request_.uv_scale),
        ));
    }
    let gpu = match (request_.cpu, gpu) {
        (true, _) => None,
        (false, Some(g)) => Some(g),
        (false, None) => {
            return Err(request(
                &request_.out,
                "no GPU adapter was found (install Mesa's lavapipe: apt-get install \
                 mesa-vulkan-drivers), or pass --cpu for the CPU reference renderer"
                    .to_owned(),
            ));
        }
    };
    let pca = BtfPca::read(&request_.btf)?;
    if let Some(frames) = request_.frames {
        return run_frames(request_, gpu, &pca, frames);
    }
    let object = render_mesh(&request_.mesh)?;
    let (centre, radius) =
        render::bounding_sphere(object.positions.iter()).unwrap_or((Vec3::ZERO, 1.0));
    let camera = framing_camera(request_, centre, radius);
    let mut params = btf::render::RenderParams::default();
    params.uv_scale = glam::Vec2::splat(request_.uv_scale);
    if !request_.parts.is_empty() {
        return super::btf_parts::run_parts(request_, gpu, &pca, &object, &camera, &params);
    }
    let Some(light) = one_light(&request_.light, request_.radiance) else {
        let Some(lighting) = request_.light.env_lighting() else {
            return Err(request(&request_.out, "no light to render with".to_owned()));
        };
        {
            let start = Instant::now();
            let (image, cost) =
                cloth_vis::btf_env::render_env(gpu, &pca, &object, &lighting, &camera, &params)?;
            let picture = cloth_vis::btf_stage::single_auto_exposed(&image);
            let seconds = start.elapsed().as_secs_f64();
            figures::strip::write_png(&request_.out, &picture)?;
            return Ok(RenderSummary {
                mesh: (object.positions.len(), object.triangles.len()),
                size: [picture.width(), picture.height()],
                backend: if gpu.is_some() { "gpu" } else { "cpu" },
                seconds,
                fins: None,
                env: Some(cost),
            });
        }
    };
    let start = Instant::now();
    let objects = [&object];
    if let Some(fins) = &request_.fins {
        let g = gpu.ok_or_else(|| {
            request(
                &request_.out,
                "--fins draws on the GPU; drop --cpu (the CPU reference has no fin pass)"
                    .to_owned(),
            )
        })?;
        let fin_pca = fins.source.load(btf::DEFAULT_COMPONENTS)?;
        let look = cloth_vis::fins_stage::FinLook::for_radius(radius, fins.height, fins.size);
        look.validate(Path::new("--fin-height/--fin-size"))?;
        let (without, with, cost) = cloth_vis::btf_stage::render_with_fins(
            g, &pca, &objects, &light, &camera, &params, &fin_pca, &look,
        )?;
        let picture = if fins.beside_without {
            cloth_vis::btf_stage::side_by_side(&without, &with)
        } else {
            cloth_vis::btf_stage::single(&with)
        };
        let seconds = start.elapsed().as_secs_f64();
        figures::strip::write_png(&request_.out, &picture)?;
        return Ok(RenderSummary {
            mesh: (object.positions.len(), object.triangles.len()),
            size: [picture.width(), picture.height()],
            backend: "gpu",
            seconds,
            fins: Some(cost),
            env: None,
        });
    }
    let image =
        cloth_vis::btf_stage::render_objects(gpu, &pca, &objects, &light, &camera, &params)?;
    let picture = if request_.beside_plain {
        let plain = cloth_vis::btf_stage::plain_material(&pca)?;
        let flat =
            cloth_vis::btf_stage::render_objects(gpu, &plain, &objects, &light, &camera, &params)?;
        cloth_vis::btf_stage::side_by_side(&image, &flat)
    } else {
        cloth_vis::btf_stage::single(&image)
    };
    let seconds = start.elapsed().as_secs_f64();
    figures::strip::write_png(&request_.out, &picture)?;
    Ok(RenderSummary {
        mesh: (object.positions.len(), object.triangles.len()),
        size: [picture.width(), picture.height()],
        backend: if gpu.is_some() { "gpu" } else { "cpu" },
        seconds,
        fins: None,
        env: None,
    })
}

/// The point or directional light of `light` (`None` for an environment).
pub(super) fn one_light(light: &RenderLight, radiance: Vec3) -> Option<btf::render::Light> {
    match *light {
        RenderLight::Direction(d) => Some(btf::render::Light::Directional {
            dir_to_light_world: d,
            radiance,
        }),
        RenderLight::Position(p) => Some(btf::render::Light::Point {
            position_world: p,
            radiance,
        }),
        RenderLight::Environment { .. } => None,
    }
}

/// The camera of `btf render`: framing the sphere (`centre`, `radius`) from `--camera-dir`,
/// turned onto `--up-axis`.
fn framing_camera(request_: &RenderRequest, centre: Vec3, radius: f32) -> render::Camera {
    let [w, h] = request_.size;
    let up = super::up_axis::up_axis_rotation(request_.up_axis).as_quat();
    cloth_vis::camera::frame_sphere(
        up * request_.camera_direction,
        up * Vec3::Y,
        centre,
        radius,
        w,
        h,
    )
}

/// `btf render --frames A..B`: the deforming drape frame by frame, each frame's visibility,
/// transfer and γ* recomputed (the thesis could light only static meshes by an environment;
/// §5.5.2), one camera framing all frames, written as a folder that appears complete or not
/// at all.
fn run_frames(
    request_: &RenderRequest,
    gpu: Option<&gpu_context::GpuContext>,
    pca: &BtfPca,
    (start, end): (usize, usize),
) -> Result<RenderSummary, Error> {
    // The drape, or an animation file (a glTF clip, an OBJ folder, a point cache with its
    // topology is not offered here) with one UV per vertex.
    let (triangles, frames_all, uvs) = if request_.mesh == Path::new("synth:cloth") {
        let anim = synth::simulate_cloth(&synth::ClothParams::default())?;
        (anim.triangles, anim.frames, anim.uvs)
    } else if request_
        .mesh
        .to_str()
        .is_some_and(|m| m.starts_with("synth:"))
    {
        return Err(request(
            &request_.mesh,
            "--frames needs an animated input: synth:cloth or an animation file (.glb/.gltf \
             clip, folder of .obj frames)"
                .to_owned(),
        ));
    } else {
        let (anim, _) =
            meshio::load_animation(&request_.mesh, &meshio::AnimationOptions::default())?;
        let uvs = anim.uvs.ok_or_else(|| {
            request(
                &request_.mesh,
                "has no per-vertex texture coordinates, and a BTF is looked up by them".to_owned(),
            )
        })?;
        (anim.triangles, anim.frames, uvs)
    };
    let total = frames_all.len();
    if total < 2 {
        return Err(request(
            &request_.mesh,
            format!("--frames needs an animated input; this one has {total} frame"),
        ));
    }
    if start >= end || end > total {
        return Err(request(
            &request_.out,
            format!("--frames {start}..{end} is outside the input's {total} frames (0..{total})"),
        ));
    }
    struct Frames {
        triangles: Vec<[u32; 3]>,
        frames: Vec<Vec<Vec3>>,
        uvs: Vec<glam::Vec2>,
    }
    let anim = Frames {
        triangles,
        frames: frames_all,
        uvs,
    };
    let existing = super::folder_output(&request_.out, false)?;
    let (centre, radius) = render::bounding_sphere(anim.frames[start..end].iter().flatten())
        .unwrap_or((Vec3::ZERO, 1.0));
    let camera = framing_camera(request_, centre, radius);
    let mut params = btf::render::RenderParams::default();
    params.uv_scale = glam::Vec2::splat(request_.uv_scale);
    let bar = cloth_vis::run::progress_bar(request_.progress, (end - start) as u64, "frames");
    let begin = Instant::now();
    let mut sum: Option<cloth_vis::btf_env::EnvCost> = None;
    let mut exposure: Option<f32> = None;
    let mut size = [0, 0];
    atomic_out::write_dir(&request_.out, existing, |dir| {
        for f in start..end {
            let positions = anim.frames[f].clone();
            let normals = meshio::compute_normals(
                &positions,
                &anim.triangles,
                meshio::NormalWeighting::Angle,
            );
            let object = cloth_vis::object::WorldObject::textured(
                format!("{} frame {f}", request_.mesh.display()),
                positions,
                normals,
                anim.triangles.clone(),
                Some(anim.uvs.clone()),
            );
            let picture = match (
                request_.light.env_lighting(),
                one_light(&request_.light, request_.radiance),
            ) {
                (Some(lighting), _) => {
                    let (image, cost) = cloth_vis::btf_env::render_env(
                        gpu, pca, &object, &lighting, &camera, &params,
                    )?;
                    sum = Some(match sum {
                        None => cost,
                        Some(s) => cloth_vis::btf_env::EnvCost {
                            visibility_ms: s.visibility_ms + cost.visibility_ms,
                            transfer_ms: s.transfer_ms + cost.transfer_ms,
                            update_ms: s.update_ms + cost.update_ms,
                            render_ms: s.render_ms + cost.render_ms,
                            ..s
                        },
                    });
                    // One exposure for the sequence (the first frame's), so it does not flicker.
                    let ev = *exposure.get_or_insert_with(|| render::output::auto_exposure(&image));
                    cloth_vis::btf_stage::single_exposed(&image, ev)
                }
                (_, Some(light)) => {
                    let image = cloth_vis::btf_stage::render_objects(
                        gpu,
                        pca,
                        &[&object],
                        &light,
                        &camera,
                        &params,
                    )?;
                    cloth_vis::btf_stage::single(&image)
                }
                (_, None) => {
                    return Err(request(&request_.out, "no light to render with".to_owned()));
                }
            };
            size = [picture.width(), picture.height()];
            figures::strip::write_png(&dir.join(format!("frame-{f:04}.png")), &picture)?;
            bar.inc(1);
        }
        Ok::<(), Error>(())
    })?;
    bar.finish_and_clear();
    let n = (end - start) as f64;
    Ok(RenderSummary {
        mesh: (
            anim.frames.first().map_or(0, Vec::len),
            anim.triangles.len(),
        ),
        size,
        backend: if gpu.is_some() { "gpu" } else { "cpu" },
        seconds: begin.elapsed().as_secs_f64(),
        fins: None,
        env: sum.map(|s| cloth_vis::btf_env::EnvCost {
            visibility_ms: s.visibility_ms / n,
            transfer_ms: s.transfer_ms / n,
            update_ms: s.update_ms / n,
            render_ms: s.render_ms / n,
            ..s
        }),
    })
}

/// `cloth-vis btf render`.
#[derive(clap::Args)]
pub struct RenderArgs {
    /// A mesh with per-vertex UVs (.obj .ply .gltf .glb), synth:cloth or synth:sphere.
    mesh: PathBuf,
    /// The .btfpca material.
    #[arg(long)]
    btf: PathBuf,
    /// Directional light: world direction towards it.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, conflicts_with = "light_pos", allow_hyphen_values = true)]
    light_dir: Option<Vec3>,
    /// Environment light (§5.5.2): an HDR map (.hdr/.exr) through the mesh's own
    /// self-shadowing (visibility at --level); turned onto --up-axis.
    #[arg(long, conflicts_with_all = ["light_dir", "light_pos", "sky", "fins", "beside_plain"])]
    env: Option<PathBuf>,
    /// Environment light from the procedural sky (see --env).
    #[arg(long, conflicts_with_all = ["light_dir", "light_pos", "fins", "beside_plain"])]
    sky: bool,
    /// Turn the environment by DEG degrees about the up axis.
    #[arg(
        long,
        visible_alias = "rotation",
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    env_rotation: f32,
    /// Lightsphere level of the environment's directions and the visibility (3: 258).
    #[arg(long, default_value_t = 3)]
    level: u32,
    /// Shadow the environment through static per-vertex hemicube maps of RES² pixels per face
    /// (the thesis's path) instead of the visibility matrix M at --level.
    #[arg(long, value_name = "RES", conflicts_with = "frames")]
    maps: Option<u32>,
    /// Turn the environment through the decomposition of eq. 5.13: W for A turns (every
    /// 360°/A), E components kept (the thesis: 30,5); prints its error against the direct
    /// update at --env-rotation.
    #[arg(long, value_name = "A,E", value_parser = super::parse::two_counts, conflicts_with = "frames")]
    decompose: Option<(usize, usize)>,
    /// Point light: world position (no distance falloff).
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, allow_hyphen_values = true)]
    light_pos: Option<Vec3>,
    /// Linear RGB radiance of the light.
    #[arg(long, value_name = "R,G,B", value_parser = super::parse::vec3, default_value = "1,1,1")]
    radiance: Vec3,
    /// Direction from the mesh towards the camera, which frames the mesh (Y-up; turned with
    /// --up-axis).
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, default_value = "0.55,0.45,1", allow_hyphen_values = true)]
    camera_dir: Vec3,
    /// The mesh's up axis: the camera turns onto it (z for Blender/CAD exports such as the
    /// Berkeley garments); --light-dir/--light-pos stay in the mesh's coordinates.
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    up_axis: super::up_axis::UpAxis,
    /// Image size.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = "512x512")]
    size: [u32; 2],
    /// Texture repeats across the mesh's UV range.
    #[arg(long, default_value_t = 4.0)]
    uv_scale: f32,
    /// Also draw plain texture mapping of the same material beside it (Fig. 5.16); under one
    /// light (--light-dir or --light-pos) of a single frame, without --fins or --part.
    #[arg(long)]
    beside_plain: bool,
    /// Use the CPU reference renderer (no GPU needed).
    #[arg(long)]
    cpu: bool,
    /// Fins along the silhouette (§5.7): a .finpca file or synth:wool.
    #[arg(long, value_name = "FILE.finpca|synth:wool", conflicts_with_all = ["beside_plain", "cpu"])]
    fins: Option<String>,
    /// Fin height in material units (default 1: the whole fin image).
    #[arg(long, requires = "fins", allow_hyphen_values = true)]
    fin_height: Option<f32>,
    /// World length of one fin material unit (default 4 % of the mesh's bounding radius).
    #[arg(long, requires = "fins", allow_hyphen_values = true)]
    fin_size: Option<f32>,
    /// Draw the mesh without fins on the left, with fins on the right (Figs. 5.23/5.24).
    #[arg(long, requires = "fins")]
    beside_no_fins: bool,
    /// Frames A..B of synth:cloth, each lit with its own visibility; --out is then a new
    /// folder of frame-NNNN.png.
    #[arg(long, value_name = "A..B", value_parser = super::parse::range, conflicts_with_all = ["fins", "beside_plain"])]
    frames: Option<(usize, usize)>,
    /// Hide the progress bar over frames.
    #[arg(long)]
    quiet: bool,
    /// A garment part (§5.6): faces of material NAME (OBJ usemtl, glTF material name) wear
    /// FILE.btfpca, the other faces --btf; repeat for several parts (GPU).
    #[arg(long = "part", value_name = "NAME=FILE.btfpca", value_parser = super::parse::named_path, conflicts_with_all = ["frames", "fins", "beside_plain", "cpu"])]
    parts: Vec<(String, PathBuf)>,
    /// Output: IMAGE.png (a folder with --frames).
    #[arg(long, short = 'o')]
    out: PathBuf,
}

impl RenderArgs {
    /// Render; the summary line.
    pub(super) fn run(self) -> anyhow::Result<String> {
        let env = super::visibility::load_environment(self.env.as_deref(), self.sky)?;
        let light = match (self.light_dir, self.light_pos, env) {
            (Some(d), _, _) => RenderLight::Direction(d),
            (None, Some(p), _) => RenderLight::Position(p),
            (None, None, Some(env)) => RenderLight::Environment {
                env: Box::new(super::visibility::turned_environment(
                    env,
                    self.up_axis,
                    0.0,
                )),
                up: super::up_axis::up_axis_rotation(self.up_axis).as_quat() * Vec3::Y,
                rotation_deg: self.env_rotation,
                visibility: match self.maps {
                    Some(res) => cloth_vis::btf_env::EnvVisibility::Maps {
                        model: hemicube::Model::Hemicube { res },
                    },
                    None => cloth_vis::btf_env::EnvVisibility::Matrix { level: self.level },
                },
                decompose: self
                    .decompose
                    .map(|(turns, components)| cloth_vis::btf_env::Decompose { turns, components }),
            },
            (None, None, None) => anyhow::bail!(
                "give the light: --light-dir X,Y,Z, --light-pos X,Y,Z, --env FILE.hdr or --sky"
            ),
        };
        let gpu = if self.cpu {
            None
        } else {
            super::optional_gpu()
        };
        let request = RenderRequest {
            mesh: self.mesh,
            btf: self.btf,
            light,
            radiance: self.radiance,
            camera_direction: self.camera_dir,
            up_axis: self.up_axis,
            size: self.size,
            uv_scale: self.uv_scale,
            beside_plain: self.beside_plain,
            cpu: self.cpu,
            fins: self.fins.map(|f| FinsRequest {
                source: cloth_vis::fins_stage::FinSource::parse(&f),
                height: self.fin_height,
                size: self.fin_size,
                beside_without: self.beside_no_fins,
            }),
            frames: self.frames,
            parts: self.parts,
            out: self.out,
            progress: !self.quiet,
        };
        let line = run_render(&request, gpu.as_ref())?.line();
        Ok(super::with_wrote(line, [request.out.as_path()]))
    }
}
