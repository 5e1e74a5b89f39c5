//! `cloth-vis view SCENE.toml | MESH | ANIMATION | demo`: the scene in a window — orbit, effect
//! toggles, level, environment turn, exposure, animation playback with per-frame
//! self-shadowing and the adaptive level — or, with `--frames N`, a scripted run that presents
//! N frames, writes the last one and exits (tests, pipelines).

use std::path::{Path, PathBuf};

use cloth_vis::Scene;
use cloth_vis::live::ViewEvent;

use super::invalid;
use super::up_axis::{UpAxis, stand_up_degrees};

/// Open a scene, mesh or animation in an interactive window.
#[derive(clap::Args)]
pub struct ViewArgs {
    /// A scene (.toml), a mesh (OBJ, PLY, glTF), an animation (glTF clip, OBJ folder, .npy),
    /// or `demo` for the embedded demo scene.
    input: PathBuf,
    /// Window size in pixels (default: the scene's camera, at most 1280×960).
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    size: Option<(u32, u32)>,
    /// Scripted: present this many frames, write `--screenshot` and exit.
    #[arg(long, value_name = "N")]
    frames: Option<u64>,
    /// Write the last presented frame here (.png or .exr; the `render` path: the scene's
    /// display mapping over the frame without the overlay). Needs `--frames`.
    #[arg(long, value_name = "FILE", requires = "frames")]
    screenshot: Option<PathBuf>,
    /// Replay these input events, one per presented frame (see `cloth_vis::live`'s script).
    #[arg(long, value_name = "FILE")]
    events: Option<PathBuf>,
    /// Write every presented frame into DIR as frame-NNNN.png (DIR new or empty).
    #[arg(long, value_name = "DIR")]
    record: Option<PathBuf>,
    /// Adapt the lightsphere level to this visibility time per animated frame (ms); idle
    /// time refines back to the scene's level.
    #[arg(long, value_name = "MS")]
    adaptive: Option<f64>,
    /// An HDR map to choose in the overlay (repeatable; the `environment N` event): a mesh
    /// or animation is lit by the first instead of the procedural sky.
    #[arg(long, value_name = "FILE")]
    env: Vec<PathBuf>,
    /// Size of `--screenshot` (and the `P` key's) pictures, when not the window's.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    screenshot_size: Option<(u32, u32)>,
    /// Hide the overlay (controls and timings) at start; `H` shows it.
    #[arg(long)]
    no_overlay: bool,
    /// Play the animation as a jump map (thesis §3.2): endless, jumping between similar
    /// frames; `C` (or the event `next-cell`) steers to the next cell.
    #[arg(long)]
    jumpmap: bool,
    /// Another clip of the same mesh as a further jump-map cell (repeatable; with --jumpmap).
    #[arg(long, value_name = "CLIP", requires = "jumpmap")]
    cell: Vec<PathBuf>,
    /// Seed of the jump map's random play.
    #[arg(long, default_value_t = 1, requires = "jumpmap")]
    seed: u64,
    /// A mesh's or animation's up axis: the object is stood up onto +Y, the world's up (a
    /// scene file stands its objects up with `rotation_deg`).
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    up_axis: UpAxis,
}

/// Where the poses come from besides the scene's own clip.
pub enum MotionSource {
    /// A jump map over these clips (frames per clip), seeded.
    JumpMap(Vec<Vec<Vec<glam::Vec3>>>, u64),
    /// A compressed animation for the GPU decoder.
    Cpca(Box<anim_pca::Compressed>),
}

/// The largest default window (a scene camera's size is kept below it, aspect preserved).
const MAX_DEFAULT: (u32, u32) = (1280, 960);

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?} is not WxH (e.g. 800x600)"))?;
    let parse = |v: &str| {
        v.parse::<u32>()
            .ok()
            .filter(|&n| (1..=8192).contains(&n))
            .ok_or_else(|| format!("{v:?} in {s:?} is not a size 1..=8192"))
    };
    Ok((parse(w)?, parse(h)?))
}

/// What the window runs: the scene and the scripted requests, all checked.
pub struct ViewRequest {
    /// The scene.
    pub scene: Scene,
    /// Window size.
    pub size: (u32, u32),
    /// Scripted frame count.
    pub frames: Option<u64>,
    /// Where the last frame goes.
    pub screenshot: Option<PathBuf>,
    /// Events replayed, one per frame.
    pub events: Vec<ViewEvent>,
    /// Recording folder (created).
    pub record: Option<PathBuf>,
    /// Adaptive target (ms).
    pub adaptive_ms: Option<f64>,
    /// Overlay shown at start.
    pub overlay: bool,
    /// Poses from a jump map or a `.cpca`.
    pub motion: Option<MotionSource>,
    /// Further environment maps to choose from.
    pub environments: Vec<PathBuf>,
    /// Screenshot size when not the window's.
    pub screenshot_size: Option<(u32, u32)>,
}

impl ViewArgs {
    /// Check everything, then open the window.
    pub fn run(self) -> anyhow::Result<()> {
        let request = self.request()?;
        super::view_window::run(request)
    }

    fn request(self) -> Result<ViewRequest, cloth_vis::Error> {
        // A window needs a display: say so before loading anything.
        let has = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
        if !has("DISPLAY") && !has("WAYLAND_DISPLAY") {
            return Err(invalid(
                &self.input,
                "view opens a window, and there is no display (DISPLAY and WAYLAND_DISPLAY are \
                 unset); run it on a desktop, or under a virtual one: xvfb-run -a -s \
                 \"-screen 0 1920x1080x24\" cloth-vis view …"
                    .to_owned(),
            ));
        }
        if self.frames == Some(0) {
            return Err(invalid(
                &self.input,
                "--frames 0 presents nothing".to_owned(),
            ));
        }
        if self.is_scene() && self.up_axis != UpAxis::PosY {
            return Err(invalid(
                &self.input,
                "--up-axis stands a mesh or an animation up; a scene stands its objects up \
                 itself ([[object]] rotation_deg, e.g. [-90, 0, 0] for a Z-up asset)"
                    .to_owned(),
            ));
        }
        if let Some(ms) = self.adaptive
            && !(ms.is_finite() && ms > 0.0)
        {
            return Err(invalid(
                &self.input,
                format!("--adaptive {ms}: a target time must be > 0 ms"),
            ));
        }
        if let Some(path) = &self.screenshot {
            check_image_path(path)?;
            super::check_output_file(path, &[&self.input])?;
        }
        let events = match &self.events {
            Some(path) => cloth_vis::live::read_events(path)?,
            None => Vec::new(),
        };
        if let (Some(n), Some(path)) = (self.frames, &self.events)
            && (n as usize) <= events.len()
        {
            return Err(invalid(
                path,
                format!(
                    "{} events are replayed one per frame before the last: --frames {n} is too \
                     few (at least {})",
                    events.len(),
                    events.len() + 1
                ),
            ));
        }
        if let Some(dir) = &self.record {
            let holds_files = std::fs::read_dir(dir).is_ok_and(|mut e| e.next().is_some());
            if holds_files || (dir.exists() && !dir.is_dir()) {
                return Err(invalid(
                    dir,
                    "--record writes frame-NNNN.png into a new or empty folder; this is not one"
                        .to_owned(),
                ));
            }
        }
        let scene = self.scene()?;
        let motion = self.motion(&scene)?;
        let environments = self.extra_environments();
        let size = self.size.unwrap_or_else(|| {
            let (w, h) = (scene.camera.width.max(1), scene.camera.height.max(1));
            let s = (MAX_DEFAULT.0 as f64 / w as f64)
                .min(MAX_DEFAULT.1 as f64 / h as f64)
                .min(1.0);
            (
                ((w as f64 * s).round() as u32).max(1),
                ((h as f64 * s).round() as u32).max(1),
            )
        });
        Ok(ViewRequest {
            scene,
            size,
            frames: self.frames,
            screenshot: self.screenshot,
            events,
            record: self.record,
            adaptive_ms: self.adaptive,
            overlay: !self.no_overlay,
            motion,
            environments,
            screenshot_size: self.screenshot_size,
        })
    }

    /// The jump map's clips, or the `.cpca` for the GPU decoder: the input, or a scene's
    /// first object loaded from a file.
    fn motion(&self, scene: &Scene) -> Result<Option<MotionSource>, cloth_vis::Error> {
        let clip = match scene.geometry_source(0) {
            Ok(cloth_vis::scene::GeometrySource::File(path)) => path,
            _ if self.jumpmap => {
                return Err(invalid(
                    &self.input,
                    "--jumpmap plays the scene's first object, and it is not a clip file"
                        .to_owned(),
                ));
            }
            _ => return Ok(None),
        };
        let is_cpca = clip
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("cpca"));
        if is_cpca {
            if self.jumpmap {
                return Err(invalid(
                    &clip,
                    "--jumpmap analyses a clip of meshes; a .cpca streams as it is".to_owned(),
                ));
            }
            let (data, _) = super::cpca::read_cpca(&clip)?;
            return Ok(Some(MotionSource::Cpca(Box::new(data))));
        }
        if !self.jumpmap {
            return Ok(None);
        }
        let options = meshio::AnimationOptions::default();
        let mut cells = Vec::new();
        for path in std::iter::once(&clip).chain(&self.cell) {
            let (clip, _) = meshio::load_animation(path, &options)?;
            if clip.frames.len() < 2 {
                return Err(invalid(
                    path,
                    format!(
                        "--jumpmap needs an animation (a glTF clip, an OBJ folder, a .npy); \
                         this has {} frame(s)",
                        clip.frames.len()
                    ),
                ));
            }
            if let Some(first) = cells.first().and_then(|c: &Vec<Vec<glam::Vec3>>| c.first())
                && clip.frames.first().map(Vec::len) != Some(first.len())
            {
                return Err(invalid(
                    path,
                    format!(
                        "a jump-map cell must have the input's {} vertices; this clip has {}",
                        first.len(),
                        clip.frames.first().map_or(0, Vec::len)
                    ),
                ));
            }
            cells.push(clip.frames);
        }
        Ok(Some(MotionSource::JumpMap(cells, self.seed)))
    }

    /// The scene to view: a scene file, the demo, or a mesh/animation lit by the sky (or
    /// `--env`) with self-shadowing.
    fn scene(&self) -> Result<Scene, cloth_vis::Error> {
        let input = &self.input;
        if input.as_os_str() == "demo" && !input.exists() {
            return cloth_vis::demo_scene();
        }
        if self.is_scene() {
            return Scene::load(input);
        }
        mesh_scene(input, self.env.first().map(PathBuf::as_path), self.up_axis)
    }

    fn is_scene(&self) -> bool {
        self.input.as_os_str() == "demo" && !self.input.exists()
            || self
                .input
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
    }

    /// The `--env` maps offered besides the scene's own (a mesh's first lights it already).
    fn extra_environments(&self) -> Vec<PathBuf> {
        let skip = usize::from(!self.is_scene());
        self.env.iter().skip(skip).cloned().collect()
    }
}

/// A mesh or animation as a scene: one two-sided light-grey object, stood up from `up`, lit by
/// the procedural sky (or `env`) over lightsphere level 3 with self-shadowing, over the
/// environment.
fn mesh_scene(path: &Path, env: Option<&Path>, up: UpAxis) -> Result<Scene, cloth_vis::Error> {
    let text_of = |p: &Path| -> Result<String, cloth_vis::Error> {
        let s = p
            .to_str()
            .ok_or_else(|| invalid(p, "the path is not valid UTF-8; rename the file".to_owned()))?;
        Ok(toml::Value::String(s.to_owned()).to_string())
    };
    let name = path
        .file_name()
        .map_or_else(|| "object".to_owned(), |n| n.to_string_lossy().into_owned());
    let env_source = match env {
        Some(p) => text_of(&std::path::absolute(p).unwrap_or_else(|_| p.to_owned()))?,
        None => "\"synth:sky\"".to_owned(),
    };
    let source = text_of(&std::path::absolute(path).unwrap_or_else(|_| path.to_owned()))?;
    let text = format!(
        "name = {name}\neffects = [\"lighting\", \"self-shadowing\"]\n\n[[object]]\nname = \
         {name}\nsource = {source}\nalbedo = [0.8, 0.8, 0.8]\ntwo_sided = true\n\n\
         [environment]\nsource = {env_source}\n\n[lighting]\nlevel = 3\n\n[output]\n\
         background = \"environment\"\n",
        name = toml::Value::String(name.clone()),
    );
    let mut scene = Scene::from_toml(&text, Path::new(""), &path.display().to_string())?;
    scene.objects[0].rotation_deg = stand_up_degrees(up);
    Ok(scene)
}

fn check_image_path(path: &Path) -> Result<(), cloth_vis::Error> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("png" | "exr") => Ok(()),
        _ => Err(invalid(
            path,
            "--screenshot writes .png or .exr; name the file with one of them".to_owned(),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_are_named() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert!(parse_size("800").unwrap_err().contains("not WxH"));
        assert!(parse_size("0x600").unwrap_err().contains("\"0\""));
        assert!(parse_size("9000x10").unwrap_err().contains("1..=8192"));
    }

    #[test]
    fn a_mesh_scene_is_lit_and_self_shadowed() {
        let scene = mesh_scene(Path::new("some dir/bunny \"x\".obj"), None, UpAxis::PosY).unwrap();
        assert_eq!(scene.effects, ["lighting", "self-shadowing"]);
        assert_eq!(scene.objects.len(), 1);
        assert!(
            scene.objects[0]
                .source
                .ends_with("some dir/bunny \"x\".obj")
        );
        assert!(scene.objects[0].two_sided);
        assert_eq!(scene.objects[0].rotation_deg, [0.0; 3]);
    }

    #[test]
    fn an_up_axis_stands_the_object_up_onto_y() {
        for (up, axis) in [
            (UpAxis::PosZ, glam::Vec3::Z),
            (UpAxis::NegZ, glam::Vec3::NEG_Z),
            (UpAxis::PosX, glam::Vec3::X),
            (UpAxis::NegX, glam::Vec3::NEG_X),
            (UpAxis::NegY, glam::Vec3::NEG_Y),
        ] {
            let scene = mesh_scene(Path::new("dress.obj"), None, up).unwrap();
            let world = scene.objects[0].world_from_object();
            let stood = world.transform_vector3(axis);
            assert!(stood.abs_diff_eq(glam::Vec3::Y, 1e-6), "{up:?}: {stood}");
            // A proper rotation: lengths and handedness kept.
            assert!((world.determinant() - 1.0).abs() < 1e-6, "{up:?}");
        }
    }
}
