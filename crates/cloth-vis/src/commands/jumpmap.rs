//! `cloth-vis anim jumpmap`: endless new animation from a short mesh clip by jump maps
//! (thesis §3.2, crate `anim-pca`), written as `.npy` [N, V, 3], a `.glb` morph-target
//! animation or a folder of numbered OBJ frames, with the analysis matrices D, D*, P, P*, P̂
//! as PNG heat maps (the thesis's Fig. 3.3) and a rendered strip of frames of the new
//! sequence ([`figures::strip`]).

use std::path::{Path, PathBuf};

use anim_pca::{Blend, Clip, JumpMap, JumpMapParams, LoopTable, PlaybackParams, Player};
use glam::Vec3;
use gpu_context::GpuContext;

use super::{anim_error, invalid};
use cloth_vis::Error;
use figures::strip::{check_strip, render_strip, write_png};

/// A rendered strip of frames of the generated sequence (`--strip`).
#[derive(Clone, Debug, PartialEq)]
pub struct StripRequest {
    /// The `.png` to write.
    pub path: PathBuf,
    /// Panels K: frames shown, evenly spaced over the generated run from its first to its
    /// last frame (default [`figures::strip::DEFAULT_STRIP_FRAMES`]).
    pub frames: usize,
    /// Size of one panel in pixels (width, height); the image is K · width × height.
    pub panel_size: [u32; 2],
}

#[cfg(test)]
impl StripRequest {
    /// A strip of the default [`figures::strip::DEFAULT_STRIP_FRAMES`] panels of the default
    /// size into `path`.
    pub fn new(path: PathBuf) -> Self {
        Self {
            path,
            frames: figures::strip::DEFAULT_STRIP_FRAMES,
            panel_size: figures::strip::DEFAULT_PANEL_SIZE,
        }
    }
}

/// How the generated run is steered beyond random play: cells and motion control
/// (thesis §3.2.2 "Motion Control") or a fixed-length loop (Fig. 3.2's loop table).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlayControl {
    /// Further clips, analysed with the input as cells 1, 2, … (the input is cell 0); they must
    /// have the input's vertex count.
    pub cells: Vec<PathBuf>,
    /// (generated frame, cell): from that frame on, move into that cell at the best transition
    /// ahead ([`Player::set_target_cell`]). Applied in frame order.
    pub cell_at: Vec<(usize, usize)>,
    /// Play the cheapest loop of exactly this many frames ([`LoopTable`]) instead of random
    /// play; the output repeats it to `frames`.
    pub loop_length: Option<usize>,
}

/// What `cloth-vis anim jumpmap` was asked to do.
#[derive(Clone, Debug)]
pub struct JumpMapRequest {
    /// The clip: a folder of numbered OBJ frames, `.npy` [F, V, 3] or an animated glTF.
    pub input: PathBuf,
    /// Which of the input's glTF clips (the first unless told; `--cell` files use their first).
    pub clip: meshio::ClipSelector,
    /// A mesh whose triangles (and UVs) a point-cache clip (`.npy`, `.pc2`, `.mdd`) takes.
    pub topology: Option<PathBuf>,
    /// Analysis parameters (c, c*, σ, σ*, q, q*, root motion).
    pub params: JumpMapParams,
    /// Cells, a cell schedule or a loop length.
    pub control: PlayControl,
    /// Playback parameters (memory m, blending, seed).
    pub playback: PlaybackParams,
    /// Frames to generate.
    pub frames: usize,
    /// `.npy`, `.glb`, or a folder (no extension) of `frame_00000.obj` …
    pub out: PathBuf,
    /// Replace an output folder that holds files (else refused before any work).
    pub force: bool,
    /// Most bytes of generated positions held in memory ([`MAX_GENERATED_BYTES`] by default).
    pub memory_limit: u64,
    /// Folder for the heat maps `D.png`, `D_velocity.png`, `P.png`, `P_velocity.png`,
    /// `P_hat.png` (`None`: none written).
    pub maps: Option<PathBuf>,
    /// A rendered strip of frames of the generated sequence (`None`: none written; needs a
    /// GPU adapter, lavapipe is fine).
    pub strip: Option<StripRequest>,
    /// Show a spinner naming each step (stderr, terminals only).
    pub progress: bool,
}

/// What was generated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JumpMapSummary {
    /// Clip frames and vertices.
    pub clip_frames: usize,
    /// Vertices per frame.
    pub vertices: usize,
    /// PCA components used (c, c*).
    pub components: (usize, usize),
    /// Statistics of the generated run.
    pub stats: anim_pca::jumpmap::metrics::SequenceStats,
    /// The loop played, for `--loop N`.
    pub loop_info: Option<LoopInfo>,
}

/// What a `--loop N` run played: one period of the cheapest acceptable loop
/// ([`anim_pca::jumpmap::loops`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LoopInfo {
    /// N: generated frames per period, blend frames included.
    pub length: usize,
    /// Jumps per period.
    pub jumps: usize,
    /// Distinct clip frames the period shows.
    pub distinct_frames: usize,
    /// Key frames of its shortest stretch of natural play between two jumps.
    pub shortest_run: usize,
    /// Σ −ln s_ij over its jumps.
    pub cost: f64,
    /// Core frames of the cell (frames the pruned jump map can always return to).
    pub core_frames: usize,
}

/// The refusal of `--loop n` when the clip has no acceptable loop of that length, naming the
/// nearest lengths below and above that have one.
fn no_loop_message(table: &LoopTable, n: usize) -> String {
    let below: Vec<String> = (2..n)
        .rev()
        .filter(|&m| table.get(m).is_some())
        .take(3)
        .map(|m| m.to_string())
        .collect();
    let above: Vec<String> = (n + 1..=table.max_len())
        .filter(|&m| table.get(m).is_some())
        .take(3)
        .map(|m| m.to_string())
        .collect();
    let list = |v: &[String]| {
        if v.is_empty() {
            "none".to_owned()
        } else {
            v.join(", ")
        }
    };
    format!(
        "--loop {n}: the clip has no acceptable loop of exactly {n} frames (one whose every \
         stretch of natural play between jumps lasts at least {} key frames, so that it does \
         not oscillate over a handful of frames); nearest lengths that have one: below {}, \
         above (up to {}) {}",
        table.min_run(n),
        list(&below),
        table.max_len(),
        list(&above)
    )
}

impl JumpMapSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        let s = &self.stats;
        format!(
            "jumpmap: {} frames from a {}-frame clip of {} vertices (c = {}, c* = {}): {} transitions, \
             {} distinct, {:.0}% of the clip visited, jump residual mean {:.2} / max {:.2} d̄",
            s.frames,
            self.clip_frames,
            self.vertices,
            self.components.0,
            self.components.1,
            s.transitions,
            s.distinct_transitions,
            100.0 * s.coverage,
            s.mean_jump_distance,
            s.max_jump_distance
        ) + &self.loop_info.map_or(String::new(), |l| {
            format!(
                "\nloop: {} frames per period, {} jump(s), {} distinct clip frames, shortest \
                 stretch of natural play {} key frames, cost {:.3}",
                l.length, l.jumps, l.distinct_frames, l.shortest_run, l.cost
            ) + &if l.core_frames < 2 * anim_pca::jumpmap::loops::MIN_STRETCH {
                format!(
                    "\nwarning: the clip's core, the frames its jump map can always return to, \
                     is only {} frames, so every loop plays stretches this short; a larger \
                     --sigma or --q widens it",
                    l.core_frames
                )
            } else {
                String::new()
            }
        })
    }
}

/// Most bytes of generated positions (F × V × 12) one `anim jumpmap` run holds by default:
/// 4 GB, e.g. 100,000 frames of a 3,000-vertex cloth; `--memory-gb` raises it.
pub const MAX_GENERATED_BYTES: u64 = 4_000_000_000;

/// The kind of output `out` names.
enum OutKind {
    Npy,
    Glb,
    /// A vertex-animation texture (`.exr`, `.png`).
    Vat,
    /// With what to do about an existing folder.
    ObjFolder(atomic_out::ExistingFolder),
}

/// Runs the request. `gpu` is needed only for [`JumpMapRequest::strip`].
///
/// # Errors
/// Loader errors naming the file; bad parameters (naming the parameter and value), an
/// unsupported output extension, a zero frame count, a strip without a GPU adapter or with a
/// bad panel count or size, refused before any computation; a strip of a clip without
/// triangles, refused before the analysis; write errors naming the file.
pub fn run_jumpmap(
    request: &JumpMapRequest,
    gpu: Option<&GpuContext>,
) -> Result<JumpMapSummary, Error> {
    let out = &request.out;
    let inputs: Vec<&Path> = std::iter::once(request.input.as_path())
        .chain(request.control.cells.iter().map(PathBuf::as_path))
        .collect();
    super::refuse_overwriting_input(out, &inputs)?;
    let kind = match out
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("npy") => OutKind::Npy,
        Some("glb") => OutKind::Glb,
        Some("exr" | "png") => OutKind::Vat,
        None => OutKind::ObjFolder(super::folder_output(out, request.force)?),
        Some(other) => {
            return Err(invalid(
                out,
                format!(
                    "output extension .{other} is not supported: use .npy ([N, V, 3]), .glb \
                     (morph-target animation), .exr/.png (vertex-animation texture) or a \
                     folder name without extension (OBJ frames)"
                ),
            ));
        }
    };
    if !matches!(kind, OutKind::ObjFolder(_)) {
        atomic_out::check_writable(out)?;
    }
    // The heat-map folder is a folder output too: refused before any work when it holds files.
    let maps_existing = request
        .maps
        .as_deref()
        .map(|dir| super::folder_output(dir, request.force))
        .transpose()?;
    if request.frames == 0 {
        return Err(invalid(out, "--frames must be at least 1".to_owned()));
    }
    let strip_gpu = match &request.strip {
        None => None,
        Some(strip) => {
            let is_png = strip
                .path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("png"));
            if !is_png {
                return Err(invalid(
                    &strip.path,
                    "--strip writes a PNG: give a file name ending in .png".to_owned(),
                ));
            }
            check_strip(request.frames, strip.frames, strip.panel_size, &strip.path)?;
            super::check_output_file(&strip.path, &inputs)?;
            let Some(gpu) = gpu else {
                return Err(invalid(
                    &strip.path,
                    "--strip needs a GPU adapter and none was found; a software one is fine \
                     (Mesa's lavapipe: apt-get install mesa-vulkan-drivers)"
                        .to_owned(),
                ));
            };
            Some((strip, gpu))
        }
    };
    let step = super::spinner(
        request.progress,
        format!("loading {}", request.input.display()),
    );
    let (clip, _) = meshio::load_animation(
        &request.input,
        &super::animation_options(&request.clip, request.topology.as_deref()),
    )?;
    // The generated run is held in memory before it is written: bound it by a named limit
    // rather than growing until the kernel kills the process (issue #12).
    let run_bytes = (request.frames as u128) * (clip.vertex_count() as u128) * 12;
    if run_bytes > u128::from(request.memory_limit) {
        return Err(invalid(
            out,
            format!(
                "--frames {}: {} frames of {} vertices take {:.1} GB, above the {:.1} GB this \
                 command holds in memory (--memory-gb); generate fewer frames per run (the \
                 jump map is endless: run again with another --seed for more), or raise \
                 --memory-gb on a machine that has it",
                request.frames,
                request.frames,
                clip.vertex_count(),
                run_bytes as f64 / 1e9,
                request.memory_limit as f64 / 1e9
            ),
        ));
    }
    let size = (request.frames, clip.vertex_count(), clip.triangles.len());
    let (obj, levers) = (
        matches!(kind, OutKind::ObjFolder(_)),
        "fewer --frames per run",
    );
    super::output_size::check_frames(out, obj, size, levers, request.force)?;
    if matches!(kind, OutKind::Vat) {
        let size = (request.frames, clip.vertex_count());
        super::vat_out::check(&request.input, out, &clip.triangles, size)?;
    }
    if strip_gpu.is_some() && clip.triangles.is_empty() {
        return Err(invalid(
            &request.input,
            "--strip draws triangles and the clip has none (an .npy clip): leave out --strip"
                .to_owned(),
        ));
    }
    let control = &request.control;
    if control.loop_length.is_some() && !control.cell_at.is_empty() {
        return Err(invalid(
            &request.input,
            "--loop plays one fixed loop and --cell-at steers random play: give one of them"
                .to_owned(),
        ));
    }
    let mut cells = Vec::with_capacity(control.cells.len());
    for path in &control.cells {
        let (cell, _) = meshio::load_animation(path, &meshio::AnimationOptions::default())?;
        let (found, expected) = (cell.frames[0].len(), clip.frames[0].len());
        if found != expected {
            return Err(invalid(
                path,
                format!(
                    "--cell clip has {found} vertices but {} has {expected}; cells share one mesh",
                    request.input.display()
                ),
            ));
        }
        cells.push(cell);
    }
    let clips: Vec<Clip<'_>> = std::iter::once(&clip)
        .chain(&cells)
        .map(|c| Clip::new(&c.frames))
        .collect();
    for &(at, cell) in &control.cell_at {
        if cell >= clips.len() {
            return Err(invalid(
                &request.input,
                format!(
                    "--cell-at {at}:{cell} names cell {cell} but there are {} cell(s) (the \
                     input is cell 0, each --cell adds one)",
                    clips.len()
                ),
            ));
        }
    }
    step.set_message(format!(
        "analysing {} frames (PCA, frame distances, transitions)",
        clip.frames.len() + cells.iter().map(|c| c.frames.len()).sum::<usize>()
    ));
    let map = JumpMap::analyze_cells(&clips, &request.params)
        .map_err(|e| anim_error(&request.input, e))?;
    step.set_message(format!("generating {} frames", request.frames));
    let (generated, loop_info) = generate(&map, request)?;
    let stats = anim_pca::jumpmap::metrics::sequence_stats(&map, &generated);
    let offsets = map.root_offsets(&generated.frames);

    // Output frames are the clip's own frames outside blends (bit for bit without root
    // motion) and position-space cross-fades inside them: c shapes the analysis only.
    let vertices = map.n_vertices();
    let clip_frames: Vec<&[Vec3]> = std::iter::once(&clip)
        .chain(&cells)
        .flat_map(|c| c.frames.iter().map(Vec::as_slice))
        .collect();
    let mut frames = Vec::with_capacity(request.frames);
    for (frame, offset) in generated.frames.iter().zip(&offsets) {
        let mut mesh = vec![Vec3::ZERO; vertices];
        map.exact_frame_into(&clip_frames, frame, *offset, &mut mesh)
            .map_err(|e| anim_error(&request.input, e))?;
        frames.push(mesh);
    }
    if let Some((strip, gpu)) = strip_gpu {
        step.set_message(format!("rendering {}", strip.path.display()));
        let image = render_strip(
            &gpu.device,
            &gpu.queue,
            &frames,
            &clip.triangles,
            &figures::strip::StripOptions {
                count: strip.frames,
                panel_size: strip.panel_size,
                albedo: None,
            },
            &strip.path,
        )?;
        write_png(&strip.path, &image)?;
    }
    step.set_message(format!("writing {}", out.display()));
    match kind {
        // Streamed frame by frame: no second copy of the run in memory.
        OutKind::Npy => meshio::write_npy_frames(out, frames.len(), vertices, &frames)?,
        OutKind::Glb => {
            if clip.triangles.is_empty() {
                return Err(invalid(
                    &request.input,
                    "the clip has no triangles (an .npy clip): write .npy instead of .glb"
                        .to_owned(),
                ));
            }
            let animation = meshio::Animation {
                triangles: clip.triangles.clone(),
                frames,
                frame_rate: clip.frame_rate,
                uvs: clip.uvs.clone(),
            };
            meshio::write_glb_animation(out, &animation)?;
        }
        OutKind::Vat => {
            let line = super::vat_out::write(
                out,
                &clip.triangles,
                clip.frame_rate,
                (frames.len(), vertices),
                |f, p, _| {
                    p.copy_from_slice(&frames[f]);
                    Ok(())
                },
            )?;
            eprintln!("{line}");
        }
        OutKind::ObjFolder(existing) => super::obj_frames::write_obj_frames(
            out,
            existing,
            frames.iter().map(Ok),
            &clip.triangles,
            "cloth-vis anim jumpmap, generated",
        )?,
    }
    if let (Some(dir), Some(existing)) = (&request.maps, maps_existing) {
        super::jumpmap_maps::write_maps(dir, existing, &map)?;
    }
    step.finish_and_clear();
    Ok(JumpMapSummary {
        clip_frames: map.n_frames(),
        vertices,
        components: (map.components(), map.velocity_components()),
        stats,
        loop_info,
    })
}

/// The new sequence `request` asks of `map`: the cheapest loop of `--loop` frames, or random
/// play steered by `--cell-at`; with the loop's figures.
fn generate(
    map: &JumpMap,
    request: &JumpMapRequest,
) -> Result<(anim_pca::Generated, Option<LoopInfo>), Error> {
    let control = &request.control;
    Ok(match control.loop_length {
        Some(n) => {
            let cell = map.cell_of(request.playback.start_frame.min(map.n_frames() - 1));
            // A quarter beyond n, for the nearest lengths to offer when n has no loop.
            let reach = (n + n / 4 + 2).min(anim_pca::jumpmap::loops::MAX_LOOP_LENGTH);
            let table = LoopTable::build(map, cell, reach, request.playback.blend)
                .map_err(|e| anim_error(&request.input, e))?;
            let Some(found) = table.get(n) else {
                return Err(invalid(&request.input, no_loop_message(&table, n)));
            };
            let info = LoopInfo {
                length: n,
                jumps: found.transitions.len(),
                distinct_frames: found.distinct_frames(),
                shortest_run: found.shortest_run(),
                cost: found.cost,
                core_frames: table.core_frames(),
            };
            (found.play(request.frames), Some(info))
        }
        None => {
            let mut player =
                Player::new(map, &request.playback).map_err(|e| anim_error(&request.input, e))?;
            let mut schedule = control.cell_at.clone();
            schedule.sort_by_key(|&(at, _)| at);
            let mut generated = anim_pca::Generated::default();
            for (at, cell) in schedule {
                let upto = at.min(request.frames);
                let part = player.generate(upto.saturating_sub(generated.frames.len()));
                generated.frames.extend(part.frames);
                generated.transitions.extend(part.transitions);
                player
                    .set_target_cell(cell)
                    .map_err(|e| anim_error(&request.input, e))?;
            }
            let rest = player.generate(request.frames - generated.frames.len());
            generated.frames.extend(rest.frames);
            generated.transitions.extend(rest.transitions);
            (generated, None)
        }
    })
}

/// Parses `--cell-at FRAME:CELL`.
///
/// # Errors
/// A message naming the text when it is not two unsigned integers joined by `:`.
pub fn parse_cell_at(text: &str) -> Result<(usize, usize), String> {
    let parse = |part: Option<&str>| part.and_then(|p| p.trim().parse::<usize>().ok());
    let mut parts = text.splitn(2, ':');
    match (parse(parts.next()), parse(parts.next())) {
        (Some(frame), Some(cell)) => Ok((frame, cell)),
        _ => Err(format!(
            "`{text}` is not FRAME:CELL (e.g. 300:1 moves into cell 1 from generated frame 300)"
        )),
    }
}

/// Playback blending from the CLI's `--blend B` / `--smoothness S` (at most one; neither:
/// the thesis's b = 3).
pub fn blend_from_flags(blend: Option<usize>, smoothness: Option<f64>) -> Blend {
    match (blend, smoothness) {
        (_, Some(s)) => Blend::Smoothness(s),
        (Some(0), None) => Blend::None,
        (Some(b), None) => Blend::Fixed(b),
        (None, None) => Blend::Fixed(3),
    }
}

/// `cloth-vis anim jumpmap`: the flags of a [`JumpMapRequest`].
#[derive(clap::Args)]
pub struct JumpmapArgs {
    /// The clip: a folder of numbered .obj frames, .npy [F, V, 3] or an animated .glb.
    input: PathBuf,
    /// The glTF animation to sample, by name or index (default: the file's first; other
    /// formats hold one clip).
    #[arg(long, value_name = "NAME|INDEX", value_parser = super::parse::clip)]
    clip: Option<meshio::ClipSelector>,
    /// A mesh (.ply .obj .gltf .glb) whose triangles and UVs a point-cache clip (.npy, .pc2,
    /// .mdd) takes; its vertex count must match.
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,
    /// A further clip of the same mesh, analysed as the next cell (motion control,
    /// thesis §3.2.2); repeat for more cells. The input is cell 0.
    #[arg(long, value_name = "CLIP")]
    cell: Vec<PathBuf>,
    /// From generated frame FRAME on, move into cell CELL at the best transition ahead;
    /// repeat to script a route (e.g. --cell-at 200:1 --cell-at 500:0).
    #[arg(long, value_name = "FRAME:CELL", value_parser = parse_cell_at)]
    cell_at: Vec<(usize, usize)>,
    /// Play the cheapest loop of exactly N frames (blend frames included), repeated,
    /// instead of random play.
    #[arg(long = "loop", value_name = "N", conflicts_with = "cell_at")]
    loop_length: Option<usize>,
    /// Take the clip's travel out before the analysis and replay it by integration (for
    /// clips that walk across the scene).
    #[arg(long)]
    root_motion: bool,
    /// c: PCA components of the frames, for the analysis only (distances D, jump
    /// probabilities, blend lengths); output frames are the clip's own frames outside blends
    /// and position-space cross-fades inside them, whatever c.
    #[arg(long, default_value_t = 10)]
    components: usize,
    /// c*: PCA components of the central velocities (analysis only, like c).
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
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an existing output folder that holds files, once the new frames are complete;
    /// write an output estimated above 8 GiB.
    #[arg(long)]
    force: bool,
    /// Most gigabytes of generated positions (frames × vertices × 12 bytes) held in memory.
    #[arg(long, default_value_t = MAX_GENERATED_BYTES as f64 / 1e9, value_parser = parse_memory_gb)]
    memory_gb: f64,
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
        default_value_t = figures::strip::DEFAULT_STRIP_FRAMES
    )]
    strip_frames: usize,
    /// Size of one --strip panel; the image is K·W × H.
    #[arg(
        long,
        value_name = "WxH",
        requires = "strip",
        value_parser = super::parse::size,
        default_value = "256x256"
    )]
    strip_size: [u32; 2],
    /// Hide the progress spinner.
    #[arg(long)]
    quiet: bool,
}

/// `--memory-gb`: a finite number of gigabytes > 0.
fn parse_memory_gb(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(gb) if gb.is_finite() && gb > 0.0 && gb <= 1e6 => Ok(gb),
        _ => Err(format!("{text:?} is not a number of gigabytes in (0, 1e6]")),
    }
}

impl JumpmapArgs {
    /// The request these flags describe.
    fn request(self) -> JumpMapRequest {
        JumpMapRequest {
            input: self.input,
            clip: self.clip.unwrap_or_default(),
            topology: self.topology,
            params: JumpMapParams {
                components: self.components,
                velocity_components: self.velocity_components,
                sigma: self.sigma,
                sigma_velocity: self.sigma_v,
                q: self.q,
                q_velocity: self.qv,
                root_motion: if self.root_motion {
                    anim_pca::RootMotion::Extract
                } else {
                    anim_pca::RootMotion::Keep
                },
                ..Default::default()
            },
            control: PlayControl {
                cells: self.cell,
                cell_at: self.cell_at,
                loop_length: self.loop_length,
            },
            playback: PlaybackParams {
                memory: self.memory,
                blend: blend_from_flags(self.blend, self.smoothness),
                seed: self.seed,
                ..Default::default()
            },
            frames: self.frames,
            out: self.out,
            force: self.force,
            memory_limit: (self.memory_gb * 1e9) as u64,
            maps: self.maps,
            strip: self.strip.map(|path| StripRequest {
                path,
                frames: self.strip_frames,
                panel_size: self.strip_size,
            }),
            progress: !self.quiet,
        }
    }

    /// Generate and write; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let request = self.request();
        let gpu = match &request.strip {
            Some(strip) => Some(super::required_gpu(&strip.path, "--strip")?),
            None => None,
        };
        let summary = run_jumpmap(&request, gpu.as_ref())?;
        let outputs = std::iter::once(&request.out)
            .chain(&request.maps)
            .chain(request.strip.as_ref().map(|s| &s.path));
        super::print_summary(&summary.line(), outputs.map(PathBuf::as_path))
    }
}
