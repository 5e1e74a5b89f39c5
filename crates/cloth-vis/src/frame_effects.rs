//! The effects that draw into the shared frame beside the Gouraud meshes — shadow volumes and
//! translucency — built once per run and prepared every frame, in stage order.

use gpu_context::GpuContext;
use render::{Camera, FramePass, Renderer};

use crate::Error;
use crate::object::WorldObject;
use crate::plan::{Plan, Stage};
use crate::scene::Scene;
use crate::shadow_volumes::ShadowVolumeStage;
use crate::translucency_stage::TranslucencyStage;

/// The frame effects a plan asks for.
pub(crate) struct FrameEffects {
    volumes: Option<ShadowVolumeStage>,
    translucency: Option<TranslucencyStage>,
}

impl FrameEffects {
    /// Build the planned effects against `renderer`'s frame.
    ///
    /// # Errors
    /// Each stage's set-up errors.
    pub fn new(
        scene: &Scene,
        plan: &Plan,
        gpu: &GpuContext,
        renderer: &Renderer,
        objects: &mut [WorldObject],
        environment: Option<&lightsphere::Environment>,
    ) -> Result<Self, Error> {
        let volumes = if plan.contains(Stage::ShadowVolumes) {
            Some(ShadowVolumeStage::new(scene, gpu, renderer, objects)?)
        } else {
            None
        };
        let translucency = if plan.contains(Stage::Translucency) {
            Some(TranslucencyStage::new(
                scene,
                gpu,
                renderer,
                objects,
                environment,
            )?)
        } else {
            None
        };
        Ok(Self {
            volumes,
            translucency,
        })
    }

    /// Prepare this frame (after posing and lighting): each planned effect's stage, its
    /// milliseconds and report parameters.
    ///
    /// # Errors
    /// Each stage's errors.
    pub fn prepare(
        &mut self,
        scene: &Scene,
        gpu: &GpuContext,
        objects: &mut [WorldObject],
        camera: &Camera,
    ) -> Result<Vec<(Stage, f64, serde_json::Value)>, Error> {
        self.prepare_where(scene, gpu, objects, camera, true, true)
    }

    /// [`FrameEffects::prepare`] for the effects switched on (a viewer's toggles): shadow
    /// volumes when `volumes`, translucency when `translucency`.
    ///
    /// # Errors
    /// Each stage's errors.
    pub fn prepare_where(
        &mut self,
        scene: &Scene,
        gpu: &GpuContext,
        objects: &mut [WorldObject],
        camera: &Camera,
        volumes: bool,
        translucency: bool,
    ) -> Result<Vec<(Stage, f64, serde_json::Value)>, Error> {
        let mut done = Vec::new();
        if let Some(stage) = self.volumes.as_mut().filter(|_| volumes) {
            let t = std::time::Instant::now();
            let params = stage.prepare(scene, gpu, objects)?;
            done.push((
                Stage::ShadowVolumes,
                t.elapsed().as_secs_f64() * 1e3,
                params,
            ));
        }
        if let Some(stage) = self.translucency.as_mut().filter(|_| translucency) {
            let t = std::time::Instant::now();
            let params = stage.prepare(scene, gpu, objects, camera.eye)?;
            done.push((Stage::Translucency, t.elapsed().as_secs_f64() * 1e3, params));
        }
        Ok(done)
    }

    /// The first point light of the effects (shadow volumes first, then translucency).
    pub fn point_light(&self) -> Option<glam::Vec3> {
        let volumes = self
            .volumes
            .as_ref()
            .and_then(ShadowVolumeStage::point_light);
        let translucency = self
            .translucency
            .as_ref()
            .and_then(TranslucencyStage::point_light);
        volumes.or(translucency).map(|p| p.as_vec3())
    }

    /// Turn the shadow volumes' sun (if any) with the environment by `turn_deg` on top of
    /// the scene's rotation.
    pub fn turn_sun(&mut self, turn_deg: f32) {
        if let Some(v) = self.volumes.as_mut() {
            v.turn_sun(turn_deg);
        }
    }

    /// Move the first point light of every effect that has one to `position`.
    pub fn set_point_light(&mut self, position: glam::Vec3) {
        let p = position.as_dvec3();
        if let Some(v) = self.volumes.as_mut() {
            v.set_point_light(p);
        }
        if let Some(t) = self.translucency.as_mut() {
            t.set_point_light(p);
        }
    }

    /// The passes to hand to the frame.
    pub fn passes(&self) -> Vec<&dyn FramePass> {
        self.passes_where(true, true)
    }

    /// The passes of the effects switched on (see [`FrameEffects::prepare_where`]).
    pub fn passes_where(&self, volumes: bool, translucency: bool) -> Vec<&dyn FramePass> {
        let mut passes: Vec<&dyn FramePass> = Vec::new();
        if let Some(v) = self.volumes.as_ref().filter(|_| volumes) {
            passes.push(v.pass());
        }
        if let Some(t) = self.translucency.as_ref().filter(|_| translucency) {
            passes.push(t.pass());
        }
        passes
    }
}
