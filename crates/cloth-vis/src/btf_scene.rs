//! The `btf` stage of a scene (crate-internal): the material (and one per garment part), the
//! plain companion, both frames and the PNG — see [`crate::btf_stage`] for what the halves
//! show.
//!
//! **Garment parts** (thesis §5.6): `[btf] parts = { NAME = "FILE.btfpca" | "synth:woven" }`
//! gives the faces of material NAME (OBJ `usemtl`, glTF material) of every BTF object loaded
//! from a file their own BTF; the other faces wear `[btf] source`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::BtfPca;
use btf::render::{Light, RenderParams};
use glam::{Vec2, Vec3};
use gpu_context::{GpuContext, HdrImage};
use render::{FramePass, Renderer};
use serde_json::json;

use crate::Error;
use crate::btf_stage::{
    Lit, material_part, plain_material, render_items, synth_material, tangents_of,
};
use crate::object::WorldObject;
use crate::run::Look;
use crate::scene::Scene;

/// One frame of the scene: the items (objects or parts, each with its BTF), the Gouraud pass
/// drawing the rest, the fins when given.
fn scene_frame(
    gpu: &GpuContext,
    renderer: &mut Renderer,
    items: &[(&BtfPca, &WorldObject)],
    light: &Lit,
    look: &Look,
    params: &RenderParams,
    fins: Option<&crate::fins_stage::FinFrame>,
) -> Result<HdrImage, Error> {
    let extra: Vec<&dyn FramePass> = fins
        .map(|f| f.draws.iter().map(|d| d as &dyn FramePass).collect())
        .unwrap_or_default();
    render_items(
        gpu,
        renderer,
        items,
        light,
        &look.camera,
        look.background,
        params,
        &extra,
    )
}

/// A BTF named in a scene: `synth:woven` or a file relative to the scene.
fn load_material(scene: &Scene, key: &str, source: &str) -> Result<(BtfPca, String), Error> {
    let desc = &scene.btf;
    match scene.material_source(key, source)? {
        crate::scene::BtfSource::SynthWoven => Ok((
            synth_material(desc.res, desc.components)?,
            format!("synth:woven ({0}x{0})", desc.res),
        )),
        crate::scene::BtfSource::File(path) => {
            Ok((BtfPca::read(&path)?, path.display().to_string()))
        }
    }
}

/// A drawn item: (material index — 0 the base material, part k at k + 1 —, index of the
/// chosen object it belongs to, the object or its part).
pub(crate) type Item = (usize, usize, WorldObject);

/// The drawn items: every chosen object whole, or split by face material when `[btf] parts`
/// names materials it has (`face_materials`: per scene object name, its file's materials).
pub(crate) fn split_into_parts(
    chosen: &[&WorldObject],
    parts: &[String],
    face_materials: &BTreeMap<String, meshio::FaceMaterials>,
) -> Result<Vec<Item>, Error> {
    let mut items = Vec::new();
    let mut used = vec![false; parts.len()];
    for (o, object) in chosen.iter().enumerate() {
        let materials = face_materials
            .get(&object.name)
            .filter(|m| m.per_triangle.len() == object.triangles.len());
        let Some(materials) = materials else {
            items.push((0, o, (*object).clone()));
            continue;
        };
        let mut ids: Vec<Option<u32>> = materials.per_triangle.clone();
        ids.sort_unstable();
        ids.dedup();
        for id in ids {
            let name = id.map(|i| materials.names[i as usize].as_str());
            let index = name
                .and_then(|n| parts.iter().position(|p| p == n))
                .map_or(0, |k| {
                    used[k] = true;
                    k + 1
                });
            let label = format!("{} ({})", object.name, name.unwrap_or("no material"));
            if let Some(part) = material_part(object, &materials.per_triangle, id, &label) {
                items.push((index, o, part));
            }
        }
    }
    if let Some(k) = used.iter().position(|u| !u) {
        return Err(Error::Request {
            path: PathBuf::from(format!("btf.parts.{}", parts[k])),
            message: "no BTF object loaded from a file has a face material of that name \
                      (OBJ usemtl, glTF material)"
                .to_owned(),
        });
    }
    Ok(items)
}

/// The objects `[btf] objects` names (all with UVs but the ground when empty).
///
/// # Errors
/// [`Error::Request`] when there is none.
pub(crate) fn chosen_objects<'a>(
    desc: &crate::scene::BtfDesc,
    objects: &'a [WorldObject],
) -> Result<Vec<&'a WorldObject>, Error> {
    let chosen: Vec<&WorldObject> = objects
        .iter()
        .filter(|o| {
            if desc.objects.is_empty() {
                o.uvs.is_some() && o.name != crate::scene::GROUND_NAME
            } else {
                desc.objects.contains(&o.name)
            }
        })
        .collect();
    if chosen.is_empty() {
        return Err(Error::Request {
            path: PathBuf::from("btf.objects"),
            message: "no object to draw with the BTF".to_owned(),
        });
    }
    Ok(chosen)
}

/// The `btf` stage's materials, loaded once for a still or a whole sequence: the base BTF and
/// one per part, their plain companions, the fin material, the objects' face materials.
pub(crate) struct BtfScene {
    pub(crate) materials: Vec<BtfPca>,
    pub(crate) plains: Vec<BtfPca>,
    source: String,
    sources: BTreeMap<String, String>,
    pub(crate) part_names: Vec<String>,
    pub(crate) face_materials: BTreeMap<String, meshio::FaceMaterials>,
    fins: Option<btf::render::GpuFinRenderer>,
    material_ms: f64,
}

impl BtfScene {
    /// The fins of `chosen` (the BTF's objects) for `camera`'s eye, lit by `[btf]`'s light
    /// (§5.7), when `[btf] fins` asks for them.
    ///
    /// # Errors
    /// Silhouette extraction and upload errors.
    pub(crate) fn fins_for(
        &self,
        scene: &Scene,
        chosen: &[&WorldObject],
        camera: &render::Camera,
    ) -> Result<Option<crate::fins_stage::FinFrame>, Error> {
        let desc = &scene.btf;
        let (Some(f), Some(fin_renderer)) = (&desc.fins, &self.fins) else {
            return Ok(None);
        };
        let (_, radius) = render::bounding_sphere(chosen.iter().flat_map(|o| &o.positions))
            .unwrap_or((Vec3::ZERO, 1.0));
        let look_fins = crate::fins_stage::FinLook::for_radius(radius, f.height, f.size);
        let light = Light::Directional {
            dir_to_light_world: Vec3::from(desc.light_dir),
            radiance: Vec3::from(desc.radiance),
        };
        Ok(Some(crate::fins_stage::fin_frame(
            fin_renderer,
            chosen,
            &light,
            camera,
            &look_fins,
        )?))
    }

    /// Loads what `[btf]` names.
    ///
    /// # Errors
    /// Material and mesh-file errors.
    pub(crate) fn load(
        scene: &Scene,
        renderer: &Renderer,
        gpu: &GpuContext,
    ) -> Result<Self, Error> {
        let desc = &scene.btf;
        let start = Instant::now();
        let (pca, source) = load_material(scene, "btf.source", &desc.source)?;
        let mut materials = vec![pca];
        let mut sources: BTreeMap<String, String> = BTreeMap::new();
        for (name, src) in &desc.parts {
            let (p, s) = load_material(scene, &format!("btf.parts.{name}"), src)?;
            materials.push(p);
            sources.insert(name.clone(), s);
        }
        let plains = materials
            .iter()
            .map(plain_material)
            .collect::<Result<Vec<_>, _>>()?;
        let mut face_materials = BTreeMap::new();
        if !desc.parts.is_empty() {
            for (i, o) in scene.objects.iter().enumerate() {
                if let crate::scene::GeometrySource::File(path) = scene.geometry_source(i)?
                    && let Some(m) = meshio::load_face_materials(&path)?
                {
                    face_materials.insert(o.name.clone(), m);
                }
            }
        }
        let fins = match &desc.fins {
            Some(f) => {
                let source = match f.source.as_str() {
                    crate::fins_stage::SYNTH_WOOL => crate::fins_stage::FinSource::SynthWool,
                    file => crate::fins_stage::FinSource::File(scene.base_dir.join(file)),
                };
                let fin_pca = source.load(btf::DEFAULT_COMPONENTS)?;
                Some(crate::fins_stage::fin_renderer(
                    &gpu.device,
                    &fin_pca,
                    &renderer.pass_context(),
                )?)
            }
            None => None,
        };
        Ok(Self {
            materials,
            plains,
            source,
            sources,
            part_names: desc.parts.keys().cloned().collect(),
            face_materials,
            fins,
            material_ms: start.elapsed().as_secs_f64() * 1e3,
        })
    }
}

/// Runs the `btf` stage of a scene for a still: loads the materials and writes `[btf] png`.
///
/// # Errors
/// Material, object and rendering errors; write errors naming the PNG.
pub(crate) fn run(
    scene: &Scene,
    out_dir: &Path,
    gpu: &GpuContext,
    renderer: &mut Renderer,
    objects: &[WorldObject],
    look: &Look,
    environment: Option<&lightsphere::Environment>,
) -> Result<(Vec<PathBuf>, serde_json::Value), Error> {
    BtfScene::load(scene, renderer, gpu)?.frame(
        scene,
        out_dir,
        &scene.btf.png,
        gpu,
        renderer,
        objects,
        look,
        environment,
    )
}

impl BtfScene {
    /// One frame of the stage: both halves (BTF | plain texture mapping, one exposure) as
    /// `png` in `out_dir`, and the stage's report.
    ///
    /// # Errors
    /// Object and rendering errors; write errors naming the PNG.
    #[allow(clippy::too_many_arguments)] // one frame's inputs; a struct would only rename them
    pub(crate) fn frame(
        &self,
        scene: &Scene,
        out_dir: &Path,
        png: &str,
        gpu: &GpuContext,
        renderer: &mut Renderer,
        objects: &[WorldObject],
        look: &Look,
        environment: Option<&lightsphere::Environment>,
    ) -> Result<(Vec<PathBuf>, serde_json::Value), Error> {
        let desc = &scene.btf;
        let (materials, plains, source, sources, material_ms) = (
            &self.materials,
            &self.plains,
            &self.source,
            &self.sources,
            self.material_ms,
        );
        let chosen = chosen_objects(desc, objects)?;
        for o in &chosen {
            tangents_of(o)?;
        }
        let items = split_into_parts(&chosen, &self.part_names, &self.face_materials)?;
        let names: Vec<&str> = chosen.iter().map(|o| o.name.as_str()).collect();
        crate::run::set_gouraud_meshes(gpu, renderer, objects, &look.camera, &names)?;
        let light = Light::Directional {
            dir_to_light_world: Vec3::from(desc.light_dir),
            radiance: Vec3::from(desc.radiance),
        };
        let env_start = Instant::now();
        let (lit, env_costs) = match (desc.illumination, environment) {
            (crate::scene::BtfIllumination::Light, _) => (Lit::Light(light), Vec::new()),
            (crate::scene::BtfIllumination::Environment, None) => {
                return Err(Error::Scene {
                    origin: scene.origin.clone(),
                    message: "btf illumination = \"environment\" planned without an environment"
                        .to_owned(),
                });
            }
            (crate::scene::BtfIllumination::Environment, Some(env)) => {
                let lighting = crate::btf_env::EnvLighting {
                    env,
                    up: Vec3::Y,
                    rotation_deg: 0.0,
                    visibility: match desc.maps {
                        Some(res) => crate::btf_env::EnvVisibility::Maps {
                            model: hemicube::Model::Hemicube { res },
                        },
                        None => crate::btf_env::EnvVisibility::Matrix { level: desc.level },
                    },
                    decompose: None,
                };
                // W per item, through the visibility of the whole object it belongs to (a part
                // shares its object's vertices, so W is indexed alike).
                let mut ws = Vec::with_capacity(items.len());
                let mut costs = Vec::new();
                for (m, o, _) in &items {
                    let (w, c) =
                        crate::btf_env::env_weights(&materials[*m], chosen[*o], &lighting)?;
                    ws.push(w);
                    costs.push(c);
                }
                (Lit::Environment(ws), costs)
            }
        };
        let env_ms = env_start.elapsed().as_secs_f64() * 1e3;
        let mut params = RenderParams::default();
        params.uv_scale = Vec2::splat(desc.uv_scale);
        let fins = self.fins_for(scene, &chosen, &look.camera)?;
        let render_start = Instant::now();
        let with: Vec<(&BtfPca, &WorldObject)> =
            items.iter().map(|(m, _, o)| (&materials[*m], o)).collect();
        let with_btf = scene_frame(gpu, renderer, &with, &lit, look, &params, fins.as_ref())?;
        let plain: Vec<(&BtfPca, &WorldObject)> =
            items.iter().map(|(m, _, o)| (&plains[*m], o)).collect();
        let with_plain = scene_frame(gpu, renderer, &plain, &lit, look, &params, None)?;
        let render_ms = render_start.elapsed().as_secs_f64() * 1e3;
        let display = crate::run::display_for(scene, &with_btf);
        let left = render::output::to_rgba8(&with_btf, &display, look.background);
        let right = render::output::to_rgba8(&with_plain, &display, look.background);
        let (w, h) = (with_btf.width() as usize, with_btf.height() as usize);
        let mut both = Vec::with_capacity(2 * left.len());
        for row in 0..h {
            both.extend_from_slice(&left[row * w * 4..(row + 1) * w * 4]);
            both.extend_from_slice(&right[row * w * 4..(row + 1) * w * 4]);
        }
        let path = out_dir.join(png);
        gpu_context::write_rgba8_png(&path, &both, 2 * w as u32, h as u32)?;
        let pca = &materials[0];
        let kept = pca.slots().iter().map(|s| s.components());
        let params = json!({
            "source": source,
            "objects": names,
            "parts": sources,
            "drawn": items.iter().map(|(_, _, o)| json!({
                "name": o.name,
                "triangles": o.triangles.len(),
            })).collect::<Vec<_>>(),
            "size": [pca.width(), pca.height()],
            "components": [kept.clone().min().unwrap_or(0), kept.max().unwrap_or(0)],
            "light_dir": desc.light_dir,
            "uv_scale": desc.uv_scale,
            "material_ms": material_ms,
            "render_ms": render_ms,
            "exposure_ev": display.exposure_ev,
            "illumination": match desc.illumination {
                crate::scene::BtfIllumination::Light => json!("light"),
                crate::scene::BtfIllumination::Environment => json!({
                    "visibility": desc.maps.map_or_else(
                        || format!("M at lightsphere level {}", desc.level),
                        |r| format!("hemicube maps {r}x{r}"),
                    ),
                    "environment_ms": env_ms,
                    "objects": env_costs.iter().map(|c| json!({
                        "vertices": c.vertices,
                        "directions": c.directions,
                        "visibility_ms": c.visibility_ms,
                        "transfer_ms": c.transfer_ms,
                        "update_ms": c.update_ms,
                    })).collect::<Vec<_>>(),
                }),
            },
            "fins": fins.as_ref().map(|f| json!({
                "source": desc.fins.as_ref().map(|d| d.source.clone()),
                "fins": f.fins,
                "extract_ms": f.extract_ms,
                "prepare_ms": f.prepare_ms,
            })),
            "image": "left: BTF (§5.5, with fins §5.7 when asked), right: plain texture mapping (frontal normtexture); other objects Gouraud, one depth buffer",
        });
        Ok((vec![path], params))
    }
}
