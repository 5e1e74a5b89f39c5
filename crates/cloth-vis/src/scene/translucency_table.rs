//! The `[translucency]` table of a scene: subsurface appearance by spherical harmonics
//! (seed 004, Banterle & Chalmers; crate `translucency`).
//!
//! ```toml
//! [translucency]
//! material = "marble"          # a preset of Jensen et al. 2001 (apple … wholemilk), or:
//! # sigma_a = [0.0021, 0.0041, 0.0071]   # absorption, mm⁻¹ (R, G, B)
//! # sigma_s = [2.19, 2.62, 3.00]         # reduced scattering σ′_s, mm⁻¹
//! # eta = 1.5
//! mm_per_unit = 1000.0         # millimetres per scene unit (metres, glTF's convention)
//! objects = ["statue"]         # default: every object
//! cube_size = 64               # external cube map faces (TR 164)
//! light_map_size = 512         # light distance map faces (TR 164)
//! window = 0.0                 # 0: none; W > 0: Gaussian SH window (W ≤ 5 keeps B ≥ 0)
//! peel = true                  # the peeled layer for concave objects (TR 155)
//! intensity = 1.0              # a factor on eq. 12
//! light = { position = [0.5, 1.0, 0.8], intensity = [1.0, 1.0, 1.0] }
//! # light = { direction = [0.3, 1.0, 0.2], irradiance = [2.0, 2.0, 2.0] }
//! # light = { environment = true }  # the scene's lighting: E_t from the lit vertices, the
//! #                                 # thickness along the environment's dominant direction
//! deform = { amplitude = 0.05, waves = 1.0, frames = 60 }  # the sine deformer of Fig. 12
//! ```

use serde::Deserialize;

use super::Scene;
use crate::{Effect, Error};

/// The light the translucent objects are lit by.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TranslucencyLightDesc {
    /// Position of a point light.
    pub position: Option<[f64; 3]>,
    /// Radiant intensity of a point light (linear RGB, W/sr); default: an irradiance of 1 at
    /// the translucent objects' centre.
    pub intensity: Option<[f32; 3]>,
    /// Direction towards a directional light.
    pub direction: Option<[f64; 3]>,
    /// Irradiance of a directional light at normal incidence (default 1).
    pub irradiance: Option<[f32; 3]>,
    /// The scene's environment lighting (needs `lighting`, `self-shadowing` or
    /// `static-shadowing`).
    #[serde(default)]
    pub environment: bool,
}

/// The sine deformer of seed 004's Fig. 12: every vertex moves along x by
/// A·H·h·sin(2π(k·h − f/N)), h = (y − y_min)/H its height fraction (H the object's height),
/// so the base stays and the top sways; it turns a static object into an N-frame loop.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SineDeformDesc {
    /// Amplitude A as a fraction of the object's height.
    #[serde(default = "default_amplitude")]
    pub amplitude: f64,
    /// Waves k over the height.
    #[serde(default = "default_waves")]
    pub waves: f64,
    /// Frames N of one period (the loop's length).
    #[serde(default = "default_deform_frames")]
    pub frames: usize,
}

fn default_amplitude() -> f64 {
    0.05
}
fn default_waves() -> f64 {
    1.0
}
fn default_deform_frames() -> usize {
    60
}

/// The `translucency` effect's table.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslucencyDesc {
    /// A preset of Jensen et al. 2001 (`translucency::PRESETS`).
    pub material: Option<String>,
    /// Absorption σ_a (mm⁻¹), with `sigma_s`, instead of a preset.
    pub sigma_a: Option<[f64; 3]>,
    /// Reduced scattering σ′_s (mm⁻¹), with `sigma_a`.
    pub sigma_s: Option<[f64; 3]>,
    /// Relative index of refraction (default: the preset's, or 1.3).
    pub eta: Option<f64>,
    /// Millimetres per scene unit.
    #[serde(default = "default_mm_per_unit")]
    pub mm_per_unit: f64,
    /// Translucent objects by name; empty = every object.
    #[serde(default)]
    pub objects: Vec<String>,
    /// The light.
    #[serde(default)]
    pub light: TranslucencyLightDesc,
    /// External cube map face size.
    #[serde(default = "default_cube")]
    pub cube_size: u32,
    /// Light distance map face size.
    #[serde(default = "default_light_map")]
    pub light_map_size: u32,
    /// Gaussian SH window width (0 = none).
    #[serde(default)]
    pub window: f64,
    /// The peeled-layer test.
    #[serde(default = "default_true")]
    pub peel: bool,
    /// Factor on eq. 12.
    #[serde(default = "default_intensity")]
    pub intensity: f64,
    /// The sine deformer.
    pub deform: Option<SineDeformDesc>,
}

fn default_mm_per_unit() -> f64 {
    translucency::material::DEFAULT_MM_PER_UNIT
}
fn default_cube() -> u32 {
    64
}
fn default_light_map() -> u32 {
    512
}
fn default_true() -> bool {
    true
}
fn default_intensity() -> f64 {
    1.0
}

impl Default for TranslucencyDesc {
    fn default() -> Self {
        Self {
            material: None,
            sigma_a: None,
            sigma_s: None,
            eta: None,
            mm_per_unit: default_mm_per_unit(),
            objects: Vec::new(),
            light: TranslucencyLightDesc::default(),
            cube_size: default_cube(),
            light_map_size: default_light_map(),
            window: 0.0,
            peel: true,
            intensity: default_intensity(),
            deform: None,
        }
    }
}

impl TranslucencyDesc {
    /// The material the table names (preset, or σ_a + σ′_s + η), with its scale.
    ///
    /// # Errors
    /// The material's own error (unknown preset, bad coefficients).
    pub fn material(&self) -> Result<translucency::Material, translucency::TranslucencyError> {
        let base = match (&self.sigma_a, &self.sigma_s) {
            (Some(a), Some(s)) => translucency::Material::new(*a, *s, self.eta.unwrap_or(1.3))?,
            _ => {
                let mut m =
                    translucency::Material::preset(self.material.as_deref().unwrap_or("marble"))?;
                if let Some(eta) = self.eta {
                    m = translucency::Material::new(m.sigma_a, m.sigma_s_prime, eta)?;
                }
                m
            }
        };
        base.with_scale(self.mm_per_unit)
    }

    /// The SH window the table names.
    pub fn sh_window(&self) -> translucency::Window {
        if self.window > 0.0 {
            translucency::Window::Gaussian { width: self.window }
        } else {
            translucency::Window::None
        }
    }

    /// Whether `name` is one of the translucent objects.
    pub fn covers(&self, name: &str) -> bool {
        name != super::GROUND_NAME
            && (self.objects.is_empty() || self.objects.iter().any(|o| o == name))
    }
}

impl Scene {
    /// Checks `[translucency]` by its keys.
    pub(super) fn validate_translucency(&self, effects: &[Effect]) -> Result<(), Error> {
        let t = &self.translucency;
        if t.sigma_a.is_some() != t.sigma_s.is_some() {
            return Err(self.invalid(
                "translucency.sigma_a",
                "give sigma_a and sigma_s together (or a material preset)".to_owned(),
            ));
        }
        if t.sigma_a.is_some() && t.material.is_some() {
            return Err(self.invalid(
                "translucency.material",
                "give a preset or sigma_a + sigma_s, not both".to_owned(),
            ));
        }
        if !(t.mm_per_unit.is_finite() && t.mm_per_unit > 0.0) {
            return Err(self.invalid(
                "translucency.mm_per_unit",
                format!("{} must be finite and > 0", t.mm_per_unit),
            ));
        }
        let key = if t.sigma_a.is_some() {
            "translucency.sigma_a"
        } else {
            "translucency.material"
        };
        t.material().map_err(|e| self.invalid(key, e.to_string()))?;
        let l = &t.light;
        let kinds = [l.position.is_some(), l.direction.is_some(), l.environment];
        if kinds.iter().filter(|&&k| k).count() != 1 {
            return Err(self.invalid(
                "translucency.light",
                "give exactly one of position (+ intensity), direction (+ irradiance), \
                 environment = true"
                    .to_owned(),
            ));
        }
        let point = (l.position, l.intensity, "position", "intensity");
        let directional = (l.direction, l.irradiance, "direction", "irradiance");
        for (place, power, place_key, power_key) in [point, directional] {
            let Some(v) = place else { continue };
            let bound = crate::inputs::MAX_WORLD_COORDINATE;
            // Compared as the f32 the stages use.
            if !v.iter().all(|c| c.is_finite() && (c.abs() as f32) <= bound)
                || v == [0.0; 3] && place_key == "direction"
            {
                return Err(self.invalid(
                    &format!("translucency.light.{place_key}"),
                    format!(
                        "{v:?}: every coordinate must be finite with |x| ≤ {bound:e} \
                         (MAX_WORLD_COORDINATE){}",
                        if place_key == "direction" {
                            ", and the direction non-zero"
                        } else {
                            ""
                        }
                    ),
                ));
            }
            match power {
                Some(p) if p.iter().all(|c| c.is_finite() && *c >= 0.0) => {}
                Some(p) => {
                    return Err(self.invalid(
                        &format!("translucency.light.{power_key}"),
                        format!("{p:?} must be finite and ≥ 0"),
                    ));
                }
                // Unit irradiance at the translucent objects' centre.
                None => {}
            }
        }
        if l.environment {
            let lit = effects.iter().any(|e| {
                matches!(
                    e,
                    Effect::Lighting | Effect::SelfShadowing | Effect::StaticShadowing
                )
            });
            if !lit {
                return Err(self.invalid(
                    "translucency.light.environment",
                    "the environment reaches the translucent objects through the scene's lighting: \
                     add \"lighting\", \"self-shadowing\" or \"static-shadowing\" to effects"
                        .to_owned(),
                ));
            }
        }
        for name in &t.objects {
            if !self.objects.iter().any(|o| &o.name == name) {
                return Err(self.invalid(
                    "translucency.objects",
                    format!("{name:?} is not an object of the scene"),
                ));
            }
        }
        for (key, v, range) in [
            ("translucency.cube_size", t.cube_size, 4..=2048),
            ("translucency.light_map_size", t.light_map_size, 16..=4096),
        ] {
            if !range.contains(&v) {
                return Err(self.invalid(key, format!("{v} is outside {range:?}")));
            }
        }
        for (key, v) in [
            ("translucency.window", t.window),
            ("translucency.intensity", t.intensity),
            ("translucency.mm_per_unit", t.mm_per_unit),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(self.invalid(key, format!("{v} must be finite and ≥ 0")));
            }
        }
        if let Some(d) = &t.deform {
            if !(d.amplitude.is_finite() && d.amplitude.abs() <= 10.0) {
                return Err(self.invalid(
                    "translucency.deform.amplitude",
                    format!("{} must be finite, |A| ≤ 10 heights", d.amplitude),
                ));
            }
            if !(d.waves.is_finite() && d.waves.abs() <= 1000.0) {
                return Err(self.invalid(
                    "translucency.deform.waves",
                    format!("{} must be finite, |k| ≤ 1000", d.waves),
                ));
            }
            if !(1..=10_000).contains(&d.frames) {
                return Err(self.invalid(
                    "translucency.deform.frames",
                    format!("{} is outside 1..=10000", d.frames),
                ));
            }
        }
        Ok(())
    }
}
