//! `cloth-vis sh` (the SH9 irradiance of an environment map) and `cloth-vis translucency` (a
//! mesh rendered with seed 004's subsurface term; crate `translucency`, SEED-NOTES §5).

use std::path::{Path, PathBuf};

use super::invalid;
use super::up_axis::{UpAxis, stand_up_degrees, up_axis_rotation};
use cloth_vis::scene::{
    AutoKeyword, BackgroundDesc, BackgroundKeyword, EnvironmentDesc, ExposureDesc, SineDeformDesc,
    TranslucencyDesc, TranslucencyLightDesc,
};
use cloth_vis::{RunOptions, Scene};
use glam::{DVec3, Vec3};
use render::sequence::FrameRange;
use translucency::{Sh9, Window};

/// `cloth-vis sh`: the flags.
#[derive(clap::Args)]
pub struct ShArgs {
    /// An equirectangular environment (.hdr or .exr; +Y up).
    input: PathBuf,
    /// A Gaussian window of width W on the SH bands (W ≤ 5 keeps B ≥ 0 for any map).
    #[arg(long, value_name = "W", allow_negative_numbers = true)]
    window: Option<f64>,
    /// Sloan's Lanczos σ factors of width W instead (W = 3 is the classic for l ≤ 2).
    #[arg(
        long,
        value_name = "W",
        conflicts_with = "window",
        allow_negative_numbers = true
    )]
    lanczos: Option<f64>,
    /// Rotate the map about +Y by DEG before projecting.
    #[arg(
        long,
        value_name = "DEG",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    rotation: f64,
    /// E_lm as f32 [9, 3] (.npy): row k = l(l+1)+m in R&H's order (Y00, Y1−1 ∝ y, Y10 ∝ z,
    /// Y11 ∝ x, Y2−2 ∝ xy, Y2−1 ∝ yz, Y20 ∝ 3z²−1, Y21 ∝ xz, Y22 ∝ x²−y²), columns R, G, B;
    /// windowed when a window is given.
    #[arg(long, short = 'o')]
    out: PathBuf,
}

impl ShArgs {
    /// Run the command.
    ///
    /// # Errors
    /// Bad flags, an unreadable map, an output that cannot be written — naming the file.
    pub fn run(self) -> anyhow::Result<()> {
        super::check_output_file(&self.out, &[&self.input])?;
        if super::visibility::lower_extension(&self.out).as_deref() != Some("npy") {
            return Err(
                invalid(&self.out, "--out must end in .npy (f32 [9, 3])".to_owned()).into(),
            );
        }
        let window = match (self.window, self.lanczos) {
            (Some(w), _) => Window::Gaussian { width: w },
            (None, Some(w)) => Window::Lanczos { width: w },
            (None, None) => Window::None,
        };
        let flag = if self.lanczos.is_some() {
            "--lanczos"
        } else {
            "--window"
        };
        let window = window
            .validate()
            .map_err(|e| invalid(&self.input, format!("{flag}: {e}")))?;
        if !self.rotation.is_finite() {
            return Err(invalid(
                &self.input,
                format!("--rotation {} must be finite", self.rotation),
            )
            .into());
        }
        let start = std::time::Instant::now();
        let env = lightsphere::Environment::load(&self.input)?;
        let q = glam::Quat::from_rotation_y(self.rotation.to_radians() as f32);
        let env = env.with_rotation(q);
        let raw = Sh9::project_latlong(&env);
        let sh = raw.windowed(window);
        let millis = start.elapsed().as_secs_f64() * 1e3;
        let flat: Vec<f32> = sh.to_f32().iter().flatten().copied().collect();
        meshio::write_npy_f32(&self.out, &[9, 3], &flat)?;
        let mut text = format!(
            "sh: {} × {} map projected exactly in {millis:.1} ms ({window}); E00 = {:.5}, {:.5}, {:.5}\n\
             irradiance B(r) = r̃ᵀ M r̃ (eq. 10; unclamped, a negative value is ringing):\n",
            env.width(),
            env.height(),
            sh.coeffs[0][0],
            sh.coeffs[0][1],
            sh.coeffs[0][2],
        );
        for (name, r) in [
            ("+x", DVec3::X),
            ("-x", DVec3::NEG_X),
            ("+y", DVec3::Y),
            ("-y", DVec3::NEG_Y),
            ("+z", DVec3::Z),
            ("-z", DVec3::NEG_Z),
        ] {
            let b = sh.irradiance(r);
            text.push_str(&format!("  {name}: {:.5} {:.5} {:.5}\n", b[0], b[1], b[2]));
        }
        super::print_summary(text.trim_end(), [self.out.as_path()])
    }
}

/// `cloth-vis translucency`: the flags.
#[derive(clap::Args)]
pub struct TranslucencyArgs {
    /// A mesh (.ply .obj .gltf .glb) or an animation (with --frames).
    input: PathBuf,
    /// A point light at X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, allow_hyphen_values = true,
          required_unless_present_any = ["light_dir", "env"], conflicts_with_all = ["light_dir", "env"])]
    light_pos: Option<Vec3>,
    /// A directional light: the direction X,Y,Z towards it.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, allow_hyphen_values = true,
          conflicts_with = "env")]
    light_dir: Option<Vec3>,
    /// Light power: intensity (W/sr) of --light-pos, irradiance of --light-dir (default: an
    /// irradiance of 1 at the object's centre).
    #[arg(long, value_name = "R,G,B", value_parser = super::parse::vec3, allow_hyphen_values = true)]
    power: Option<Vec3>,
    /// An environment map (.hdr/.exr): it lights the mesh per vertex (lightsphere level 3) and
    /// the thickness is measured along its dominant direction.
    #[arg(long, value_name = "FILE")]
    env: Option<PathBuf>,
    /// With --env: per-vertex self-shadowing (occlusion-gpu) instead of unshadowed lighting.
    #[arg(long, requires = "env")]
    self_shadowing: bool,
    /// The input's up axis (z for Blender/CAD exports): the object is stood up — turned so
    /// that this axis is +Y, the environment's zenith and the camera's up — before it is lit;
    /// --light-pos and --light-dir stay in the input's frame.
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    up_axis: UpAxis,
    /// A measured material (Jensen et al. 2001): apple, chicken1, chicken2, cream, ketchup,
    /// marble, potato, skimmilk, skin1, skin2, spectralon, wholemilk.
    #[arg(long, default_value = "marble", conflicts_with = "sigma_a")]
    material: String,
    /// Absorption σ_a per mm (R,G,B), with --sigma-s, instead of a preset.
    #[arg(long, value_name = "R,G,B", value_parser = super::parse::vec3, requires = "sigma_s", allow_hyphen_values = true)]
    sigma_a: Option<Vec3>,
    /// Reduced scattering σ′_s per mm (R,G,B), with --sigma-a.
    #[arg(long, value_name = "R,G,B", value_parser = super::parse::vec3, requires = "sigma_a", allow_hyphen_values = true)]
    sigma_s: Option<Vec3>,
    /// Relative index of refraction (default: the preset's, 1.3 with --sigma-a).
    #[arg(long, allow_negative_numbers = true)]
    eta: Option<f64>,
    /// Millimetres per scene unit.
    #[arg(long, default_value_t = translucency::material::DEFAULT_MM_PER_UNIT, allow_negative_numbers = true)]
    mm_per_unit: f64,
    /// Gaussian SH window width (W ≤ 5 keeps B ≥ 0).
    #[arg(long, value_name = "W", allow_negative_numbers = true)]
    window: Option<f64>,
    /// Cube-map face size.
    #[arg(long, default_value_t = 64)]
    cube_size: u32,
    /// Light distance map face size.
    #[arg(long, default_value_t = 512)]
    light_map_size: u32,
    /// Turn the peeled-layer test off (concave objects then glow through their gaps).
    #[arg(long)]
    no_peel: bool,
    /// The sine deformer of Fig. 12: AMPLITUDE,WAVES,FRAMES (a loop of FRAMES frames).
    #[arg(long, value_name = "A,K,N", value_parser = super::parse::vec3, allow_hyphen_values = true)]
    deform: Option<Vec3>,
    /// Render frames A..B to DIR/frame-NNNN.png (an animation, or --deform).
    #[arg(long, value_name = "A..B")]
    frames: Option<FrameRange>,
    /// An image (.png tone-mapped, .exr linear), or a folder with --frames.
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an output folder that already holds files, once the new one is complete.
    #[arg(long)]
    force: bool,
    /// Image size.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = "512x512")]
    render_size: [u32; 2],
    /// PNG exposure in stops (default: automatic).
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// Hide the progress bars.
    #[arg(long)]
    quiet: bool,
}

impl TranslucencyArgs {
    /// Run the command.
    ///
    /// # Errors
    /// Bad flags before any work; loader, GPU and output errors naming the file.
    pub fn run(self) -> anyhow::Result<()> {
        super::check_output_file(&self.out, &[&self.input])?;
        let ext = super::visibility::lower_extension(&self.out);
        let still = matches!(ext.as_deref(), Some("png" | "exr"));
        if self.frames.is_some() == still {
            return Err(invalid(
                &self.out,
                "--out is an image (.png, .exr) for one frame, or a folder with --frames A..B"
                    .to_owned(),
            )
            .into());
        }
        let scene = self.scene()?;
        let options = RunOptions {
            progress: !self.quiet,
            frames: self.frames,
            replace_output: self.force,
            ..RunOptions::default()
        };
        let report = if still {
            self.run_still(&scene, &options, ext.as_deref() == Some("exr"))?
        } else {
            cloth_vis::run_scene(&scene, &self.out, &options)?.report
        };
        let mut text = String::new();
        for s in &report.stages {
            if s.stage == "translucency" {
                let p = &s.params;
                let ms = |k: &str| p["pass_ms"][k].as_f64().unwrap_or(f64::NAN);
                let per_frame = p["mean_ms_per_frame"].as_f64().map_or(String::new(), |m| {
                    format!(", {m:.1} ms per frame over {} frames", p["frames"])
                });
                text.push_str(&format!(
                    "translucency: {} vertices, {} triangles; passes (last frame): cube map \
                     {:.1} ms, SH projection {:.1} ms, light map + peel {:.1} ms, blur {:.1} ms{per_frame}\n",
                    p["vertices"],
                    p["triangles"],
                    ms("cube_map"),
                    ms("sh_projection"),
                    ms("light_map"),
                    ms("blur"),
                ));
            } else {
                text.push_str(&format!("{}: {:.1} ms\n", s.stage, s.millis));
            }
        }
        super::print_summary(text.trim_end(), [self.out.as_path()])
    }

    /// The one-object scene the flags describe.
    fn scene(&self) -> Result<Scene, cloth_vis::Error> {
        let mut scene = Scene::one_object(&self.input, "cloth-vis translucency")?;
        scene.camera.width = self.render_size[0];
        scene.camera.height = self.render_size[1];
        scene.output.exposure = match self.exposure {
            Some(ev) => ExposureDesc::Fixed(ev),
            None => ExposureDesc::Auto(AutoKeyword::Auto),
        };
        // Standing the object up turns the input's frame into the world's: its lights too.
        let stand = up_axis_rotation(self.up_axis).inverse();
        scene.objects[0].rotation_deg = stand_up_degrees(self.up_axis);
        let mut effects = vec!["translucency".to_owned()];
        let light = match (self.light_pos, self.light_dir, &self.env) {
            (Some(p), _, _) => TranslucencyLightDesc {
                position: Some((stand * p.as_dvec3()).to_array()),
                intensity: self.power.map(|v| v.to_array()),
                ..Default::default()
            },
            (None, Some(d), _) => TranslucencyLightDesc {
                direction: Some((stand * d.as_dvec3()).to_array()),
                irradiance: Some(self.power.map_or([1.0; 3], |v| v.to_array())),
                ..Default::default()
            },
            (None, None, Some(env)) => {
                let source = env.to_str().ok_or_else(|| {
                    invalid(
                        env,
                        "the path is not valid UTF-8; rename the file".to_owned(),
                    )
                })?;
                scene.environment = Some(EnvironmentDesc {
                    source: source.to_owned(),
                    rotation_deg: 0.0,
                    prefilter_sigma_deg: 0.0,
                });
                effects.insert(
                    0,
                    if self.self_shadowing {
                        "self-shadowing"
                    } else {
                        "lighting"
                    }
                    .to_owned(),
                );
                TranslucencyLightDesc {
                    environment: true,
                    ..Default::default()
                }
            }
            _ => {
                return Err(invalid(
                    &self.input,
                    "give --light-pos, --light-dir or --env".to_owned(),
                ));
            }
        };
        scene.output.background = if self.env.is_some() {
            BackgroundDesc::Named(BackgroundKeyword::Environment)
        } else {
            BackgroundDesc::Color([0.0; 3])
        };
        scene.effects = effects;
        scene.translucency = TranslucencyDesc {
            material: self.sigma_a.is_none().then(|| self.material.clone()),
            sigma_a: self.sigma_a.map(|v| v.as_dvec3().to_array()),
            sigma_s: self.sigma_s.map(|v| v.as_dvec3().to_array()),
            eta: self.eta,
            mm_per_unit: self.mm_per_unit,
            light,
            cube_size: self.cube_size,
            light_map_size: self.light_map_size,
            window: self.window.unwrap_or(0.0),
            peel: !self.no_peel,
            deform: self.deform.map(|d| SineDeformDesc {
                amplitude: f64::from(d.x),
                waves: f64::from(d.y),
                frames: d.z.max(0.0) as usize,
            }),
            ..TranslucencyDesc::default()
        };
        Ok(scene)
    }

    /// One frame into the image `self.out`: the scene runs into a hidden folder beside it and
    /// the image is renamed into place (nothing is left on error).
    fn run_still(
        &self,
        scene: &Scene,
        options: &RunOptions,
        exr: bool,
    ) -> Result<cloth_vis::RunReport, cloth_vis::Error> {
        let mut scene = scene.clone();
        let name = if exr { "image.exr" } else { "image.png" };
        scene.output.png = (!exr).then(|| name.to_owned());
        scene.output.exr = exr.then(|| name.to_owned());
        let parent = self
            .out
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let file = self
            .out
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let tmp = parent.join(format!(".{file}.{}.run", std::process::id()));
        let result = cloth_vis::run_scene(
            &scene,
            &tmp,
            &RunOptions {
                replace_output: true,
                ..options.clone()
            },
        )
        .and_then(|out| {
            std::fs::rename(tmp.join(name), &self.out).map_err(|e| cloth_vis::Error::Io {
                path: self.out.clone(),
                reason: e.to_string(),
            })?;
            Ok(out.report)
        });
        let _ = std::fs::remove_dir_all(&tmp);
        result
    }
}
