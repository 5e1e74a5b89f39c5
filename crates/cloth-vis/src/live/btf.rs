//! The `btf` effect drawn live (thesis §5.5, Fig. 5.16): the scene's BTF objects as
//! [`btf::render::BtfDraw`] passes in the viewer's own frame — the compressed BTF, or with
//! the "plain" switch the same objects under plain texture mapping — while every other object
//! stays Gouraud-shaded. The materials are uploaded once. Under an environment, visibility and
//! transfer are computed once per pose ([`crate::btf_env::EnvBinner`]) and a turn only updates
//! W from the turned look-up. `[btf] fins` (§5.7) are extracted along the silhouettes of each
//! drawn view, as `render` does, on the BTF only (not under the plain switch: the still's right
//! half has none).

use btf::render::{BtfDraw, FinDraw, GpuBtfRenderer, Light, RenderParams};
use glam::{Vec2, Vec3};
use gpu_context::GpuContext;
use render::{Camera, Renderer};

use crate::Error;
use crate::btf_scene::{BtfScene, chosen_objects, split_into_parts};
use crate::btf_stage::{btf_mesh, tangents_of};
use crate::object::WorldObject;
use crate::scene::{BtfIllumination, Scene};

/// The environment binned per drawn item for one pose (visibility and transfer done), and W
/// per item at one turn.
struct EnvCache {
    pose: usize,
    binners: Vec<crate::btf_env::EnvBinner>,
    turn_bits: u32,
    weights: Vec<Vec<btf::env::EnvLightWeights>>,
}

/// The scene's BTF materials on the GPU, and the environment weights of the current pose.
pub(crate) struct LiveBtf {
    scene_btf: BtfScene,
    with: Vec<GpuBtfRenderer>,
    plain: Vec<GpuBtfRenderer>,
    env: Option<EnvCache>,
}

impl LiveBtf {
    /// Load `[btf]`'s materials and upload them and their plain companions once.
    pub(crate) fn new(scene: &Scene, renderer: &Renderer, gpu: &GpuContext) -> Result<Self, Error> {
        let scene_btf = BtfScene::load(scene, renderer, gpu)?;
        let upload = |materials: &[btf::BtfPca]| {
            materials
                .iter()
                .map(|pca| {
                    GpuBtfRenderer::for_frame(
                        &gpu.device,
                        &gpu.queue,
                        pca,
                        &renderer.pass_context(),
                    )
                })
                .collect::<Result<Vec<_>, _>>()
        };
        let with = upload(&scene_btf.materials)?;
        let plain = upload(&scene_btf.plains)?;
        Ok(Self {
            scene_btf,
            with,
            plain,
            env: None,
        })
    }

    /// Drop the environment weights (another map was chosen).
    pub(crate) fn forget_environment(&mut self) {
        self.env = None;
    }

    /// The names of the objects the BTF draws (the Gouraud pass skips them).
    pub(crate) fn names(scene: &Scene, objects: &[WorldObject]) -> Result<Vec<String>, Error> {
        Ok(chosen_objects(&scene.btf, objects)?
            .iter()
            .map(|o| o.name.clone())
            .collect())
    }

    /// This frame's draws: each BTF object (or garment part) with its material, or its plain
    /// companion when `plain`, lit by `[btf]`'s light or by `environment` turned by
    /// `rotation_deg` (W recomputed only when `pose` or the turn changed); and the fins of
    /// this view when the scene asks for them and `plain` is off.
    #[allow(clippy::too_many_arguments)] // one frame's inputs
    pub(crate) fn draws(
        &mut self,
        scene: &Scene,
        objects: &[WorldObject],
        camera: &Camera,
        plain: bool,
        environment: Option<&lightsphere::Environment>,
        pose: usize,
        rotation_deg: f32,
    ) -> Result<(Vec<BtfDraw>, Vec<FinDraw>), Error> {
        let desc = &scene.btf;
        let chosen = chosen_objects(desc, objects)?;
        let items = split_into_parts(
            &chosen,
            &self.scene_btf.part_names,
            &self.scene_btf.face_materials,
        )?;
        let mut params = RenderParams::default();
        params.uv_scale = Vec2::splat(desc.uv_scale);
        let weights = match (desc.illumination, environment) {
            (BtfIllumination::Light, _) => None,
            (BtfIllumination::Environment, None) => {
                return Err(Error::Scene {
                    origin: scene.origin.clone(),
                    message: "btf illumination = \"environment\" without an environment".to_owned(),
                });
            }
            (BtfIllumination::Environment, Some(env)) => {
                if self.env.as_ref().is_none_or(|c| c.pose != pose) {
                    let visibility = match desc.maps {
                        Some(res) => crate::btf_env::EnvVisibility::Maps {
                            model: hemicube::Model::Hemicube { res },
                        },
                        None => crate::btf_env::EnvVisibility::Matrix { level: desc.level },
                    };
                    let binners = items
                        .iter()
                        .map(|(m, o, _)| {
                            crate::btf_env::EnvBinner::new(
                                &self.scene_btf.materials[*m],
                                chosen[*o],
                                env,
                                Vec3::Y,
                                visibility,
                            )
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    self.env = Some(EnvCache {
                        pose,
                        binners,
                        // Not a turn's bits: the weights below are computed.
                        turn_bits: f32::NAN.to_bits(),
                        weights: Vec::new(),
                    });
                }
                let cache = self.env.as_mut().expect("binned above");
                if cache.turn_bits != rotation_deg.to_bits() {
                    cache.weights = cache
                        .binners
                        .iter()
                        .map(|b| b.weights(rotation_deg))
                        .collect::<Result<Vec<_>, _>>()?;
                    cache.turn_bits = rotation_deg.to_bits();
                }
                Some(&cache.weights)
            }
        };
        let light = Light::Directional {
            dir_to_light_world: Vec3::from(desc.light_dir),
            radiance: Vec3::from(desc.radiance),
        };
        let renderers = if plain { &self.plain } else { &self.with };
        let mut draws = Vec::with_capacity(items.len());
        for (i, (m, _, object)) in items.iter().enumerate() {
            let (tangents, uvs) = tangents_of(object)?;
            let mesh = btf_mesh(object, &tangents, uvs);
            let draw = match weights {
                None => renderers[*m].prepare(&mesh, &light, camera, &params)?,
                Some(ws) => renderers[*m].prepare_env(&mesh, &ws[i], camera, &params)?,
            };
            draws.push(draw);
        }
        let fins = if plain {
            Vec::new()
        } else {
            self.scene_btf
                .fins_for(scene, &chosen, camera)?
                .map(|f| f.draws)
                .unwrap_or_default()
        };
        Ok((draws, fins))
    }
}
