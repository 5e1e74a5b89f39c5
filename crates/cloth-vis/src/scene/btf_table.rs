//! The `[btf]` table of a scene: the material of the `btf` effect (thesis §5.3–5.5).

use std::path::Path;

use glam::Vec3;
use serde::Deserialize;

use super::{BtfSource, Scene};
use crate::Error;

/// The BTF material of the `btf` effect (thesis §5.3–5.5).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BtfDesc {
    /// `synth:woven` (the woven-cloth BTF, compressed in memory) or a `.btfpca` file.
    #[serde(default = "default_btf_source")]
    pub source: String,
    /// Objects that wear it, by name (default: every object with texture coordinates).
    #[serde(default)]
    pub objects: Vec<String>,
    /// Texels per side of `synth:woven`.
    #[serde(default = "default_btf_res")]
    pub res: usize,
    /// Eigen-normtextures per view slot for `synth:woven`.
    #[serde(default = "default_btf_components")]
    pub components: usize,
    /// World-space direction towards the (directional) light.
    #[serde(default = "default_btf_light_dir")]
    pub light_dir: [f32; 3],
    /// Linear RGB radiance g of the light (eq. 5.4).
    #[serde(default = "default_btf_radiance")]
    pub radiance: [f32; 3],
    /// Texture repeats across the object's UV range.
    #[serde(default = "default_btf_uv_scale")]
    pub uv_scale: f32,
    /// The picture: the BTF on the left, plain texture mapping on the right.
    #[serde(default = "default_btf_png")]
    pub png: String,
    /// Fins along the BTF objects' silhouettes (§5.7), drawn on the BTF half of the picture.
    #[serde(default)]
    pub fins: Option<FinsDesc>,
    /// `light` (the directional light above, eq. 5.4) or `environment`: the scene's
    /// `[environment]` (its rotation included) through each BTF object's own self-shadowing
    /// (§5.5.2, eqs. 5.10–5.11).
    #[serde(default)]
    pub illumination: BtfIllumination,
    /// Lightsphere level of the visibility matrix M under `environment` (3: 258 directions).
    #[serde(default = "default_btf_level")]
    pub level: u32,
    /// Shadow the environment through static hemicube maps of `maps`² pixels per face (the
    /// thesis's path) instead of M; static objects only.
    #[serde(default)]
    pub maps: Option<u32>,
    /// Garment parts (§5.6): face material NAME (OBJ `usemtl`, glTF material) of the BTF
    /// objects loaded from files wears this BTF (`synth:woven` or a `.btfpca` relative to the
    /// scene); other faces wear `source`.
    #[serde(default)]
    pub parts: std::collections::BTreeMap<String, String>,
}

/// How the BTF objects are lit.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum BtfIllumination {
    /// `[btf] light_dir` and `radiance`.
    #[default]
    Light,
    /// The scene's environment.
    Environment,
}

/// `[btf] fins = { source = "synth:wool" | "FILE.finpca", height = H, size = S }`.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinsDesc {
    /// `synth:wool` (the synthetic wool, rendered and compressed in memory) or a `.finpca`
    /// file (relative to the scene file).
    pub source: String,
    /// Fin height in material units (default 1: the whole fin image).
    #[serde(default)]
    pub height: Option<f32>,
    /// World length of one material unit (default 4 % of the BTF objects' bounding radius).
    #[serde(default)]
    pub size: Option<f32>,
}

fn default_btf_source() -> String {
    "synth:woven".to_owned()
}
fn default_btf_res() -> usize {
    32
}
fn default_btf_components() -> usize {
    btf::DEFAULT_COMPONENTS
}
fn default_btf_light_dir() -> [f32; 3] {
    [0.4, 0.8, 0.45]
}
fn default_btf_radiance() -> [f32; 3] {
    [1.0, 1.0, 1.0]
}
fn default_btf_uv_scale() -> f32 {
    6.0
}
fn default_btf_level() -> u32 {
    3
}
fn default_btf_png() -> String {
    "btf.png".to_owned()
}

impl Default for BtfDesc {
    fn default() -> Self {
        Self {
            source: default_btf_source(),
            objects: Vec::new(),
            res: default_btf_res(),
            components: default_btf_components(),
            light_dir: default_btf_light_dir(),
            radiance: default_btf_radiance(),
            uv_scale: default_btf_uv_scale(),
            png: default_btf_png(),
            fins: None,
            illumination: BtfIllumination::Light,
            level: default_btf_level(),
            maps: None,
            parts: std::collections::BTreeMap::new(),
        }
    }
}

impl Scene {
    /// Checks the `[btf]` table (only when the `btf` effect is requested).
    pub(super) fn validate_btf(&self) -> Result<(), Error> {
        let b = &self.btf;
        if let BtfSource::File(path) = self.btf_source()?
            && !path.exists()
        {
            return Err(self.invalid("btf.source", format!("{} does not exist", path.display())));
        }
        for (name, source) in &b.parts {
            let key = format!("btf.parts.{name}");
            if let BtfSource::File(path) = self.material_source(&key, source)?
                && !path.is_file()
            {
                return Err(self.invalid(
                    &key,
                    format!(
                        "{} is not a file; give a .btfpca or \"synth:woven\"",
                        path.display()
                    ),
                ));
            }
        }
        if let Some(name) = b
            .objects
            .iter()
            .find(|n| !self.objects.iter().any(|o| &o.name == *n))
        {
            return Err(self.invalid("btf.objects", format!("no object is named {name:?}")));
        }
        if !(1..=512).contains(&b.res) {
            return Err(self.invalid("btf.res", format!("{} is outside 1..=512", b.res)));
        }
        if !(1..=btf::MAX_COMPONENTS).contains(&b.components) {
            return Err(self.invalid(
                "btf.components",
                format!("{} is outside 1..={}", b.components, btf::MAX_COMPONENTS),
            ));
        }
        let dir = Vec3::from(b.light_dir);
        if !dir.is_finite() || dir.length_squared() == 0.0 {
            return Err(self.invalid(
                "btf.light_dir",
                format!("{:?} must be a finite non-zero direction", b.light_dir),
            ));
        }
        if b.radiance.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(self.invalid(
                "btf.radiance",
                format!("{:?} must be finite and ≥ 0", b.radiance),
            ));
        }
        if !(b.uv_scale.is_finite() && b.uv_scale > 0.0) {
            return Err(self.invalid(
                "btf.uv_scale",
                format!("{} must be finite and > 0", b.uv_scale),
            ));
        }
        if let Some(f) = &b.fins {
            if f.source != crate::fins_stage::SYNTH_WOOL {
                let path = self.base_dir.join(&f.source);
                if !path.is_file() {
                    return Err(self.invalid(
                        "btf.fins.source",
                        format!(
                            "{} is not a file; give a .finpca or \"synth:wool\"",
                            path.display()
                        ),
                    ));
                }
            }
            for (key, v) in [("btf.fins.height", f.height), ("btf.fins.size", f.size)] {
                if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0 && *v < 1e9)) {
                    return Err(self.invalid(key, format!("{v} must be finite and > 0")));
                }
            }
        }
        if b.illumination == BtfIllumination::Environment {
            if self.environment.is_none() {
                return Err(self.invalid(
                    "btf.illumination",
                    "\"environment\" needs an [environment] (e.g. source = \"synth:sky\")"
                        .to_owned(),
                ));
            }
            if b.fins.is_some() {
                return Err(self.invalid(
                    "btf.fins",
                    "fins are lit by the directional light only; use illumination = \"light\" \
                     with fins"
                        .to_owned(),
                ));
            }
            if b.level > super::MAX_LEVEL {
                return Err(self.invalid(
                    "btf.level",
                    format!("{} is outside 0..={}", b.level, super::MAX_LEVEL),
                ));
            }
            if let Some(res) = b
                .maps
                .filter(|r| !(2..=256).contains(r) || !r.is_multiple_of(2))
            {
                return Err(self.invalid(
                    "btf.maps",
                    format!("{res} must be even and within 2..=256 (hemicube pixels per side)"),
                ));
            }
        }
        if Path::new(&b.png)
            .file_name()
            .is_none_or(|f| f != b.png.as_str())
        {
            return Err(self.invalid(
                "btf.png",
                format!(
                    "{:?} must be a plain file name inside the output folder",
                    b.png
                ),
            ));
        }
        Ok(())
    }
}
