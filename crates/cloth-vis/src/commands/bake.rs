//! `cloth-vis bake`: ambient occlusion (and radiance, bent normals) baked into the user's own
//! asset — the input with everything it had, plus per-vertex attributes (issue #18 item 1).
//!
//! The values are paper 000's: a_i = (1/π) Σ_j ω_j M_ij over the lightsphere of `--level`
//! (the same engine and parameters as `cloth-vis visibility`, so COLOR_0 equals its a_i on the
//! same mesh), computed on the asset **as written** (a glTF in its rest pose: node transforms,
//! default morph weights and skins evaluated without an animation; `visibility` poses an
//! animated glTF at frame 0 of its first clip instead).
//!
//! Outputs by the input's kind:
//! - `.glb`/`.gltf` → `.glb`, or `.gltf` + `.bin` of the same name ([`meshio::write_gltf_with`]):
//!   every node, mesh, material, texture, skin, animation and extension kept, buffers and images
//!   embedded byte for byte; a_i as
//!   **linear** vertex colour in the chosen channel (`COLOR_0` RGB by default, `COLOR_0.a` over
//!   the existing colour, or `COLOR_1`), `_RADIANCE` (`VEC3` float, unclamped, a white
//!   Lambertian surface: c_i = (1/π) Σ_j M_ij I_j ω_j) under `--env`/`--sky`, `_BENT_NORMAL`
//!   with `--bent-normals`, `_AO_BACK` (a_i of the back side, normals flipped) with
//!   `--back-side`; materials double-sided per `--two-sided` (auto: primitives with a
//!   border edge, i.e. open surfaces such as cloth); primitives without a material get a
//!   non-metallic rough one.
//! - `.obj` → `.obj`: the file's lines unchanged except each `v x y z` line, which gets the
//!   linear colour `r g b` = (a_i, a_i, a_i) (the extension Blender, MeshLab and trimesh read).
//! - `.ply` → `.ply`: positions, normals, 8-bit linear colour and a float `ao` (other vertex
//!   properties of the input are not carried).
//!
//! - `.exr`/`.png` from an animation (a folder of numbered OBJ, an animated glTF with `--clip`, a
//!   point cache with `--topology`): a vertex-animation texture ([`meshio::write_vat_with`]) of
//!   every frame, a_i **of that frame** in alpha — per-frame baking of a deforming mesh, one
//!   engine for all frames (the cpu backend refits its BVH), a progress bar over frames.
//!
//! `--per-face FILE.npy` adds a_f per triangle: the ambient term at the triangle's centroid about
//! its face normal (receivers without triangles of their own, in the same engine call).
//!
//! Vertices used by no face get a_i = 1 in colours (NaN in the PLY's `ao`) and zero radiance.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use cloth_vis::Error;
use cloth_vis::lighting::shadowed_radiance;
use cloth_vis::object::WorldObject;
use cloth_vis::scene::{Scene, VisibilityBackendDesc};
use cloth_vis::shadowing::VisibilityStage;
use glam::Vec3;
use meshio::{BakeValues, ColourChannel, DoubleSided, GltfBake};

use super::invalid;
use super::visibility::lower_extension;

/// What the input and output extensions ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Gltf,
    Obj,
    Ply,
    /// A vertex-animation texture of every frame, a_i in alpha.
    Vat,
}

/// `--two-sided`: which materials become double-sided.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TwoSided {
    /// Materials of open surfaces (a border edge): cloth, leaves, planes.
    Auto,
    /// Every baked material.
    On,
    /// Leave `doubleSided` as the input has it.
    Off,
}

/// `cloth-vis bake`: the flags.
#[derive(clap::Args)]
pub struct BakeArgs {
    /// The asset: .glb, .gltf, .obj or .ply; for a .exr/.png output an animation (folder of
    /// numbered .obj, animated .glb, point cache .npy/.pc2/.mdd with --topology).
    input: PathBuf,
    /// Output: .glb (or .gltf + .bin beside it) for a glTF input, .obj for an OBJ, .ply for a
    /// PLY; .exr/.png for a vertex-animation texture of an animation with a_i per frame in
    /// alpha.
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Lightsphere level s (k = 2 + 4^(s+1) directions), as for `visibility`.
    #[arg(long, default_value_t = 3)]
    level: u32,
    /// Backend: cpu (exact rays), rays (the same exact rays on the GPU), depth or query (GPU
    /// depth maps); default as for `visibility`.
    #[arg(long, value_parser = ["depth", "query", "cpu", "rays"])]
    backend: Option<String>,
    /// Occluders farther than D (the asset's units) are ignored (cpu and rays backends).
    #[arg(long, value_name = "D")]
    max_distance: Option<f32>,
    /// Where a_i goes in a glTF: COLOR_0 (RGB), COLOR_0.a (alpha over the existing colour) or
    /// COLOR_1.
    #[arg(long, default_value = "COLOR_0", value_parser = ["COLOR_0", "COLOR_0.a", "COLOR_1"])]
    channel: String,
    /// Materials set double-sided: auto (open surfaces), on (all), off (as in the input).
    #[arg(long, value_enum, default_value = "auto")]
    two_sided: TwoSided,
    /// Also write `_BENT_NORMAL` (glTF): the cosine-weighted mean open direction.
    #[arg(long)]
    bent_normals: bool,
    /// Also bake the back side (normals flipped: what the inside of a garment sees) as the
    /// scalar `_AO_BACK` (glTF; a shader picks it for back faces). The front values are
    /// unchanged; the visibility work doubles.
    #[arg(long)]
    back_side: bool,
    /// Also write a_f per triangle (at its centroid, about its face normal) as f32 [T] .npy,
    /// triangles in the loaded mesh's order (polygons fan-triangulated in place; NaN for a
    /// degenerate triangle).
    #[arg(long, value_name = "FILE.npy")]
    per_face: Option<PathBuf>,
    #[command(flatten)]
    environment: super::env_args::EnvironmentArgs,
    /// A mesh whose triangles a point-cache input (.npy, .pc2, .mdd) takes (VAT output).
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// The glTF animation to bake per frame (VAT output), by name or index.
    #[arg(long, value_name = "NAME|INDEX", value_parser = super::parse::clip)]
    clip: Option<meshio::ClipSelector>,
    /// Frames A..B of an animation (VAT output; end exclusive; default all).
    #[arg(long, value_parser = super::parse::range)]
    frames: Option<(usize, usize)>,
    /// Hide the progress bar over frames.
    #[arg(long)]
    quiet: bool,
}

/// What was baked, for the summary line.
#[derive(Clone, Debug)]
pub struct BakeSummary {
    /// Vertices baked.
    pub vertices: usize,
    /// Light directions.
    pub directions: usize,
    /// Visibility time (ms).
    pub millis: f64,
    /// The glTF writer's report (glTF outputs).
    pub gltf: Option<meshio::GltfBakeReport>,
}

impl BakeArgs {
    /// Bake and print one summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let summary = bake(&self)?;
        let mut line = format!(
            "bake: a_i of {} vertices over {} directions in {:.1} ms",
            summary.vertices, summary.directions, summary.millis,
        );
        if let Some(r) = &summary.gltf {
            line.push_str(&format!(
                " ({} primitive(s); {} mesh(es) duplicated for instances; {} image(s) embedded; \
                 {} material(s) double-sided{}{})",
                r.primitives,
                r.meshes_duplicated,
                r.images_embedded,
                r.materials_double_sided,
                if r.default_material_added {
                    "; a default material added"
                } else {
                    ""
                },
                if r.colours_replaced > 0 {
                    "; an existing COLOR_0 replaced"
                } else {
                    ""
                },
            ));
        }
        super::print_summary(&line, [self.out.as_path()])
    }
}

fn kind_of(path: &Path, what: &str) -> Result<Kind, Error> {
    match lower_extension(path).as_deref() {
        Some("glb" | "gltf") => Ok(Kind::Gltf),
        Some("obj") => Ok(Kind::Obj),
        Some("ply") => Ok(Kind::Ply),
        _ => Err(invalid(
            path,
            format!(
                "{what} must be .glb, .gltf, .obj or .ply (animations: see `visibility --frames`)"
            ),
        )),
    }
}

/// Computes and writes the bake `args` asks for.
///
/// # Errors
/// Flag, loader, engine and writer errors, naming the file; refused before any work: an output
/// whose kind does not match the input's, an output equal to the input, a bad distance.
pub fn bake(args: &BakeArgs) -> Result<BakeSummary, Error> {
    let input = &args.input;
    super::check_output_file(&args.out, &[input])?;
    let vat = super::vat_out::is_vat(&args.out);
    let kind = if vat {
        Kind::Vat
    } else {
        kind_of(input, "the input")?
    };
    let wanted: &[&str] = match kind {
        Kind::Gltf => &["glb", "gltf"],
        Kind::Obj => &["obj"],
        Kind::Ply => &["ply"],
        Kind::Vat => &["exr"],
    };
    let out_extension = lower_extension(&args.out);
    if !vat && !wanted.contains(&out_extension.as_deref().unwrap_or("")) {
        return Err(invalid(
            &args.out,
            format!(
                "--out must be a .{} for this input (the input's kind, its content kept)",
                wanted.join(" or .")
            ),
        ));
    }
    if out_extension.as_deref() == Some("gltf") {
        // Its buffer file beside it must not be the input either.
        super::check_output_file(&meshio::text_gltf_buffer(&args.out), &[input])?;
    }
    if args.back_side && kind != Kind::Gltf {
        return Err(invalid(
            &args.out,
            "--back-side writes `_AO_BACK` into a glTF; OBJ and PLY colours and VATs hold one \
             side"
                .to_owned(),
        ));
    }
    if let Some(path) = &args.per_face {
        super::check_output_file(path, &[input])?;
        if vat || lower_extension(path).as_deref() != Some("npy") {
            return Err(invalid(
                path,
                "--per-face writes a_f of a mesh's triangles as .npy (not with a VAT output)"
                    .to_owned(),
            ));
        }
    }
    let mut scene = Scene::one_object(input, "cloth-vis bake")?;
    scene.lighting.level = args.level;
    scene.visibility.backend = match args.backend.as_deref() {
        Some("cpu") => VisibilityBackendDesc::Cpu,
        Some("depth") => VisibilityBackendDesc::Depth,
        Some("query") => VisibilityBackendDesc::Query,
        Some("rays") => VisibilityBackendDesc::Rays,
        _ => VisibilityBackendDesc::Auto,
    };
    if let Some(d) = args.max_distance {
        if !(d.is_finite() && d > 0.0) {
            return Err(invalid(
                input,
                format!("--max-distance {d} must be finite and > 0"),
            ));
        }
        if matches!(args.backend.as_deref(), Some("depth" | "query")) {
            return Err(invalid(
                input,
                "--max-distance needs the cpu or rays backend (exact rays)".into(),
            ));
        }
    }
    scene.visibility.max_distance = args.max_distance;
    let environment = args.environment.load_turned()?;
    let gpu = match scene.visibility.backend {
        VisibilityBackendDesc::Depth
        | VisibilityBackendDesc::Query
        | VisibilityBackendDesc::Rays => Some(gpu_context::GpuContext::new(
            &gpu_context::GpuOptions::default(),
        )?),
        VisibilityBackendDesc::Auto if args.max_distance.is_none() => super::optional_gpu(),
        _ => None,
    };
    let sphere = lightsphere::Lightsphere::new(args.level)?;
    let mut stage =
        VisibilityStage::new(&scene, gpu.as_ref()).map_err(|e| invalid(input, e.to_string()))?;
    if vat {
        return bake_vat(args, &mut stage, &sphere);
    }
    // The asset as written: a glTF's rest pose, not a clip's first frame.
    let (mesh, _) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
    let normals = meshio::compute_normals(
        &mesh.positions,
        &mesh.triangles,
        meshio::NormalWeighting::Angle,
    );
    let n = mesh.positions.len();
    let mut asset = world_object(mesh.positions.clone(), normals, mesh.triangles.clone());
    // Two-sided: the stage adds rows with flipped normals.
    asset.two_sided = args.back_side;
    let mut objects = vec![asset];
    if args.per_face.is_some() {
        // Triangle centroids as receivers without triangles of their own: rows after the
        // vertices', the same engine and rays.
        let (centroids, face_normals) = face_receivers(&mesh.positions, &mesh.triangles);
        objects.push(world_object(centroids, face_normals, Vec::new()));
    }
    let what = format!(
        "a_i: {} directions x {} vertices ({})",
        sphere.len(),
        n,
        stage.backend().name()
    );
    let step = super::engine_bar(!args.quiet, &mut stage, what);
    let t = Instant::now();
    let (visibility, _) = stage.compute(&objects, &sphere)?;
    let millis = t.elapsed().as_secs_f64() * 1e3;
    step.finish_and_clear();
    let matrix = visibility.matrix();
    let all = matrix.ambient();
    let rows = |object: usize| visibility.rows(object).cloned().unwrap_or((0..0, None));
    let (front, back) = rows(0);
    let ambient = all[front.clone()].to_vec();
    let ambient_back = back.map(|b| all[b].to_vec());
    let per_face = all[rows(1).0].to_vec();
    if let Some(path) = &args.per_face {
        meshio::write_npy_f32(path, &[per_face.len()], &per_face)?;
    }
    let finite = |v: Vec3| if v.is_finite() { v } else { Vec3::ZERO };
    let radiance: Option<Vec<Vec3>> = match &environment {
        Some(env) => {
            let light = cloth_vis::inputs::light_directions(&scene, env)?.0.1;
            Some(
                shadowed_radiance(matrix, &sphere, &light)?[front.clone()]
                    .iter()
                    .copied()
                    .map(finite)
                    .collect(),
            )
        }
        None => None,
    };
    let bent = args
        .bent_normals
        .then(|| matrix.bent_normals()[front.clone()].to_vec());
    let mut gltf = None;
    match kind {
        Kind::Gltf => {
            let channel = match args.channel.as_str() {
                "COLOR_0.a" => ColourChannel::Color0Alpha,
                "COLOR_1" => ColourChannel::Color1,
                _ => ColourChannel::Color0,
            };
            let mut attributes = Vec::new();
            if let Some(r) = &radiance {
                attributes.push(("_RADIANCE".to_owned(), BakeValues::Vec3(r)));
            }
            if let Some(b) = &bent {
                attributes.push(("_BENT_NORMAL".to_owned(), BakeValues::Vec3(b)));
            }
            // Unused vertices (NaN) get 1, as in the colour; glTF forbids NaN.
            let back_values: Option<Vec<f32>> = ambient_back
                .as_ref()
                .map(|b| b.iter().map(|a| linear(*a)).collect());
            if let Some(b) = &back_values {
                attributes.push(("_AO_BACK".to_owned(), BakeValues::Scalar(b)));
            }
            let request = GltfBake {
                colour: Some((channel, &ambient)),
                attributes,
                double_sided: match args.two_sided {
                    TwoSided::Auto => DoubleSided::Open,
                    TwoSided::On => DoubleSided::All,
                    TwoSided::Off => DoubleSided::Keep,
                },
            };
            gltf = Some(meshio::write_gltf_with(input, &args.out, &request)?);
        }
        Kind::Obj => write_obj_colours(input, &args.out, &ambient)?,
        Kind::Vat => unreachable!("returned above"),
        Kind::Ply => {
            let colours: Vec<Vec3> = ambient.iter().map(|a| Vec3::splat(linear(*a))).collect();
            super::visibility::write_ply(
                &args.out,
                "cloth-vis bake: linear colour = ao = a_i (NaN: vertex used by no face)",
                &mesh.positions,
                matrix.normals(),
                &mesh.triangles,
                &colours,
                &ambient,
            )?;
        }
    }
    Ok(BakeSummary {
        vertices: ambient.len(),
        directions: sphere.len(),
        millis,
        gltf,
    })
}

/// Bakes every frame of an animation (or frames `--frames`) into a vertex-animation texture:
/// positions and normals per frame, a_i of that frame in alpha (#18 item 2); one engine for all
/// frames, so the cpu backend refits its BVH instead of rebuilding it.
fn bake_vat(
    args: &BakeArgs,
    stage: &mut VisibilityStage,
    sphere: &lightsphere::Lightsphere,
) -> Result<BakeSummary, Error> {
    let input = &args.input;
    let clip = args.clip.clone().unwrap_or(meshio::ClipSelector::First);
    let (animation, _) = meshio::load_animation(
        input,
        &super::animation_options(&clip, args.topology.as_deref()),
    )?;
    let total = animation.frames.len();
    let (start, end) = args.frames.unwrap_or((0, total));
    if start >= end || end > total {
        return Err(invalid(
            input,
            format!("--frames {start}..{end} is outside the {total} frames (0..{total})"),
        ));
    }
    let count = end - start;
    let size = (count, animation.vertex_count());
    super::vat_out::check(input, &args.out, &animation.triangles, size)?;
    let bar = cloth_vis::run::progress_bar(!args.quiet && count > 1, count as u64, "frames");
    let mut millis = 0.0;
    let mut ambient = Vec::with_capacity(count);
    for frame in &animation.frames[start..end] {
        let normals =
            meshio::compute_normals(frame, &animation.triangles, meshio::NormalWeighting::Angle);
        let object = world_object(frame.clone(), normals, animation.triangles.clone());
        let t = Instant::now();
        let (visibility, _) = stage.compute(std::slice::from_ref(&object), sphere)?;
        millis += t.elapsed().as_secs_f64() * 1e3;
        ambient.push(visibility.matrix().ambient());
        bar.inc(1);
    }
    bar.finish_and_clear();
    let vertices = animation.vertex_count();
    let line = super::vat_out::write(
        &args.out,
        &animation.triangles,
        animation.frame_rate,
        (count, vertices),
        |f, p, alpha| {
            p.copy_from_slice(&animation.frames[start + f]);
            for (a, v) in alpha.iter_mut().zip(&ambient[f]) {
                *a = linear(*v);
            }
            Ok(())
        },
    )?;
    if !args.quiet {
        eprintln!("{line}");
    }
    Ok(BakeSummary {
        vertices,
        directions: sphere.len(),
        millis,
        gltf: None,
    })
}

/// A white one-sided object of the bake's scene.
fn world_object(positions: Vec<Vec3>, normals: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> WorldObject {
    WorldObject {
        name: "bake".to_owned(),
        positions,
        normals,
        triangles,
        uvs: None,
        albedo: Vec3::ONE,
        two_sided: false,
        front: None,
        back: None,
        animation: None,
    }
}

/// Each triangle's centroid (in f64) and unit face normal (zero for a degenerate triangle,
/// whose a_f is then NaN).
fn face_receivers(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<Vec3>) {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].as_dvec3());
            (
                ((a + b + c) / 3.0).as_vec3(),
                (b - a).cross(c - a).normalize_or_zero().as_vec3(),
            )
        })
        .unzip()
}

/// a_i as a colour value: clamped to [0, 1], 1 where undefined (a vertex used by no face).
fn linear(a: f32) -> f32 {
    if a.is_finite() {
        a.clamp(0.0, 1.0)
    } else {
        1.0
    }
}

/// Copies the OBJ `input` to `output` with the colour (a, a, a) on each `v` line (replacing
/// colours already there), every other line byte for byte; written atomically.
fn write_obj_colours(input: &Path, output: &Path, ambient: &[f32]) -> Result<(), Error> {
    let bytes = input_guard::read_regular(input).map_err(|e| Error::Io {
        path: input.to_owned(),
        reason: e.to_string(),
    })?;
    let mut vertex = 0usize;
    let mut out = Vec::with_capacity(bytes.len() + ambient.len() * 30);
    for line in bytes.split_inclusive(|b| *b == b'\n') {
        let ending = line
            .iter()
            .rev()
            .take_while(|b| matches!(b, b'\r' | b'\n'))
            .count();
        let (body, ending) = line.split_at(line.len() - ending);
        let text = String::from_utf8_lossy(body);
        let mut tokens = text.split_whitespace();
        if tokens.next() != Some("v") {
            out.extend_from_slice(line);
            continue;
        }
        let coords: Vec<&str> = tokens.collect();
        let Some(&a) = ambient.get(vertex) else {
            return Err(invalid(
                input,
                format!(
                    "has more `v` lines than the {} vertices loaded",
                    ambient.len()
                ),
            ));
        };
        vertex += 1;
        let keep = if coords.len() >= 6 { 3 } else { coords.len() };
        let a = linear(a);
        write!(out, "v {} {a} {a} {a}", coords[..keep].join(" ")).expect("writing to a Vec");
        out.extend_from_slice(ending);
    }
    if vertex != ambient.len() {
        return Err(invalid(
            input,
            format!(
                "has {vertex} `v` lines but {} vertices were loaded",
                ambient.len()
            ),
        ));
    }
    atomic_out::write_with(output, |w| w.write_all(&out))?;
    Ok(())
}
