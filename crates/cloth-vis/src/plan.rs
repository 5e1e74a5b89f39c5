//! The effect graph: from a scene's effects to the ordered stages that must run — and no others.
//!
//! | stage | runs when |
//! |---|---|
//! | `geometry` | always (meshes, animation frames, procedural cloth) |
//! | `environment` | `lighting` is requested, or an environment is drawn as the backdrop |
//! | `light-directions` | `lighting` or `self-shadowing` (lightsphere level, I_j per direction) |
//! | `visibility` | `self-shadowing` (the visibility matrix M, occlusion-gpu) |
//! | `static-visibility` | `static-shadowing` (per-vertex visibility maps and their radiance, hemicube) |
//! | `lighting` | `lighting` or `self-shadowing` (per-vertex radiance, with M when computed) |
//! | `render` | always (PNG/EXR) |
//! | `shadow-volumes` | `shadow-volumes` (per frame: caster volumes per light, stencil-masked direct light in the frame) |
//! | `translucency` | `translucency` (per frame: cube map, SH, light distance map, eq. 12 added in the frame) |
//! | `btf` | `btf` (a compressed BTF on the objects with UVs, beside plain texturing; its own PNG) |
//!
//! Later effects (self-shadowing, BTF, shadow volumes, translucency) add their own stages here
//! without touching the others.

use serde::Serialize;

use crate::scene::{BackgroundDesc, Scene};
use crate::{Effect, Error};

/// A unit of work in a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stage {
    /// Load or generate every object's geometry.
    Geometry,
    /// Load or generate the HDR environment (rotation, prefilter).
    Environment,
    /// Build the lightsphere and sample I_j per direction.
    LightDirections,
    /// The visibility matrix M of every vertex towards every light direction.
    Visibility,
    /// Per-vertex visibility maps (thesis §4.3) and the radiance they let through.
    StaticVisibility,
    /// Per-vertex image-based radiance.
    Lighting,
    /// Shadow volumes of the casters for every light, drawn into the frame's stencil.
    ShadowVolumes,
    /// Seed 004's translucency passes, its eq. 12 added in the frame.
    Translucency,
    /// Rasterise and write images.
    Render,
    /// The BTF material on the chosen objects, beside plain texture mapping (own image).
    Btf,
}

impl Stage {
    /// The stage's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Geometry => "geometry",
            Stage::Environment => "environment",
            Stage::LightDirections => "light-directions",
            Stage::Visibility => "visibility",
            Stage::StaticVisibility => "static-visibility",
            Stage::Lighting => "lighting",
            Stage::ShadowVolumes => "shadow-volumes",
            Stage::Translucency => "translucency",
            Stage::Render => "render",
            Stage::Btf => "btf",
        }
    }

    /// Stages an effect needs (beyond geometry and render, which always run).
    pub fn needed_by(effect: Effect) -> &'static [Stage] {
        match effect {
            Effect::Lighting => &[Stage::Environment, Stage::LightDirections, Stage::Lighting],
            Effect::SelfShadowing => &[
                Stage::Environment,
                Stage::LightDirections,
                Stage::Visibility,
                Stage::Lighting,
            ],
            Effect::StaticShadowing => &[Stage::Environment, Stage::StaticVisibility],
            Effect::Btf => &[Stage::Btf],
            Effect::ShadowVolumes => &[Stage::ShadowVolumes],
            Effect::Translucency => &[Stage::Translucency],
        }
    }
}

/// The validated effects of a scene and the stages that will run, in order.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    effects: Vec<Effect>,
    stages: Vec<Stage>,
}

impl Plan {
    /// Validate the scene and plan its stages. Nothing is loaded or computed.
    ///
    /// # Errors
    /// Every error of [`Scene::validate`]: unknown effects, bad values, missing files.
    pub fn for_scene(scene: &Scene) -> Result<Self, Error> {
        let effects = scene.validate()?;
        let mut stages = vec![Stage::Geometry, Stage::Render];
        for effect in &effects {
            stages.extend_from_slice(Stage::needed_by(*effect));
        }
        let btf_env = effects.contains(&Effect::Btf)
            && scene.btf.illumination == crate::scene::BtfIllumination::Environment;
        if scene.environment.is_some()
            && (btf_env || scene.output.background == BackgroundDesc::ENVIRONMENT)
        {
            stages.push(Stage::Environment);
        }
        stages.sort();
        stages.dedup();
        Ok(Self { effects, stages })
    }

    /// The requested effects, in stage order.
    pub fn effects(&self) -> &[Effect] {
        &self.effects
    }

    /// The stages that will run, in order.
    pub fn stages(&self) -> &[Stage] {
        &self.stages
    }

    /// Whether `stage` will run.
    pub fn contains(&self, stage: Stage) -> bool {
        self.stages.contains(&stage)
    }
}
