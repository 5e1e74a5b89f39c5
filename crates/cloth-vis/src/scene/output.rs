//! The `[output]` and `[ground]` tables of a scene: exposure, tone curve, background, image
//! names, frame range, and the ground plane.

use serde::Deserialize;

/// Exposure: stops (EV; radiance is multiplied by 2^EV before the tone curve), or `"auto"`
/// (the 90th percentile of the objects' pixels' brightest channel — never the backdrop's —
/// maps to 0.8, so a saturated colour keeps its hue).
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, serde::Serialize)]
#[serde(untagged)]
pub enum ExposureDesc {
    /// A fixed exposure in EV.
    Fixed(f32),
    /// `"auto"`.
    Auto(AutoKeyword),
}

/// The keyword `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AutoKeyword {
    /// Automatic exposure.
    Auto,
}

/// What is drawn behind the objects: `"environment"` (default; black without one),
/// `"black"`, `"transparent"` (PNG and EXR carry the objects' coverage as alpha), or a linear
/// colour `[r, g, b]`.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize, serde::Serialize)]
#[serde(untagged, try_from = "BackgroundText")]
pub enum BackgroundDesc {
    /// A keyword.
    Named(BackgroundKeyword),
    /// A constant linear colour.
    Color([f32; 3]),
}

/// What a scene file may write for `background`, before the keyword is checked (so that a
/// misspelt keyword gets a message listing the choices, not serde's "no variant matched").
#[derive(Deserialize)]
#[serde(untagged)]
enum BackgroundText {
    Text(String),
    Color([f32; 3]),
}

impl TryFrom<BackgroundText> for BackgroundDesc {
    type Error = String;
    fn try_from(raw: BackgroundText) -> Result<Self, String> {
        match raw {
            BackgroundText::Color(c) => Ok(Self::Color(c)),
            BackgroundText::Text(t) => match t.as_str() {
                "environment" => Ok(Self::ENVIRONMENT),
                "black" => Ok(Self::BLACK),
                "transparent" => Ok(Self::TRANSPARENT),
                other => Err(format!(
                    "background {other:?} is not one of \"environment\", \"black\",                      \"transparent\" or a linear colour [r, g, b]"
                )),
            },
        }
    }
}

impl Default for BackgroundDesc {
    fn default() -> Self {
        Self::Named(BackgroundKeyword::Environment)
    }
}

impl BackgroundDesc {
    /// The environment as the backdrop.
    pub const ENVIRONMENT: Self = Self::Named(BackgroundKeyword::Environment);
    /// Black.
    pub const BLACK: Self = Self::Named(BackgroundKeyword::Black);
    /// Transparent (alpha matte).
    pub const TRANSPARENT: Self = Self::Named(BackgroundKeyword::Transparent);
}

/// The background keywords.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BackgroundKeyword {
    /// The environment map as seen by the camera.
    Environment,
    /// Black, opaque.
    Black,
    /// Nothing: alpha 0.
    Transparent,
}

/// The tone curve of the PNG output (`render::tone`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ToneDesc {
    /// Narkowicz's ACES fit, then sRGB (default).
    #[default]
    Aces,
    /// The seed's clamp then x^(1/gamma).
    Clamp,
}

/// An optional ground plane under the scene: a real object that receives and casts
/// visibility like any other (`render::ground`).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundDesc {
    /// Diffuse albedo (linear RGB in [0, 1]).
    #[serde(default = "default_ground_albedo")]
    pub albedo: [f32; 3],
    /// Side of the square as a multiple of the scene's bounding-sphere radius.
    #[serde(default = "default_ground_size")]
    pub size: f32,
    /// Grid cells per side (the resolution of the shadows it receives per vertex).
    #[serde(default = "default_ground_cells")]
    pub cells: u32,
}

fn default_ground_albedo() -> [f32; 3] {
    [0.5, 0.5, 0.5]
}
fn default_ground_size() -> f32 {
    5.0
}
fn default_ground_cells() -> u32 {
    64
}

/// Image outputs, written into the output folder.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputDesc {
    /// PNG file name (tone-mapped). A table that names only `exr` writes no PNG; one that
    /// names neither writes both defaults, `render.png` and `render.exr`.
    #[serde(default)]
    pub png: Option<String>,
    /// EXR file name (linear radiance). A table that names only `png` writes no EXR; one that
    /// names neither writes both defaults.
    #[serde(default)]
    pub exr: Option<String>,
    /// Exposure multiplier or `"auto"`.
    #[serde(default = "default_exposure")]
    pub exposure: ExposureDesc,
    /// Display gamma.
    #[serde(default = "default_gamma")]
    pub gamma: f32,
    /// Background.
    #[serde(default)]
    pub background: BackgroundDesc,
    /// Tone curve.
    #[serde(default)]
    pub tone: ToneDesc,
    /// A frame range `"A..B"` of the scene's animated objects, rendered to a numbered
    /// sequence `frame-0000.png`, … (`png`/`exr` name the still when omitted).
    #[serde(default)]
    pub frames: Option<String>,
    /// Also write `frame-NNNN.exr` for each frame of a sequence.
    #[serde(default)]
    pub sequence_exr: bool,
}

fn default_png() -> Option<String> {
    Some("render.png".to_owned())
}
fn default_exr() -> Option<String> {
    Some("render.exr".to_owned())
}
fn default_exposure() -> ExposureDesc {
    ExposureDesc::Auto(AutoKeyword::Auto)
}
fn default_gamma() -> f32 {
    2.2
}

impl OutputDesc {
    /// The default names where the table named neither image (a table naming one asked for
    /// that one only).
    pub(crate) fn name_default_images(&mut self) {
        if self.png.is_none() && self.exr.is_none() {
            self.png = default_png();
            self.exr = default_exr();
        }
    }
}

impl Default for OutputDesc {
    fn default() -> Self {
        Self {
            png: default_png(),
            exr: default_exr(),
            exposure: default_exposure(),
            gamma: default_gamma(),
            background: BackgroundDesc::default(),
            tone: ToneDesc::default(),
            frames: None,
            sequence_exr: false,
        }
    }
}
