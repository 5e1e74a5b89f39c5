//! `cloth-vis anim compress | decompress | stats`: the clustered-PCA (CPCA) codec of crate
//! `anim-pca` (thesis §3.3.2, eqs. 3.14–3.18; `anim_pca::compress`) on files.
//!
//! - `compress` loads a clip (folder of numbered OBJ frames, `.npy` [F, V, 3] or an animated
//!   glTF), encodes it with [`Compressed::encode`] and writes the `.cpca` container.
//! - `decompress` reads a `.cpca`, rebuilds every frame with the CPU [`Decoder`] and writes
//!   them as `.npy` [F, V, 3], a `.glb` morph-target animation or a folder of OBJ frames,
//!   with the triangles stored in the file.
//! - `stats` compares a `.cpca` with its original: bpvf by eqs. 3.16–3.18 and from the file
//!   size, d_a (Karni–Gotsman) and the worst d_f.
//!
//! Every output is written atomically (`atomic_out::write_with`): a refused request or a
//! failed decode leaves no partial file behind. A corrupt `.cpca` gets the decoder's error
//! prefixed with the file's path.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anim_pca::compress::{
    Compressed, CpcaModel, CpcaParams, DEFAULT_BITS_TOLERANCE, Decoder, Distortion, RateParams,
    RateTarget, RdLimits, bpvf_from_file,
};

pub use super::cpca_bits::AutoBits;
use super::cpca_bits::choose_bits_for;
pub use super::cpca_decompress::DecompressArgs;
pub use super::cpca_figures::{cluster_strip, error_chart};
use super::cpca_search::SearchArg;
pub use super::cpca_search::{FrontierPosition, SearchMode, SearchReport};
use super::{anim_error, invalid};
use cloth_vis::Error;

/// What `cloth-vis anim compress` was asked to do.
#[derive(Clone, Debug)]
pub struct CompressRequest {
    /// The clip: a folder of numbered OBJ frames, `.npy` [F, V, 3] or an animated glTF.
    pub input: PathBuf,
    /// Which of its glTF clips (the first unless told).
    pub clip: meshio::ClipSelector,
    /// A mesh whose triangles (and UVs) a point-cache clip (`.npy`, `.pc2`, `.mdd`) takes.
    pub topology: Option<PathBuf>,
    /// k, c, c*, q_c, q_w, seed and the local-PCA limits.
    pub params: CpcaParams,
    /// Search for this target instead of using `params` as given: every parameter, or k
    /// alone as the thesis does (§3.3.2), as `search` says.
    pub target: Option<RateTarget>,
    /// How a target is searched.
    pub search: SearchMode,
    /// Choose q_c and/or q_w ([`choose_bits`]) instead of taking them from `params`: the
    /// fewest bits that add at most [`DEFAULT_BITS_TOLERANCE`] to the unquantized d_a. Only
    /// without a target.
    pub auto_bits: AutoBits,
    /// The `.cpca` file to write.
    pub out: PathBuf,
    /// Show the spinner over loading, fitting and measuring (stderr, terminals only).
    pub progress: bool,
}

/// Largest k `--target-da`/`--target-bpvf` tries unless told (`--k-max`).
pub const DEFAULT_K_MAX: usize = 32;

/// What `compress` produced and measured.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressSummary {
    /// Vertices V.
    pub vertices: usize,
    /// Frames F.
    pub frames: usize,
    /// Triangles stored.
    pub triangles: usize,
    /// The rate parameters actually used (k and c after clamping, c*, q_c, q_w).
    pub rate: RateParams,
    /// Size of the written file in bytes.
    pub file_bytes: usize,
    /// d_a and d_f of the decoded clip against the input.
    pub distortion: Distortion,
    /// Wall-clock seconds of [`Compressed::encode`] (fit, time PCA, quantization); with a
    /// target, of the whole search.
    pub encode_seconds: f64,
    /// With a target: what the search did, and whether the chosen point meets the target.
    pub search: Option<SearchReport>,
    /// With chosen bits: d_a of the unquantized model (32-bit codes) and the encodings tried.
    pub bits: Option<(f64, usize)>,
}

impl CompressSummary {
    /// Bits per vertex per frame of the written file (everything counted).
    pub fn bpvf_file(&self) -> f64 {
        bpvf_from_file(self.file_bytes, self.vertices, self.frames)
    }

    /// One line for the terminal: V, F, k, c, c*, q_c/q_w, file size, bpvf, d_a, worst d_f
    /// and the encode time (and, after a search, how many k were tried and whether the
    /// target was met).
    pub fn line(&self) -> String {
        let r = &self.rate;
        let (worst_frame, worst) = worst_frame(&self.distortion);
        let search = self
            .search
            .as_ref()
            .map_or_else(String::new, SearchReport::text);
        let bits = match self.bits {
            None => String::new(),
            Some((d0, tried)) => format!(
                "\nbits: q_c = {}, q_w = {} chosen ({tried} encodings): quantization adds {:.1e} \
                 to the unquantized d_a {d0:.4} (allowed: {:.0} % of it, or {:.0e} if more; \
                 --qc/--qw fix them)",
                r.bits_components,
                r.bits_weights,
                self.distortion.da - d0,
                100.0 * DEFAULT_BITS_TOLERANCE,
                anim_pca::compress::DA_FLOOR
            ),
        };
        format!(
            "compress: V = {}, F = {}, {} triangles, k = {}, c = {}, c* = {}, q_c = {}, q_w = {}: \
             {} bytes, {:.3} bpvf (file), d_a = {:.4}, worst d_f = {:.4e} (frame {}), \
             encoded in {:.2} s{}{bits}",
            self.vertices,
            self.frames,
            self.triangles,
            r.clusters,
            r.components,
            time_text(r.time_components),
            r.bits_components,
            r.bits_weights,
            self.file_bytes,
            self.bpvf_file(),
            self.distortion.da,
            worst,
            worst_frame,
            self.encode_seconds,
            search
        )
    }
}

/// What `cloth-vis anim stats` measured.
#[derive(Clone, Debug, PartialEq)]
pub struct StatsSummary {
    /// The rate parameters stored in the file.
    pub rate: RateParams,
    /// Size of the `.cpca` file in bytes.
    pub file_bytes: usize,
    /// d_a and d_f of the file's frames against the original.
    pub distortion: Distortion,
    /// With `--frontier`: the searched point at the file's rate, and how the file compares.
    pub frontier: Option<FrontierPosition>,
}

impl StatsSummary {
    /// Bits per vertex per frame of the file (everything counted).
    pub fn bpvf_file(&self) -> f64 {
        bpvf_from_file(self.file_bytes, self.rate.vertices, self.rate.frames)
    }

    /// The frame with the largest d_f and that d_f.
    pub fn worst_df(&self) -> (usize, f64) {
        worst_frame(&self.distortion)
    }

    /// One line for the terminal.
    pub fn line(&self) -> String {
        let r = &self.rate;
        let eq_3_18 = r
            .eq_3_18()
            .map_or_else(|| "-".to_owned(), |b| format!("{b:.3}"));
        let (frame, worst) = self.worst_df();
        format!(
            "stats: V = {}, F = {}, k = {}, c = {}, c* = {}, q_c = {}, q_w = {}: bpvf eq. 3.16 = \
             {:.3}, eq. 3.17 = {:.3}, eq. 3.18 = {}, file = {:.3} ({} bytes); d_a = {:.4}, \
             worst d_f = {:.4e} (frame {}){}",
            r.vertices,
            r.frames,
            r.clusters,
            r.components,
            time_text(r.time_components),
            r.bits_components,
            r.bits_weights,
            r.eq_3_16(),
            r.eq_3_17(),
            eq_3_18,
            self.bpvf_file(),
            self.file_bytes,
            self.distortion.da,
            worst,
            frame,
            self.frontier
                .as_ref()
                .map_or_else(String::new, FrontierPosition::text)
        )
    }
}

fn time_text(cs: Option<usize>) -> String {
    cs.map_or_else(|| "-".to_owned(), |c| c.to_string())
}

/// Index and value of the largest d_f (frame 0 and 0 for an empty list).
fn worst_frame(d: &Distortion) -> (usize, f64) {
    d.df.iter().copied().enumerate().fold(
        (0, 0.0),
        |best, (f, x)| if x > best.1 { (f, x) } else { best },
    )
}

/// Refuses a `--out` of `compress` that does not end in `.cpca`.
fn check_cpca_out(out: &Path) -> Result<(), Error> {
    if out
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("cpca"))
    {
        Ok(())
    } else {
        Err(invalid(
            out,
            "compress writes the .cpca container: give a file name ending in .cpca".to_owned(),
        ))
    }
}

fn read_bytes(path: &Path) -> Result<Vec<u8>, Error> {
    input_guard::read_regular(path).map_err(|e| Error::Io {
        path: path.to_owned(),
        reason: e.to_string(),
    })
}

/// Reads and validates a `.cpca` file; any decoder error is prefixed with the path.
///
/// Returns the animation and the file size in bytes.
///
/// # Errors
/// [`Error::Io`] if the file cannot be read; [`Error::Request`] naming the file with the
/// decoder's message if it is not a valid `.cpca` (bad magic, version, size, checksum, …).
pub fn read_cpca(path: &Path) -> Result<(Compressed, usize), Error> {
    let bytes = read_bytes(path)?;
    let data = Compressed::from_bytes(&bytes).map_err(|e| anim_error(path, e))?;
    Ok((data, bytes.len()))
}

/// Runs `compress`: load, encode, write the `.cpca` atomically, and measure the distortion of
/// the decoded result.
///
/// # Errors
/// An output name not ending in `.cpca`, refused before loading; loader errors naming the
/// input; encoder errors (bad parameters, a clip too large for the format) naming the input;
/// write errors naming the output.
pub fn run_compress(request: &CompressRequest) -> Result<CompressSummary, Error> {
    check_cpca_out(&request.out)?;
    super::check_output_file(&request.out, &[&request.input])?;
    let step = super::spinner(
        request.progress,
        format!("loading {}", request.input.display()),
    );
    let (clip, _) = meshio::load_animation(
        &request.input,
        &super::animation_options(&request.clip, request.topology.as_deref()),
    )?;
    step.set_message(format!(
        "clustered PCA of {} frames x {} vertices (k = {}, c = {})",
        clip.frames.len(),
        clip.vertex_count(),
        request.params.clusters,
        request.params.components
    ));
    let start = Instant::now();
    let auto = request.auto_bits;
    let (packed, search, bits) = match request.target {
        None if auto.components || auto.weights => {
            let model = CpcaModel::fit(&clip.frames, &request.params)
                .map_err(|e| anim_error(&request.input, e))?;
            let chosen = choose_bits_for(&model, &clip, &request.params, auto)
                .map_err(|e| anim_error(&request.input, e))?;
            (
                chosen.compressed,
                None,
                Some((chosen.da_unquantized, chosen.tried)),
            )
        }
        None => (
            Compressed::encode(
                &clip.frames,
                &clip.triangles,
                clip.frame_rate,
                &request.params,
            )
            .map_err(|e| anim_error(&request.input, e))?,
            None,
            None,
        ),
        Some(target) => {
            let (packed, report) =
                super::cpca_search::search(&clip, &request.params, target, request.search)
                    .map_err(|e| anim_error(&request.input, e))?;
            (packed, Some(report), None)
        }
    };
    let encode_seconds = start.elapsed().as_secs_f64();
    step.set_message("measuring the distortion of the decoded clip".to_owned());
    let bytes = packed.to_bytes();
    let distortion = Decoder::new(&packed)
        .distortion(&clip.frames)
        .map_err(|e| anim_error(&request.input, e))?;
    step.finish_and_clear();
    atomic_out::write_with(&request.out, |w| w.write_all(&bytes))?;
    Ok(CompressSummary {
        vertices: packed.vertices(),
        frames: packed.frames(),
        triangles: packed.triangles().len(),
        rate: packed.rate(),
        file_bytes: bytes.len(),
        distortion,
        encode_seconds,
        search,
        bits,
    })
}

/// Runs `stats`: the rate of `cpca` (eqs. 3.16–3.18 and file size) and its distortion
/// against `original`.
///
/// # Errors
/// A corrupt `.cpca` (the decoder's message prefixed with its path); loader errors naming the
/// original; a vertex or frame count that differs between the two, naming both files and
/// counts.
#[cfg(test)]
pub fn run_stats(original: &Path, cpca: &Path) -> Result<StatsSummary, Error> {
    run_stats_with_pictures(
        &StatsRequest {
            original: original.to_owned(),
            clip: meshio::ClipSelector::First,
            topology: None,
            cpca: cpca.to_owned(),
            clusters_png: None,
            error_plot: None,
            frontier: false,
            progress: false,
        },
        None,
    )
}

/// What `cloth-vis anim stats` was asked to do, pictures included.
#[derive(Clone, Debug, Default)]
pub struct StatsRequest {
    /// The original clip.
    pub original: PathBuf,
    /// Which of its glTF clips (the one compressed; the first unless told).
    pub clip: meshio::ClipSelector,
    /// A mesh whose triangles (and UVs) a point-cache clip (`.npy`, `.pc2`, `.mdd`) takes.
    pub topology: Option<PathBuf>,
    /// The `.cpca` file.
    pub cpca: PathBuf,
    /// Write the decoded mesh coloured by cluster (thesis Figs. 3.12/3.13) here, as a PNG
    /// strip of [`figures::strip::DEFAULT_STRIP_FRAMES`] frames (needs a GPU adapter; Mesa's
    /// lavapipe will do).
    pub clusters_png: Option<PathBuf>,
    /// Write d_f against the frame index (thesis Fig. 3.15) here, as an SVG chart.
    pub error_plot: Option<PathBuf>,
    /// Also search the frontier at the file's rate ([`FrontierPosition`]).
    pub frontier: bool,
    /// Show a spinner naming each step (stderr, terminals only).
    pub progress: bool,
}

/// Runs `stats` (bpvf, d_a, worst d_f) and writes the pictures `request` asks for. `gpu` is needed
/// only for `clusters_png`.
///
/// # Errors
/// A corrupt `.cpca`, loader errors and count mismatches, naming the files; a picture path with the wrong extension (refused before any work); a
/// missing GPU for `clusters_png` or a file without triangles ([`Error::Request`]);
/// rendering and write errors naming the picture.
pub fn run_stats_with_pictures(
    request: &StatsRequest,
    gpu: Option<&gpu_context::GpuContext>,
) -> Result<StatsSummary, Error> {
    let (original, cpca) = (request.original.as_path(), request.cpca.as_path());
    super::refuse_swapped_stats("anim stats", original, cpca, "cpca")?;
    for (path, ext) in [(&request.clusters_png, "png"), (&request.error_plot, "svg")] {
        if let Some(p) = path.as_ref().filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .map(str::to_ascii_lowercase)
                .as_deref()
                != Some(ext)
        }) {
            return Err(invalid(
                p,
                format!("this picture is written as .{ext}; name it so"),
            ));
        }
    }
    if let (Some(png), None) = (&request.clusters_png, gpu) {
        return Err(invalid(
            png,
            "--clusters-png renders with wgpu and no GPU adapter was found (install Mesa's \
             lavapipe: apt-get install mesa-vulkan-drivers)"
                .to_owned(),
        ));
    }
    let step = super::spinner(request.progress, format!("loading {}", original.display()));
    let (data, file_bytes) = read_cpca(cpca)?;
    let (clip, _) = meshio::load_animation(
        original,
        &super::animation_options(&request.clip, request.topology.as_deref()),
    )?;
    step.set_message("decoding and measuring d_a, d_f".to_owned());
    let (f, v) = (
        clip.frames.len(),
        clip.frames.first().map_or(0, std::vec::Vec::len),
    );
    if (f, v) != (data.frames(), data.vertices()) {
        return Err(invalid(
            original,
            format!(
                "has {f} frames x {v} vertices but {} holds {} frames x {} vertices; compare a \
                 .cpca with the clip it was compressed from (a glTF with several clips: \
                 --clip NAME|INDEX names the one that was compressed)",
                cpca.display(),
                data.frames(),
                data.vertices()
            ),
        ));
    }
    let distortion = Decoder::new(&data)
        .distortion(&clip.frames)
        .map_err(|e| anim_error(original, e))?;
    if let (Some(png), Some(gpu)) = (&request.clusters_png, gpu) {
        let image = cluster_strip(gpu, &data, png)?;
        figures::strip::write_png(png, &image)?;
    }
    if let Some(svg) = &request.error_plot {
        let chart = error_chart(&distortion, cpca);
        atomic_out::write_with(svg, |w| w.write_all(chart.as_bytes()))?;
    }
    step.set_message("searching the rate-distortion frontier at the file's rate".to_owned());
    let frontier = request
        .frontier
        .then(|| {
            let bpvf = bpvf_from_file(file_bytes, data.vertices(), data.frames());
            FrontierPosition::measure(&clip, bpvf, distortion.da)
        })
        .transpose()
        .map_err(|e| anim_error(original, e))?;
    step.finish_and_clear();
    Ok(StatsSummary {
        rate: data.rate(),
        file_bytes,
        distortion,
        frontier,
    })
}

/// `cloth-vis anim compress`: the flags of a [`CompressRequest`].
#[derive(clap::Args)]
pub struct CompressArgs {
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
    /// k: vertex clusters (clamped to V).
    #[arg(long, default_value_t = CpcaParams::default().clusters)]
    clusters: usize,
    /// c: eigentrajectories per cluster (clamped to 3F) [default: 20].
    #[arg(long, value_name = "C")]
    components: Option<usize>,
    /// c*: components of the second PCA along time (default: none).
    #[arg(long, value_name = "C*")]
    time_components: Option<usize>,
    /// q_c: bits of the means and eigentrajectories, 1..=32 (default: the fewest that add at
    /// most 1 % to the unquantized d_a, measured; 18 with a target).
    #[arg(long, value_name = "BITS")]
    qc: Option<u8>,
    /// q_w: bits of the weights, 1..=32 (default: chosen as q_c is; 18 with a target).
    #[arg(long, value_name = "BITS")]
    qw: Option<u8>,
    /// Seed of the local PCA (same seed, same file).
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Instead of --clusters: the smallest file whose decoded clip has d_a ≤ X, searched over
    /// k, c, c*, q_c and q_w (see --search).
    #[arg(long, value_name = "X", conflicts_with_all = ["clusters", "target_bpvf"])]
    target_da: Option<f64>,
    /// Instead of --clusters: the lowest d_a whose file needs ≤ X bits per vertex per frame,
    /// searched over k, c, c*, q_c and q_w (see --search).
    #[arg(long, value_name = "X", conflicts_with = "clusters")]
    target_bpvf: Option<f64>,
    /// How a target is searched: `full` (k, c, c*, q_c, q_w; --components, --time-components,
    /// --qc and --qw are searched, not used) or `k` (the thesis's §3.3.2 search: k = 1, 2, …
    /// with the given c, c* and bits, 18 unless told).
    #[arg(long, value_enum, default_value_t = SearchArg::Full)]
    search: SearchArg,
    /// Largest k a --target-da/--target-bpvf search tries.
    #[arg(long, default_value_t = DEFAULT_K_MAX)]
    k_max: usize,
    /// Largest c a full search tries (clamped to 3F).
    #[arg(long, default_value_t = RdLimits::default().c_max)]
    c_max: usize,
    /// Most local-PCA fits a full search runs (its cost: each fit is one clustering of the
    /// clip).
    #[arg(long, default_value_t = RdLimits::default().max_fits)]
    max_fits: usize,
    /// Largest V·k·c·3F (one local-PCA iteration) a full search fits.
    #[arg(long, default_value_t = RdLimits::default().max_cost)]
    max_cost: f64,
    /// Output: FILE.cpca.
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Hide the progress spinner.
    #[arg(long)]
    quiet: bool,
}

impl CompressArgs {
    /// Encode and write; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        super::cpca_search::check_flags(
            [
                ("--target-da", self.target_da),
                ("--target-bpvf", self.target_bpvf),
                ("--max-cost", Some(self.max_cost)),
            ],
            [
                ("--k-max", self.k_max),
                ("--c-max", self.c_max),
                ("--max-fits", self.max_fits),
            ],
            [
                ("--components", self.components.is_some()),
                ("--time-components", self.time_components.is_some()),
                ("--qc", self.qc.is_some()),
                ("--qw", self.qw.is_some()),
            ],
            self.search,
        )?;
        let target = match (self.target_da, self.target_bpvf) {
            (Some(x), _) => Some(RateTarget::Distortion(x)),
            (None, Some(x)) => Some(RateTarget::Bpvf(x)),
            (None, None) => None,
        };
        let request = CompressRequest {
            input: self.input,
            clip: self.clip.unwrap_or_default(),
            topology: self.topology,
            params: CpcaParams {
                clusters: self.clusters,
                components: self.components.unwrap_or(CpcaParams::default().components),
                time_components: self.time_components,
                bits_components: self.qc.unwrap_or(anim_pca::compress::DEFAULT_BITS),
                bits_weights: self.qw.unwrap_or(anim_pca::compress::DEFAULT_BITS),
                seed: self.seed,
                ..Default::default()
            },
            target,
            search: match self.search {
                SearchArg::Full => SearchMode::Full(RdLimits {
                    k_max: self.k_max,
                    c_max: self.c_max,
                    max_fits: self.max_fits,
                    max_cost: self.max_cost,
                    ..RdLimits::default()
                }),
                SearchArg::K => SearchMode::Clusters { k_max: self.k_max },
            },
            auto_bits: AutoBits {
                components: self.qc.is_none(),
                weights: self.qw.is_none(),
            },
            out: self.out,
            progress: !self.quiet,
        };
        let line = run_compress(&request)?.line();
        super::print_summary(&line, [request.out.as_path()])
    }
}

/// `cloth-vis anim stats`: the flags of a [`StatsRequest`].
#[derive(clap::Args)]
pub struct StatsArgs {
    /// The original clip (folder of .obj frames, .npy or .glb).
    original: PathBuf,
    /// The .cpca file.
    cpca: PathBuf,
    /// The glTF animation to sample, by name or index (the one that was compressed; default: the first).
    #[arg(long, value_name = "NAME|INDEX", value_parser = super::parse::clip)]
    clip: Option<meshio::ClipSelector>,
    /// A mesh (.ply .obj .gltf .glb) whose triangles and UVs a point-cache clip (.npy, .pc2,
    /// .mdd) takes; its vertex count must match.
    #[arg(long, value_name = "MESH")]
    topology: Option<PathBuf>,

    /// Also write the decoded mesh coloured by cluster (Figs. 3.12/3.13) as a PNG strip.
    #[arg(long, value_name = "FILE.png")]
    clusters_png: Option<PathBuf>,
    /// Also write d_f against the frame (Fig. 3.15) as an SVG chart.
    #[arg(long, value_name = "FILE.svg")]
    error_plot: Option<PathBuf>,
    /// Also say where the file sits against the rate–distortion frontier: the full
    /// `--target-bpvf` search at the file's own rate (about a minute on a 3,000-vertex,
    /// 170-frame clip).
    #[arg(long)]
    frontier: bool,
    /// Hide the progress spinner.
    #[arg(long)]
    quiet: bool,
}

impl StatsArgs {
    /// Compare, write the pictures asked for; print the summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let gpu = match &self.clusters_png {
            Some(png) => Some(super::required_gpu(png, "--clusters-png")?),
            None => None,
        };
        let request = StatsRequest {
            original: self.original,
            clip: self.clip.unwrap_or_default(),
            topology: self.topology,
            cpca: self.cpca,
            clusters_png: self.clusters_png,
            error_plot: self.error_plot,
            frontier: self.frontier,
            progress: !self.quiet,
        };
        let line = run_stats_with_pictures(&request, gpu.as_ref())?.line();
        let outputs = [&request.clusters_png, &request.error_plot];
        super::print_summary(&line, outputs.into_iter().flatten().map(PathBuf::as_path))
    }
}
