//! An image sequence of a scene (`--frames A..B`, `[output] frames`): per frame the pose, the
//! visibility and lighting, the frame effects, the render and its files, and the btf stage's
//! own picture — one renderer for the whole range, each stage timed per frame.

use std::path::{Path, PathBuf};
use std::time::Instant;

use gpu_context::{GpuContext, HdrImage};
use render::Renderer;
use render::sequence::{FrameRange, frame_file_name};
use render::tone::Display;
use serde_json::json;

use crate::Error;
use crate::frame_effects::FrameEffects;
use crate::object::WorldObject;
use crate::plan::Stage;
use crate::run::{
    FrameTimes, Lights, Look, Timer, display_for, ms_since, progress_bar, set_gouraud_meshes,
    write_images,
};
use crate::scene::Scene;
use crate::shadowing::VisibilityStage;
use crate::static_shadowing::StaticShadowingStage;

/// The frames of `range`: pose, visibility, lighting, render, write — one renderer, buffers
/// rewritten in place. Exposure is fixed on the first frame (automatic exposure per frame
/// would flicker).
#[allow(clippy::too_many_arguments)]
pub(crate) fn render_sequence(
    scene: &Scene,
    out_dir: &Path,
    gpu: &GpuContext,
    mut shadowing: Option<&mut VisibilityStage>,
    statics: Option<(&StaticShadowingStage, &lightsphere::Environment)>,
    effects: &mut FrameEffects,
    renderer: &mut Renderer,
    objects: &mut [WorldObject],
    lights: Option<&Lights>,
    btf: Option<(
        &crate::btf_scene::BtfScene,
        Option<&lightsphere::Environment>,
    )>,
    look: &Look,
    range: FrameRange,
    progress: bool,
    timer: &mut Timer,
) -> Result<(HdrImage, Vec<PathBuf>), Error> {
    let bar = progress_bar(progress, range.len() as u64, "rendering frames");
    let (mut pose_t, mut vis_t, mut light_t, mut render_t, mut write_t) = Default::default();
    let mut static_t = FrameTimes::default();
    let (mut btf_t, mut btf_params) = (FrameTimes::default(), json!({}));
    let (mut vis_params, mut light_params, mut static_params) = (json!({}), json!({}), json!({}));
    let mut effect_t: Vec<(Stage, FrameTimes, serde_json::Value)> = Vec::new();
    let mut display: Option<Display> = None;
    let mut written = Vec::new();
    let mut last = None;
    for f in range.iter() {
        let t = Instant::now();
        for o in objects.iter_mut() {
            o.pose(f);
        }
        FrameTimes::add(&mut pose_t, ms_since(t));
        if let Some((sphere, radiance)) = lights {
            let visibility = if let Some(stage) = shadowing.as_deref_mut() {
                let t = Instant::now();
                let (v, p) = stage.compute(objects, sphere)?;
                FrameTimes::add(&mut vis_t, ms_since(t));
                vis_params = p;
                Some(v)
            } else {
                None
            };
            let t = Instant::now();
            let vertices =
                crate::shadowing::light_objects(objects, sphere, radiance, visibility.as_ref())?;
            FrameTimes::add(&mut light_t, ms_since(t));
            light_params = json!({ "vertices": vertices, "directions": sphere.len() });
        }
        if let Some((stage, env)) = statics {
            let t = Instant::now();
            static_params = stage.light(Some(gpu), objects, env)?;
            FrameTimes::add(&mut static_t, ms_since(t));
        }
        for (stage, millis, params) in effects.prepare(scene, gpu, objects, &look.camera)? {
            match effect_t.iter_mut().find(|e| e.0 == stage) {
                Some(e) => {
                    e.1.add(millis);
                    e.2 = params;
                }
                None => {
                    let mut t = FrameTimes::default();
                    t.add(millis);
                    effect_t.push((stage, t, params));
                }
            }
        }
        let passes = effects.passes();
        let t = Instant::now();
        set_gouraud_meshes(gpu, renderer, objects, &look.camera, &[])?;
        let image = renderer.render(
            &gpu.device,
            &gpu.queue,
            &look.camera,
            look.background,
            &passes,
        )?;
        crate::image_checks::check_rendered(scene, &image, Some(f))?;
        FrameTimes::add(&mut render_t, ms_since(t));
        let t = Instant::now();
        let d = *display.get_or_insert_with(|| display_for(scene, &image));
        let png = Some(out_dir.join(frame_file_name("frame", f, "png")));
        let exr = scene
            .output
            .sequence_exr
            .then(|| out_dir.join(frame_file_name("frame", f, "exr")));
        written.extend(write_images(&image, &d, look.background, png, exr)?);
        FrameTimes::add(&mut write_t, ms_since(t));
        last = Some(image);
        if let Some((stage, env)) = btf {
            let t = Instant::now();
            let png = frame_file_name("btf", f, "png");
            let (files, params) =
                stage.frame(scene, out_dir, &png, gpu, renderer, objects, look, env)?;
            written.extend(files);
            FrameTimes::add(&mut btf_t, ms_since(t));
            btf_params = params;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let times: [(Stage, &FrameTimes, serde_json::Value); 6] = [
        (
            Stage::Geometry,
            &pose_t,
            json!({ "what": "pose and normals per frame" }),
        ),
        (Stage::Visibility, &vis_t, vis_params),
        (Stage::StaticVisibility, &static_t, static_params),
        (Stage::Lighting, &light_t, light_params),
        (
            Stage::Render,
            &render_t,
            json!({
                "width": look.camera.width,
                "height": look.camera.height,
                "adapter": look.adapter,
                "msaa_samples": look.samples,
                "exposure_ev": display.map(|d| d.exposure_ev),
                "range": range.to_string(),
                "gpu_mesh_allocations": renderer.gouraud.allocations(),
                "write_mean_ms_per_frame": write_t.total_ms / write_t.frames.max(1) as f64,
            }),
        ),
        (Stage::Btf, &btf_t, btf_params),
    ];
    let effect_times = effect_t.iter().map(|(s, t, p)| (*s, t, p.clone()));
    for (stage, t, params) in times.into_iter().chain(effect_times) {
        if t.frames > 0 {
            timer.stages.push(t.record(stage, params));
        }
    }
    let image = last.ok_or_else(|| Error::Scene {
        origin: scene.origin.clone(),
        message: format!("output.frames = {range} holds no frame"),
    })?;
    Ok((image, written))
}
