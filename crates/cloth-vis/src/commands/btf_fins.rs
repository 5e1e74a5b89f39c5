//! `cloth-vis btf fins synth | compress`: the fin BTF of silhouette enhancement (thesis
//! §5.7.2) on files.
//!
//! - `synth` writes the synthetic wool (`synth::fins`) as the 81 images of Table 5.3 at the
//!   grazing view, `tl… pl… tv090 pv000.png` (8-bit sRGB over black), into a new folder that
//!   appears complete or not at all.
//! - `compress` runs the PCA of eq. 5.14 (with the mean) over a fin folder — synthetic or
//!   measured — and writes a `.finpca`, reporting the reconstruction error of every image.

use std::path::{Path, PathBuf};
use std::time::Instant;

use btf::fin_pca::{FIN_SAMPLING, FinDir, FinPca, write_fin_dir};
use btf::{BtfPcaParams, DIRECTIONS};

use super::invalid as request;
use cloth_vis::Error;
use cloth_vis::run::progress_bar as bar;

/// What `btf fins synth` wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct FinSynthSummary {
    /// Image width and height.
    pub size: (usize, usize),
    /// Mean alpha (fibre coverage) of the bottom and top quarter of the rows, light 0.
    pub alpha_base_tips: (f32, f32),
    /// Bytes on disk.
    pub bytes: u64,
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl FinSynthSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        format!(
            "btf fins synth: 81 images of {}x{} (Table 5.3 lights, view θ = 90°), coverage {:.2} \
             at the base, {:.2} at the tips, {:.2} MB of PNG, {:.1} s",
            self.size.0,
            self.size.1,
            self.alpha_base_tips.0,
            self.alpha_base_tips.1,
            self.bytes as f64 / 1e6,
            self.seconds
        )
    }
}

/// Runs `btf fins synth`.
///
/// # Errors
/// An `out` that is a file or a folder holding files (refused before any work); bad generator
/// parameters; write errors. On error nothing is left at `out`.
pub fn run_synth(
    params: &synth::fins::WoolFinParams,
    out: &Path,
    force: bool,
    progress: bool,
) -> Result<FinSynthSummary, Error> {
    let existing = super::folder_output(out, force)?;
    let start = Instant::now();
    let wool = synth::fins::WoolFins::new(params)?;
    let alpha = wool.alpha();
    let (w, h) = (params.width, params.height);
    let band = |rows: std::ops::Range<usize>| {
        let n = rows.len() * w;
        rows.flat_map(|r| &alpha[r * w..(r + 1) * w]).sum::<f32>() / n.max(1) as f32
    };
    let quarter = (h / 4).max(1);
    let alpha_base_tips = (band(h - quarter..h), band(0..quarter));
    let ticker = bar(progress, DIRECTIONS as u64, "fin images");
    atomic_out::write_dir(out, existing, |temp| {
        write_fin_dir(temp, w, h, |light| {
            let image = wool.image(FIN_SAMPLING.vector(light));
            ticker.inc(1);
            image.rgba.iter().map(|p| [p[0], p[1], p[2]]).collect()
        })
        .map_err(Error::from)
    })?;
    ticker.finish_and_clear();
    Ok(FinSynthSummary {
        size: (w, h),
        alpha_base_tips,
        bytes: super::btf::dir_bytes(out),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// What `btf fins compress` did.
#[derive(Clone, Debug, PartialEq)]
pub struct FinCompressSummary {
    /// Image width and height.
    pub size: (usize, usize),
    /// c asked for and kept (the rank of the centred images bounds it).
    pub components: (usize, usize),
    /// RMS error over all 81 images, 8-bit sRGB units, and PSNR in dB.
    pub rms_psnr: (f64, f64),
    /// Bytes of the 81 images as 8-bit RGB, and of the file.
    pub bytes: (u64, u64),
    /// Wall-clock seconds.
    pub seconds: f64,
}

impl FinCompressSummary {
    /// One line for the terminal.
    pub fn line(&self) -> String {
        format!(
            "btf fins compress: 81 images of {}x{}, c = {} (asked {}), RMS {:.2} (8-bit sRGB), \
             PSNR {:.1} dB, {:.2} MB raw -> {:.2} MB, {:.2} s",
            self.size.0,
            self.size.1,
            self.components.1,
            self.components.0,
            self.rms_psnr.0,
            self.rms_psnr.1,
            self.bytes.0 as f64 / 1e6,
            self.bytes.1 as f64 / 1e6,
            self.seconds
        )
    }
}

/// Runs `btf fins compress`.
///
/// # Errors
/// An output not named `.finpca` (refused before reading); folder errors naming the file;
/// write errors. Nothing is written on error.
pub fn run_compress(
    dir: &Path,
    params: &BtfPcaParams,
    out: &Path,
) -> Result<FinCompressSummary, Error> {
    let ok = out
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("finpca"));
    if !ok {
        return Err(request(
            out,
            "the compressed fin BTF is written as .finpca; name the output so".to_owned(),
        ));
    }
    atomic_out::check_writable(out)?;
    if params.components == 0 || params.components > DIRECTIONS {
        return Err(request(
            out,
            format!(
                "--components {}: must be 1..=81 (80 keeps every image exactly)",
                params.components
            ),
        ));
    }
    let start = Instant::now();
    let folder = FinDir::open(dir)?;
    let images = folder.load()?;
    let fins = FinPca::from_images(&images, params)?;
    let stats = fins.stats(&images)?;
    fins.write(out)?;
    let file_bytes = std::fs::metadata(out).map(|m| m.len()).unwrap_or(0);
    let (w, h) = (folder.width(), folder.height());
    Ok(FinCompressSummary {
        size: (w, h),
        components: (params.components, fins.slot().components()),
        rms_psnr: (stats.rms_srgb8, stats.psnr_db),
        bytes: ((DIRECTIONS * 3 * w * h) as u64, file_bytes),
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The `btf fins` subcommands.
#[derive(clap::Subcommand)]
pub enum FinsCommand {
    /// Write the synthetic wool fin BTF: 81 images of Table 5.3 at the grazing view
    /// (tl… pl… tv090 pv000.png) into a new folder.
    Synth(FinSynthArgs),
    /// Compress a fin folder by PCA (eq. 5.14, with the mean) into a .finpca file.
    Compress(FinCompressArgs),
}

impl FinsCommand {
    /// Run the subcommand; its summary line.
    pub fn run(self) -> anyhow::Result<String> {
        Ok(match self {
            Self::Synth(a) => {
                let defaults = synth::fins::WoolFinParams::default();
                let width = a.size[0] as usize;
                let params = synth::fins::WoolFinParams {
                    width,
                    height: a.size[1] as usize,
                    // The same coverage at any width: strands in proportion to it.
                    strands: (defaults.strands * width).div_ceil(defaults.width).max(1),
                    supersample: a.supersample,
                    seed: a.seed,
                    ..defaults
                };
                let line = run_synth(&params, &a.out, a.force, !a.quiet)?.line();
                super::with_wrote(line, [a.out.as_path()])
            }
            Self::Compress(a) => {
                let params = BtfPcaParams {
                    components: a.components,
                    storage: a.storage,
                    mean_storage: a.mean_storage,
                    ..Default::default()
                };
                let line = run_compress(&a.dir, &params, &a.out)?.line();
                super::with_wrote(line, [a.out.as_path()])
            }
        })
    }
}

/// `cloth-vis btf fins synth`.
#[derive(clap::Args)]
pub struct FinSynthArgs {
    /// Image size: width along the fin edge (one material unit) x height.
    #[arg(long, value_name = "WxH", value_parser = super::parse::size, default_value = "128x128")]
    size: [u32; 2],
    /// Sub-samples per pixel side (anti-aliasing of the fibres).
    #[arg(long, default_value_t = synth::fins::WoolFinParams::default().supersample)]
    supersample: usize,
    /// Seed of the strands.
    #[arg(long, default_value_t = synth::fins::WoolFinParams::default().seed)]
    seed: u64,
    /// Output folder (must not exist, or be empty).
    #[arg(long, short = 'o')]
    out: PathBuf,
    /// Replace an output folder that already holds files, once the new one is complete.
    #[arg(long)]
    force: bool,
    /// Hide the progress bar.
    #[arg(long)]
    quiet: bool,
}

/// `cloth-vis btf fins compress`.
#[derive(clap::Args)]
pub struct FinCompressArgs {
    /// The folder of 81 fin images (tl… pl… tv090 pv000.png; PNG/JPEG sRGB or EXR linear).
    dir: PathBuf,
    /// c: eigen-images (the thesis's "around 16"; 80 reconstructs every image exactly).
    #[arg(long, default_value_t = btf::DEFAULT_COMPONENTS)]
    components: usize,
    /// Bits of the eigen-images: u8, u16 or f32.
    #[arg(long, default_value = "u8", value_parser = super::btf::parse_storage)]
    storage: btf::Storage,
    /// Bits of the mean image: u8, u16 (default) or f32.
    #[arg(long, default_value = "u16", value_parser = super::btf::parse_storage)]
    mean_storage: btf::Storage,
    /// Output: FILE.finpca.
    #[arg(long, short = 'o')]
    out: PathBuf,
}
