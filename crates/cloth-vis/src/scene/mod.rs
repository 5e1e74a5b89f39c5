//! Scene files (TOML): inputs, transforms, environment, camera, materials and the effects wanted.
//!
//! ```toml
//! name = "drape"
//! effects = ["lighting"]
//!
//! [[object]]
//! name = "cloth"
//! source = "synth:cloth"        # or a mesh (.ply .obj .gltf .glb) or an animation
//!                               # (a point cache .npy .pc2 .mdd also needs topology = "mesh.obj")
//! frame = -1                    # animation frame; negative counts from the end
//! albedo = [0.75, 0.2, 0.15]
//! two_sided = true
//!
//! [environment]
//! source = "synth:sky"          # or an equirectangular .hdr / .exr
//! rotation_deg = 30.0           # about +Y
//!
//! [lighting]
//! level = 3
//!
//! [camera]
//! width = 768
//! height = 768
//! ```
//!
//! Relative paths are resolved against the scene file's folder. [`Scene::validate`] checks every
//! name, range and file before any work starts; its errors name the scene file, the key and the
//! value.

use std::path::{Path, PathBuf};

use glam::{EulerRot, Mat4, Quat, Vec3};
use serde::Deserialize;

use crate::{Effect, Error};

mod btf_table;
mod output;
mod shadow_table;
mod sources;
mod static_table;
mod translucency_table;

pub use btf_table::{BtfDesc, BtfIllumination, FinsDesc};
pub use output::{
    AutoKeyword, BackgroundDesc, BackgroundKeyword, ExposureDesc, GroundDesc, OutputDesc, ToneDesc,
};
pub use shadow_table::{ShadowLightDesc, ShadowVolumesDesc};
pub use sources::{BtfSource, EnvironmentSource, GeometrySource};
pub use static_table::{StaticBuilderDesc, StaticShadowingDesc};
pub use translucency_table::{SineDeformDesc, TranslucencyDesc, TranslucencyLightDesc};

/// Prefix of procedural sources in scene files.
pub const SYNTH_PREFIX: &str = "synth:";
/// Largest lightsphere level a scene may ask for (k = 2 + 4^8 = 65,538 directions).
pub const MAX_LEVEL: u32 = 7;
/// Largest image side a scene may ask for.
pub const MAX_IMAGE_SIDE: u32 = 8192;
/// Largest `[synth] sky_width` a scene may ask for (a 4096 × 2048 sky, 100 MB as f32 RGB).
/// Beyond it the sky's texels, not the scene, set the run's time and memory: a 16384-wide sky
/// prefiltered at 90° was still running after 60 s at 6.2 GB (issue #12). The lightsphere's
/// finest level (k = 65,538, about 0.9° apart) gains nothing from a finer sky.
pub const MAX_SKY_WIDTH: usize = 4096;
/// The name of the `[ground]` object in reports and `[btf] objects`.
pub const GROUND_NAME: &str = "ground";

/// A parsed scene file.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Name used in reports.
    #[serde(default = "default_name")]
    pub name: String,
    /// Effects wanted, by name (see [`Effect`]).
    #[serde(default)]
    pub effects: Vec<String>,
    /// Objects to render (at least one).
    #[serde(rename = "object", default)]
    pub objects: Vec<ObjectDesc>,
    /// The HDR environment; required by `lighting`.
    pub environment: Option<EnvironmentDesc>,
    /// Lighting parameters.
    #[serde(default)]
    pub lighting: LightingDesc,
    /// Visibility parameters (the `self-shadowing` effect).
    #[serde(default)]
    pub visibility: VisibilityDesc,
    /// Visibility maps (the `static-shadowing` effect).
    #[serde(default)]
    pub static_shadowing: StaticShadowingDesc,
    /// Procedural data parameters (for `synth:` sources).
    #[serde(default)]
    pub synth: SynthDesc,
    /// The camera; framed automatically where fields are omitted.
    #[serde(default)]
    pub camera: CameraDesc,
    /// Image outputs.
    #[serde(default)]
    pub output: OutputDesc,
    /// The BTF material (the `btf` effect).
    #[serde(default)]
    pub btf: BtfDesc,
    /// An optional ground plane under the objects.
    pub ground: Option<GroundDesc>,
    /// Hard shadows (the `shadow-volumes` effect).
    #[serde(default)]
    pub shadow_volumes: ShadowVolumesDesc,
    /// Subsurface appearance (the `translucency` effect).
    #[serde(default)]
    pub translucency: TranslucencyDesc,
    /// Folder that relative paths are resolved against (the scene file's folder).
    #[serde(skip)]
    pub base_dir: PathBuf,
    /// Where the scene came from, for error messages.
    #[serde(skip)]
    pub origin: String,
}

fn default_name() -> String {
    "scene".to_owned()
}

/// One object: a mesh or one frame of an animation, with a transform and a material.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObjectDesc {
    /// Name used in reports.
    pub name: String,
    /// `synth:cloth`, `synth:cloth-obstacle`, or a path to a mesh or animation.
    pub source: String,
    /// A mesh whose triangles (and UVs) a point-cache `source` (`.npy`, `.pc2`, `.mdd`)
    /// takes; its vertex count must match.
    #[serde(default)]
    pub topology: Option<String>,
    /// Animation frame to show; negative counts from the end (-1 = last).
    #[serde(default)]
    pub frame: i64,
    /// Diffuse albedo ρ (linear RGB, each in [0, 1]).
    #[serde(default = "default_albedo")]
    pub albedo: [f32; 3],
    /// Light both sides (cloth); the back side uses the flipped normal.
    #[serde(default)]
    pub two_sided: bool,
    /// Translation (world units).
    #[serde(default)]
    pub translation: [f32; 3],
    /// Rotation as XYZ Euler angles in degrees.
    #[serde(default)]
    pub rotation_deg: [f32; 3],
    /// Uniform scale.
    #[serde(default = "one")]
    pub scale: f32,
}

fn default_albedo() -> [f32; 3] {
    [0.7, 0.7, 0.7]
}
fn one() -> f32 {
    1.0
}

impl ObjectDesc {
    /// `world_from_object` of this object.
    pub fn world_from_object(&self) -> Mat4 {
        let [rx, ry, rz] = self.rotation_deg.map(f32::to_radians);
        Mat4::from_scale_rotation_translation(
            Vec3::splat(self.scale),
            Quat::from_euler(EulerRot::XYZ, rx, ry, rz),
            Vec3::from(self.translation),
        )
    }
}

/// The HDR environment.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentDesc {
    /// `synth:sky` or a path to an equirectangular `.hdr` / `.exr`.
    pub source: String,
    /// Rotation of the environment about +Y relative to the world, in degrees.
    #[serde(default)]
    pub rotation_deg: f32,
    /// Spherical Gaussian prefilter σ in degrees (0 = none).
    #[serde(default)]
    pub prefilter_sigma_deg: f64,
}

/// How I_j is computed for each light direction.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RadianceMethodDesc {
    /// Mean radiance over each direction's Voronoi cell (exact power; the default).
    #[default]
    CellMean,
    /// Look-up of the prefiltered map at l_j, as published (paper 000 §5).
    PrefilteredLookup,
}

/// Lighting parameters.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingDesc {
    /// Lightsphere subdivision level s (k = 2 + 4^(s+1) directions).
    #[serde(default = "default_level")]
    pub level: u32,
    /// How I_j is computed.
    #[serde(default)]
    pub method: RadianceMethodDesc,
}

fn default_level() -> u32 {
    3
}

impl Default for LightingDesc {
    fn default() -> Self {
        Self {
            level: default_level(),
            method: RadianceMethodDesc::default(),
        }
    }
}

/// Which visibility backend computes M.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum VisibilityBackendDesc {
    /// `depth` on a hardware adapter, `cpu` on a software one (lavapipe rasterises on the CPU,
    /// where exact ray casting is both faster and exact).
    #[default]
    Auto,
    /// Exact ray casting on the CPU (the reference).
    Cpu,
    /// GPU depth maps and a compute-pass depth test.
    Depth,
    /// The published per-vertex hardware occlusion queries (paper 000 §3.2; slow: N·k draws).
    Query,
    /// Exact ray casting on the GPU (a compute shader; `cpu`'s answers).
    Rays,
}

/// Visibility parameters.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VisibilityDesc {
    /// Backend.
    #[serde(default)]
    pub backend: VisibilityBackendDesc,
    /// Depth-map side for the `depth` backend.
    #[serde(default = "default_depth_resolution")]
    pub depth_resolution: u32,
    /// Occluders farther than this along a ray are ignored (world units; `cpu` and `rays` only;
    /// unset: unbounded, paper 000's visibility).
    #[serde(default)]
    pub max_distance: Option<f32>,
}

fn default_depth_resolution() -> u32 {
    occlusion_gpu::DEFAULT_DEPTH_RESOLUTION
}

impl Default for VisibilityDesc {
    fn default() -> Self {
        Self {
            backend: VisibilityBackendDesc::default(),
            depth_resolution: default_depth_resolution(),
            max_distance: None,
        }
    }
}

/// Parameters of procedural sources.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SynthDesc {
    /// Cloth grid side (vertices per side; ≥ 2).
    pub cloth_grid: Option<usize>,
    /// Simulated frames.
    pub cloth_frames: Option<usize>,
    /// Seed of the cloth simulation.
    #[serde(default)]
    pub seed: u64,
    /// Sun elevation above the horizon, degrees.
    pub sun_elevation_deg: Option<f32>,
    /// Sun azimuth, degrees.
    pub sun_azimuth_deg: Option<f32>,
    /// Sky map width (height is half).
    pub sky_width: Option<usize>,
}

/// A pinhole camera.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraDesc {
    /// Eye position; omitted = framed automatically from `direction`.
    pub eye: Option<[f32; 3]>,
    /// Look-at point; omitted = the scene's bounding-sphere centre.
    pub target: Option<[f32; 3]>,
    /// Direction from the target towards the eye when the eye is framed automatically.
    #[serde(default = "default_view_direction")]
    pub direction: [f32; 3],
    /// Up vector.
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    #[serde(default = "default_fov")]
    pub fov_deg: f32,
    /// Image width in pixels.
    #[serde(default = "default_side")]
    pub width: u32,
    /// Image height in pixels.
    #[serde(default = "default_side")]
    pub height: u32,
}

fn default_view_direction() -> [f32; 3] {
    render::camera::DEFAULT_VIEW_DIRECTION.to_array()
}
fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    render::camera::DEFAULT_FOV_Y_DEG
}
fn default_side() -> u32 {
    768
}

impl Default for CameraDesc {
    fn default() -> Self {
        Self {
            eye: None,
            target: None,
            direction: default_view_direction(),
            up: default_up(),
            fov_deg: default_fov(),
            width: default_side(),
            height: default_side(),
        }
    }
}

impl Scene {
    /// Parse a scene from TOML text; `base_dir` resolves relative paths and `origin` names the
    /// text in errors.
    ///
    /// # Errors
    /// [`Error::Scene`] with the parser's line and column.
    pub fn from_toml(text: &str, base_dir: &Path, origin: &str) -> Result<Self, Error> {
        let mut scene: Scene = toml::from_str(text).map_err(|e| Error::Scene {
            origin: origin.to_owned(),
            message: e.to_string(),
        })?;
        scene.base_dir = base_dir.to_owned();
        scene.origin = origin.to_owned();
        scene.output.name_default_images();
        Ok(scene)
    }

    /// A scene of one object read from `path` (a mesh, or an animation posed at frame 0),
    /// one-sided, white (ρ = 1), every other table at its default: what `cloth-vis
    /// visibility` runs through the stages. Callers set the tables they need.
    ///
    /// # Errors
    /// [`Error::Request`] when `path` is not valid UTF-8 (scene sources are text).
    pub fn one_object(path: &Path, origin: &str) -> Result<Self, Error> {
        let source = path.to_str().ok_or_else(|| Error::Request {
            path: path.to_owned(),
            message: "the path is not valid UTF-8; rename the file".to_owned(),
        })?;
        let mut scene = Self::from_toml("", Path::new(""), origin)?;
        scene.name = path
            .file_name()
            .map_or_else(|| source.to_owned(), |n| n.to_string_lossy().into_owned());
        scene.objects.push(ObjectDesc {
            name: scene.name.clone(),
            source: source.to_owned(),
            topology: None,
            frame: 0,
            albedo: [1.0; 3],
            two_sided: false,
            translation: [0.0; 3],
            rotation_deg: [0.0; 3],
            scale: 1.0,
        });
        Ok(scene)
    }

    /// Read and parse a scene file.
    ///
    /// # Errors
    /// [`Error::Io`] when the file cannot be read, [`Error::Scene`] when it does not parse.
    pub fn load(path: &Path) -> Result<Self, Error> {
        let text = input_guard::read_regular_to_string(path).map_err(|e| Error::Io {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
        let base = path.parent().map(Path::to_owned).unwrap_or_default();
        Self::from_toml(&text, &base, &path.display().to_string())
    }

    /// An [`Error::Scene`] naming this scene, `key` and `message`.
    pub(crate) fn invalid(&self, key: &str, message: String) -> Error {
        Error::Scene {
            origin: self.origin.clone(),
            message: format!("{key}: {message}"),
        }
    }

    /// The requested effects, parsed and deduplicated, in stage order.
    ///
    /// # Errors
    /// [`Error::Scene`] naming an unknown effect and listing the known ones.
    pub fn requested_effects(&self) -> Result<Vec<Effect>, Error> {
        let mut effects = Vec::new();
        for name in &self.effects {
            let effect = name.parse::<Effect>().map_err(|_| {
                self.invalid(
                    "effects",
                    format!(
                        "unknown effect {name:?}; known effects: {}",
                        crate::effects::known_effect_names()
                    ),
                )
            })?;
            if !effects.contains(&effect) {
                effects.push(effect);
            }
        }
        effects.sort();
        Ok(effects)
    }

    /// The `[output] frames` range, parsed (its end is checked against the animation later).
    ///
    /// # Errors
    /// [`Error::Scene`] naming `output.frames` and the text.
    pub fn frame_range(&self) -> Result<Option<render::sequence::FrameRange>, Error> {
        self.output
            .frames
            .as_deref()
            .map(|text| {
                text.parse()
                    .map_err(|e: String| self.invalid("output.frames", e))
            })
            .transpose()
    }

    /// Check everything that can be checked without doing the work: effect names, value
    /// ranges, and that every named file exists.
    ///
    /// # Errors
    /// The first problem found, naming the scene, the key and the value.
    pub fn validate(&self) -> Result<Vec<Effect>, Error> {
        let effects = self.requested_effects()?;
        if self.objects.is_empty() {
            return Err(self.invalid(
                "object",
                "the scene has no [[object]]; add at least one".to_owned(),
            ));
        }
        for (i, object) in self.objects.iter().enumerate() {
            let key = |field: &str| format!("object[{i}] ({}).{field}", object.name);
            if self.objects[..i].iter().any(|o| o.name == object.name) {
                return Err(self.invalid(
                    &key("name"),
                    format!("duplicate object name {:?}", object.name),
                ));
            }
            if let Some(c) = object.albedo.iter().find(|c| !(0.0..=1.0).contains(*c)) {
                return Err(self.invalid(&key("albedo"), format!("{c} is outside [0, 1]")));
            }
            if !(object.scale.is_finite() && object.scale > 0.0) {
                return Err(self.invalid(
                    &key("scale"),
                    format!("{} must be finite and > 0", object.scale),
                ));
            }
            let finite = object
                .translation
                .iter()
                .chain(&object.rotation_deg)
                .all(|v| v.is_finite());
            if !finite {
                return Err(self.invalid(
                    &key("translation/rotation_deg"),
                    "values must be finite".to_owned(),
                ));
            }
            if let GeometrySource::File(path) = self.geometry_source(i)?
                && !path.exists()
            {
                return Err(
                    self.invalid(&key("source"), format!("{} does not exist", path.display()))
                );
            }
            if let Some(path) = self.topology_path(i)
                && !path.exists()
            {
                return Err(self.invalid(
                    &key("topology"),
                    format!("{} does not exist", path.display()),
                ));
            }
        }
        if effects.contains(&Effect::Btf) {
            self.validate_btf()?;
        }
        if effects.contains(&Effect::StaticShadowing) {
            if effects.contains(&Effect::SelfShadowing) {
                return Err(self.invalid(
                    "effects",
                    "\"self-shadowing\" and \"static-shadowing\" both light the vertices: choose one \
                     (self-shadowing recomputes per frame, static-shadowing reads per-vertex maps)"
                        .to_owned(),
                ));
            }
            self.validate_static_shadowing()?;
        }
        if effects.contains(&Effect::ShadowVolumes) {
            self.validate_shadow_volumes()?;
        }
        if effects.contains(&Effect::Translucency) {
            self.validate_translucency(&effects)?;
        }
        let lit = effects.iter().find(|e| {
            matches!(
                e,
                Effect::Lighting | Effect::SelfShadowing | Effect::StaticShadowing
            )
        });
        if let (Some(effect), None) = (lit, &self.environment) {
            return Err(self.invalid(
                "environment",
                format!("effect \"{effect}\" needs an [environment] (e.g. source = \"synth:sky\")"),
            ));
        }
        let res = self.visibility.depth_resolution;
        if !(16..=16384).contains(&res) {
            return Err(self.invalid(
                "visibility.depth_resolution",
                format!("{res} is outside 16..=16384"),
            ));
        }
        if let Some(d) = self.visibility.max_distance {
            let cpu = !matches!(
                self.visibility.backend,
                VisibilityBackendDesc::Depth | VisibilityBackendDesc::Query
            );
            if !(d.is_finite() && d > 0.0 && cpu) {
                let why = "must be finite and > 0, on the cpu or rays backend (the only ones \
                           bounding rays)";
                return Err(self.invalid("visibility.max_distance", format!("{d} {why}")));
            }
        }
        if let Some(EnvironmentSource::File(path)) = self.environment_source()?
            && !path.exists()
        {
            return Err(self.invalid(
                "environment.source",
                format!("{} does not exist", path.display()),
            ));
        }
        if let Some(w) = self.synth.sky_width
            && !(2..=MAX_SKY_WIDTH).contains(&w)
        {
            return Err(self.invalid(
                "synth.sky_width",
                format!("{w} is outside 2..={MAX_SKY_WIDTH} (cloth_vis::scene::MAX_SKY_WIDTH)"),
            ));
        }
        // The sky the scene's `[synth]` keys set, checked by the generator itself but refused
        // here, before any work, by the scene's key rather than the library's field.
        if let Err(e) = crate::inputs::sky_params(self).validate() {
            let key = |field: &str| match field.rsplit("::").next() {
                Some(f @ ("sun_elevation_deg" | "sun_azimuth_deg")) => format!("synth.{f}"),
                _ => "synth.sky_width".to_owned(),
            };
            // Named by the scene's key only: the library's `Struct::field` means nothing to
            // someone who wrote a TOML file.
            let (key, message) = match &e {
                synth::SynthError::InvalidParameter {
                    field,
                    value,
                    expected,
                } => (
                    key(field),
                    format!("{value} is not valid: expected {expected}"),
                ),
                synth::SynthError::TooLarge {
                    field,
                    requested,
                    maximum,
                    unit,
                } => (
                    key(field),
                    format!("{requested} {unit} exceeds the maximum {maximum}"),
                ),
            };
            return Err(self.invalid(&key, message));
        }
        if let Some(env) = &self.environment {
            let s = env.prefilter_sigma_deg;
            if !(s.is_finite() && (0.0..=90.0).contains(&s)) {
                return Err(self.invalid(
                    "environment.prefilter_sigma_deg",
                    format!("{s} is outside [0, 90]"),
                ));
            }
            if !env.rotation_deg.is_finite() {
                return Err(self.invalid(
                    "environment.rotation_deg",
                    format!("{} is not finite", env.rotation_deg),
                ));
            }
        }
        if self.lighting.level > MAX_LEVEL {
            return Err(self.invalid(
                "lighting.level",
                format!("{} exceeds the maximum {MAX_LEVEL}", self.lighting.level),
            ));
        }
        let cam = &self.camera;
        crate::camera::check_desc(cam).map_err(|(key, message)| self.invalid(key, message))?;
        for (key, side) in [("camera.width", cam.width), ("camera.height", cam.height)] {
            if side == 0 || side > MAX_IMAGE_SIDE {
                return Err(self.invalid(key, format!("{side} is outside 1..={MAX_IMAGE_SIDE}")));
            }
        }
        if !(cam.fov_deg > 0.0 && cam.fov_deg < 179.0) {
            return Err(self.invalid(
                "camera.fov_deg",
                format!("{} is outside (0, 179)", cam.fov_deg),
            ));
        }
        if let ExposureDesc::Fixed(x) = self.output.exposure
            && !(x.is_finite() && x.abs() <= 64.0)
        {
            return Err(self.invalid(
                "output.exposure",
                format!("{x} EV must be finite and within ±64, or \"auto\""),
            ));
        }
        if let BackgroundDesc::Color(c) = self.output.background
            && !c.iter().all(|v| v.is_finite() && *v >= 0.0)
        {
            return Err(self.invalid(
                "output.background",
                format!("{c:?}: a colour needs finite linear values ≥ 0"),
            ));
        }
        self.frame_range()?;
        if let Some(g) = &self.ground {
            if let Some(c) = g.albedo.iter().find(|c| !(0.0..=1.0).contains(*c)) {
                return Err(self.invalid("ground.albedo", format!("{c} is outside [0, 1]")));
            }
            if !(g.size.is_finite() && g.size > 0.0 && g.size <= 1e4) {
                return Err(self.invalid("ground.size", format!("{} is outside (0, 1e4]", g.size)));
            }
            if !(1..=1024).contains(&g.cells) {
                return Err(
                    self.invalid("ground.cells", format!("{} is outside 1..=1024", g.cells))
                );
            }
            if self.objects.iter().any(|o| o.name == GROUND_NAME) {
                return Err(self.invalid(
                    "ground",
                    format!("an [[object]] is already named {GROUND_NAME:?}; rename it"),
                ));
            }
        }
        if !(self.output.gamma.is_finite() && self.output.gamma > 0.0) {
            return Err(self.invalid(
                "output.gamma",
                format!("{} must be finite and > 0", self.output.gamma),
            ));
        }
        for (key, name) in [
            ("output.png", &self.output.png),
            ("output.exr", &self.output.exr),
        ] {
            if let Some(name) = name {
                let plain = Path::new(name)
                    .file_name()
                    .is_some_and(|f| f == name.as_str());
                if !plain {
                    return Err(self.invalid(
                        key,
                        format!("{name:?} must be a plain file name inside the output folder"),
                    ));
                }
            }
        }
        if let Some(grid) = self.synth.cloth_grid
            && !(2..=1024).contains(&grid)
        {
            return Err(self.invalid("synth.cloth_grid", format!("{grid} is outside 2..=1024")));
        }
        if let Some(frames) = self.synth.cloth_frames
            && !(1..=100_000).contains(&frames)
        {
            return Err(self.invalid(
                "synth.cloth_frames",
                format!("{frames} is outside 1..=100000"),
            ));
        }
        Ok(effects)
    }
}
