//! A scene held live for an interactive viewer (`cloth-vis view`): loaded once, then drawn
//! frame after frame from any camera, with each effect switched on and off, the lightsphere
//! level changed, the environment turned and the animation posed — recomputing only what a
//! change invalidates (paper 000 §4.2, §5; thesis §4.4.4–4.4.5).
//!
//! What a change costs:
//!
//! | change | recomputed |
//! |---|---|
//! | camera | nothing but the frame (and translucency, which depends on the eye) |
//! | exposure | nothing (the tone map's parameter) |
//! | environment rotation | I_j by rotated look-ups ([`crate::lighting::rotated_lookup_radiance`]), then c_i; M is reused |
//! | level | lights at the new level (cached per level); M refined when only directions are added ([`VisibilityStage::refine`]), else recomputed |
//! | animation frame | pose, M, c_i (per-frame self-shadowing) |
//! | effect on/off | the lighting it changes; frame passes dropped from the frame |
//!
//! The same stages as [`crate::run_scene`] run in the same order, so a [`LiveScene::capture`]
//! through the scene's own camera is the still `cloth-vis render` writes (tested).
//!
//! ```no_run
//! use cloth_vis::live::LiveScene;
//! let gpu = gpu_context::GpuContext::new(&Default::default())?;
//! let mut live = LiveScene::new(cloth_vis::demo_scene()?, &gpu)?;
//! let camera = live.start_camera();
//! live.settings_mut().toggle(cloth_vis::Effect::SelfShadowing);
//! let unshadowed = live.capture(&gpu, &camera)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod apply;
mod btf;
mod orbit;
mod script;

pub use orbit::{Orbit, POLE_MARGIN_DEG};
pub use script::{MAX_EVENTS, ViewEvent, parse_events, read_events};

use std::time::Instant;

use glam::Vec3;
use gpu_context::{GpuContext, HdrImage};
use render::tone::Display;
use render::{Background, Camera, FramePass, Renderer};

use crate::effects::Effect;
use crate::frame_effects::FrameEffects;
use crate::object::WorldObject;
use crate::plan::{Plan, Stage};
use crate::run::{
    Lights, display_for, frame_camera, ground_object, renderer_for, set_gouraud_meshes,
};
use crate::scene::Scene;
use crate::shadowing::{Visibility, VisibilityStage};
use crate::static_shadowing::StaticShadowingStage;
use crate::{Error, inputs};

/// What the viewer may change between frames.
#[derive(Clone, Debug, PartialEq)]
pub struct LiveSettings {
    /// The scene's effects, each on or off.
    pub effects: Vec<(Effect, bool)>,
    /// Lightsphere level of the per-vertex lighting and of M.
    pub level: u32,
    /// The environment's turn about +Y in degrees, on top of the scene's `rotation_deg`.
    pub rotation_deg: f32,
    /// Fixed exposure in EV; `None` keeps the scene's (automatic exposure is measured once,
    /// on the first frame, so the picture does not flicker).
    pub exposure_ev: Option<f32>,
    /// The animation frame the animated objects are posed at.
    pub frame: usize,
    /// With the `btf` effect on: draw its objects under plain texture mapping (the BTF's
    /// frontal normtexture) instead of the BTF — the right half of Fig. 5.16.
    pub btf_plain: bool,
    /// The first point light of the shadow-volume and translucency effects (`None` when the
    /// scene has none); moving it rebuilds their volumes and light maps, not M.
    pub point_light: Option<Vec3>,
    /// The environment shown and lighting: 0 the scene's own, then those added with
    /// [`LiveScene::add_environment`] (M is kept; I_j, the lighting and the backdrop follow).
    pub environment: usize,
    /// A tone curve replacing the scene's (`None`: the scene's).
    pub tone: Option<render::tone::ToneCurve>,
    /// The visibility backend of self-shadowing (`auto`, `cpu`, `depth`, `query`).
    pub backend: crate::scene::VisibilityBackendDesc,
    /// Depth-map side of the `depth` backend.
    pub depth_resolution: u32,
}

impl LiveSettings {
    /// Whether `effect` is in the scene and switched on.
    pub fn is_on(&self, effect: Effect) -> bool {
        self.effects.iter().any(|&(e, on)| e == effect && on)
    }

    /// Switch `effect` on or off; returns false when the scene does not have it.
    pub fn set(&mut self, effect: Effect, on: bool) -> bool {
        match self.effects.iter_mut().find(|(e, _)| *e == effect) {
            Some(entry) => {
                entry.1 = on;
                true
            }
            None => false,
        }
    }

    /// Flip `effect`; returns false when the scene does not have it.
    pub fn toggle(&mut self, effect: Effect) -> bool {
        let on = self.is_on(effect);
        self.set(effect, !on)
    }
}

/// An environment to choose: its name, the map shown and the map lighting the vertices.
struct EnvChoice {
    name: String,
    shown: Option<lightsphere::Environment>,
    lighting: Option<lightsphere::Environment>,
}

/// The inputs the vertex lighting was last computed for.
#[derive(Clone, Debug, PartialEq)]
struct LitKey {
    pose: usize,
    level: u32,
    rotation_bits: u32,
    shadowing: bool,
    statics: bool,
    lighting: bool,
}

/// One stage's time when it last ran, for a viewer's HUD.
#[derive(Clone, Debug, PartialEq)]
pub struct StageTime {
    /// The stage's report name ([`Stage::name`]).
    pub stage: &'static str,
    /// Milliseconds on the CPU clock (GPU stages: recording and submission).
    pub millis: f64,
    /// Whether it ran for the last frame (else its result was reused).
    pub fresh: bool,
}

/// A scene loaded once and drawn live; see the module docs.
pub struct LiveScene {
    scene: Scene,
    plan: Plan,
    objects: Vec<WorldObject>,
    /// The environment that lights the vertices (without the sun when a shadow-volume light
    /// carries it), as the scene rotates it.
    light_env: Option<lightsphere::Environment>,
    /// The environment shown by the backdrop.
    environment: Option<lightsphere::Environment>,
    /// The environments to choose from (0: the scene's), and the one in use.
    choices: Vec<EnvChoice>,
    chosen: usize,
    shadowing: Option<VisibilityStage>,
    statics: Option<StaticShadowingStage>,
    effects: FrameEffects,
    btf: Option<btf::LiveBtf>,
    btf_draws: Vec<::btf::render::BtfDraw>,
    fin_draws: Vec<::btf::render::FinDraw>,
    renderer: Renderer,
    background: Background,
    start_camera: Camera,
    centre: Vec3,
    radius: f32,
    frame_count: usize,
    /// Lights per level at the default rotation (the nested lightsphere; I_j of a turned
    /// environment is looked up again, M is not).
    lights: Vec<Lights>,
    /// M, its level and the frame it was computed for.
    visibility: Option<(u32, usize, Visibility)>,
    lit: Option<LitKey>,
    backdrop_rotation_bits: u32,
    posed: usize,
    /// Counts geometry changes (an animation frame, a pose from elsewhere): M, the lighting
    /// and the BTF's environment weights are kept while it holds.
    pose_id: usize,
    settings: LiveSettings,
    display: Option<Display>,
    times: Vec<StageTime>,
}

impl LiveScene {
    /// Load `scene` (validated as `cloth-vis render` validates it) and build every stage its
    /// effects plan, against `gpu`.
    ///
    /// # Errors
    /// As [`crate::run_scene`] before its first frame.
    pub fn new(scene: Scene, gpu: &GpuContext) -> Result<Self, Error> {
        let plan = Plan::for_scene(&scene)?;
        let (mut objects, _) = inputs::load_geometry(&scene, false)?;
        if plan.contains(Stage::Translucency) {
            crate::deform::apply(&scene, &mut objects)?;
        }
        let frame_count = objects
            .iter()
            .map(WorldObject::frame_count)
            .filter(|&n| n > 1)
            .max()
            .unwrap_or(0);
        let posed = scene
            .objects
            .iter()
            .zip(&objects)
            .find(|(_, o)| o.frame_count() > 1)
            .map_or(0, |(d, o)| {
                let n = o.frame_count() as i64;
                (d.frame.rem_euclid(n.max(1))) as usize
            });
        let (start_camera, centre, radius) = frame_camera(&scene, &objects, None);
        crate::image_checks::check_in_view(&scene, &start_camera, centre, radius)?;
        if let Some(ground) = &scene.ground {
            objects.push(ground_object(ground, &objects, None));
        }
        let environment = if plan.contains(Stage::Environment) {
            Some(inputs::load_environment(&scene)?.0)
        } else {
            None
        };
        let light_env = if plan.contains(Stage::ShadowVolumes) && scene.shadow_volumes.takes_sun() {
            Some(inputs::load_environment_with(&scene, false)?.0)
        } else {
            environment.clone()
        };
        let depth = if plan.contains(Stage::ShadowVolumes) {
            render::DepthConvention::ReversedInfinite
        } else {
            render::DepthConvention::Standard
        };
        let (renderer, background, _) = renderer_for(&scene, gpu, environment.as_ref(), depth);
        let effects = FrameEffects::new(
            &scene,
            &plan,
            gpu,
            &renderer,
            &mut objects,
            environment.as_ref(),
        )?;
        let shadowing = if plan.contains(Stage::Visibility) {
            Some(VisibilityStage::new(&scene, Some(gpu))?)
        } else {
            None
        };
        let statics = if plan.contains(Stage::StaticVisibility) {
            Some(StaticShadowingStage::new(&scene, Some(gpu))?)
        } else {
            None
        };
        let btf = if plan.contains(Stage::Btf) {
            Some(btf::LiveBtf::new(&scene, &renderer, gpu)?)
        } else {
            None
        };
        let settings = LiveSettings {
            effects: plan.effects().iter().map(|&e| (e, true)).collect(),
            level: scene.lighting.level,
            rotation_deg: 0.0,
            exposure_ev: None,
            frame: posed,
            btf_plain: false,
            point_light: effects.point_light(),
            environment: 0,
            tone: None,
            backend: scene.visibility.backend,
            depth_resolution: scene.visibility.depth_resolution,
        };
        let choices = vec![EnvChoice {
            name: scene
                .environment
                .as_ref()
                .map_or_else(|| "none".to_owned(), |e| e.source.clone()),
            shown: environment.clone(),
            lighting: light_env.clone(),
        }];
        Ok(Self {
            scene,
            plan,
            objects,
            light_env,
            environment,
            choices,
            chosen: 0,
            shadowing,
            statics,
            effects,
            btf,
            btf_draws: Vec::new(),
            fin_draws: Vec::new(),
            renderer,
            background,
            start_camera,
            centre,
            radius,
            frame_count,
            lights: Vec::new(),
            visibility: None,
            lit: None,
            backdrop_rotation_bits: 0f32.to_bits(),
            posed,
            pose_id: 0,
            settings,
            display: None,
            times: Vec::new(),
        })
    }

    /// The scene as loaded.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The scene's effects, in plan order.
    pub fn effects(&self) -> &[Effect] {
        self.plan.effects()
    }

    /// The camera `cloth-vis render` draws the still through.
    pub fn start_camera(&self) -> Camera {
        self.start_camera
    }

    /// The bounding sphere (centre, radius) of the objects as loaded: what "frame the object"
    /// frames.
    pub fn bounds(&self) -> (Vec3, f32) {
        (self.centre, self.radius)
    }

    /// Frames of the longest animated object (0 when nothing is animated).
    pub fn frame_count(&self) -> usize {
        self.frame_count
    }

    /// Whether the lights need an environment the scene has (`lighting`, shadowing).
    pub fn has_lights(&self) -> bool {
        self.light_env.is_some() && self.plan.contains(Stage::LightDirections)
    }

    /// The current settings.
    pub fn settings(&self) -> &LiveSettings {
        &self.settings
    }

    /// The settings, to change before the next frame.
    pub fn settings_mut(&mut self) -> &mut LiveSettings {
        &mut self.settings
    }

    /// Each stage's time when it last ran, in the order stages first ran; `fresh` marks those
    /// that ran for the last frame.
    pub fn times(&self) -> &[StageTime] {
        &self.times
    }

    /// The renderer (its [`Renderer::hdr_view`] holds the last frame drawn).
    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    /// The background the frame clears to.
    pub fn background(&self) -> Background {
        self.background
    }

    /// Offer `env` (named `name`) as a further environment choice; returns its index for
    /// [`LiveSettings::environment`].
    pub fn add_environment(&mut self, name: String, env: lightsphere::Environment) -> usize {
        self.choices.push(EnvChoice {
            name,
            shown: Some(env.clone()),
            lighting: Some(env),
        });
        self.choices.len() - 1
    }

    /// The names of the environment choices (index 0: the scene's own).
    pub fn environment_names(&self) -> Vec<&str> {
        self.choices.iter().map(|c| c.name.as_str()).collect()
    }

    /// The display mapping: the settings' exposure, else the scene's (automatic exposure as
    /// measured on the first frame captured). `None` before the first capture of a scene
    /// with automatic exposure.
    pub fn display(&self) -> Option<Display> {
        let mut display = self.display?;
        if let Some(ev) = self.settings.exposure_ev {
            display.exposure_ev = ev;
        }
        if let Some(curve) = self.settings.tone {
            display.curve = curve;
        }
        Some(display)
    }

    /// Draw one frame through `camera` into the renderer's target, reading nothing back.
    ///
    /// # Errors
    /// Stage and render errors.
    pub fn draw(&mut self, gpu: &GpuContext, camera: &Camera) -> Result<(), Error> {
        self.prepare(gpu, camera)?;
        let t = Instant::now();
        let passes = passes(
            &self.effects,
            &self.btf_draws,
            &self.fin_draws,
            &self.settings,
        );
        self.renderer
            .draw_frame(&gpu.device, &gpu.queue, camera, self.background, &passes)?;
        record(
            &mut self.times,
            Stage::Render.name(),
            crate::run::ms_since(t),
        );
        Ok(())
    }

    /// Draw one frame through `camera` and read it back as linear HDR; the first capture fixes
    /// automatic exposure. `cloth-vis render`'s still, for the same camera and settings.
    ///
    /// # Errors
    /// Stage and render errors.
    pub fn capture(&mut self, gpu: &GpuContext, camera: &Camera) -> Result<HdrImage, Error> {
        self.prepare(gpu, camera)?;
        let t = Instant::now();
        let passes = passes(
            &self.effects,
            &self.btf_draws,
            &self.fin_draws,
            &self.settings,
        );
        let image =
            self.renderer
                .render(&gpu.device, &gpu.queue, camera, self.background, &passes)?;
        record(
            &mut self.times,
            Stage::Render.name(),
            crate::run::ms_since(t),
        );
        if self.display.is_none() {
            self.display = Some(display_for(&self.scene, &image));
        }
        Ok(image)
    }

    /// Bring poses, M, vertex lighting and the frame effects up to date with the settings.
    fn prepare(&mut self, gpu: &GpuContext, camera: &Camera) -> Result<(), Error> {
        for t in &mut self.times {
            t.fresh = false;
        }
        let s = self.settings.clone();
        if s.frame != self.posed && self.frame_count > 0 {
            let t = Instant::now();
            let frame = s.frame % self.frame_count;
            for o in &mut self.objects {
                if o.frame_count() > 1 {
                    o.pose(frame.min(o.frame_count() - 1));
                }
            }
            self.posed = s.frame;
            self.pose_id += 1;
            self.time(Stage::Geometry, t);
        }
        if s.environment != self.chosen && s.environment < self.choices.len() {
            // Another map: I_j, the lighting, the BTF's weights and the backdrop; M is kept.
            let choice = &self.choices[s.environment];
            self.environment = choice.shown.clone();
            self.light_env = choice.lighting.clone();
            self.chosen = s.environment;
            self.lights.clear();
            self.lit = None;
            if let Some(b) = self.btf.as_mut() {
                b.forget_environment();
            }
            self.backdrop_rotation_bits = f32::NAN.to_bits();
        }
        self.turn_backdrop(gpu, s.rotation_deg);
        if self.shadowing.is_some()
            && (s.backend, s.depth_resolution)
                != (
                    self.scene.visibility.backend,
                    self.scene.visibility.depth_resolution,
                )
        {
            // A new engine for the new backend: M and the lighting are computed again.
            let mut scene = self.scene.clone();
            scene.visibility.backend = s.backend;
            scene.visibility.depth_resolution = s.depth_resolution;
            self.shadowing = Some(VisibilityStage::new(&scene, Some(gpu))?);
            self.scene = scene;
            self.visibility = None;
            self.lit = None;
        }
        let key = LitKey {
            pose: self.pose_id,
            level: s.level,
            rotation_bits: s.rotation_deg.to_bits(),
            shadowing: s.is_on(Effect::SelfShadowing) && self.shadowing.is_some(),
            statics: s.is_on(Effect::StaticShadowing) && self.statics.is_some(),
            lighting: self.has_lights(),
        };
        if self.lit.as_ref() != Some(&key) {
            self.light(gpu, &key)?;
            self.lit = Some(key);
        }
        // The sun of the shadow volumes turns with the sky it was taken from (the scene's
        // map only: another map has no such sun, and its light stays where the scene put it).
        self.effects.turn_sun(if s.environment == 0 {
            s.rotation_deg
        } else {
            0.0
        });
        if let Some(p) = s.point_light
            && self.effects.point_light() != Some(p)
        {
            self.effects.set_point_light(p);
        }
        let (volumes, translucency) = (
            s.is_on(Effect::ShadowVolumes),
            s.is_on(Effect::Translucency),
        );
        for (stage, millis, _) in self.effects.prepare_where(
            &self.scene,
            gpu,
            &mut self.objects,
            camera,
            volumes,
            translucency,
        )? {
            record(&mut self.times, stage.name(), millis);
        }
        self.btf_draws.clear();
        self.fin_draws.clear();
        let mut except = Vec::new();
        if let Some(live_btf) = self.btf.as_mut().filter(|_| s.is_on(Effect::Btf)) {
            let t = Instant::now();
            except = btf::LiveBtf::names(&self.scene, &self.objects)?;
            (self.btf_draws, self.fin_draws) = live_btf.draws(
                &self.scene,
                &self.objects,
                camera,
                s.btf_plain,
                self.environment.as_ref(),
                self.pose_id,
                s.rotation_deg,
            )?;
            record(&mut self.times, Stage::Btf.name(), crate::run::ms_since(t));
        }
        let except: Vec<&str> = except.iter().map(String::as_str).collect();
        set_gouraud_meshes(gpu, &mut self.renderer, &self.objects, camera, &except)?;
        Ok(())
    }

    fn time(&mut self, stage: Stage, since: Instant) {
        record(&mut self.times, stage.name(), crate::run::ms_since(since));
    }

    /// The lights at `level` (lightsphere and I_j at the scene's rotation), cached.
    fn lights_at(&mut self, level: u32) -> Result<Lights, Error> {
        if let Some(l) = self.lights.iter().find(|(s, _)| s.level() == level) {
            return Ok(l.clone());
        }
        let env = self.light_env.as_ref().ok_or_else(|| Error::Scene {
            origin: self.scene.origin.clone(),
            message: "lighting planned without an environment".to_owned(),
        })?;
        let mut scene = self.scene.clone();
        scene.lighting.level = level;
        let (lights, _) = inputs::light_directions(&scene, env)?;
        self.lights.push(lights.clone());
        Ok(lights)
    }

    fn light(&mut self, gpu: &GpuContext, key: &LitKey) -> Result<(), Error> {
        if !key.lighting {
            for o in &mut self.objects {
                o.front = None;
                o.back = None;
            }
            return Ok(());
        }
        let t = Instant::now();
        let (sphere, mut radiance) = self.lights_at(key.level)?;
        let rotation = f32::from_bits(key.rotation_bits);
        if rotation != 0.0
            && let Some(env) = &self.light_env
        {
            radiance = crate::lighting::rotated_lookup_radiance(env, &sphere, rotation)?;
        }
        self.time(Stage::LightDirections, t);
        if key.shadowing {
            self.update_visibility(key, &sphere)?;
        }
        let t = Instant::now();
        let visibility = match (&self.visibility, key.shadowing) {
            (Some((_, _, v)), true) => Some(v),
            _ => None,
        };
        crate::shadowing::light_objects(&mut self.objects, &sphere, &radiance, visibility)?;
        self.time(Stage::Lighting, t);
        if key.statics {
            let t = Instant::now();
            if let (Some(stage), Some(env)) = (&self.statics, &self.light_env) {
                let turned;
                let env = if rotation == 0.0 {
                    env
                } else {
                    let r = crate::lighting::environment_rotation(rotation);
                    turned = env.clone().with_rotation(r * env.world_from_env());
                    &turned
                };
                stage.light(Some(gpu), &mut self.objects, env)?;
            }
            self.time(Stage::StaticVisibility, t);
        }
        Ok(())
    }

    /// M for the posed objects at `key.level`: kept when current, refined when the level only
    /// grew on the same pose (new directions traced only), else computed.
    fn update_visibility(
        &mut self,
        key: &LitKey,
        sphere: &lightsphere::Lightsphere,
    ) -> Result<(), Error> {
        let Some(stage) = self.shadowing.as_mut() else {
            return Ok(());
        };
        let t = Instant::now();
        match self.visibility.as_mut() {
            Some((level, frame, _)) if *level == key.level && *frame == key.pose => return Ok(()),
            Some((level, frame, vis)) if *level < key.level && *frame == key.pose => {
                stage.refine(&self.objects, vis, sphere)?;
                *level = key.level;
            }
            _ => {
                let (vis, _) = stage.compute(&self.objects, sphere)?;
                self.visibility = Some((key.level, key.pose, vis));
            }
        }
        self.time(Stage::Visibility, t);
        Ok(())
    }

    /// Turn the backdrop with the environment (a re-upload, only when the angle changed).
    fn turn_backdrop(&mut self, gpu: &GpuContext, rotation_deg: f32) {
        if rotation_deg.to_bits() == self.backdrop_rotation_bits
            || self.background != Background::Environment
        {
            return;
        }
        self.backdrop_rotation_bits = rotation_deg.to_bits();
        if let Some(env) = &self.environment {
            let r = crate::lighting::environment_rotation(rotation_deg);
            self.renderer.backdrop.set_environment(
                &gpu.device,
                Some(render::Backdrop {
                    width: env.width(),
                    height: env.height(),
                    texels: env.texels(),
                    world_from_env: r * env.world_from_env(),
                }),
            );
        }
    }
}

/// The frame passes of the effects switched on: the BTF draws and their fins, then the frame
/// effects.
fn passes<'a>(
    effects: &'a FrameEffects,
    btf_draws: &'a [::btf::render::BtfDraw],
    fin_draws: &'a [::btf::render::FinDraw],
    settings: &LiveSettings,
) -> Vec<&'a dyn FramePass> {
    let mut passes: Vec<&dyn FramePass> = btf_draws.iter().map(|d| d as &dyn FramePass).collect();
    passes.extend(fin_draws.iter().map(|d| d as &dyn FramePass));
    passes.extend(effects.passes_where(
        settings.is_on(Effect::ShadowVolumes),
        settings.is_on(Effect::Translucency),
    ));
    passes
}

/// Record `stage`'s time for this frame (replacing its last one).
fn record(times: &mut Vec<StageTime>, stage: &'static str, millis: f64) {
    let entry = StageTime {
        stage,
        millis,
        fresh: true,
    };
    match times.iter_mut().find(|t| t.stage == stage) {
        Some(t) => *t = entry,
        None => times.push(entry),
    }
}
