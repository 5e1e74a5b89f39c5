//! `cloth-vis shadows`: the shadow a mesh casts on a ground plane, as a mask for measurement
//! (crate `shadows`; thesis §2.4.1, §4.2, §5.5.1).
//!
//! The mesh (optionally a simplified caster, `--lod`) casts onto the plane y = Y under a point
//! or directional light. The output is an f32 `[N, N]` `.npy` over the extent (default: the
//! mesh's x/z bounding box scaled ×3 about its centre, grown to hold the whole shadow —
//! [`shadows::GroundGrid::around_shadow`]): row j ↔ z_j = Z0 + (j + ½)(Z1 − Z0)/N
//! ascending, column i ↔ x_i likewise; 1 = the ground point's segment to the light is blocked,
//! 0 = lit. Computed through the z-fail stencil pipeline seen by an orthographic camera from
//! above, or by exact rays through a BVH with `--cpu`. `--render` draws the mesh over the
//! ground lit by the light through the shared frame's shadow volumes, with eq. 5.6's smooth
//! boundary (`--alpha`).
//!
//! `--up-axis` stands an asset authored with another axis up onto +Y first (an exact quarter
//! or half turn, [`stand_up_matrix`]), its lights with it: the ground is then the plane at
//! height Y along the input's up axis, and x/z above are the stood-up frame's (for `z`: the
//! file's x and −y).

use std::path::PathBuf;
use std::time::Instant;

use super::invalid;
use super::up_axis::{UpAxis, stand_up_matrix};
use super::visibility::{DEFAULT_GAMMA, DEFAULT_RENDER_SIZE, check_render, display_scene};
use cloth_vis::Error;
use cloth_vis::object::WorldObject;
use cloth_vis::scene::{GROUND_NAME, ShadowLightDesc};
use cloth_vis::shadow_volumes::ShadowVolumeStage;
use glam::{DVec3, Vec3};
use gpu_context::GpuContext;
use render::tone::{Display, ToneCurve};
use render::{Background, Camera, DepthConvention, DrawMesh, FrameFormat, Renderer};
use shadows::volume::{CasterTopology, Sides};
use shadows::{GroundGrid, Light, LodTarget};

/// `cloth-vis shadows`: the flags.
#[derive(clap::Args)]
pub struct ShadowsArgs {
    /// A mesh (.ply .obj .gltf .glb), an animation (its --frame is used) or synth:cloth.
    input: PathBuf,
    /// Triangles for a point-cache input (.npy, .pc2, .mdd).
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// Frame of an animation.
    #[arg(long, default_value_t = 0)]
    frame: usize,
    /// A point light at X,Y,Z.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, allow_hyphen_values = true,
          conflicts_with = "light_dir", required_unless_present = "light_dir")]
    light_pos: Option<Vec3>,
    /// A directional light: the direction X,Y,Z towards it.
    #[arg(long, value_name = "X,Y,Z", value_parser = super::parse::vec3, allow_hyphen_values = true)]
    light_dir: Option<Vec3>,
    /// Height Y of the ground plane y = Y (with --up-axis: the height along that axis).
    #[arg(long, value_name = "Y", allow_negative_numbers = true)]
    ground: f64,
    /// The input's up axis: the mesh and the lights (given in the input's frame) are stood up
    /// onto +Y by an exact quarter or half turn before casting, so the ground lies under an
    /// asset authored Z-up (Blender, CAD, the Berkeley garments).
    #[arg(long, value_enum, default_value = "y", allow_hyphen_values = true)]
    up_axis: UpAxis,
    /// The sampled extent X0,Z0,X1,Z1 (default: the mesh's x/z box scaled ×3 about its centre,
    /// grown to hold the whole shadow up to 16 × the mesh's size from its centre; with
    /// --up-axis, the stood-up frame's x/z: for z, the input's x and −y).
    #[arg(long, value_name = "X0,Z0,X1,Z1", value_parser = parse_extent, allow_hyphen_values = true)]
    ground_extent: Option<[f64; 4]>,
    /// Cells per side of the mask.
    #[arg(long, value_name = "N", default_value_t = 512)]
    grid: usize,
    /// A simplified caster: soft (1 % of the triangles), hard (10 %), a ratio in (0, 1], or a
    /// Hausdorff budget in % of the diagonal ("0.5%").
    #[arg(long, value_name = "LEVEL")]
    lod: Option<String>,
    /// Which faces cast: one (closed solids), two (cloth), auto (two when the mesh has border
    /// edges).
    #[arg(long, default_value = "auto", value_parser = ["auto", "one", "two"])]
    sides: String,
    /// Eq. 5.6's offset α in degrees (the smooth boundary of --render).
    #[arg(long, value_name = "DEG", default_value_t = shadows::DEFAULT_ALPHA_DEG)]
    alpha: f64,
    /// Exact rays through a BVH instead of the stencil pipeline.
    #[arg(long)]
    cpu: bool,
    /// The mask, f32 [N, N] (.npy).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Also draw the mesh over the ground, lit and shadowed (.png tone-mapped, .exr linear).
    #[arg(long, value_name = "FILE")]
    render: Option<PathBuf>,
    /// PNG exposure in stops (default: automatic).
    #[arg(long, value_name = "EV", allow_negative_numbers = true)]
    exposure: Option<f32>,
    /// Rendered image size.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = DEFAULT_RENDER_SIZE)]
    render_size: [u32; 2],
    /// Hide the progress spinner (loading, a --lod search, casting, drawing).
    #[arg(long)]
    quiet: bool,
}

/// Why no mesh can shadow the ground y = `ground` (in the stood-up frame), when that is so: the
/// mesh lies wholly at or below it, or the light does. Said beside an all-lit mask, which is
/// otherwise a silent surprise.
fn nothing_casts(positions: &[Vec3], light: &Light, ground: f64) -> Option<String> {
    let top = positions
        .iter()
        .map(|p| f64::from(p.y))
        .fold(f64::NEG_INFINITY, f64::max);
    if top <= ground {
        return Some(format!(
            "the mesh lies at or below the ground (its top at height {top:.4} ≤ {ground})"
        ));
    }
    match *light {
        Light::Point(p) if p.y <= ground => Some(format!(
            "the light at height {:.4} is at or below the ground at {ground}",
            p.y
        )),
        Light::Directional(d) if d.y <= 0.0 => Some(format!(
            "the light direction ({:.3}, {:.3}, {:.3}) points at or below the horizon",
            d.x, d.y, d.z
        )),
        _ => None,
    }
}

/// Parse `X0,Z0,X1,Z1`.
fn parse_extent(text: &str) -> Result<[f64; 4], String> {
    let values: Vec<f64> = text
        .split(',')
        .map(|s| {
            s.trim()
                .parse::<f64>()
                .map_err(|e| format!("{s:?} in {text:?}: {e}"))
        })
        .collect::<Result<_, _>>()?;
    <[f64; 4]>::try_from(values).map_err(|_| format!("{text:?} is not X0,Z0,X1,Z1"))
}

impl ShadowsArgs {
    /// Run the command.
    ///
    /// # Errors
    /// Bad flags before any work; loader, GPU and output errors naming the file.
    pub fn run(self) -> anyhow::Result<()> {
        let light = match (self.light_pos, self.light_dir) {
            (Some(p), _) => Light::Point(p.as_dvec3()),
            (None, Some(d)) => Light::Directional(d.as_dvec3()),
            (None, None) => anyhow::bail!("give --light-pos X,Y,Z or --light-dir X,Y,Z"),
        };
        let flag = if self.light_pos.is_some() {
            "--light-pos"
        } else {
            "--light-dir"
        };
        let light = light
            .validated()
            .map_err(|e| invalid(&self.input, format!("{flag}: {e}")))?;
        for output in std::iter::once(&self.out).chain(&self.render) {
            super::check_output_file(output, &[&self.input])?;
        }
        if super::visibility::lower_extension(&self.out).as_deref() != Some("npy") {
            return Err(
                invalid(&self.out, "--out must end in .npy (f32 [N, N])".to_owned()).into(),
            );
        }
        let lod = self
            .lod
            .as_deref()
            .map(LodTarget::parse)
            .transpose()
            .map_err(|e| invalid(&self.input, format!("--lod: {e}")))?;
        shadows::boundary::BoundaryTexture::blurred(16, 0.0, self.alpha)
            .map_err(|e| invalid(&self.input, format!("--alpha: {e}")))?;
        let gpu = if self.cpu && self.render.is_none() {
            None
        } else {
            let flag = if self.render.is_some() {
                "--render"
            } else {
                "the stencil mask (or --cpu)"
            };
            Some(super::required_gpu(
                self.render.as_ref().unwrap_or(&self.out),
                flag,
            )?)
        };
        if let Some(path) = &self.render {
            check_render(
                path,
                gpu.as_ref(),
                self.render_size,
                DEFAULT_GAMMA,
                self.exposure,
            )?;
        }
        let step = super::spinner(!self.quiet, format!("loading {}", self.input.display()));
        let scene = display_scene(
            &self.input,
            self.topology.as_deref(),
            "cloth-vis shadows",
            self.render_size,
            self.exposure,
            DEFAULT_GAMMA,
        )?;
        let (mut objects, _) = cloth_vis::inputs::load_geometry(&scene, false)?;
        let frames = objects[0].frame_count();
        if self.frame >= frames {
            return Err(invalid(
                &self.input,
                format!(
                    "--frame {} is outside the {frames} frames (0..{frames})",
                    self.frame
                ),
            )
            .into());
        }
        objects[0].pose(self.frame);
        let mut mesh = objects.swap_remove(0);
        let light = if self.up_axis == UpAxis::PosY {
            light
        } else {
            let stand = stand_up_matrix(self.up_axis);
            mesh.animation = None;
            mesh.pose_positions(&mesh.positions.clone(), stand);
            let turn = glam::DMat3::from_mat4(stand.as_dmat4());
            match light {
                Light::Point(p) => Light::Point(turn * p),
                Light::Directional(d) => Light::Directional(turn * d),
            }
        };
        if mesh.triangles.is_empty() {
            return Err(invalid(
                &self.input,
                "the input has no triangles (a point cache carries none): add --topology MESH"
                    .to_owned(),
            )
            .into());
        }
        let grid = match self.ground_extent {
            Some(extent) => GroundGrid::new(self.ground, extent, self.grid),
            None => GroundGrid::around_shadow(&mesh.positions, &light, self.ground, self.grid),
        }
        .map_err(|e| invalid(&self.input, e.to_string()))?;
        let (caster, lod_note, level) = match lod {
            Some(target) => {
                step.set_message(format!(
                    "simplifying the caster's {} triangles (--lod {})",
                    mesh.triangles.len(),
                    self.lod.as_deref().unwrap_or_default()
                ));
                let level = shadows::caster_lod(
                    &mesh.positions,
                    &mesh.triangles,
                    target,
                    shadows::lod::DEFAULT_SAMPLES,
                    0,
                )
                .map_err(|e| invalid(&self.input, e.to_string()))?;
                let note = format!(
                    " (LOD of {} triangles, Hausdorff {:.3} % of the diagonal)",
                    mesh.triangles.len(),
                    level.hausdorff.percent()
                );
                (level.triangles.clone(), note, Some(level))
            }
            None => (mesh.triangles.clone(), String::new(), None),
        };
        let sides = match self.sides.as_str() {
            "one" => Sides::One,
            "two" => Sides::Two,
            _ => {
                let topology = CasterTopology::new(mesh.positions.len(), &caster)
                    .map_err(|e| invalid(&self.input, e.to_string()))?;
                if topology.border_edge_count() > 0 {
                    Sides::Two
                } else {
                    Sides::One
                }
            }
        };
        step.set_message(format!("casting {} triangles", caster.len()));
        let start = Instant::now();
        let (mask, method) = match (&gpu, self.cpu) {
            (Some(gpu), false) => {
                let (mask, _) = shadows::stencil_ground_mask(
                    gpu,
                    &mesh.positions,
                    &caster,
                    &light,
                    sides,
                    &grid,
                )
                .map_err(|e| invalid(&self.input, e.to_string()))?;
                (mask, "stencil")
            }
            _ => (
                shadows::exact_ground_mask(&mesh.positions, &caster, &light, &grid)
                    .map_err(|e| invalid(&self.input, e.to_string()))?,
                "rays",
            ),
        };
        let millis = start.elapsed().as_secs_f64() * 1e3;
        meshio::write_npy_f32(&self.out, &[grid.n, grid.n], &mask)?;
        let unshadowable = nothing_casts(&mesh.positions, &light, grid.y);
        if let (Some(path), Some(gpu)) = (&self.render, &gpu) {
            step.set_message(format!("drawing {}", path.display()));
            self.draw(
                path,
                gpu,
                &scene,
                (mesh, level),
                (&grid, &mask),
                light,
                sides,
            )?;
        }
        step.finish_and_clear();
        let shadowed = mask.iter().filter(|&&v| v > 0.0).count() as f64 / mask.len() as f64;
        super::print_line(&format!(
            "shadows: {} triangles (caster) in {millis:.1} ms{lod_note}, {method}, {}-sided, \
             {} x {} cells, {:.2} % shadowed",
            caster.len(),
            if sides == Sides::Two { "two" } else { "one" },
            grid.n,
            grid.n,
            100.0 * shadowed
        ))?;
        if let Some(why) = unshadowable {
            super::print_line(&format!(
                "note: {why}, so nothing can shadow the ground (--ground is a height along the \
                 up axis, --light-dir points towards the light)"
            ))?;
        }
        let outputs = std::iter::once(&self.out).chain(&self.render);
        if let Some(wrote) = super::wrote_line(outputs.map(PathBuf::as_path)) {
            super::print_line(&wrote)?;
        }
        Ok(())
    }

    /// Draw the mesh over the ground quad of the grid's extent, lit by `light` through the
    /// `shadow-volumes` stage (caster: the mesh, at the command's LOD), under a dim ambient,
    /// framed on the mesh and its shadow (`mask`).
    #[allow(clippy::too_many_arguments)]
    fn draw(
        &self,
        path: &std::path::Path,
        gpu: &GpuContext,
        scene: &cloth_vis::Scene,
        (mut mesh, level): (WorldObject, Option<shadows::LodLevel>),
        (grid, mask): (&GroundGrid, &[f32]),
        light: Light,
        sides: Sides,
    ) -> Result<(), Error> {
        let mut scene = scene.clone();
        let table = &mut scene.shadow_volumes;
        table.lod = self.lod.clone();
        table.alpha_deg = self.alpha;
        table.ambient = 0.1;
        // Unit irradiance: a point light's intensity is d², d its distance to the grid's centre.
        table.lights = vec![match light {
            Light::Point(p) => ShadowLightDesc {
                position: Some(p.to_array()),
                intensity: Some([(p - grid.centre()).length_squared() as f32; 3]),
                ..Default::default()
            },
            Light::Directional(d) => ShadowLightDesc {
                direction: Some(d.to_array()),
                irradiance: Some([1.0; 3]),
                ..Default::default()
            },
        }];
        mesh.albedo = Vec3::splat(0.8);
        mesh.two_sided = sides == Sides::Two;
        let [x0, z0, x1, z1] = grid.extent.map(|v| v as f32);
        let y = grid.y as f32;
        let ground = WorldObject {
            name: GROUND_NAME.to_owned(),
            positions: vec![
                Vec3::new(x0, y, z0),
                Vec3::new(x1, y, z0),
                Vec3::new(x1, y, z1),
                Vec3::new(x0, y, z1),
            ],
            normals: vec![Vec3::Y; 4],
            triangles: vec![[0, 2, 1], [0, 3, 2]],
            uvs: None,
            albedo: Vec3::splat(0.8),
            two_sided: false,
            front: None,
            back: None,
            animation: None,
        };
        let mut objects = vec![mesh, ground];
        let format = FrameFormat::for_context(gpu).with_depth(DepthConvention::ReversedInfinite);
        let mut renderer = Renderer::new(&gpu.device, format);
        // The mesh is object 0: its level is the one the mask used.
        let levels: Vec<(usize, shadows::LodLevel)> = level.into_iter().map(|l| (0, l)).collect();
        let mut stage = ShadowVolumeStage::with_levels(&scene, gpu, &renderer, &objects, &levels)?;
        stage.prepare(&scene, gpu, &mut objects)?;
        let meshes: Vec<DrawMesh> = objects
            .iter()
            .map(|o| DrawMesh {
                positions: &o.positions,
                triangles: &o.triangles,
                front: o.front.as_deref().unwrap_or_default(),
                back: o.back.as_deref().unwrap_or_default(),
            })
            .collect();
        renderer
            .gouraud
            .set_meshes(&gpu.device, &gpu.queue, &meshes)?;
        // Framed on the mesh and its shadow, not the whole ground.
        let shadow = (0..grid.n * grid.n)
            .filter(|&k| mask[k] > 0.0)
            .map(|k| grid.cell_centre(k % grid.n, k / grid.n).as_vec3());
        let (lo, hi) = objects[0]
            .positions
            .iter()
            .copied()
            .chain(shadow)
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p), hi.max(p))
            });
        let (centre, radius) = ((lo + hi) / 2.0, (hi - lo).length() / 2.0);
        let direction = match light {
            Light::Directional(d) => (DVec3::new(0.55, 0.7, 1.0) - d * 0.3).as_vec3(),
            Light::Point(_) => Vec3::new(0.55, 0.7, 1.0),
        };
        let [w, h] = self.render_size;
        let camera = Camera::framing(centre, radius, centre, direction, Vec3::Y, 35.0, w, h);
        let background = Background::Color([0.0; 3]);
        let image = renderer.render(
            &gpu.device,
            &gpu.queue,
            &camera,
            background,
            &[stage.pass()],
        )?;
        if super::visibility::lower_extension(path).as_deref() == Some("exr") {
            render::output::write_exr(&image, path, background)?;
        } else {
            let display = Display {
                exposure_ev: self
                    .exposure
                    .unwrap_or_else(|| render::output::auto_exposure(&image)),
                curve: ToneCurve::AcesFitted,
            };
            render::output::write_png(&image, path, &display, background)?;
        }
        Ok(())
    }
}
