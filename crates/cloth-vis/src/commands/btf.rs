//! `cloth-vis btf synth | compress | stats`: measured-material (BTF) data on files, through
//! crate `btf` (thesis §5.3–5.5) and the woven-cloth generator of `synth`.
//!
//! - `synth` writes the synthetic woven-cloth BTF (`synth::WovenBtf`) as a folder of 81 × 81
//!   8-bit sRGB PNGs named as the Bonn UBO2003 archives name them (`tl… pl… tv… pv….png`),
//!   so that everything downstream reads it through the same loader as measured data. The
//!   folder appears complete or not at all: it is written under a temporary name beside the
//!   target and renamed at the end.
//! - `compress` runs the per-view PCA (§5.4, eq. 5.1) slot by slot and writes a `.btfpca`.
//! - `stats` compares a `.btfpca` with its folder: sizes, RMS error in 8-bit sRGB units and
//!   PSNR over every image.

use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::{BtfDir, BtfPca, BtfPcaParams, ErrorStats, Sampling};

use super::invalid as request;
use cloth_vis::Error;
use cloth_vis::run::progress_bar as bar;

/// What `cloth-vis btf synth` was asked to do.
#[derive(Clone, Debug)]
pub struct SynthRequest {
    /// The generator's parameters (resolution, weave, colours, supersampling).
    pub params: synth::WovenBtfParams,
    /// The measured direction set, H1 or H2 (Table 5.1).
    pub sampling: Sampling,
    /// The folder to create; it must not exist or be empty unless `force`.
    pub out: PathBuf,
    /// Replace an `out` that holds files, once the new folder is complete.
    pub force: bool,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// What `synth` wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthSummary {
    /// Texels per image side.
    pub res: usize,
    /// The sampling written.
    pub sampling: Sampling,
    /// Images written (81 × 81).
    pub images: usize,
    /// Bytes on disk.
    pub bytes: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl SynthSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        format!(
            "btf synth: {} images of {r}x{r} ({}), {:.1} MB of PNG, {:.1} s",
            self.images,
            self.sampling.name(),
            self.bytes as f64 / 1e6,
            self.seconds,
            r = self.res
        )
    }
}

/// What `cloth-vis btf compress` was asked to do.
#[derive(Clone, Debug)]
pub struct CompressRequest {
    /// The BTF folder.
    pub dir: PathBuf,
    /// c, storage of the eigen-normtextures and of the means.
    pub params: BtfPcaParams,
    /// The `.btfpca` file to write.
    pub out: PathBuf,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// What `compress` did.
#[derive(Clone, Debug, PartialEq)]
pub struct CompressSummary {
    /// Texels per image (width × height).
    pub size: (usize, usize),
    /// The c asked for.
    pub requested: usize,
    /// The smallest and largest c_j kept (c is clamped to each slot's rank and to 80).
    pub kept: (usize, usize),
    /// Bytes of the images as 8-bit RGB (6,561 × 3wh, the thesis's "1,230 MB" at 256²).
    pub raw_bytes: u64,
    /// Bytes of the written file.
    pub file_bytes: u64,
    /// Wall-clock seconds of the compression (loading included).
    pub seconds: f64,
}

impl CompressSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        let clamp = if self.kept.0 < self.requested {
            format!(
                " (c_j {}..={} kept: clamped to each slot's rank)",
                self.kept.0, self.kept.1
            )
        } else {
            String::new()
        };
        format!(
            "btf compress: {}x{}, c = {}{clamp}: {:.1} MB of 8-bit images -> {:.1} MB ({:.2}:1) in {:.1} s",
            self.size.0,
            self.size.1,
            self.requested,
            self.raw_bytes as f64 / 1e6,
            self.file_bytes as f64 / 1e6,
            self.raw_bytes as f64 / self.file_bytes.max(1) as f64,
            self.seconds
        )
    }
}

/// What `cloth-vis btf stats` measured.
#[derive(Clone, Debug, PartialEq)]
pub struct StatsSummary {
    /// Texels per image (width × height).
    pub size: (usize, usize),
    /// Components per slot, smallest and largest.
    pub kept: (usize, usize),
    /// Bytes of the images as 8-bit RGB.
    pub raw_bytes: u64,
    /// Bytes of the `.btfpca` file.
    pub file_bytes: u64,
    /// The error over every image.
    pub error: ErrorStats,
}

impl StatsSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        format!(
            "btf stats: {}x{}, c_j {}..={}: {:.1} MB -> {:.1} MB ({:.2}:1); {} images: RMS {:.3} \
             (8-bit sRGB), PSNR {:.2} dB, worst {:.0}",
            self.size.0,
            self.size.1,
            self.kept.0,
            self.kept.1,
            self.raw_bytes as f64 / 1e6,
            self.file_bytes as f64 / 1e6,
            self.raw_bytes as f64 / self.file_bytes.max(1) as f64,
            self.error.images,
            self.error.rms_srgb8,
            self.error.psnr_db,
            self.error.max_abs_srgb8
        )
    }
}

/// 8-bit RGB bytes of a full 81 × 81 BTF of w × h texels.
fn raw_bytes(w: usize, h: usize) -> u64 {
    (btf::DIRECTIONS * btf::DIRECTIONS * 3 * w * h) as u64
}

pub(super) fn dir_bytes(dir: &Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(|e| e.ok()?.metadata().ok())
                .map(|m| m.len())
                .sum()
        })
        .unwrap_or(0)
}

/// Runs `btf synth`: every view slot's primary hits once, then its 81 light images.
///
/// # Errors
/// An `out` that is a file or a folder holding files (refused before any work); bad generator
/// parameters ([`Error::Synth`]); write errors. On error nothing is left at `out`.
pub fn run_synth(request_: &SynthRequest) -> Result<SynthSummary, Error> {
    let out = &request_.out;
    let existing = super::folder_output(out, request_.force)?;
    let woven = synth::WovenBtf::new(&request_.params)?;
    let start = Instant::now();
    // Built in a hidden folder beside `out` and renamed into place when all 6,561 images are
    // written; removed on error and on SIGINT/SIGTERM.
    atomic_out::write_dir(out, existing, |temp| write_views(&woven, request_, temp))
        .map_err(Error::from)?;
    Ok(SynthSummary {
        res: woven.res(),
        sampling: request_.sampling,
        images: btf::DIRECTIONS * btf::DIRECTIONS,
        bytes: dir_bytes(out),
        seconds: start.elapsed().as_secs_f64(),
    })
}

fn write_views(woven: &synth::WovenBtf, request_: &SynthRequest, dir: &Path) -> Result<(), Error> {
    let s = request_.sampling;
    let progress = bar(request_.progress, btf::DIRECTIONS as u64, "view slots");
    for view in 0..btf::DIRECTIONS {
        let hits = woven.view(s.vector(view))?;
        btf::write_btf_view(dir, s, woven.res(), view, |light| {
            hits.shade(s.vector(light))
        })?;
        progress.inc(1);
    }
    progress.finish_and_clear();
    Ok(())
}

fn check_btfpca_out(out: &Path) -> Result<(), Error> {
    let ok = out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("btfpca"));
    if !ok {
        return Err(request(
            out,
            "the compressed BTF is written as .btfpca; name the output so".to_owned(),
        ));
    }
    atomic_out::check_writable(out)?;
    Ok(())
}

/// Runs `btf compress`.
///
/// # Errors
/// An output not named `.btfpca` (refused before reading); folder errors (a missing pair,
/// mismatched sizes, an unreadable name — the file is named); write errors. Nothing is
/// written on error.
pub fn run_compress(request_: &CompressRequest) -> Result<CompressSummary, Error> {
    check_btfpca_out(&request_.out)?;
    let dir = BtfDir::open(&request_.dir)?;
    let progress = bar(request_.progress, btf::DIRECTIONS as u64, "view slots");
    let tick = |_: usize, _: usize| progress.inc(1);
    let (pca, report) = BtfPca::compress_with(
        dir.sampling(),
        dir.width(),
        dir.height(),
        &request_.params,
        |j| dir.load_view(j),
        Some(&tick),
    )?;
    progress.finish_and_clear();
    pca.write(&request_.out)?;
    let file_bytes = std::fs::metadata(&request_.out)
        .map(|m| m.len())
        .unwrap_or(0);
    let kept = report.slots.iter().map(|s| s.components);
    Ok(CompressSummary {
        size: (dir.width(), dir.height()),
        requested: report.requested,
        kept: (kept.clone().min().unwrap_or(0), kept.max().unwrap_or(0)),
        raw_bytes: raw_bytes(dir.width(), dir.height()),
        file_bytes,
        seconds: report.seconds,
    })
}

/// Runs `btf stats`: the error of `file` against every image of `dir`.
///
/// # Errors
/// Folder and file errors naming the file; a `.btfpca` of another size or sampling than the
/// folder, naming both.
pub fn run_stats(dir: &Path, file: &Path, progress: bool) -> Result<StatsSummary, Error> {
    super::refuse_swapped_stats("btf stats", dir, file, "btfpca")?;
    let pca = BtfPca::read(file)?;
    let folder = BtfDir::open(dir)?;
    let (a, b) = (
        (folder.sampling(), folder.width(), folder.height()),
        (pca.sampling(), pca.width(), pca.height()),
    );
    if a != b {
        return Err(request(
            file,
            format!(
                "holds a {} BTF of {}x{} but {} is {} of {}x{}; compare a .btfpca with the \
                 folder it was compressed from",
                b.0.name(),
                b.1,
                b.2,
                dir.display(),
                a.0.name(),
                a.1,
                a.2
            ),
        ));
    }
    let bar = bar(progress, btf::DIRECTIONS as u64, "view slots compared");
    let error = pca.stats_with(
        &folder,
        None,
        Some(&|done, _| bar.set_position(done as u64)),
    )?;
    bar.finish_and_clear();
    let kept = pca.slots().iter().map(|s| s.components());
    Ok(StatsSummary {
        size: (pca.width(), pca.height()),
        kept: (kept.clone().min().unwrap_or(0), kept.max().unwrap_or(0)),
        raw_bytes: raw_bytes(pca.width(), pca.height()),
        file_bytes: std::fs::metadata(file).map(|m| m.len()).unwrap_or(0),
        error,
    })
}

/// The `btf` subcommands.
#[derive(clap::Subcommand)]
pub enum BtfCommand {
    /// Write the synthetic woven-cloth BTF as 81 × 81 PNGs named as the Bonn UBO2003 archives
    /// (tl… pl… tv… pv….png) into a new folder.
    Synth(SynthArgs),
    /// Compress a BTF folder by per-view PCA (§5.4) into a .btfpca file.
    Compress(CompressArgs),
    /// Compare a .btfpca with its folder: sizes, RMS error (8-bit sRGB) and PSNR over every
    /// image.
    Stats(StatsArgs),
    /// Render a mesh with UVs textured by a compressed BTF under one light (§5.5), to PNG.
    Render(Box<super::btf_render::RenderArgs>),
    /// Fin BTFs for silhouette enhancement of fuzzy cloth (§5.7): synth, compress.
    Fins {
        /// What to do.
        #[command(subcommand)]
        command: super::btf_fins::FinsCommand,
    },
}

impl BtfCommand {
    /// Run the subcommand; print its summary line.
    pub fn run(self) -> anyhow::Result<()> {
        let line = match self {
            Self::Synth(a) => {
                let request = SynthRequest {
                    params: synth::WovenBtfParams {
                        res: a.res,
                        supersample: a.supersample,
                        ..Default::default()
                    },
                    sampling: a.sampling,
                    out: a.out,
                    force: a.force,
                    progress: !a.quiet,
                };
                super::with_wrote(run_synth(&request)?.line(), [request.out.as_path()])
            }
            Self::Compress(a) => {
                let request = CompressRequest {
                    dir: a.dir,
                    params: BtfPcaParams {
                        components: a.components,
                        storage: a.storage,
                        mean_storage: a.mean_storage,
                        ..Default::default()
                    },
                    out: a.out,
                    progress: !a.quiet,
                };
                super::with_wrote(run_compress(&request)?.line(), [request.out.as_path()])
            }
            Self::Stats(a) => run_stats(&a.dir, &a.file, !a.quiet)?.line(),
            Self::Render(a) => a.run()?,
            Self::Fins { command } => command.run()?,
        };
        super::print_line(&line)
    }
}

/// `cloth-vis btf synth`.
#[derive(clap::Args)]
pub struct SynthArgs {
    /// Texels per image side (the thesis's normtextures are 256).
    #[arg(long, default_value_t = synth::WovenBtfParams::default().res)]
    res: usize,
    /// Measured directions: h1 (θ up to 85°) or h2 (θ up to 75°), Table 5.1.
    #[arg(long, default_value = "h1", value_parser = parse_sampling)]
    sampling: Sampling,
    /// Rays per texel side (anti-aliasing of the mesostructure).
    #[arg(long, default_value_t = synth::WovenBtfParams::default().supersample)]
    supersample: usize,
    /// Output folder (must not exist, or be empty; created with its parents).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an output folder that already holds files, once the new one is complete.
    #[arg(long)]
    force: bool,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

/// `cloth-vis btf compress`.
#[derive(clap::Args)]
pub struct CompressArgs {
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
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

/// `cloth-vis btf stats`.
#[derive(clap::Args)]
pub struct StatsArgs {
    /// The BTF folder.
    dir: PathBuf,
    /// The .btfpca file.
    file: PathBuf,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

fn parse_sampling(text: &str) -> Result<Sampling, String> {
    match text.to_ascii_lowercase().as_str() {
        "h1" => Ok(Sampling::H1),
        "h2" => Ok(Sampling::H2),
        _ => Err(format!("{text:?}: the samplings are h1 and h2 (Table 5.1)")),
    }
}

pub(super) fn parse_storage(text: &str) -> Result<btf::Storage, String> {
    match text.to_ascii_lowercase().as_str() {
        "u8" => Ok(btf::Storage::U8),
        "u16" => Ok(btf::Storage::U16),
        "f32" => Ok(btf::Storage::F32),
        _ => Err(format!("{text:?}: the storages are u8, u16 and f32")),
    }
}
