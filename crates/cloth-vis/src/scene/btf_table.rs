//! The `[btf]` table of a scene: the material of the `btf` effect (thesis §5.3–5.5).

use serde::Deserialize;

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
        }
    }
}
