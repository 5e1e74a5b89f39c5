//! Inputs to a [`LiveScene`]: scripted or interactive events, animation steps and poses from
//! outside the scene's own clip.

use glam::Vec3;

use super::{LiveScene, Orbit, ViewEvent};
use crate::effects::Effect;

impl LiveScene {
    /// Apply one scripted or interactive input to the settings, the camera `orbit` and the
    /// play state.
    ///
    /// # Errors
    /// A message naming the effect when the scene does not have it, or the level beyond
    /// the lights' range.
    pub fn apply(
        &mut self,
        event: ViewEvent,
        orbit: &mut Orbit,
        playing: &mut bool,
    ) -> Result<(), String> {
        let missing = |e: Effect, effects: &[Effect]| {
            let names: Vec<&str> = effects.iter().map(|e| e.name()).collect();
            format!(
                "the scene has no effect {:?} (it has: {})",
                e.name(),
                names.join(", ")
            )
        };
        match event {
            ViewEvent::Orbit(yaw, pitch) => orbit.orbit(yaw, pitch),
            ViewEvent::Pan(dx, dy) => orbit.pan(dx, dy),
            ViewEvent::Zoom(f) => orbit.zoom(f),
            ViewEvent::Home => *orbit = Orbit::from_camera(&self.start_camera, self.bounds()),
            ViewEvent::Toggle(e) => {
                if !self.settings.toggle(e) {
                    return Err(missing(e, self.plan.effects()));
                }
            }
            ViewEvent::Set(e, on) => {
                if !self.settings.set(e, on) {
                    return Err(missing(e, self.plan.effects()));
                }
            }
            ViewEvent::Level(level) => self.settings.level = level,
            ViewEvent::Backend(backend, side) => {
                if self.shadowing.is_none() {
                    return Err(missing(Effect::SelfShadowing, self.plan.effects()));
                }
                self.settings.backend = backend;
                if let Some(side) = side {
                    self.settings.depth_resolution = side;
                }
            }
            ViewEvent::PointLight(p) => {
                if self.settings.point_light.is_none() {
                    return Err(
                        "the scene has no point light (shadow volumes, translucency)".to_owned(),
                    );
                }
                self.settings.point_light = Some(p);
            }
            ViewEvent::Rotation(deg) => self.settings.rotation_deg = deg,
            ViewEvent::Environment(i) => {
                if i >= self.choices.len() {
                    return Err(format!(
                        "environment {i} does not exist: the choices are 0..={} (0: the \
                         scene's; add maps with --env)",
                        self.choices.len() - 1
                    ));
                }
                self.settings.environment = i;
            }
            ViewEvent::Tone(curve) => self.settings.tone = Some(curve),
            ViewEvent::Exposure(ev) => self.settings.exposure_ev = ev,
            ViewEvent::Frame(f) => {
                if self.frame_count == 0 {
                    return Err("the scene has no animated object".to_owned());
                }
                self.settings.frame = f % self.frame_count;
            }
            ViewEvent::BtfPlain(plain) => {
                if self.btf.is_none() {
                    return Err(missing(Effect::Btf, self.plan.effects()));
                }
                self.settings.btf_plain = plain;
            }
            ViewEvent::NextCell => {
                return Err(
                    "next-cell steers a jump map (cloth-vis view CLIP --jumpmap)".to_owned(),
                );
            }
            ViewEvent::Play => *playing = self.frame_count > 1,
            ViewEvent::Pause => *playing = false,
        }
        Ok(())
    }

    /// Pose object `index` at object-space `positions` from outside the scene's own
    /// animation (a jump map's player, a GPU decoder), placed by the object's transform;
    /// the next frame recomputes M and the lighting for it.
    ///
    /// # Errors
    /// A message when there is no such object or the vertex count differs.
    pub fn set_pose(&mut self, index: usize, positions: &[Vec3]) -> Result<(), String> {
        let object = self
            .objects
            .get_mut(index)
            .ok_or_else(|| format!("the scene has no object {index}"))?;
        if positions.len() != object.positions.len() {
            return Err(format!(
                "object {:?} has {} vertices, the pose {}",
                object.name,
                object.positions.len(),
                positions.len()
            ));
        }
        // A clip's own transform; a `.cpca` object is loaded as one decoded frame and holds
        // none, so its scene entry's (the pose must land where the loaded frame did).
        let world = match &object.animation {
            Some(a) => a.world_from_object,
            None => self.scene.objects.get(index).map_or(
                glam::Mat4::IDENTITY,
                crate::scene::ObjectDesc::world_from_object,
            ),
        };
        object.pose_positions(positions, world);
        self.pose_id += 1;
        Ok(())
    }

    /// Advance the animation one frame, looping.
    pub fn step(&mut self, frames: isize) {
        if self.frame_count > 0 {
            let n = self.frame_count as isize;
            self.settings.frame = (self.settings.frame as isize + frames).rem_euclid(n) as usize;
        }
    }
}
