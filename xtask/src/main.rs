//! `cargo xtask …`: reproduction scripts that write reports under `target/repro/`.
//!
//! - `cargo xtask repro lightsphere`: what each lightsphere level and I_j method costs in time
//!   and buys in accuracy, on every HDR map in `../shared/data/env` and the procedural sky
//!   (`target/repro/lightsphere.md` and `lightsphere.svg`).
//! - `cargo xtask repro visibility [--quick] [--max-level 4]`: the visibility engine's `cpu`,
//!   `depth` and `query` backends on the full bunny and the synthetic cloth — time, rays/s,
//!   |Δa| against `cpu` and against a level-6 reference — beside the seed's Table 1
//!   (`target/repro/visibility.md` and `visibility.svg`).
//! - `cargo xtask repro jumpmap`: jump maps (thesis §3.2.3) on every animation in
//!   `../shared/data/anim` and the synthetic cloth — Table 3.1 (storage against c), Table 3.2
//!   (E, E* beside the thesis's), analysis time and playback frames/s, and the σ and q sweeps
//!   of Figs. 3.8–3.10 as numbers (`target/repro/jumpmap.md`, `jumpmap.svg` and a rendered
//!   strip of frames per sequence, `jumpmap-<sequence>.png`).
//! - `cargo xtask repro anim-compression`: clustered-PCA compression (thesis §3.3) on every
//!   animation and the synthetic cloth — rate–distortion of CPCA against plain PCA and
//!   per-frame quantization, the Table 3.4 front, Figs. 3.14/3.15/3.17 and Table 3.5 on the
//!   chicken, cluster pictures (`target/repro/anim-compression.md` and its plots).
//! - `cargo xtask repro btf [--quick]`: per-view PCA compression of the synthetic woven BTF
//!   (thesis §5.4) — error, time and `.btfpca` size against c, eigenvalue decay and a Fig. 5.7
//!   panel; FMF, PCMF and PVMF side by side (Fig. 2.22); compression time and peak memory at
//!   256² (`target/repro/btf.md`, `btf-error.svg`, `btf-eigenvalues.svg`, `btf-fig5.7.png`).
//! - `cargo xtask repro hemicube [--quick]`: static visibility maps (thesis §4.3) on the shared
//!   dress — Table 4.1 rebuilt (GPU atlas and exact rays beside the thesis's four builders),
//!   HC 64² of the whole dress, convergence of HC/SP/HS against an HC 256² reference, the
//!   lightsphere's a_i beside it, bytes per vertex (`target/repro/hemicube.md`, `hemicube.svg`).
//! - `cargo xtask repro shadows [--quick]`: shadow volumes (thesis §2.4.1, §4.2, §5.5.1) — the
//!   LOD chain on the bunny (Hausdorff %, hard- and soft-mask error, build and mask times, the
//!   speed-up beside the thesis's), the zig-zag of the stencil's terminator against eq. 5.6's
//!   on spheres and cylinders, popping under sun motion on the drape (`target/repro/shadows.md`,
//!   `shadows-lod.svg`, `shadows-zigzag.svg`, `shadows-popping.svg`).
//! - `cargo xtask repro translucency [--quick]`: seed 004's Table 1 (per-pass times on the
//!   bunny and the dragon, static and under the sine deformer, beside the paper's fps), the
//!   cube-map size against E_lm (TR 164), SH ringing per window (`target/repro/translucency.md`).
//! - `cargo xtask bench visibility [--quick] [--threads 2]`: occlusion-gpu's `cpu` backend
//!   beside Mitsuba 3 (Embree) and Open3D on the same rays, as ratios
//!   (`target/repro/bench-visibility.md`; the peers in a virtual environment).
//! - `cargo xtask bench visibility-gpu [--quick] [--runs 21] [--only bunny]`: occlusion-gpu's `depth` backend
//!   on the adapter at hand, beside the exact `cpu` backend on the same machine: time, host
//!   CPU and cells of M that differ (`target/repro/bench-visibility-gpu.md`).
//! - `cargo xtask compare clustering [--quick]`: the clustering crate beside scikit-learn's
//!   PCA and KMeans on the same data (numpy and scikit-learn in a virtual environment).
//! - `cargo xtask compare translucency [--quick]`: seed 004's translucency model against
//!   Mitsuba 3's volumetric path tracer on the bunny and the dragon (image error and SSIM
//!   beside plain diffuse shading's; Mitsuba in a virtual environment).

mod bench_visibility;
mod bench_visibility_gpu;
mod compare_clustering;
mod compare_translucency;
mod python;
mod repro_anim_compression;
mod repro_btf;
mod repro_btf_env;
mod repro_btf_env_turns;
mod repro_fins;
mod repro_hemicube;
mod repro_jumpmap;
mod repro_lightsphere;
mod repro_rd_search;
mod repro_shadows;
mod repro_translucency;
mod repro_visibility;
mod sequences;

use std::path::PathBuf;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "xtask", about = "cloth-vis reproduction scripts")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Reproduce a figure or table as a markdown report and a plot under target/repro/.
    Repro {
        #[command(subcommand)]
        what: Repro,
    },
    /// Benchmarks beside the tools users would pick instead, in one run.
    Bench {
        #[command(subcommand)]
        what: Bench,
    },
    /// Compare a crate with the tools users would pick instead, on the same data.
    Compare {
        #[command(subcommand)]
        what: Compare,
    },
}

#[derive(Subcommand)]
enum Bench {
    /// occlusion-gpu's `cpu` backend beside Mitsuba 3 (Embree) and Open3D on the same rays:
    /// bunny k = 6 … 1026, dragon and igea at k = 258, the drape at k = 66 and 258.
    Visibility {
        /// The bunny at k = 66 and 258 only.
        #[arg(long)]
        quick: bool,
        /// Threads for every library.
        #[arg(long, default_value_t = 2)]
        threads: usize,
    },
    /// occlusion-gpu's `depth` backend on the adapter at hand beside the exact `cpu` backend:
    /// time per frame, host CPU per frame, and what the depth maps cost in accuracy.
    VisibilityGpu {
        /// The bunny at k = 66 and 258, at 256² and 1024² (checks the run on a software
        /// adapter).
        #[arg(long)]
        quick: bool,
        /// Timed calls per case (after three warm-up calls).
        #[arg(long, default_value_t = 21)]
        runs: usize,
        /// Only this mesh's rows.
        #[arg(long, value_parser = ["bunny", "dragon", "igea", "drape"])]
        only: Option<String>,
    },
}

#[derive(Subcommand)]
enum Compare {
    /// PCA, k-means and local PCA against scikit-learn (time and quality).
    Clustering {
        /// One seed instead of five.
        #[arg(long)]
        quick: bool,
    },
    /// Seed 004's translucency against Mitsuba 3's volumetric path tracer (image error, SSIM).
    Translucency {
        /// The small bunny at 96², 32 samples per pixel.
        #[arg(long)]
        quick: bool,
        /// A cloth-vis binary to use (default: build the release one).
        #[arg(long, value_name = "PATH")]
        cloth_vis: Option<PathBuf>,
    },
}

#[derive(Subcommand)]
enum Repro {
    /// Lightsphere levels × I_j methods: power error, irradiance error, time.
    Lightsphere {
        /// Highest level to evaluate.
        #[arg(long, default_value_t = 6)]
        max_level: u32,
    },
    /// Visibility backends (cpu, depth, query) × levels × depth resolutions: time, rays/s,
    /// ambient error against cpu and against a level-6 cpu reference (paper 000, Table 1).
    Visibility {
        /// Levels 0–3, resolutions 256 and 1024, level-5 reference, smaller query budget.
        #[arg(long)]
        quick: bool,
        /// Highest level to evaluate (at most 3 with --quick).
        #[arg(long, default_value_t = 4)]
        max_level: u32,
    },
    /// Jump maps (thesis §3.2.3): Tables 3.1 and 3.2, analysis and playback speed, σ and q
    /// sweeps (Figs. 3.8–3.10 as numbers) and a strip of frames per sequence.
    Jumpmap,
    /// Clustered-PCA compression (thesis §3.3): rate–distortion against plain PCA and
    /// per-frame quantization (Table 3.4), c* and q_c × q_w sweeps (Figs. 3.14, 3.15, 3.17),
    /// timings (Table 3.5) and cluster pictures (Figs. 3.12/3.13).
    AnimCompression {
        /// Only the sequences whose name contains this (e.g. `chicken`).
        #[arg(long)]
        only: Option<String>,
        /// Only the `--target-bpvf` search against its grid
        /// (`anim-compression-search.md`; part of the full report too).
        #[arg(long)]
        search_only: bool,
    },
    /// BTF compression (thesis §5.4, §2.1.12): error, time and size against c (Figs. 5.7/5.8),
    /// FMF / PCMF / PVMF side by side (Fig. 2.22), and the 256² compression's time and peak
    /// memory.
    Btf {
        /// 32² throughout and no 256² timing.
        #[arg(long)]
        quick: bool,
    },
    /// BTF under a point light and an HDR map (§5.5.2, Table 5.2): HEM update and frame
    /// times on the dress and two drapes beside the seed's rows.
    BtfEnv,
    /// BTF fins (§5.7): the wool's PCA against c, fin extraction per frame on the drape,
    /// Figs. 5.23/5.24 with and without fins and the fins' share of the frame.
    Fins,
    /// Shadow volumes (thesis §2.4.1, §4.2, §5.5.1): the LOD chain on the bunny (Hausdorff,
    /// mask error, soft-mask error, build and mask times), the zig-zag against tessellation,
    /// popping under sun motion on the drape.
    Shadows {
        /// 256² masks, three levels, fewer tessellations and sun steps.
        #[arg(long)]
        quick: bool,
    },
    /// Translucency by SH (seed 004): Table 1's per-pass times on the bunny and the dragon,
    /// static and deformed, the cube-map size against E_lm, SH ringing under each window.
    Translucency {
        /// Four frames per model instead of twenty.
        #[arg(long)]
        quick: bool,
    },
    /// Static visibility maps (thesis §4.3): Table 4.1 rebuilt on the shared dress, convergence
    /// of HC/SP/HS against an HC 256² reference, the lightsphere's a_i beside it, bytes per
    /// vertex.
    Hemicube {
        /// HC 128² reference instead of 256².
        #[arg(long)]
        quick: bool,
    },
}

/// `target/repro` of the workspace.
fn repro_dir() -> anyhow::Result<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/repro");
    std::fs::create_dir_all(&dir)?;
    Ok(dir)
}

fn main() -> anyhow::Result<()> {
    // An interrupted report leaves no hidden `.NAME.PID.N.tmp` beside its outputs.
    atomic_out::remove_temporaries_on_signal()?;
    match Cli::parse().command {
        Command::Repro {
            what: Repro::Lightsphere { max_level },
        } => repro_lightsphere::run(&repro_dir()?, max_level),
        Command::Repro {
            what: Repro::Visibility { quick, max_level },
        } => repro_visibility::run(&repro_dir()?, quick, max_level),
        Command::Repro {
            what: Repro::Jumpmap,
        } => repro_jumpmap::run(&repro_dir()?),
        Command::Repro {
            what: Repro::AnimCompression { only, search_only },
        } => repro_anim_compression::run(&repro_dir()?, only.as_deref(), search_only),
        Command::Repro {
            what: Repro::Btf { quick },
        } => repro_btf::run(&repro_dir()?, quick),
        Command::Repro {
            what: Repro::Hemicube { quick },
        } => repro_hemicube::run(&repro_dir()?, quick),
        Command::Repro { what: Repro::Fins } => repro_fins::run(&repro_dir()?),
        Command::Repro {
            what: Repro::BtfEnv,
        } => repro_btf_env::run(&repro_dir()?),
        Command::Repro {
            what: Repro::Shadows { quick },
        } => repro_shadows::run(&repro_dir()?, quick),
        Command::Repro {
            what: Repro::Translucency { quick },
        } => repro_translucency::run(&repro_dir()?, quick),
        Command::Bench {
            what: Bench::Visibility { quick, threads },
        } => {
            let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
            bench_visibility::run(&root, &repro_dir()?, quick, threads)
        }
        Command::Bench {
            what: Bench::VisibilityGpu { quick, runs, only },
        } => bench_visibility_gpu::run(&repro_dir()?, quick, runs, only.as_deref()),
        Command::Compare {
            what: Compare::Clustering { quick },
        } => {
            let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
            compare_clustering::run_comparison(&root, quick)
        }
        Command::Compare {
            what: Compare::Translucency { quick, cloth_vis },
        } => {
            let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
            compare_translucency::run_comparison(&root, quick, cloth_vis.as_deref())
        }
    }
}
