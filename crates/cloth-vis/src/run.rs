//! Executing a plan: each stage in order, timed, its parameters recorded in the run report.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::{Quat, Vec3};
use gpu_context::{GpuContext, GpuOptions, HdrImage, Tonemap};
use indicatif::{ProgressBar, ProgressStyle};
use serde_json::json;

use crate::Error;
use crate::camera::{Camera, bounding_sphere};
use crate::plan::{Plan, Stage};
use crate::render::{Backdrop, DrawMesh, render};
use crate::report::{RunReport, StageRecord};
use crate::scene::{EnvironmentSource, ExposureDesc, GeometrySource, RadianceMethodDesc, Scene};

/// Where automatic exposure puts the 90th percentile of the objects' vertex luminance.
const AUTO_EXPOSURE_KEY: f32 = 0.8;
/// Percentile used by automatic exposure.
const AUTO_EXPOSURE_PERCENTILE: f64 = 0.9;

/// How a scene is run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Show progress bars on stderr for long stages.
    pub progress: bool,
    /// Adapter choice.
    pub gpu: GpuOptions,
}

/// What a run produced.
#[derive(Debug)]
pub struct RunOutput {
    /// Stages, times and files.
    pub report: RunReport,
    /// The linear HDR image.
    pub image: HdrImage,
    /// The plan that ran.
    pub plan: Plan,
}

/// One object in world space, with its lighting once computed.
#[derive(Clone, Debug)]
pub struct WorldObject {
    /// Object name.
    pub name: String,
    /// World-space positions.
    pub positions: Vec<Vec3>,
    /// World-space unit normals (zero for unreferenced vertices).
    pub normals: Vec<Vec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, one per position, when the source has them (the synthetic cloth
    /// and meshes with per-vertex UVs); the `btf` effect needs them.
    pub uvs: Option<Vec<glam::Vec2>>,
    /// Albedo ρ.
    pub albedo: Vec3,
    /// Lit on both sides.
    pub two_sided: bool,
    /// Radiance towards the front side, once the lighting stage ran.
    pub front: Option<Vec<Vec3>>,
    /// Radiance towards the back side, once the lighting stage ran.
    pub back: Option<Vec<Vec3>>,
}

struct Timer {
    stages: Vec<StageRecord>,
}

impl Timer {
    fn run<T>(
        &mut self,
        stage: Stage,
        work: impl FnOnce() -> Result<(T, serde_json::Value), Error>,
    ) -> Result<T, Error> {
        let start = Instant::now();
        let (value, params) = work()?;
        self.stages.push(StageRecord {
            stage: stage.name().to_owned(),
            millis: start.elapsed().as_secs_f64() * 1e3,
            params,
        });
        Ok(value)
    }
}

/// Validate, plan and run `scene`, writing its images and run report into `out_dir`.
///
/// Every check that needs no work (effects, values, files) happens before any stage starts,
/// and the GPU adapter is acquired before the first stage so that a machine without one fails
/// at once.
///
/// # Errors
/// Any [`Error`]; files already written by this run are complete (each is written atomically).
pub fn run_scene(scene: &Scene, out_dir: &Path, options: &RunOptions) -> Result<RunOutput, Error> {
    let start = Instant::now();
    let plan = Plan::for_scene(scene)?;
    std::fs::create_dir_all(out_dir).map_err(|e| Error::Io {
        path: out_dir.to_owned(),
        reason: e.to_string(),
    })?;
    let gpu = GpuContext::new(&options.gpu)?;
    let mut timer = Timer { stages: Vec::new() };

    let mut objects = timer.run(Stage::Geometry, || load_geometry(scene, options.progress))?;

    let environment = if plan.contains(Stage::Environment) {
        Some(timer.run(Stage::Environment, || load_environment(scene))?)
    } else {
        None
    };

    if plan.contains(Stage::Lighting) {
        let env = environment.as_ref().ok_or_else(|| Error::Scene {
            origin: scene.origin.clone(),
            message: "lighting planned without an environment".to_owned(),
        })?;
        let (sphere, radiance) =
            timer.run(Stage::LightDirections, || light_directions(scene, env))?;
        let visibility = if plan.contains(Stage::Visibility) {
            Some(timer.run(Stage::Visibility, || {
                crate::shadowing::visibility(scene, &gpu, &objects, &sphere)
            })?)
        } else {
            None
        };
        timer.run(Stage::Lighting, || {
            let vertices = crate::shadowing::light_objects(
                &mut objects,
                &sphere,
                &radiance,
                visibility.as_ref(),
            )?;
            let params = json!({
                "vertices": vertices,
                "directions": sphere.len(),
                "visibility": visibility.is_some(),
            });
            Ok(((), params))
        })?;
    }

    let mut outputs = Vec::new();
    let image = timer.run(Stage::Render, || {
        let (image, params, written) =
            render_stage(scene, out_dir, &gpu, &objects, environment.as_ref())?;
        outputs = written;
        Ok((image, params))
    })?;

    if plan.contains(Stage::Btf) {
        let written = timer.run(Stage::Btf, || {
            crate::btf_stage::run(scene, out_dir, &gpu, &objects)
        })?;
        outputs.extend(written);
    }

    let mut report = RunReport {
        scene: scene.name.clone(),
        origin: scene.origin.clone(),
        effects: plan.effects().iter().map(|e| e.name().to_owned()).collect(),
        stages: timer.stages,
        total_millis: 0.0,
        outputs,
    };
    report.total_millis = start.elapsed().as_secs_f64() * 1e3;
    let (json_path, text_path) = report.write(out_dir)?;
    report.outputs.extend([json_path, text_path]);
    Ok(RunOutput {
        report,
        image,
        plan,
    })
}

/// A progress bar on stderr labelled `message`, hidden when `show` is false.
pub(crate) fn progress_bar(show: bool, len: u64, message: &'static str) -> ProgressBar {
    if !show {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    if let Ok(style) = ProgressStyle::with_template("{msg:>18} [{bar:40}] {pos}/{len} ({eta})") {
        bar.set_style(style.progress_chars("=> "));
    }
    bar.set_message(message);
    bar
}

/// The synthetic cloth parameters of a scene.
fn cloth_params(scene: &Scene) -> synth::ClothParams {
    let mut params = synth::ClothParams::default();
    if let Some(grid) = scene.synth.cloth_grid {
        params.grid = grid;
    }
    if let Some(frames) = scene.synth.cloth_frames {
        params.frames = frames;
    }
    params.seed = scene.synth.seed;
    params
}

fn load_geometry(
    scene: &Scene,
    progress: bool,
) -> Result<(Vec<WorldObject>, serde_json::Value), Error> {
    let uses_cloth = (0..scene.objects.len())
        .any(|i| matches!(scene.geometry_source(i), Ok(GeometrySource::SynthCloth)));
    let cloth = if uses_cloth {
        let p = cloth_params(scene);
        let bar = progress_bar(progress, p.frames as u64, "simulating cloth");
        let anim =
            synth::simulate_cloth_with_progress(&p, &mut |done, _| bar.set_position(done as u64))?;
        bar.finish_and_clear();
        Some(anim)
    } else {
        None
    };
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut params = serde_json::Map::new();
    for (index, desc) in scene.objects.iter().enumerate() {
        let (positions, triangles, uvs, detail) = match (scene.geometry_source(index)?, &cloth) {
            (GeometrySource::SynthCloth, Some(anim)) => {
                let frame = frame_index(&desc.name, desc.frame, anim.frames.len())?;
                let detail = json!({ "source": "synth:cloth", "frame": frame, "frames": anim.frames.len(), "grid": anim.grid });
                (
                    anim.frames[frame].clone(),
                    anim.triangles.clone(),
                    Some(anim.uvs.clone()),
                    detail,
                )
            }
            (GeometrySource::SynthCloth, None) => unreachable!("uses_cloth is true for this scene"),
            (GeometrySource::SynthClothObstacle, _) => {
                let obstacle = cloth
                    .as_ref()
                    .map_or(cloth_params(scene).obstacle, |a| a.obstacle);
                let (positions, triangles) = synth::obstacle_mesh(&obstacle, OBSTACLE_DETAIL);
                (
                    positions,
                    triangles,
                    None,
                    json!({ "source": "synth:cloth-obstacle" }),
                )
            }
            (GeometrySource::File(path), _) => load_file(&path, desc)?,
        };
        let world_from_object = desc.world_from_object();
        let positions: Vec<Vec3> = positions
            .iter()
            .map(|p| world_from_object.transform_point3(*p))
            .collect();
        // Normals are computed in world space from the transformed positions, so any transform
        // (including mirroring scales) keeps them consistent with the winding.
        let normals =
            meshio::compute_normals(&positions, &triangles, meshio::NormalWeighting::Angle);
        params.insert(
            desc.name.clone(),
            json!({ "vertices": positions.len(), "triangles": triangles.len(), "input": detail }),
        );
        objects.push(WorldObject {
            name: desc.name.clone(),
            positions,
            normals,
            triangles,
            uvs,
            albedo: Vec3::from(desc.albedo),
            two_sided: desc.two_sided,
            front: None,
            back: None,
        });
    }
    Ok((objects, serde_json::Value::Object(params)))
}

/// Subdivision detail of the obstacle sphere mesh.
const OBSTACLE_DETAIL: u32 = 4;

fn frame_index(object: &str, frame: i64, count: usize) -> Result<usize, Error> {
    let resolved = if frame < 0 {
        count as i64 + frame
    } else {
        frame
    };
    if resolved < 0 || resolved >= count as i64 {
        return Err(Error::Frame {
            object: object.to_owned(),
            frame,
            count,
        });
    }
    Ok(resolved as usize)
}

/// Positions, triangles, UVs (when the file has them) and what the report says of the input.
type Geometry = (
    Vec<Vec3>,
    Vec<[u32; 3]>,
    Option<Vec<glam::Vec2>>,
    serde_json::Value,
);

fn load_file(path: &Path, desc: &crate::scene::ObjectDesc) -> Result<Geometry, Error> {
    let has_ext = |ext: &str| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    let animation = if path.is_dir() || has_ext("npy") {
        Some(meshio::load_animation(
            path,
            &meshio::AnimationOptions::default(),
        )?)
    } else if has_ext("glb") || has_ext("gltf") {
        // A glTF with an animation is posed at the requested frame; one without is static.
        meshio::load_animation(path, &meshio::AnimationOptions::default()).ok()
    } else {
        None
    };
    if let Some((anim, report)) = animation {
        let frame = frame_index(&desc.name, desc.frame, anim.frames.len())?;
        let detail = json!({
            "source": path.display().to_string(),
            "frame": frame,
            "frames": anim.frames.len(),
            "unreferenced_vertices": report.unreferenced_vertices.len(),
            "degenerate_triangles": report.degenerate_triangles.len(),
        });
        let positions = anim.frames[frame].clone();
        return Ok((positions, anim.triangles, anim.uvs, detail));
    }
    let (mesh, report) = meshio::load_mesh(path, &meshio::LoadOptions::default())?;
    let detail = json!({
        "source": path.display().to_string(),
        "unreferenced_vertices": report.unreferenced_vertices.len(),
        "degenerate_triangles": report.degenerate_triangles.len(),
        "duplicate_positions": report.duplicate_positions,
    });
    Ok((mesh.positions, mesh.triangles, mesh.uvs, detail))
}

fn load_environment(scene: &Scene) -> Result<(lightsphere::Environment, serde_json::Value), Error> {
    let desc = scene.environment.as_ref().ok_or_else(|| Error::Scene {
        origin: scene.origin.clone(),
        message: "environment stage planned without [environment]".to_owned(),
    })?;
    let (env, source) = match scene.environment_source()? {
        Some(EnvironmentSource::SynthSky) => {
            let params = sky_params(scene);
            let image = synth::sky(&params)?;
            let env =
                lightsphere::Environment::from_latlong(image.width, image.height, image.texels)?;
            (env, "synth:sky".to_owned())
        }
        Some(EnvironmentSource::File(path)) => (
            lightsphere::Environment::load(&path)?,
            path.display().to_string(),
        ),
        None => unreachable!("checked above"),
    };
    let rotation = Quat::from_rotation_y(desc.rotation_deg.to_radians());
    let mut env = env.with_rotation(rotation);
    if desc.prefilter_sigma_deg > 0.0 {
        env = env.prefiltered(desc.prefilter_sigma_deg)?;
    }
    let power = env.total_power();
    let params = json!({
        "source": source,
        "width": env.width(),
        "height": env.height(),
        "rotation_deg": desc.rotation_deg,
        "prefilter_sigma_deg": desc.prefilter_sigma_deg,
        "power_rgb": power,
    });
    Ok((env, params))
}

fn sky_params(scene: &Scene) -> synth::SkyParams {
    let mut params = synth::SkyParams::default();
    if let Some(e) = scene.synth.sun_elevation_deg {
        params.sun_elevation_deg = e;
    }
    if let Some(a) = scene.synth.sun_azimuth_deg {
        params.sun_azimuth_deg = a;
    }
    if let Some(w) = scene.synth.sky_width {
        params.width = w;
        params.height = (w / 2).max(1);
    }
    params
}

fn light_directions(
    scene: &Scene,
    env: &lightsphere::Environment,
) -> Result<((lightsphere::Lightsphere, Vec<Vec3>), serde_json::Value), Error> {
    let sphere = lightsphere::Lightsphere::new(scene.lighting.level)?;
    let method = match scene.lighting.method {
        RadianceMethodDesc::CellMean => lightsphere::RadianceMethod::CellMean,
        RadianceMethodDesc::PrefilteredLookup => lightsphere::RadianceMethod::PrefilteredLookup {
            sigma_deg: lightsphere::matched_sigma_deg(sphere.len()),
        },
    };
    let radiance = env.radiance_per_direction(&sphere, method)?;
    let power: [f64; 3] = std::array::from_fn(|c| {
        radiance
            .iter()
            .zip(sphere.solid_angles())
            .map(|(r, w)| f64::from(r[c]) * w)
            .sum()
    });
    let total = env.total_power();
    let power_error: Vec<f64> = (0..3)
        .map(|c| (power[c] - total[c]) / total[c].max(f64::MIN_POSITIVE))
        .collect();
    let params = json!({
        "level": sphere.level(),
        "directions": sphere.len(),
        "method": scene.lighting.method,
        "relative_power_error_rgb": power_error,
    });
    Ok(((sphere, radiance), params))
}

/// Preview shading when no lighting effect ran: albedo × (0.15 + 0.85 |n·v|), a headlight.
fn preview_shading(object: &WorldObject, eye: Vec3) -> Vec<Vec3> {
    object
        .positions
        .iter()
        .zip(&object.normals)
        .map(|(p, n)| {
            let v = (eye - *p).normalize_or_zero();
            object.albedo * (0.15 + 0.85 * n.dot(v).abs())
        })
        .collect()
}

fn luminance(c: Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

fn auto_exposure(objects: &[WorldObject], colors: &[(Vec<Vec3>, Vec<Vec3>)]) -> f32 {
    let mut lum: Vec<f32> = colors
        .iter()
        .zip(objects)
        .flat_map(|((f, _), o)| {
            f.iter()
                .zip(&o.normals)
                .filter(|(_, n)| **n != Vec3::ZERO)
                .map(|(c, _)| luminance(*c))
        })
        .filter(|l| l.is_finite() && *l > 0.0)
        .collect();
    if lum.is_empty() {
        return 1.0;
    }
    let k = ((lum.len() - 1) as f64 * AUTO_EXPOSURE_PERCENTILE) as usize;
    let (_, key, _) = lum.select_nth_unstable_by(k, f32::total_cmp);
    AUTO_EXPOSURE_KEY / *key
}

fn render_stage(
    scene: &Scene,
    out_dir: &Path,
    gpu: &GpuContext,
    objects: &[WorldObject],
    environment: Option<&lightsphere::Environment>,
) -> Result<(HdrImage, serde_json::Value, Vec<PathBuf>), Error> {
    let (centre, radius) = bounding_sphere(objects.iter().flat_map(|o| o.positions.iter()))
        .unwrap_or((Vec3::ZERO, 1.0));
    let camera = Camera::frame(&scene.camera, centre, radius);
    let colors: Vec<(Vec<Vec3>, Vec<Vec3>)> = objects
        .iter()
        .map(|o| match (&o.front, &o.back) {
            (Some(f), Some(b)) => (f.clone(), b.clone()),
            _ => {
                let c = preview_shading(o, camera.eye);
                (c.clone(), c)
            }
        })
        .collect();
    let meshes: Vec<DrawMesh<'_>> = objects
        .iter()
        .zip(&colors)
        .map(|(o, (f, b))| DrawMesh {
            positions: &o.positions,
            triangles: &o.triangles,
            front: f,
            back: b,
        })
        .collect();
    let backdrop = environment.map(|env| Backdrop {
        width: env.width(),
        height: env.height(),
        texels: env.texels(),
        world_from_env: env.world_from_env(),
    });
    let image = render(&gpu.device, &gpu.queue, &camera, &meshes, backdrop)?;
    let exposure = match scene.output.exposure {
        ExposureDesc::Fixed(x) => x,
        ExposureDesc::Auto(_) => auto_exposure(objects, &colors),
    };
    let tonemap = Tonemap {
        exposure,
        gamma: scene.output.gamma,
    };
    let mut written = Vec::new();
    if let Some(name) = &scene.output.png {
        let path = out_dir.join(name);
        image.write_png(&path, &tonemap)?;
        written.push(path);
    }
    if let Some(name) = &scene.output.exr {
        let path = out_dir.join(name);
        image.write_exr(&path)?;
        written.push(path);
    }
    let params = json!({
        "width": camera.width,
        "height": camera.height,
        "adapter": gpu.summary().to_string(),
        "exposure": exposure,
        "gamma": scene.output.gamma,
        "eye": camera.eye.to_array(),
    });
    Ok((image, params, written))
}
