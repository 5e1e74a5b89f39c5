//! The input stages of a run: geometry (meshes, animations, the simulated cloth, posed at the
//! scene's frame and kept whole for sequences), the HDR environment, and the lightsphere with
//! its radiance per direction I_j.

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;
use serde_json::json;

use crate::Error;
use crate::object::{Animation, WorldObject};
use crate::run::progress_bar;
use crate::scene::{EnvironmentSource, GeometrySource, RadianceMethodDesc, Scene};

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

/// Load every object of `scene` in world space: files through `meshio`, the simulated cloth
/// (simulated once, shared by every object that shows it, with a progress bar when
/// `progress`), the obstacle; posed at each object's `frame`, with angle-weighted normals
/// computed in world space and, for animated sources, every frame kept for sequences.
/// Returns the objects and what the run report records of each.
///
/// # Errors
/// Loader errors naming the file, [`Error::Frame`] for a frame outside an animation,
/// [`Error::Scene`] for a source the scene cannot resolve.
pub fn load_geometry(
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
        Some(SharedCloth {
            frames: Arc::new(anim.frames),
            triangles: anim.triangles,
            uvs: anim.uvs,
            grid: anim.grid,
            obstacle: anim.obstacle,
        })
    } else {
        None
    };
    let mut objects = Vec::with_capacity(scene.objects.len());
    let mut params = serde_json::Map::new();
    for (index, desc) in scene.objects.iter().enumerate() {
        let (positions, triangles, uvs, detail, animation) = match (
            scene.geometry_source(index)?,
            &cloth,
        ) {
            (GeometrySource::SynthCloth, Some(anim)) => {
                let frame = frame_index(scene, index, anim.frames.len())?;
                let detail = json!({ "source": "synth:cloth", "frame": frame, "frames": anim.frames.len(), "grid": anim.grid });
                (
                    anim.frames[frame].clone(),
                    anim.triangles.clone(),
                    Some(anim.uvs.clone()),
                    detail,
                    Some(Arc::clone(&anim.frames)),
                )
            }
            (GeometrySource::SynthCloth, None) => {
                return Err(Error::Scene {
                    origin: scene.origin.clone(),
                    message: format!(
                        "object {:?}: the synthetic cloth was not simulated",
                        desc.name
                    ),
                });
            }
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
                    None,
                )
            }
            (GeometrySource::File(path), _) => load_file(&path, scene, index)?,
        };
        let world_from_object = desc.world_from_object();
        let positions: Vec<Vec3> = positions
            .iter()
            .map(|p| world_from_object.transform_point3(*p))
            .collect();
        // A huge scale or translation overflows f32 here or in the first squared length
        // downstream (the camera framing); refused by the object's keys instead.
        if let Some(p) = positions
            .iter()
            .find(|p| !(p.is_finite() && p.abs().max_element() <= MAX_WORLD_COORDINATE))
        {
            return Err(scene.invalid(
                &format!("object[{index}] ({}).scale/translation", desc.name),
                format!(
                    "a vertex lands at {p}, beyond ±{MAX_WORLD_COORDINATE:e} \
                     (cloth_vis::inputs::MAX_WORLD_COORDINATE; squared lengths would overflow \
                     f32); scale {} and translation {:?} are too large",
                    desc.scale, desc.translation
                ),
            ));
        }
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
            animation: animation.map(|frames| Animation {
                frames,
                world_from_object,
            }),
        });
    }
    Ok((objects, serde_json::Value::Object(params)))
}

/// The largest world coordinate an object may reach after its scale and translation: its
/// square stays far inside f32 (1e30 < 3.4e38), so bounding spheres and camera framing stay
/// finite. Real assets (even a city in millimetres, ~1e7) sit far below it.
pub const MAX_WORLD_COORDINATE: f32 = 1e15;

/// Subdivision detail of the obstacle sphere mesh.
const OBSTACLE_DETAIL: u32 = 4;

fn frame_index(scene: &Scene, index: usize, count: usize) -> Result<usize, Error> {
    let desc = &scene.objects[index];
    let frame = desc.frame;
    let resolved = if frame < 0 {
        count as i64 + frame
    } else {
        frame
    };
    if resolved < 0 || resolved >= count as i64 {
        return Err(Error::Frame {
            origin: scene.origin.clone(),
            key: format!("object[{index}] ({}).frame", desc.name),
            frame,
            count,
        });
    }
    Ok(resolved as usize)
}

/// Positions, triangles, UVs (when the file has them), what the report says of the input, and
/// the object-space frames of an animation.
type Geometry = (
    Vec<Vec3>,
    Vec<[u32; 3]>,
    Option<Vec<glam::Vec2>>,
    serde_json::Value,
    Option<Arc<Vec<Vec<Vec3>>>>,
);

/// The simulated cloth, its frames shared by every object that shows it.
struct SharedCloth {
    frames: Arc<Vec<Vec<Vec3>>>,
    triangles: Vec<[u32; 3]>,
    uvs: Vec<glam::Vec2>,
    grid: usize,
    obstacle: synth::Obstacle,
}

/// One frame (the object's `frame`) of a compressed animation (`.cpca`, thesis §3.3),
/// decoded on the CPU: a scene shows it as a still; `cloth-vis view` streams the rest through
/// the GPU decoder.
fn load_cpca_frame(path: &Path, scene: &Scene, index: usize) -> Result<Geometry, Error> {
    let refuse = |message: String| Error::Request {
        path: path.to_owned(),
        message,
    };
    let bytes = input_guard::read_regular(path).map_err(|e| Error::Io {
        path: path.to_owned(),
        reason: e.to_string(),
    })?;
    let data = anim_pca::Compressed::from_bytes(&bytes).map_err(|e| refuse(e.to_string()))?;
    if data.triangles().is_empty() {
        return Err(refuse(
            "the file stores no triangles (it was compressed from an .npy clip); compress the \
             clip from a mesh format to show it"
                .to_owned(),
        ));
    }
    let frame = frame_index(scene, index, data.frames())?;
    let decoder = anim_pca::compress::Decoder::new(&data);
    let mut scratch = decoder.scratch();
    let mut positions = vec![Vec3::ZERO; data.vertices()];
    decoder
        .frame_into(frame, &mut positions, &mut scratch)
        .map_err(|e| refuse(e.to_string()))?;
    let detail = json!({
        "source": path.display().to_string(),
        "frame": frame,
        "frames": data.frames(),
        "compressed": true,
    });
    Ok((positions, data.triangles().to_vec(), None, detail, None))
}

fn load_file(path: &Path, scene: &Scene, index: usize) -> Result<Geometry, Error> {
    let has_ext = |ext: &str| {
        path.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    let animation = if path.is_dir() || ["npy", "pc2", "mdd"].iter().any(|e| has_ext(e)) {
        // Point caches take their triangles from the object's `topology` mesh.
        let options = meshio::AnimationOptions {
            topology: scene.topology_path(index),
            ..meshio::AnimationOptions::default()
        };
        Some(meshio::load_animation(path, &options)?)
    } else if has_ext("glb") || has_ext("gltf") {
        // A glTF with an animation is posed at the requested frame; one without is static.
        meshio::load_animation(path, &meshio::AnimationOptions::default()).ok()
    } else {
        None
    };
    if has_ext("cpca") {
        return load_cpca_frame(path, scene, index);
    }
    if let Some((anim, report)) = animation {
        let frame = frame_index(scene, index, anim.frames.len())?;
        let detail = json!({
            "source": path.display().to_string(),
            "frame": frame,
            "frames": anim.frames.len(),
            "unreferenced_vertices": report.unreferenced_vertices.len(),
            "degenerate_triangles": report.degenerate_triangles.len(),
        });
        let positions = anim.frames[frame].clone();
        let frames = Arc::new(anim.frames);
        return Ok((positions, anim.triangles, anim.uvs, detail, Some(frames)));
    }
    // A BTF needs one texture coordinate per vertex: with the `btf` effect, an OBJ's UV seams
    // are split (normals stay welded, so the seams do not show in the shading).
    let (mesh, report) = if scene.effects.iter().any(|e| e == "btf") {
        let (split, report) = meshio::load_mesh_split_seams(path, &meshio::LoadOptions::default())?;
        (split.mesh, report)
    } else {
        meshio::load_mesh(path, &meshio::LoadOptions::default())?
    };
    let detail = json!({
        "source": path.display().to_string(),
        "unreferenced_vertices": report.unreferenced_vertices.len(),
        "degenerate_triangles": report.degenerate_triangles.len(),
        "duplicate_positions": report.duplicate_positions,
    });
    Ok((mesh.positions, mesh.triangles, mesh.uvs, detail, None))
}

/// Load or make the scene's HDR environment (a file, or the procedural sky), rotated about
/// +Y by `[environment] rotation_deg` and prefiltered when asked. Returns the environment and
/// what the run report records of it.
///
/// # Errors
/// Loader errors naming the file; [`Error::Scene`] when the scene has no environment.
pub fn load_environment(
    scene: &Scene,
) -> Result<(lightsphere::Environment, serde_json::Value), Error> {
    load_environment_with(scene, true)
}

/// [`load_environment`], with the procedural sky's sun left out when `sun` is false (a
/// `shadow-volumes` light then carries the sun's direct light, so the sky must not light with
/// it twice).
///
/// # Errors
/// As [`load_environment`].
pub fn load_environment_with(
    scene: &Scene,
    sun: bool,
) -> Result<(lightsphere::Environment, serde_json::Value), Error> {
    let desc = scene.environment.as_ref().ok_or_else(|| Error::Scene {
        origin: scene.origin.clone(),
        message: "environment stage planned without [environment]".to_owned(),
    })?;
    let (env, source) = match scene.environment_source()? {
        Some(EnvironmentSource::SynthSky) => {
            let mut params = sky_params(scene);
            if !sun {
                params.sun_to_sky_ratio = 0.0;
            }
            let image = synth::sky(&params)?;
            let env =
                lightsphere::Environment::from_latlong(image.width, image.height, image.texels)?;
            (env, "synth:sky".to_owned())
        }
        Some(EnvironmentSource::File(path)) => (
            lightsphere::Environment::load(&path)?,
            path.display().to_string(),
        ),
        None => {
            return Err(Error::Scene {
                origin: scene.origin.clone(),
                message: "environment stage planned without an environment source".to_owned(),
            });
        }
    };
    let rotation = crate::lighting::environment_rotation(desc.rotation_deg);
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

pub(crate) fn sky_params(scene: &Scene) -> synth::SkyParams {
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

/// The lightsphere of `[lighting] level` and the radiance I_j of `env` per direction (paper
/// 000 §3.4, by the scene's method), with the relative error of the total power Σ_j I_j ω_j
/// against the environment's for the run report.
///
/// # Errors
/// [`Error::Light`] for a level outside the lightsphere's range.
pub fn light_directions(
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
