//! The `[shadow_volumes]` table of a scene: hard shadows of the `shadow-volumes` effect
//! (thesis §2.4.1, §4.2, §5.5.1; crate `shadows`).
//!
//! ```toml
//! [shadow_volumes]
//! casters = ["cloth", "ball"]   # default: every object
//! receivers = ["cloth", "ground"] # default: every object and the ground
//! lod = "hard"                  # soft (1 %), hard (10 %), a ratio, or a Hausdorff budget "0.5%"
//! boundary = "smooth"           # eq. 5.6 (default), "angle-linear" (the prose), or "stencil"
//! alpha_deg = 15.0              # eq. 5.6's offset α
//! blur = 0.0                    # width in u of a blurred boundary texture (soft edges)
//! ambient = 0.05                # radiance × albedo of objects no other effect lights
//!
//! [[shadow_volumes.light]]
//! sun = true                    # the procedural sky's sun (and it leaves the sky's lighting)
//! [[shadow_volumes.light]]
//! direction = [0.3, 1.0, 0.2]   # towards the light
//! irradiance = [2.0, 2.0, 2.0]  # at normal incidence
//! [[shadow_volumes.light]]
//! position = [1.0, 4.0, 0.0]
//! intensity = [20.0, 20.0, 20.0] # radiant intensity: irradiance I/d²
//! ```

use serde::Deserialize;

use super::{EnvironmentSource, Scene};
use crate::Error;

/// One light that casts volumes.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ShadowLightDesc {
    /// The procedural sky's sun: its direction and irradiance, taken out of the sky's lighting.
    #[serde(default)]
    pub sun: bool,
    /// Direction towards a directional light.
    pub direction: Option<[f64; 3]>,
    /// Irradiance of a directional light at normal incidence (linear RGB).
    pub irradiance: Option<[f32; 3]>,
    /// Position of a point light.
    pub position: Option<[f64; 3]>,
    /// Radiant intensity of a point light (linear RGB, W/sr).
    pub intensity: Option<[f32; 3]>,
}

/// The `shadow-volumes` effect's table.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowVolumesDesc {
    /// Lights (at least one).
    #[serde(rename = "light", default)]
    pub lights: Vec<ShadowLightDesc>,
    /// Objects that cast, by name; empty = every object.
    #[serde(default)]
    pub casters: Vec<String>,
    /// Objects that receive the lights' direct term, by name (`"ground"` for the ground);
    /// empty = every object and the ground. The others keep only what other effects give them.
    #[serde(default)]
    pub receivers: Vec<String>,
    /// Caster level of detail.
    pub lod: Option<String>,
    /// `smooth` (eq. 5.6), `angle-linear`, or `stencil` (no boundary texture).
    #[serde(default = "default_boundary")]
    pub boundary: String,
    /// Eq. 5.6's α in degrees.
    #[serde(default = "default_alpha")]
    pub alpha_deg: f64,
    /// Blur width of the boundary texture, in u.
    #[serde(default)]
    pub blur: f64,
    /// Radiance factor (× albedo) of objects that no other effect lights.
    #[serde(default = "default_ambient")]
    pub ambient: f32,
}

fn default_boundary() -> String {
    "smooth".to_owned()
}
fn default_alpha() -> f64 {
    shadows::DEFAULT_ALPHA_DEG
}
fn default_ambient() -> f32 {
    0.05
}

impl Default for ShadowVolumesDesc {
    fn default() -> Self {
        Self {
            lights: Vec::new(),
            casters: Vec::new(),
            receivers: Vec::new(),
            lod: None,
            boundary: default_boundary(),
            alpha_deg: default_alpha(),
            blur: 0.0,
            ambient: default_ambient(),
        }
    }
}

impl ShadowVolumesDesc {
    /// The boundary rule the table names (unchecked): `None` for `stencil`.
    pub fn boundary_mode(&self) -> Option<Option<shadows::BoundaryMode>> {
        match self.boundary.as_str() {
            "smooth" => Some(Some(shadows::BoundaryMode::Cosine)),
            "angle-linear" => Some(Some(shadows::BoundaryMode::AngleLinear)),
            "stencil" => Some(None),
            _ => None,
        }
    }

    /// Whether a light is the sky's sun.
    pub fn takes_sun(&self) -> bool {
        self.lights.iter().any(|l| l.sun)
    }
}

impl Scene {
    /// Checks `[shadow_volumes]` by its keys.
    pub(super) fn validate_shadow_volumes(&self) -> Result<(), Error> {
        let t = &self.shadow_volumes;
        if t.lights.is_empty() {
            return Err(self.invalid(
                "shadow_volumes.light",
                "the effect needs at least one [[shadow_volumes.light]] (sun = true, direction + \
                 irradiance, or position + intensity)"
                    .to_owned(),
            ));
        }
        for (i, l) in t.lights.iter().enumerate() {
            let key = format!("shadow_volumes.light[{i}]");
            let kinds = [l.sun, l.direction.is_some(), l.position.is_some()];
            if kinds.iter().filter(|&&k| k).count() != 1 {
                return Err(self.invalid(
                    &key,
                    "give exactly one of sun = true, direction, position".to_owned(),
                ));
            }
            if l.sun && self.environment_source()? != Some(EnvironmentSource::SynthSky) {
                return Err(self.invalid(
                    &format!("{key}.sun"),
                    "the sun is the procedural sky's: set [environment] source = \"synth:sky\", or \
                     give the light a direction and irradiance"
                        .to_owned(),
                ));
            }
            if let Some(d) = l.direction {
                let ok = d.iter().all(|v| v.is_finite()) && d.iter().any(|v| *v != 0.0);
                if !ok {
                    return Err(self.invalid(
                        &format!("{key}.direction"),
                        format!("{d:?} must be finite and non-zero"),
                    ));
                }
            }
            let bound = crate::inputs::MAX_WORLD_COORDINATE;
            if let Some(p) = l.position
                && !p.iter().all(|v| v.is_finite() && (v.abs() as f32) <= bound)
            {
                return Err(self.invalid(
                    &format!("{key}.position"),
                    format!(
                        "{p:?}: every coordinate must be finite with |x| ≤ {bound:e} \
                         (MAX_WORLD_COORDINATE)"
                    ),
                ));
            }
            let power = match (l.direction.is_some(), l.position.is_some()) {
                (true, _) => Some(("irradiance", l.irradiance, l.intensity.is_some())),
                (_, true) => Some(("intensity", l.intensity, l.irradiance.is_some())),
                _ => None,
            };
            if let Some((name, value, other)) = power {
                let Some(v) = value else {
                    return Err(self.invalid(&format!("{key}.{name}"), "is missing".to_owned()));
                };
                if other || !v.iter().all(|c| c.is_finite() && *c >= 0.0) {
                    return Err(self.invalid(
                        &format!("{key}.{name}"),
                        format!(
                            "{v:?} must be finite and ≥ 0 (and the light has no other power key)"
                        ),
                    ));
                }
            }
        }
        for name in &t.casters {
            if !self.objects.iter().any(|o| &o.name == name) {
                return Err(self.invalid(
                    "shadow_volumes.casters",
                    format!("{name:?} is not an object of the scene"),
                ));
            }
        }
        for name in &t.receivers {
            let ground = name == super::GROUND_NAME && self.ground.is_some();
            if !ground && !self.objects.iter().any(|o| &o.name == name) {
                return Err(self.invalid(
                    "shadow_volumes.receivers",
                    format!("{name:?} is neither an object of the scene nor its [ground]"),
                ));
            }
        }
        if let Some(lod) = &t.lod {
            shadows::LodTarget::parse(lod)
                .map_err(|e| self.invalid("shadow_volumes.lod", e.to_string()))?;
        }
        if t.boundary_mode().is_none() {
            return Err(self.invalid(
                "shadow_volumes.boundary",
                format!(
                    "{:?} is not one of \"smooth\", \"angle-linear\", \"stencil\"",
                    t.boundary
                ),
            ));
        }
        shadows::BoundaryTexture::blurred(16, t.blur, t.alpha_deg).map_err(|e| {
            let key = if (0.0..=1.0).contains(&t.blur) {
                "shadow_volumes.alpha_deg"
            } else {
                "shadow_volumes.blur"
            };
            self.invalid(key, e.to_string())
        })?;
        if !(t.ambient.is_finite() && t.ambient >= 0.0) {
            return Err(self.invalid(
                "shadow_volumes.ambient",
                format!("{} must be finite and ≥ 0", t.ambient),
            ));
        }
        Ok(())
    }
}
