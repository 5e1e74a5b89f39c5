//! The `shadow-volumes` stage: hard shadows of the scene's casters for each of its lights,
//! counted in the frame's stencil and masking each light's direct term (crate `shadows`;
//! thesis §2.4.1, §4.2, §5.5.1).
//!
//! Per frame (a deforming cloth changes its silhouette every frame): each caster's volume is
//! rebuilt for each light into reusable buffers (its LOD triangles index the object's current
//! positions, so a simplified caster follows the deformation), the receivers — every object
//! and the ground — are handed over with their positions and normals, and the frame records,
//! per light, stencil reset → volumes → direct light where the count is 0, through eq. 5.6's
//! boundary texture. The frame uses the reversed-infinite depth (volumes reach infinity).
//!
//! The procedural sky's sun as a light (`sun = true`) has the direction of the sky's sun and
//! the irradiance E = L̄_sun · Ω_sun of its disc (mean radiance × solid angle); the sky that
//! lights the vertices is then generated without the sun, so its energy is counted once.

use glam::{DVec3, Vec3};
use gpu_context::GpuContext;
use render::Renderer;
use serde_json::json;
use shadows::frame::{FrameLight, Receiver, SmoothBoundary, StencilShadows};
use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};
use shadows::{BoundaryTexture, Counting, Light, LodTarget};

use crate::Error;
use crate::inputs::sky_params;
use crate::object::WorldObject;
use crate::scene::{GROUND_NAME, Scene};

/// One casting object.
struct Caster {
    object: usize,
    topology: CasterTopology,
    sides: Sides,
    offset: f64,
}

/// The stage: the effect pass (pipelines built once), casters, lights and volume buffers.
pub struct ShadowVolumeStage {
    effect: StencilShadows,
    casters: Vec<Caster>,
    lights: Vec<(Light, Vec3)>,
    /// The sky's sun among `lights`: its index and its direction at the scene's own
    /// environment rotation (a viewer's turn is applied on top).
    suns: Vec<(usize, DVec3)>,
    boundary: Option<SmoothBoundary>,
    volumes: Vec<ShadowVolume>,
    scratch: ShadowVolume,
    ambient: f32,
    /// Receiver names (empty = every object and the ground).
    receivers: Vec<String>,
    /// What the run report records of the setup (casters, levels, lights, time).
    setup: serde_json::Value,
}

impl ShadowVolumeStage {
    /// Build the pass against `renderer`'s frame (which must use the reversed-infinite depth),
    /// the casters' topologies and levels, and the lights.
    ///
    /// # Errors
    /// [`Error::Scene`] for a caster LOD that fails or a frame without reversed depth or float
    /// blending.
    pub fn new(
        scene: &Scene,
        gpu: &GpuContext,
        renderer: &Renderer,
        objects: &[WorldObject],
    ) -> Result<Self, Error> {
        Self::with_levels(scene, gpu, renderer, objects, &[])
    }

    /// [`Self::new`] with some casters' levels already computed, as (object index, level)
    /// for the table's `lod`: the `shadows` command draws the level its mask used instead of
    /// searching for it a second time (`--lod 0.5%` on the dragon with `--render`: 19.9 s →
    /// 8.5 s with the search's first speed-up, 3.7 s since it tests levels against the budget
    /// rather than measuring them).
    ///
    /// # Errors
    /// As [`Self::new`].
    pub fn with_levels(
        scene: &Scene,
        gpu: &GpuContext,
        renderer: &Renderer,
        objects: &[WorldObject],
        levels: &[(usize, shadows::LodLevel)],
    ) -> Result<Self, Error> {
        let start = std::time::Instant::now();
        let desc = &scene.shadow_volumes;
        let invalid = |key: &str, e: shadows::ShadowError| scene.invalid(key, e.to_string());
        let texture =
            BoundaryTexture::blurred(shadows::boundary::TEXTURE_TEXELS, desc.blur, desc.alpha_deg)
                .map_err(|e| invalid("shadow_volumes.blur", e))?;
        let effect = StencilShadows::new(
            &gpu.device,
            &renderer.pass_context(),
            &texture,
            Counting::ZFail,
        )
        .map_err(|e| invalid("shadow_volumes", e))?;
        let lod = desc
            .lod
            .as_deref()
            .map(LodTarget::parse)
            .transpose()
            .map_err(|e| invalid("shadow_volumes.lod", e))?;
        let mut casters = Vec::new();
        let mut caster_params = Vec::new();
        for (index, o) in objects.iter().enumerate() {
            let named = desc.casters.is_empty() || desc.casters.contains(&o.name);
            if o.name == GROUND_NAME || !named || o.triangles.is_empty() {
                continue;
            }
            let (triangles, offset, hausdorff) = match lod {
                Some(target) => {
                    let given = levels.iter().find(|(i, _)| *i == index);
                    let level = match given {
                        Some((_, level)) => level.clone(),
                        None => shadows::caster_lod(
                            &o.positions,
                            &o.triangles,
                            target,
                            shadows::lod::DEFAULT_SAMPLES,
                            0,
                        )
                        .map_err(|e| invalid("shadow_volumes.lod", e))?,
                    };
                    let offset = level.receiver_offset();
                    let percent = level.hausdorff.percent();
                    (level.triangles, offset, Some(percent))
                }
                None => (o.triangles.clone(), 0.0, None),
            };
            caster_params.push(json!({
                "object": o.name,
                "triangles": o.triangles.len(),
                "caster_triangles": triangles.len(),
                "hausdorff_percent": hausdorff,
                "offset": offset,
                "two_sided": o.two_sided,
            }));
            casters.push(Caster {
                object: index,
                topology: CasterTopology::new(o.positions.len(), &triangles)
                    .map_err(|e| invalid("shadow_volumes.casters", e))?,
                sides: if o.two_sided { Sides::Two } else { Sides::One },
                offset,
            });
        }
        let lights = scene_lights(scene)?;
        let boundary = desc.boundary_mode().flatten().map(|mode| SmoothBoundary {
            alpha_deg: desc.alpha_deg,
            mode,
        });
        let setup = json!({
            "casters": caster_params,
            "lights": lights.len(),
            "boundary": desc.boundary,
            "alpha_deg": desc.alpha_deg,
            "blur": desc.blur,
            "lod": desc.lod,
            "setup_ms": start.elapsed().as_secs_f64() * 1e3,
        });
        let suns = scene
            .shadow_volumes
            .lights
            .iter()
            .zip(&lights)
            .enumerate()
            .filter_map(|(i, (desc, (light, _)))| match light {
                Light::Directional(d) if desc.sun => Some((i, *d)),
                _ => None,
            })
            .collect();
        Ok(Self {
            effect,
            suns,
            volumes: (0..lights.len()).map(|_| ShadowVolume::new()).collect(),
            casters,
            lights,
            boundary,
            scratch: ShadowVolume::new(),
            ambient: desc.ambient,
            receivers: desc.receivers.clone(),
            setup,
        })
    }

    /// Rebuild every volume for the objects' current positions and hand receivers and lights
    /// to the pass; objects that no other effect lit get the ambient radiance. Returns what
    /// the run report records: the setup (casters, levels, lights, `setup_ms`) and the frame's
    /// volume triangles.
    ///
    /// # Errors
    /// [`Error::Scene`] when a caster's positions are not finite.
    pub fn prepare(
        &mut self,
        scene: &Scene,
        gpu: &GpuContext,
        objects: &mut [WorldObject],
    ) -> Result<serde_json::Value, Error> {
        let invalid = |e: shadows::ShadowError| scene.invalid("shadow_volumes", e.to_string());
        for o in objects.iter_mut() {
            if o.front.is_none() || o.back.is_none() {
                let c = vec![o.albedo * self.ambient; o.positions.len()];
                o.front = Some(c.clone());
                o.back = Some(c);
            }
        }
        let mut triangles = 0;
        for (volume, (light, _)) in self.volumes.iter_mut().zip(&self.lights) {
            volume.clear();
            for caster in &self.casters {
                let params = VolumeParams {
                    sides: caster.sides,
                    extrusion: Extrusion::Infinite,
                    origin: DVec3::ZERO,
                    offset: caster.offset,
                };
                self.scratch
                    .build(
                        &caster.topology,
                        &objects[caster.object].positions,
                        light,
                        &params,
                    )
                    .map_err(invalid)?;
                volume.append(&self.scratch);
            }
            triangles += volume.stats().triangles();
        }
        let receiving: Vec<(usize, &WorldObject)> = objects
            .iter()
            .enumerate()
            .filter(|(_, o)| self.receivers.is_empty() || self.receivers.contains(&o.name))
            .collect();
        let albedo: Vec<Vec<Vec3>> = receiving
            .iter()
            .map(|(_, o)| vec![o.albedo; o.positions.len()])
            .collect();
        let receivers: Vec<Receiver> = receiving
            .iter()
            .zip(&albedo)
            .map(|((index, o), albedo)| Receiver {
                positions: &o.positions,
                normals: &o.normals,
                albedo,
                triangles: &o.triangles,
                // Eq. 5.6's boundary belongs on the casters' own surfaces only.
                casts: self.casters.iter().any(|c| c.object == *index),
            })
            .collect();
        self.effect
            .set_receivers(&gpu.device, &receivers)
            .map_err(invalid)?;
        let lights: Vec<FrameLight> = self
            .lights
            .iter()
            .zip(&self.volumes)
            .map(|((light, intensity), volume)| FrameLight {
                light: *light,
                intensity: *intensity,
                volume,
                boundary: self.boundary,
            })
            .collect();
        self.effect
            .set_lights(&gpu.device, &gpu.queue, &lights)
            .map_err(invalid)?;
        let mut params = self.setup.clone();
        if let serde_json::Value::Object(map) = &mut params {
            map.insert("volume_triangles".into(), json!(triangles));
        }
        Ok(params)
    }

    /// The pass to hand to the renderer.
    pub fn pass(&self) -> &StencilShadows {
        &self.effect
    }

    /// The position of the first point light, if there is one.
    pub fn point_light(&self) -> Option<glam::DVec3> {
        self.lights.iter().find_map(|(l, _)| match l {
            Light::Point(p) => Some(*p),
            Light::Directional(_) => None,
        })
    }

    /// Turn the sky's sun with the environment by `turn_deg` about +Y on top of the scene's
    /// own rotation (a viewer's environment turn: the sun's volumes follow the sky that its
    /// light was taken out of). The next [`ShadowVolumeStage::prepare`] builds from there.
    pub fn turn_sun(&mut self, turn_deg: f32) {
        let turn = crate::lighting::environment_rotation(turn_deg).as_dquat();
        for &(i, base) in &self.suns {
            self.lights[i].0 = Light::Directional(if turn_deg == 0.0 { base } else { turn * base });
        }
    }

    /// Move the first point light to `position` (a viewer's light control); the next
    /// [`ShadowVolumeStage::prepare`] builds its volumes from there.
    pub fn set_point_light(&mut self, position: glam::DVec3) {
        if let Some((light, _)) = self
            .lights
            .iter_mut()
            .find(|(l, _)| matches!(l, Light::Point(_)))
        {
            *light = Light::Point(position);
        }
    }
}

/// The scene's lights: the sky's sun (direction rotated with the environment, irradiance of
/// its disc), directional and point lights.
///
/// # Errors
/// [`Error::Scene`] when the sky's parameters are invalid.
pub fn scene_lights(scene: &Scene) -> Result<Vec<(Light, Vec3)>, Error> {
    let mut lights = Vec::new();
    for desc in &scene.shadow_volumes.lights {
        lights.push(if desc.sun {
            let params = sky_params(scene);
            let radiance = synth::sun_radiance(&params)?;
            let radius = f64::from(params.sun_angular_radius_deg).to_radians();
            let solid_angle = 2.0 * std::f64::consts::PI * (1.0 - radius.cos());
            let rotation = scene.environment.as_ref().map_or(0.0, |e| e.rotation_deg);
            let direction =
                crate::lighting::environment_rotation(rotation) * synth::sun_direction(&params);
            (
                Light::Directional(direction.as_dvec3()),
                radiance * solid_angle as f32,
            )
        } else if let Some(d) = desc.direction {
            (
                Light::Directional(DVec3::from_array(d)),
                Vec3::from_array(desc.irradiance.unwrap_or_default()),
            )
        } else {
            (
                Light::Point(DVec3::from_array(desc.position.unwrap_or_default())),
                Vec3::from_array(desc.intensity.unwrap_or_default()),
            )
        });
    }
    Ok(lights)
}
