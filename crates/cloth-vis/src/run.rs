//! Executing a plan: each stage in order, timed, its parameters recorded in the run report; a
//! still image or, with `[output] frames = "A..B"`, a numbered image sequence of the scene's
//! animated objects, every frame drawn by one [`render::Renderer`] built once.

use std::path::{Path, PathBuf};
use std::time::Instant;

use glam::Vec3;
use gpu_context::{GpuContext, GpuOptions, HdrImage};
use indicatif::{ProgressBar, ProgressStyle};
use render::sequence::FrameRange;
use render::tone::{Display, ToneCurve};
use render::{
    Background, Camera, DrawMesh, FrameFormat, FramePass, Renderer, bounding_sphere, output,
};
use serde_json::json;

use crate::Error;
use crate::frame_effects::FrameEffects;
use crate::inputs::{light_directions, load_environment, load_geometry};
use crate::object::WorldObject;
use crate::plan::{Plan, Stage};
use crate::report::{RunReport, StageRecord};
use crate::scene::{BackgroundDesc, BackgroundKeyword, ExposureDesc, GROUND_NAME, Scene, ToneDesc};
use crate::shadowing::VisibilityStage;
use crate::static_shadowing::StaticShadowingStage;

/// How a scene is run.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    /// Show progress bars on stderr for long stages.
    pub progress: bool,
    /// Adapter choice.
    pub gpu: GpuOptions,
    /// Render this frame range as an image sequence (overrides the scene's `[output] frames`).
    pub frames: Option<FrameRange>,
    /// Replace an output folder that already holds files (`--force`) once the new one is
    /// complete; without it such a folder is refused before any work.
    pub replace_output: bool,
}

/// What a run produced.
#[derive(Debug)]
pub struct RunOutput {
    /// Stages, times and files.
    pub report: RunReport,
    /// The linear HDR image (the last frame of a sequence).
    pub image: HdrImage,
    /// The plan that ran.
    pub plan: Plan,
    /// Render pipelines built during the run (gpu-context's per-thread count): constant in the
    /// number of frames, since the renderer builds its pipelines once.
    pub pipelines_built: u64,
}

pub(crate) struct Timer {
    pub(crate) stages: Vec<StageRecord>,
}

impl Timer {
    pub(crate) fn run<T>(
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

/// Per-frame times of one stage over a sequence.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FrameTimes {
    pub(crate) total_ms: f64,
    pub(crate) max_ms: f64,
    pub(crate) frames: usize,
}

impl FrameTimes {
    pub(crate) fn add(&mut self, ms: f64) {
        self.total_ms += ms;
        self.max_ms = self.max_ms.max(ms);
        self.frames += 1;
    }

    pub(crate) fn record(&self, stage: Stage, mut params: serde_json::Value) -> StageRecord {
        if let serde_json::Value::Object(map) = &mut params {
            map.insert("frames".into(), json!(self.frames));
            map.insert(
                "mean_ms_per_frame".into(),
                json!(self.total_ms / self.frames.max(1) as f64),
            );
            map.insert("max_ms_per_frame".into(), json!(self.max_ms));
        }
        StageRecord {
            stage: stage.name().to_owned(),
            millis: self.total_ms,
            params,
        }
    }
}

pub(crate) fn ms_since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}

/// Validate, plan and run `scene`, writing its images and run report into `out_dir`.
///
/// Every check that needs no work (effects, values, files) happens before any stage starts,
/// and the GPU adapter is acquired before the first stage so that a machine without one fails
/// at once.
///
/// `out_dir` (and its missing parents) appear only when the run succeeds: the images and the
/// report are written into a hidden folder beside it, renamed into place at the end. A folder
/// that already holds files is refused before any work unless `options.replace_output`.
///
/// # Errors
/// Any [`Error`], including a camera that sees none of the objects and a rendered image that
/// is non-finite or black where the objects are; nothing is left at `out_dir`.
pub fn run_scene(scene: &Scene, out_dir: &Path, options: &RunOptions) -> Result<RunOutput, Error> {
    let start = Instant::now();
    let pipelines_before = gpu_context::PipelineStats::on_this_thread().render_pipelines;
    let plan = Plan::for_scene(scene)?;
    let frames = match options.frames {
        Some(range) => Some(range),
        None => scene.frame_range()?,
    };
    // The folder is built in a hidden temporary folder beside `out_dir`, created only after
    // the inputs have loaded (below) and renamed into place when every image and the report
    // are written: a run that fails or is interrupted leaves nothing behind.
    let existing = folder_output(out_dir, options.replace_output)?;
    let gpu = GpuContext::new(&options.gpu)?;
    let mut timer = Timer { stages: Vec::new() };

    let mut objects = timer.run(Stage::Geometry, || {
        let (mut objects, params) = load_geometry(scene, options.progress)?;
        if plan.contains(Stage::Translucency) {
            crate::deform::apply(scene, &mut objects)?;
        }
        Ok((objects, params))
    })?;
    if let Some(range) = frames {
        check_range(scene, &objects, range)?;
    }
    // The camera frames the objects (over the whole range for a sequence), not the ground.
    let (camera, centre, radius) = frame_camera(scene, &objects, frames);
    // A camera that sees none of the objects is refused before any stage runs.
    crate::image_checks::check_in_view(scene, &camera, centre, radius)?;
    if let Some(ground) = &scene.ground {
        objects.push(ground_object(ground, &objects, frames));
    }

    let environment = if plan.contains(Stage::Environment) {
        Some(timer.run(Stage::Environment, || load_environment(scene))?)
    } else {
        None
    };
    // A shadow-volume light that is the sky's sun carries its direct light: the sky that
    // lights the vertices is made without it.
    let volumes_planned = plan.contains(Stage::ShadowVolumes);
    let sunless = if volumes_planned && scene.shadow_volumes.takes_sun() {
        Some(crate::inputs::load_environment_with(scene, false)?.0)
    } else {
        None
    };
    let lights = if plan.contains(Stage::LightDirections) {
        let env = sunless
            .as_ref()
            .or(environment.as_ref())
            .ok_or_else(|| Error::Scene {
                origin: scene.origin.clone(),
                message: "lighting planned without an environment".to_owned(),
            })?;
        Some(timer.run(Stage::LightDirections, || light_directions(scene, env))?)
    } else {
        None
    };

    // Volumes reach infinity: their frame has no far plane.
    let depth = if volumes_planned {
        render::DepthConvention::ReversedInfinite
    } else {
        render::DepthConvention::Standard
    };
    let (mut renderer, background, format) = renderer_for(scene, &gpu, environment.as_ref(), depth);
    // Set-up times (caster levels) are reported with the first frame.
    let mut effects = FrameEffects::new(
        scene,
        &plan,
        &gpu,
        &renderer,
        &mut objects,
        environment.as_ref(),
    )?;
    // One engine for the whole run: GPU backends keep their pipelines across frames.
    let mut shadowing = if plan.contains(Stage::Visibility) {
        Some(VisibilityStage::new(scene, Some(&gpu))?)
    } else {
        None
    };
    let statics = if plan.contains(Stage::StaticVisibility) {
        let env = environment.as_ref().ok_or_else(|| Error::Scene {
            origin: scene.origin.clone(),
            message: "static-shadowing planned without an environment".to_owned(),
        })?;
        Some((StaticShadowingStage::new(scene, Some(&gpu))?, env))
    } else {
        None
    };
    let look = Look {
        camera,
        background,
        adapter: gpu.summary().to_string(),
        samples: format.samples,
    };

    let mut finished = None;
    atomic_out::write_dir(out_dir, existing, |tmp| -> Result<(), Error> {
        let mut outputs = Vec::new();
        let image = match frames {
            None => {
                if let Some(lights) = &lights {
                    light_frame(shadowing.as_mut(), &mut objects, lights, &mut timer)?;
                }
                if let Some((stage, env)) = &statics {
                    timer.run(Stage::StaticVisibility, || {
                        Ok(((), stage.light(Some(&gpu), &mut objects, env)?))
                    })?;
                }
                for (stage, millis, params) in
                    effects.prepare(scene, &gpu, &mut objects, &look.camera)?
                {
                    let stage = stage.name().to_owned();
                    timer.stages.push(StageRecord {
                        stage,
                        millis,
                        params,
                    });
                }
                let passes = effects.passes();
                timer.run(Stage::Render, || {
                    let (image, params, written) =
                        render_still(scene, tmp, &gpu, &mut renderer, &objects, &look, &passes)?;
                    outputs = written;
                    Ok((image, params))
                })?
            }
            Some(range) => {
                // The btf stage follows the sequence: btf-NNNN.png per frame, materials once.
                let btf = if plan.contains(Stage::Btf) {
                    Some(crate::btf_scene::BtfScene::load(scene, &renderer, &gpu)?)
                } else {
                    None
                };
                let (image, written) = crate::run_sequence::render_sequence(
                    scene,
                    tmp,
                    &gpu,
                    shadowing.as_mut(),
                    statics.as_ref().map(|(stage, env)| (stage, *env)),
                    &mut effects,
                    &mut renderer,
                    &mut objects,
                    lights.as_ref(),
                    btf.as_ref().map(|b| (b, environment.as_ref())),
                    &look,
                    range,
                    options.progress,
                    &mut timer,
                )?;
                outputs = written;
                image
            }
        };

        if plan.contains(Stage::Btf) && frames.is_none() {
            let written = timer.run(Stage::Btf, || {
                crate::btf_scene::run(
                    scene,
                    tmp,
                    &gpu,
                    &mut renderer,
                    &objects,
                    &look,
                    environment.as_ref(),
                )
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
        report.total_millis = ms_since(start);
        let (json, text) = report.write(tmp, out_dir)?;
        report.outputs.extend([json, text]);
        finished = Some((image, report));
        Ok(())
    })?;
    let (image, report) = finished.ok_or_else(|| Error::Io {
        path: out_dir.to_owned(),
        reason: "the run's folder was written without its report".to_owned(),
    })?;
    Ok(RunOutput {
        report,
        image,
        plan,
        pipelines_built: gpu_context::PipelineStats::on_this_thread().render_pipelines
            - pipelines_before,
    })
}

/// How a folder output treats an existing folder at `out`: refused before any work when it
/// holds files (or is a file) and `replace` (`--force`) is not given — old frames would sit
/// beside new ones, or a shorter clip would overwrite the start of a longer one and look
/// complete — else replaced once the new folder is complete ([`atomic_out::write_dir`]).
///
/// # Errors
/// [`Error::Request`] naming the folder and `--force`.
pub fn folder_output(out: &Path, replace: bool) -> Result<atomic_out::ExistingFolder, Error> {
    if replace {
        return Ok(atomic_out::ExistingFolder::Replace);
    }
    let holds_files = std::fs::read_dir(out).is_ok_and(|mut entries| entries.next().is_some());
    let what = if holds_files {
        "is a folder that holds files"
    } else if out.exists() && !out.is_dir() {
        "is a file, and this output is a folder"
    } else {
        return Ok(atomic_out::ExistingFolder::Refuse);
    };
    Err(Error::Request {
        path: out.to_owned(),
        message: format!(
            "{what}; choose a new folder, or pass --force to replace it once the new output \
             is complete"
        ),
    })
}

/// What every image of a run shares: the camera, the background and where it was drawn.
#[derive(Clone, Debug)]
pub(crate) struct Look {
    /// The camera (fixed over a sequence).
    pub camera: Camera,
    /// The background.
    pub background: Background,
    /// The adapter, for reports.
    pub adapter: String,
    /// MSAA samples of the frame.
    pub samples: u32,
}

/// The background a scene asks for; `environment` without an environment is black.
pub(crate) fn background(scene: &Scene, has_environment: bool) -> Background {
    match scene.output.background {
        BackgroundDesc::Named(BackgroundKeyword::Environment) if has_environment => {
            Background::Environment
        }
        BackgroundDesc::Named(BackgroundKeyword::Environment | BackgroundKeyword::Black) => {
            Background::Color([0.0; 3])
        }
        BackgroundDesc::Named(BackgroundKeyword::Transparent) => Background::Transparent,
        BackgroundDesc::Color(c) => Background::Color(c),
    }
}

/// The scene's camera: framed on the bounding sphere of the vertices the objects' triangles
/// use (a stray unreferenced vertex does not shrink the picture), over every frame of `range`
/// for a sequence, so the camera holds still.
/// Returns the camera and the sphere (centre, radius) it frames.
pub(crate) fn frame_camera(
    scene: &Scene,
    objects: &[WorldObject],
    range: Option<FrameRange>,
) -> (Camera, Vec3, f32) {
    let mut points = Vec::new();
    for o in objects {
        let used = o.used_vertices();
        match (&o.animation, range) {
            (Some(a), Some(r)) => {
                for frame in &a.frames[r.start..r.end] {
                    points.extend(
                        used.iter()
                            .map(|&i| a.world_from_object.transform_point3(frame[i])),
                    );
                }
            }
            _ => points.extend(used.iter().map(|&i| o.positions[i])),
        }
    }
    let (centre, radius) = bounding_sphere(&points).unwrap_or((Vec3::ZERO, 1.0));
    let camera = crate::camera::resolve(&scene.camera, centre, radius);
    (camera, centre, radius)
}

/// A ground grid under the objects: at their lowest point (over the range), centred under
/// their bounding sphere, `size` radii wide.
pub(crate) fn ground_object(
    desc: &crate::scene::GroundDesc,
    objects: &[WorldObject],
    range: Option<FrameRange>,
) -> WorldObject {
    let points: Vec<Vec3> = objects
        .iter()
        .flat_map(|o| match range {
            Some(_) => o.all_world_positions(),
            None => o.positions.clone(),
        })
        .collect();
    let (centre, radius) = bounding_sphere(&points).unwrap_or((Vec3::ZERO, 1.0));
    let height = points.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    let height = if height.is_finite() { height } else { 0.0 };
    let (positions, triangles, uvs) = render::ground::ground_grid(
        centre,
        height,
        desc.size * render::usable_radius(radius),
        desc.cells,
    );
    let normals = vec![Vec3::Y; positions.len()];
    WorldObject {
        name: GROUND_NAME.to_owned(),
        positions,
        normals,
        triangles,
        uvs: Some(uvs),
        albedo: Vec3::from(desc.albedo),
        two_sided: false,
        front: None,
        back: None,
        animation: None,
    }
}

/// Every animated object must hold the range; at least one object must be animated.
fn check_range(scene: &Scene, objects: &[WorldObject], range: FrameRange) -> Result<(), Error> {
    let animated: Vec<&WorldObject> = objects.iter().filter(|o| o.animation.is_some()).collect();
    if animated.is_empty() {
        return Err(Error::Scene {
            origin: scene.origin.clone(),
            message: format!(
                "output.frames = {range}: no object is animated (use an animation source: \
                 synth:cloth, .npy, an OBJ frame folder or an animated glTF{})",
                if scene.effects.iter().any(|e| e == "translucency")
                    && scene.translucency.deform.is_none()
                {
                    "; or [translucency] deform = {…} — `--deform A,K,N` — to sway a static mesh"
                } else {
                    ""
                }
            ),
        });
    }
    for o in animated {
        range.check(o.frame_count()).map_err(|m| Error::Scene {
            origin: scene.origin.clone(),
            message: format!("output.frames for object {:?}: {m}", o.name),
        })?;
    }
    Ok(())
}

/// The lightsphere and I_j per direction.
pub(crate) type Lights = (lightsphere::Lightsphere, Vec<Vec3>);

/// Visibility (when planned) and lighting of the objects as posed, recorded as stages.
fn light_frame(
    shadowing: Option<&mut VisibilityStage>,
    objects: &mut [WorldObject],
    (sphere, radiance): &Lights,
    timer: &mut Timer,
) -> Result<(), Error> {
    let visibility = match shadowing {
        Some(stage) => Some(timer.run(Stage::Visibility, || stage.compute(objects, sphere))?),
        None => None,
    };
    timer.run(Stage::Lighting, || {
        let vertices =
            crate::shadowing::light_objects(objects, sphere, radiance, visibility.as_ref())?;
        let params = json!({
            "vertices": vertices,
            "directions": sphere.len(),
            "visibility": visibility.is_some(),
        });
        Ok(((), params))
    })
}

/// A renderer for `scene`: its frame format, the environment backdrop when the background
/// shows it, and the background itself.
pub(crate) fn renderer_for(
    scene: &Scene,
    gpu: &GpuContext,
    environment: Option<&lightsphere::Environment>,
    depth: render::DepthConvention,
) -> (Renderer, Background, FrameFormat) {
    let format = FrameFormat::for_context(gpu).with_depth(depth);
    let mut renderer = Renderer::new(&gpu.device, format);
    let background = background(scene, environment.is_some());
    if background == Background::Environment {
        renderer.backdrop.set_environment(
            &gpu.device,
            environment.map(|env| render::Backdrop {
                width: env.width(),
                height: env.height(),
                texels: env.texels(),
                world_from_env: env.world_from_env(),
            }),
        );
    }
    (renderer, background, format)
}

/// One still of `objects` as they are lit (preview shading where unlit) through the scene's
/// camera framed on them, over its background, with its display mapping — what
/// [`run_scene`] draws and writes, for callers that run the stages themselves (`cloth-vis
/// visibility --render`). Returns the linear image, the display mapping for a PNG and the
/// background (for the alpha matte).
///
/// # Errors
/// [`Error::Render`] when the renderer refuses the meshes or the camera.
pub fn render_still_image(
    scene: &Scene,
    gpu: &GpuContext,
    objects: &[WorldObject],
    environment: Option<&lightsphere::Environment>,
) -> Result<(HdrImage, Display, Background), Error> {
    let (mut renderer, background, _) =
        renderer_for(scene, gpu, environment, render::DepthConvention::Standard);
    let (camera, centre, radius) = frame_camera(scene, objects, None);
    crate::image_checks::check_in_view(scene, &camera, centre, radius)?;
    set_gouraud_meshes(gpu, &mut renderer, objects, &camera, &[])?;
    let image = renderer.render(&gpu.device, &gpu.queue, &camera, background, &[])?;
    crate::image_checks::check_rendered(scene, &image, None)?;
    let display = display_for(scene, &image);
    Ok((image, display, background))
}

/// A progress bar on stderr labelled `message`, hidden when `show` is false.
pub fn progress_bar(show: bool, len: u64, message: &'static str) -> ProgressBar {
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

/// Hand the objects' current positions and radiance to the Gouraud pass (in place when the
/// topology is unchanged), skipping `except` (objects another pass draws).
pub(crate) fn set_gouraud_meshes(
    gpu: &GpuContext,
    renderer: &mut Renderer,
    objects: &[WorldObject],
    camera: &Camera,
    except: &[&str],
) -> Result<(), Error> {
    let drawn: Vec<&WorldObject> = objects
        .iter()
        .filter(|o| !except.contains(&o.name.as_str()))
        .collect();
    let colors: Vec<(Vec<Vec3>, Vec<Vec3>)> = drawn
        .iter()
        .map(|o| match (&o.front, &o.back) {
            (Some(f), Some(b)) => (f.clone(), b.clone()),
            _ => {
                let c = preview_shading(o, camera.eye);
                (c.clone(), c)
            }
        })
        .collect();
    let meshes: Vec<DrawMesh<'_>> = drawn
        .iter()
        .zip(&colors)
        .map(|(o, (f, b))| DrawMesh {
            positions: &o.positions,
            triangles: &o.triangles,
            front: f,
            back: b,
        })
        .collect();
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, &meshes)?;
    Ok(())
}

/// The display mapping of a scene for `image`: fixed EV, or automatic from the objects'
/// pixels (the backdrop never counts).
pub(crate) fn display_for(scene: &Scene, image: &HdrImage) -> Display {
    let exposure_ev = match scene.output.exposure {
        ExposureDesc::Fixed(ev) => ev,
        ExposureDesc::Auto(_) => output::auto_exposure(image),
    };
    let curve = match scene.output.tone {
        ToneDesc::Aces => ToneCurve::AcesFitted,
        ToneDesc::Clamp => ToneCurve::Clamp {
            gamma: scene.output.gamma,
        },
    };
    Display { exposure_ev, curve }
}

/// Write `image` as the scene's PNG and/or EXR names (`png`, `exr`); returns the paths.
pub(crate) fn write_images(
    image: &HdrImage,
    display: &Display,
    background: Background,
    png: Option<PathBuf>,
    exr: Option<PathBuf>,
) -> Result<Vec<PathBuf>, Error> {
    let mut written = Vec::new();
    if let Some(path) = png {
        output::write_png(image, &path, display, background)?;
        written.push(path);
    }
    if let Some(path) = exr {
        output::write_exr(image, &path, background)?;
        written.push(path);
    }
    Ok(written)
}

fn render_still(
    scene: &Scene,
    out_dir: &Path,
    gpu: &GpuContext,
    renderer: &mut Renderer,
    objects: &[WorldObject],
    look: &Look,
    passes: &[&dyn FramePass],
) -> Result<(HdrImage, serde_json::Value, Vec<PathBuf>), Error> {
    set_gouraud_meshes(gpu, renderer, objects, &look.camera, &[])?;
    let image = renderer.render(
        &gpu.device,
        &gpu.queue,
        &look.camera,
        look.background,
        passes,
    )?;
    crate::image_checks::check_rendered(scene, &image, None)?;
    let display = display_for(scene, &image);
    let written = write_images(
        &image,
        &display,
        look.background,
        scene.output.png.as_ref().map(|n| out_dir.join(n)),
        scene.output.exr.as_ref().map(|n| out_dir.join(n)),
    )?;
    let params = json!({
        "width": look.camera.width,
        "height": look.camera.height,
        "adapter": look.adapter,
        "msaa_samples": look.samples,
        "exposure_ev": display.exposure_ev,
        "tone": scene.output.tone,
        "background": scene.output.background,
        "eye": look.camera.eye.to_array(),
    });
    Ok((image, params, written))
}
