//! The `cloth-vis` command line.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

use clap::{Parser, Subcommand};
use cloth_vis::{RunOptions, Scene};

/// Real-time cloth appearance: self-shadowing under HDR light, BTFs, shadows, animation PCA.
#[derive(Parser)]
#[command(name = "cloth-vis", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a scene file: only the effects it names are built; images and a run report go to DIR.
    Render {
        /// The scene (TOML).
        scene: PathBuf,
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Render frames A..B of the scene's animated objects to frame-NNNN.png (overrides
        /// `[output] frames`).
        #[arg(long, value_name = "A..B")]
        frames: Option<render::sequence::FrameRange>,
        /// Hide progress bars.
        #[arg(long)]
        quiet: bool,
    },
    /// Render the embedded demo scene (synthetic cloth under a procedural sky) into DIR.
    Demo {
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Render frames A..B of the cloth animation (120 frames: 0..120) to frame-NNNN.png,
        /// with the visibility recomputed per frame.
        #[arg(long, value_name = "A..B")]
        frames: Option<render::sequence::FrameRange>,
        /// Hide progress bars.
        #[arg(long)]
        quiet: bool,
    },
    /// Animation from mesh clips by PCA (thesis §3).
    Anim {
        #[command(subcommand)]
        command: AnimCommand,
    },
    /// Measured materials (BTFs, thesis §5.3–5.5): a synthetic woven BTF, per-view PCA
    /// compression, error statistics.
    Btf {
        #[command(subcommand)]
        command: BtfCommand,
    },
    /// Visibility matrix M and ambient term a_i of a mesh or an animation (paper 000).
    Visibility {
        /// A mesh (.ply .obj .gltf .glb) or an animation (folder of numbered .obj, .npy, .glb).
        input: PathBuf,
        /// Lightsphere level s (k = 2 + 4^(s+1) directions).
        #[arg(long, default_value_t = 3)]
        level: u32,
        /// Backend: depth (GPU depth maps), query (the published per-vertex occlusion
        /// queries; slow, N·k draws) or cpu (exact ray casting); default depth on a hardware
        /// GPU, cpu otherwise.
        #[arg(long, value_parser = ["depth", "query", "cpu"])]
        backend: Option<String>,
        /// Depth-map side for the depth and query backends.
        #[arg(long, default_value_t = occlusion_gpu::DEFAULT_DEPTH_RESOLUTION)]
        depth_res: u32,
        /// HDR environment (.hdr/.exr) for the colours of a .ply/.glb output and --render
        /// (without --env or --sky: the grey ambient term a_i).
        #[arg(long, conflicts_with = "sky")]
        env: Option<PathBuf>,
        /// Use the procedural sky as the environment (see --env).
        #[arg(long)]
        sky: bool,
        /// Rotate the environment by DEG degrees about +Y relative to the object (rotated
        /// look-ups of I_j; M is not recomputed). Needs --env or --sky.
        #[arg(
            long,
            value_name = "DEG",
            default_value_t = 0.0,
            allow_negative_numbers = true
        )]
        env_rotation: f32,
        /// Output: .npy (a_i as f32 [N] or [F, N]; M as [N, k] or [F, N, k] with --matrix),
        /// .ply (one frame: colour, float `ao` = a_i, NaN for unused vertices) or .glb (one
        /// frame: linear float COLOR_0, float `_AO` = a_i, -1 for unused vertices).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the matrix M instead of a_i (.npy only).
        #[arg(long)]
        matrix: bool,
        /// Frames A..B of an animation (end exclusive).
        #[arg(long, value_parser = parse_range)]
        frames: Option<(usize, usize)>,
        /// Render the last frame with its vertex radiance: FILE.png (tone-mapped) or FILE.exr
        /// (linear HDR). Needs a GPU adapter (lavapipe is fine).
        #[arg(long, value_name = "FILE")]
        render: Option<PathBuf>,
        /// PNG exposure in stops (multiplier 2^EV); default: auto (the 90th percentile of the
        /// vertex luminance maps to 0.8).
        #[arg(long, value_name = "EV", allow_negative_numbers = true)]
        exposure: Option<f32>,
        /// PNG display gamma.
        #[arg(long, value_name = "G", default_value_t = cloth_vis::visibility_cmd::DEFAULT_GAMMA)]
        gamma: f32,
        /// Rendered image size.
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "768x768")]
        render_size: [u32; 2],
    },
    /// Load a mesh or an animation and print what the loader found (counts, quirks, time).
    Inspect {
        /// A mesh (.ply .obj .gltf .glb), an animation (.glb, .npy, a folder of numbered .obj).
        input: PathBuf,
        /// Treat a glTF as an animation (default: static mesh).
        #[arg(long)]
        animation: bool,
    },
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        // A closed pipe (`cloth-vis inspect … | head`) is not an error of ours.
        Err(e)
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe) =>
        {
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[derive(Subcommand)]
enum BtfCommand {
    /// Write the synthetic woven-cloth BTF as 81 × 81 PNGs named as the Bonn UBO2003 archives
    /// (tl… pl… tv… pv….png) into a new folder.
    Synth {
        /// Texels per image side (the thesis's normtextures are 256).
        #[arg(long, default_value_t = synth::WovenBtfParams::default().res)]
        res: usize,
        /// Measured directions: h1 (θ up to 85°) or h2 (θ up to 75°), Table 5.1.
        #[arg(long, default_value = "h1", value_parser = parse_sampling)]
        sampling: btf::Sampling,
        /// Rays per texel side (anti-aliasing of the mesostructure).
        #[arg(long, default_value_t = synth::WovenBtfParams::default().supersample)]
        supersample: usize,
        /// Output folder (must not exist, or be empty).
        #[arg(long)]
        out: PathBuf,
        /// Hide the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Compress a BTF folder by per-view PCA (§5.4) into a .btfpca file.
    Compress {
        /// The folder of 81 × 81 images (UBO2003 names; PNG/JPEG sRGB or EXR linear).
        dir: PathBuf,
        /// c: eigen-normtextures per view slot (clamped to each slot's rank, at most 80).
        #[arg(long, default_value_t = btf::DEFAULT_COMPONENTS)]
        components: usize,
        /// Bits of the eigen-normtextures: u8 (the thesis's), u16 or f32.
        #[arg(long, default_value = "u8", value_parser = parse_storage)]
        storage: btf::Storage,
        /// Bits of the mean normtextures: u8, u16 (default) or f32.
        #[arg(long, default_value = "u16", value_parser = parse_storage)]
        mean_storage: btf::Storage,
        /// Output: FILE.btfpca.
        #[arg(long)]
        out: PathBuf,
        /// Hide the progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Compare a .btfpca with its folder: sizes, RMS error (8-bit sRGB) and PSNR over every
    /// image.
    Stats {
        /// The BTF folder.
        dir: PathBuf,
        /// The .btfpca file.
        file: PathBuf,
    },
    /// Render a mesh with UVs textured by a compressed BTF under one light (§5.5), to PNG.
    Render {
        /// A mesh with per-vertex UVs (.obj .ply .gltf .glb) or synth:cloth.
        mesh: PathBuf,
        /// The .btfpca material.
        #[arg(long)]
        btf: PathBuf,
        /// Directional light: world direction towards it.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, conflicts_with = "light_pos")]
        light_dir: Option<glam::Vec3>,
        /// Point light: world position (no distance falloff).
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3)]
        light_pos: Option<glam::Vec3>,
        /// Linear RGB radiance of the light.
        #[arg(long, value_name = "R,G,B", value_parser = parse_vec3, default_value = "1,1,1")]
        radiance: glam::Vec3,
        /// Direction from the mesh towards the camera, which frames the mesh.
        #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, default_value = "0.55,0.45,1")]
        camera_dir: glam::Vec3,
        /// Image size.
        #[arg(long, value_name = "WxH", value_parser = parse_size, default_value = "512x512")]
        size: [u32; 2],
        /// Texture repeats across the mesh's UV range.
        #[arg(long, default_value_t = 4.0)]
        uv_scale: f32,
        /// Also draw plain texture mapping of the same material beside it (Fig. 5.16).
        #[arg(long)]
        beside_plain: bool,
        /// Use the CPU reference renderer (no GPU needed).
        #[arg(long)]
        cpu: bool,
        /// Output: IMAGE.png.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(Subcommand)]
enum AnimCommand {
    /// Endless new animation from a short clip by jump maps (thesis §3.2): writes N frames as
    /// .npy [N, V, 3], a .glb morph-target animation, or a folder of OBJ frames.
    Jumpmap {
        /// The clip: a folder of numbered .obj frames, .npy [F, V, 3] or an animated .glb.
        input: PathBuf,
        /// A further clip of the same mesh, analysed as the next cell (motion control,
        /// thesis §3.2.2); repeat for more cells. The input is cell 0.
        #[arg(long, value_name = "CLIP")]
        cell: Vec<PathBuf>,
        /// From generated frame FRAME on, move into cell CELL at the best transition ahead;
        /// repeat to script a route (e.g. --cell-at 200:1 --cell-at 500:0).
        #[arg(long, value_name = "FRAME:CELL", value_parser = cloth_vis::anim_cmd::parse_cell_at)]
        cell_at: Vec<(usize, usize)>,
        /// Play the cheapest loop of exactly N frames (blend frames included), repeated,
        /// instead of random play.
        #[arg(long = "loop", value_name = "N", conflicts_with = "cell_at")]
        loop_length: Option<usize>,
        /// Take the clip's travel out before the analysis and replay it by integration (for
        /// clips that walk across the scene).
        #[arg(long)]
        root_motion: bool,
        /// c: PCA components of the frames.
        #[arg(long, default_value_t = 10)]
        components: usize,
        /// c*: PCA components of the central velocities.
        #[arg(long, default_value_t = 5)]
        velocity_components: usize,
        /// σ (eq. 3.3), in units of the clip's mean frame-to-frame-pair distance.
        #[arg(long, default_value_t = 0.05)]
        sigma: f64,
        /// σ* (eq. 3.6), in the same units for velocities.
        #[arg(long, default_value_t = 0.05)]
        sigma_v: f64,
        /// q (eq. 3.8): base probability of the position term, 0..1.
        #[arg(long, default_value_t = 0.0)]
        q: f64,
        /// q* (eq. 3.8): base probability of the velocity term, 0..1.
        #[arg(long, default_value_t = 0.0)]
        qv: f64,
        /// m: recently visited frames forbidden as jump targets (< 5).
        #[arg(long, default_value_t = 2)]
        memory: usize,
        /// b: blend frames per transition (0 = cut; default 3).
        #[arg(long, conflicts_with = "smoothness")]
        blend: Option<usize>,
        /// s: variable-length blends from a smoothness (eq. 3.11), in mean frame steps.
        #[arg(long)]
        smoothness: Option<f64>,
        /// Frames to generate.
        #[arg(long, default_value_t = 300)]
        frames: usize,
        /// Seed of the jumps (same seed, same animation).
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Output: FILE.npy, FILE.glb or a folder name (OBJ frames).
        #[arg(long)]
        out: PathBuf,
        /// Folder for the heat maps of D, D*, P, P*, P̂ (PNG).
        #[arg(long)]
        maps: Option<PathBuf>,
        /// Render evenly spaced frames of the new sequence side by side into FILE.png, one
        /// camera framing the whole run. Needs a GPU adapter (lavapipe is fine).
        #[arg(long, value_name = "FILE")]
        strip: Option<PathBuf>,
        /// Frames K shown in the --strip (first to last, evenly spaced).
        #[arg(
            long,
            value_name = "K",
            requires = "strip",
            default_value_t = cloth_vis::strip::DEFAULT_STRIP_FRAMES
        )]
        strip_frames: usize,
        /// Size of one --strip panel; the image is K·W × H.
        #[arg(
            long,
            value_name = "WxH",
            requires = "strip",
            value_parser = parse_size,
            default_value = "256x256"
        )]
        strip_size: [u32; 2],
    },
    /// Compress a clip by clustered PCA (thesis §3.3.2) into a .cpca file; prints V, F, k, c,
    /// c*, bits, file size, bpvf, d_a, the worst d_f and the encode time.
    Compress {
        /// The clip: a folder of numbered .obj frames, .npy [F, V, 3] or an animated .glb.
        input: PathBuf,
        /// k: vertex clusters (clamped to V).
        #[arg(long, default_value_t = anim_pca::compress::CpcaParams::default().clusters)]
        clusters: usize,
        /// c: eigentrajectories per cluster (clamped to 3F).
        #[arg(long, default_value_t = anim_pca::compress::CpcaParams::default().components)]
        components: usize,
        /// c*: components of the second PCA along time (default: none).
        #[arg(long, value_name = "C*")]
        time_components: Option<usize>,
        /// q_c: bits of the means and eigentrajectories, 1..=32.
        #[arg(long, value_name = "BITS", default_value_t = anim_pca::compress::DEFAULT_BITS)]
        qc: u8,
        /// q_w: bits of the weights, 1..=32.
        #[arg(long, value_name = "BITS", default_value_t = anim_pca::compress::DEFAULT_BITS)]
        qw: u8,
        /// Seed of the local PCA (same seed, same file).
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Instead of --clusters: the smallest k (from 1) whose decoded clip has d_a ≤ X.
        #[arg(long, value_name = "X", conflicts_with_all = ["clusters", "target_bpvf"])]
        target_da: Option<f64>,
        /// Instead of --clusters: the k of lowest d_a whose file needs ≤ X bits per vertex
        /// per frame.
        #[arg(long, value_name = "X", conflicts_with = "clusters")]
        target_bpvf: Option<f64>,
        /// Largest k a --target-da/--target-bpvf search tries.
        #[arg(long, default_value_t = cloth_vis::anim_compress_cmd::DEFAULT_K_MAX)]
        k_max: usize,
        /// Output: FILE.cpca.
        #[arg(long)]
        out: PathBuf,
    },
    /// Decode every frame of a .cpca file into .npy [F, V, 3], a .glb morph-target animation
    /// or a folder of OBJ frames (with the triangles stored in the file).
    Decompress {
        /// The .cpca file.
        input: PathBuf,
        /// Output: FILE.npy, FILE.glb or a folder name (OBJ frames).
        #[arg(long)]
        out: PathBuf,
    },
    /// Compare a .cpca file with its original clip: bpvf (eqs. 3.16–3.18 and file size), d_a
    /// and the worst d_f.
    Stats {
        /// The original clip (folder of .obj frames, .npy or .glb).
        original: PathBuf,
        /// The .cpca file.
        cpca: PathBuf,
        /// Also write the decoded mesh coloured by cluster (Figs. 3.12/3.13) as a PNG strip.
        #[arg(long, value_name = "FILE.png")]
        clusters_png: Option<PathBuf>,
        /// Also write d_f against the frame (Fig. 3.15) as an SVG chart.
        #[arg(long, value_name = "FILE.svg")]
        error_plot: Option<PathBuf>,
    },
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Render {
            scene,
            out,
            frames,
            quiet,
        } => {
            let scene = Scene::load(&scene)?;
            let options = RunOptions {
                progress: !quiet,
                frames,
                ..RunOptions::default()
            };
            let output = cloth_vis::run_scene(&scene, &out, &options)?;
            write!(std::io::stdout().lock(), "{}", output.report.table())?;
        }
        Command::Demo { out, frames, quiet } => {
            let options = RunOptions {
                progress: !quiet,
                frames,
                ..RunOptions::default()
            };
            let output = cloth_vis::run_demo(&out, &options)?;
            write!(std::io::stdout().lock(), "{}", output.report.table())?;
        }
        Command::Inspect { input, animation } => inspect(&input, animation)?,
        Command::Anim {
            command:
                AnimCommand::Jumpmap {
                    input,
                    cell,
                    cell_at,
                    loop_length,
                    root_motion,
                    components,
                    velocity_components,
                    sigma,
                    sigma_v,
                    q,
                    qv,
                    memory,
                    blend,
                    smoothness,
                    frames,
                    seed,
                    out,
                    maps,
                    strip,
                    strip_frames,
                    strip_size,
                },
        } => {
            let request = cloth_vis::anim_cmd::JumpMapRequest {
                input,
                params: anim_pca::JumpMapParams {
                    components,
                    velocity_components,
                    sigma,
                    sigma_velocity: sigma_v,
                    q,
                    q_velocity: qv,
                    root_motion: if root_motion {
                        anim_pca::RootMotion::Extract
                    } else {
                        anim_pca::RootMotion::Keep
                    },
                    ..Default::default()
                },
                control: cloth_vis::anim_cmd::PlayControl {
                    cells: cell,
                    cell_at,
                    loop_length,
                },
                playback: anim_pca::PlaybackParams {
                    memory,
                    blend: cloth_vis::anim_cmd::blend_from_flags(blend, smoothness),
                    seed,
                    ..Default::default()
                },
                frames,
                out,
                maps,
                strip: strip.map(|path| cloth_vis::anim_cmd::StripRequest {
                    path,
                    frames: strip_frames,
                    panel_size: strip_size,
                }),
            };
            // --strip without an adapter is refused by run_jumpmap, naming the flag.
            let gpu = match request.strip {
                Some(_) => gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).ok(),
                None => None,
            };
            let summary = cloth_vis::anim_cmd::run_jumpmap(&request, gpu.as_ref())?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Anim {
            command:
                AnimCommand::Compress {
                    input,
                    clusters,
                    components,
                    time_components,
                    qc,
                    qw,
                    seed,
                    target_da,
                    target_bpvf,
                    k_max,
                    out,
                },
        } => {
            let target = match (target_da, target_bpvf) {
                (Some(x), _) => Some(anim_pca::compress::RateTarget::Distortion(x)),
                (None, Some(x)) => Some(anim_pca::compress::RateTarget::Bpvf(x)),
                (None, None) => None,
            };
            let request = cloth_vis::anim_compress_cmd::CompressRequest {
                input,
                params: anim_pca::compress::CpcaParams {
                    clusters,
                    components,
                    time_components,
                    bits_components: qc,
                    bits_weights: qw,
                    seed,
                    ..Default::default()
                },
                target,
                k_max,
                out,
            };
            let summary = cloth_vis::anim_compress_cmd::run_compress(&request)?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Anim {
            command: AnimCommand::Decompress { input, out },
        } => {
            let request = cloth_vis::anim_compress_cmd::DecompressRequest { input, out };
            let summary = cloth_vis::anim_compress_cmd::run_decompress(&request)?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Anim {
            command:
                AnimCommand::Stats {
                    original,
                    cpca,
                    clusters_png,
                    error_plot,
                },
        } => {
            let gpu = match clusters_png {
                Some(_) => gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).ok(),
                None => None,
            };
            let request = cloth_vis::anim_compress_cmd::StatsRequest {
                original,
                cpca,
                clusters_png,
                error_plot,
            };
            let summary =
                cloth_vis::anim_compress_cmd::run_stats_with_pictures(&request, gpu.as_ref())?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Btf {
            command:
                BtfCommand::Synth {
                    res,
                    sampling,
                    supersample,
                    out,
                    quiet,
                },
        } => {
            let request = cloth_vis::btf_cmd::SynthRequest {
                params: synth::WovenBtfParams {
                    res,
                    supersample,
                    ..Default::default()
                },
                sampling,
                out,
                progress: !quiet,
            };
            let summary = cloth_vis::btf_cmd::run_synth(&request)?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Btf {
            command:
                BtfCommand::Compress {
                    dir,
                    components,
                    storage,
                    mean_storage,
                    out,
                    quiet,
                },
        } => {
            let request = cloth_vis::btf_cmd::CompressRequest {
                dir,
                params: btf::BtfPcaParams {
                    components,
                    storage,
                    mean_storage,
                    ..Default::default()
                },
                out,
                progress: !quiet,
            };
            let summary = cloth_vis::btf_cmd::run_compress(&request)?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Btf {
            command:
                BtfCommand::Render {
                    mesh,
                    btf,
                    light_dir,
                    light_pos,
                    radiance,
                    camera_dir,
                    size,
                    uv_scale,
                    beside_plain,
                    cpu,
                    out,
                },
        } => {
            let light = match (light_dir, light_pos) {
                (Some(d), _) => cloth_vis::btf_cmd::RenderLight::Direction(d),
                (None, Some(p)) => cloth_vis::btf_cmd::RenderLight::Position(p),
                (None, None) => {
                    anyhow::bail!("give the light: --light-dir X,Y,Z or --light-pos X,Y,Z")
                }
            };
            let gpu = if cpu {
                None
            } else {
                gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).ok()
            };
            let request = cloth_vis::btf_cmd::RenderRequest {
                mesh,
                btf,
                light,
                radiance,
                camera_direction: camera_dir,
                size,
                uv_scale,
                beside_plain,
                cpu,
                out,
            };
            let summary = cloth_vis::btf_cmd::run_render(&request, gpu.as_ref())?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Btf {
            command: BtfCommand::Stats { dir, file },
        } => {
            let summary = cloth_vis::btf_cmd::run_stats(&dir, &file, false)?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
        Command::Visibility {
            input,
            level,
            backend,
            depth_res,
            env,
            sky,
            env_rotation,
            out,
            matrix,
            frames,
            render,
            exposure,
            gamma,
            render_size,
        } => {
            let environment = match (env, sky) {
                (Some(path), _) => Some(lightsphere::Environment::load(&path)?),
                (None, true) => {
                    let s = synth::sky(&synth::SkyParams::default())?;
                    Some(lightsphere::Environment::from_latlong(
                        s.width, s.height, s.texels,
                    )?)
                }
                (None, false) => None,
            };
            let backend = backend.map(|b| match b.as_str() {
                "cpu" => occlusion_gpu::Backend::Cpu,
                "query" => occlusion_gpu::Backend::Query,
                _ => occlusion_gpu::Backend::Depth,
            });
            let gpu = match backend {
                Some(occlusion_gpu::Backend::Cpu) if render.is_none() => None,
                // --render without an adapter is refused by run_visibility, naming the flag.
                Some(occlusion_gpu::Backend::Cpu) => {
                    gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).ok()
                }
                Some(_) => Some(gpu_context::GpuContext::new(
                    &gpu_context::GpuOptions::default(),
                )?),
                None => gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()).ok(),
            };
            let request = cloth_vis::visibility_cmd::VisibilityRequest {
                input,
                level,
                backend,
                depth_resolution: depth_res,
                environment,
                env_rotation_deg: env_rotation,
                out,
                matrix,
                frames,
                render,
                exposure_ev: exposure,
                gamma,
                render_size,
            };
            let summary = cloth_vis::visibility_cmd::run_visibility(&request, gpu.as_ref())?;
            writeln!(std::io::stdout().lock(), "{}", summary.line())?;
        }
    }
    Ok(())
}

/// Parse `A..B` (end exclusive).
fn parse_range(text: &str) -> Result<(usize, usize), String> {
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| format!("{text:?} is not A..B"))?;
    let a = a
        .trim()
        .parse::<usize>()
        .map_err(|e| format!("{a:?}: {e}"))?;
    let b = b
        .trim()
        .parse::<usize>()
        .map_err(|e| format!("{b:?}: {e}"))?;
    Ok((a, b))
}

/// Parse `WxH` (e.g. `640x480`).
fn parse_vec3(text: &str) -> Result<glam::Vec3, String> {
    let parts: Vec<&str> = text.split(',').collect();
    let [x, y, z] = parts[..] else {
        return Err(format!("{text:?} is not X,Y,Z (e.g. 0.3,0.8,0.5)"));
    };
    let num = |s: &str| {
        s.trim()
            .parse::<f32>()
            .map_err(|e| format!("{s:?} in {text:?}: {e}"))
    };
    let v = glam::Vec3::new(num(x)?, num(y)?, num(z)?);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{text:?} is not finite"))
    }
}

fn parse_sampling(text: &str) -> Result<btf::Sampling, String> {
    match text.to_ascii_lowercase().as_str() {
        "h1" => Ok(btf::Sampling::H1),
        "h2" => Ok(btf::Sampling::H2),
        _ => Err(format!("{text:?}: the samplings are h1 and h2 (Table 5.1)")),
    }
}

fn parse_storage(text: &str) -> Result<btf::Storage, String> {
    match text.to_ascii_lowercase().as_str() {
        "u8" => Ok(btf::Storage::U8),
        "u16" => Ok(btf::Storage::U16),
        "f32" => Ok(btf::Storage::F32),
        _ => Err(format!("{text:?}: the storages are u8, u16 and f32")),
    }
}

fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{text:?} is not WxH (e.g. 640x480)"))?;
    let side = |s: &str| {
        s.trim()
            .parse::<u32>()
            .map_err(|e| format!("{s:?} in {text:?}: {e}"))
    };
    Ok([side(w)?, side(h)?])
}

fn inspect(input: &Path, animation: bool) -> anyhow::Result<()> {
    let has_ext = |ext: &str| {
        input
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case(ext))
    };
    let mut out = std::io::stdout().lock();
    let start = Instant::now();
    if animation || input.is_dir() || has_ext("npy") {
        let (anim, report) = meshio::load_animation(input, &meshio::AnimationOptions::default())?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        writeln!(
            out,
            "{}: animation, {} frames x {} vertices, {} triangles, {:.1} fps, loaded in {ms:.1} ms",
            input.display(),
            anim.frame_count(),
            anim.vertex_count(),
            anim.triangles.len(),
            anim.frame_rate
        )?;
        writeln!(out, "{report:#?}")?;
    } else {
        let (mesh, report) = meshio::load_mesh(input, &meshio::LoadOptions::default())?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        writeln!(
            out,
            "{}: {} vertices, {} triangles, loaded in {ms:.1} ms",
            input.display(),
            mesh.vertex_count(),
            mesh.triangle_count()
        )?;
        writeln!(
            out,
            "unreferenced vertices: {}, degenerate triangles: {}, duplicate positions: {}, normals computed: {}",
            report.unreferenced_vertices.len(),
            report.degenerate_triangles.len(),
            report.duplicate_positions,
            report.normals_computed
        )?;
    }
    Ok(())
}
