//! `cargo xtask repro jumpmap`: the results of the thesis's §3.2.3 for jump maps (crate
//! `anim-pca`) on every animation in `../shared/data/anim` that `meshio` loads and on the
//! synthetic cloth drape:
//!
//! - Table 3.1: storage of the clip and of its PCA for c = 1, 2, 4, 6, 8, 10
//!   (`metrics::compression_ratio`), positions only and with normals;
//! - Table 3.2: E(c), E*(c) for c = 0, 2, …, 10 (`metrics::reconstruction_errors`), beside the
//!   thesis's avatar and skeleton, as printed (sums over the frames) and per frame;
//! - speed: analysis time (median of 3) and play + reconstruct frames/s with the defaults;
//! - Figs. 3.8–3.10 as numbers: σ = σ* ∈ {0.01, 0.05, 0.30, 1.0} and (q, q*) ∈ {(0, 0),
//!   (0, 1), (1, 0), (0.5, 0.5)}, each over a 20,000-frame run with a fixed seed: jump
//!   residuals in units of the clip's mean frame step d̄, the velocity discontinuity at the
//!   transitions with and without blending (b = 3) relative to the clip's own largest velocity
//!   change, distinct transitions, coverage and the core's share of the clip;
//! - a strip of 8 frames of a generated run per sequence, rendered by `cloth-vis`'s renderer
//!   (needs a GPU adapter; lavapipe is fine; skipped with a note otherwise).
//!
//! Clips longer than [`MAX_CLIP_FRAMES`] are cut to their first frames (the thesis's clips
//! have 115 and 190 frames; a jump map wants a short clip). Writes `target/repro/jumpmap.md`,
//! `jumpmap.svg` and `jumpmap-<sequence>.png`.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anim_pca::jumpmap::metrics::{
    Compression, FrameContents, ReconstructionError, SequenceStats, clip_max_velocity_change,
    compression_ratio, reconstruction_errors, sequence_stats, transition_velocity_change,
};
use anim_pca::{Blend, JumpMap, JumpMapParams, PlaybackParams, Player};
use anyhow::Context as _;
use glam::Vec3;
use rayon::prelude::*;

use crate::repro_visibility::cpu_model;
use crate::sequences::{Sequence, load_sequences};
use figures::chart::{Series, log_log_svg};

/// Longest clip analysed; longer ones are cut to their first frames (8 s at 30 fps).
const MAX_CLIP_FRAMES: usize = 240;
/// Components of Table 3.1.
const TABLE_3_1_COMPONENTS: [usize; 6] = [1, 2, 4, 6, 8, 10];
/// Components of Table 3.2.
const TABLE_3_2_COMPONENTS: [usize; 6] = [0, 2, 4, 6, 8, 10];
/// Table 3.1 of the thesis: c (0 = the raw clip), avatar MB and 1:r, skeleton MB and 1:r.
const THESIS_TABLE_3_1: [(usize, f64, f64, f64, f64); 7] = [
    (0, 138.0, 1.0, 75.2, 1.0),
    (1, 2.6, 53.0, 1.4, 54.0),
    (2, 4.0, 34.0, 1.9, 40.0),
    (4, 4.6, 30.0, 2.8, 27.0),
    (6, 6.2, 22.0, 3.8, 20.0),
    (8, 7.7, 18.0, 4.7, 16.0),
    (10, 9.2, 15.0, 5.6, 13.0),
];
/// Table 3.2 of the thesis: c, avatar E and E*, skeleton E and E*.
const THESIS_TABLE_3_2: [(usize, f64, f64, f64, f64); 6] = [
    (0, 25.06, 188.55, 31.79, 172.14),
    (2, 4.96, 121.25, 16.19, 151.95),
    (4, 1.89, 62.85, 10.61, 119.52),
    (6, 1.63, 48.49, 8.042, 92.76),
    (8, 1.24, 31.04, 6.29, 82.66),
    (10, 0.99, 26.09, 5.09, 73.82),
];
/// Frames of the thesis's avatar and skeleton sequences (§3.2.3).
const THESIS_FRAMES: (usize, usize) = (115, 190);
/// σ = σ* of the sweep (Figs. 3.8, 3.9: 0.01, 0.05, 0.30; 1.0 added as "too high").
const SIGMAS: [f64; 4] = [0.01, 0.05, 0.30, 1.0];
/// (q, q*) of the sweep (Fig. 3.10), at the default σ = σ* = 0.05.
const QS: [(f64, f64); 4] = [(0.0, 0.0), (0.0, 1.0), (1.0, 0.0), (0.5, 0.5)];
/// Frames of each generated run of the sweep.
const RUN_FRAMES: usize = 20_000;
/// Seed of every generated run.
const SEED: u64 = 7;
/// Blend frames of the blended runs (the thesis's b = 3).
const BLEND_FRAMES: usize = 3;
/// Analysis timings: median of this many runs.
const TIMING_RUNS: usize = 3;
/// Playback is timed over at least this many frames and at least [`PLAYBACK_MIN_S`].
const PLAYBACK_MIN_FRAMES: usize = 1000;
/// See [`PLAYBACK_MIN_FRAMES`].
const PLAYBACK_MIN_S: f64 = 0.5;
/// Frames of the generated run a strip is taken from, and its panels and panel size.
const STRIP_RUN_FRAMES: usize = 300;
/// Panels of a strip.
const STRIP_PANELS: usize = 8;
/// Panel size of a strip.
const STRIP_PANEL: [u32; 2] = [192, 192];

/// One configuration of the σ / q sweep.
struct SweepRow {
    sigma: f64,
    q: f64,
    q_velocity: f64,
    stats: SequenceStats,
    core_share: f64,
    /// Largest velocity change at a transition / the clip's own, cuts and b = 3.
    dv_cut: f64,
    dv_blend: f64,
    transitions_blend: usize,
}

/// Everything measured on one sequence.
struct Measured {
    compression: Vec<(Compression, Compression)>,
    errors: Vec<ReconstructionError>,
    components: (usize, usize),
    analysis_s: f64,
    playback_fps: f64,
    sweep: Vec<SweepRow>,
    strip: Option<String>,
    /// The loop table 2 ..= max(LOOP_LENGTHS) with b = 3: build seconds, the cell's core
    /// frames, and per length (length, R(n), the loop if any).
    loops: (f64, usize, Vec<LoopRow>),
}

/// A row of the loop-quality table: N, R(N) and the loop, if N has an acceptable one.
type LoopRow = (usize, usize, Option<anim_pca::Loop>);

/// Lengths of the loop-quality table (`--loop N`).
const LOOP_LENGTHS: [usize; 7] = [12, 24, 30, 48, 60, 96, 120];

/// The loop table of cell 0 with the defaults and b = 3, and the rows of the report.
fn loop_rows(map: &JumpMap) -> anyhow::Result<(f64, usize, Vec<LoopRow>)> {
    let start = Instant::now();
    let max = LOOP_LENGTHS[LOOP_LENGTHS.len() - 1];
    let table = anim_pca::LoopTable::build(map, 0, max, Blend::Fixed(BLEND_FRAMES))?;
    let built = start.elapsed().as_secs_f64();
    let rows = LOOP_LENGTHS
        .iter()
        .map(|&n| (n, table.min_run(n), table.get(n).cloned()))
        .collect();
    Ok((built, table.core_frames(), rows))
}

fn loop_table(md: &mut String, results: &[(&Sequence, Measured)]) {
    let _ = writeln!(md, "## Loops: `--loop N`\n");
    let _ = writeln!(
        md,
        "The cheapest acceptable loop of each length N (`LoopTable`, b = {BLEND_FRAMES}, cell 0): \
         every stretch of natural play between two jumps lasts at least R(N) = \
         max(min(⌈N/4⌉, ⌈core/4⌉), b + 1, min(8, ⌈core/2⌉)) key frames, so no loop oscillates \
         over a handful of frames. *exact*: generated frames of one period that are the clip's \
         own frames bit for bit (the others are cross-fades); *cost*: Σ −ln s_ij over its jumps \
         (0: perfect jumps). The table of every length 2 … {} is built once per clip.\n",
        LOOP_LENGTHS[LOOP_LENGTHS.len() - 1]
    );
    let _ = writeln!(
        md,
        "| sequence | core | table (s) | N | R(N) | jumps | distinct frames | shortest stretch | exact | cost |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (s, m) in results {
        let (built, core, rows) = &m.loops;
        for (n, r, lp) in rows {
            let _ = match lp {
                Some(lp) => writeln!(
                    md,
                    "| {} | {core} | {built:.2} | {n} | {r} | {} | {} | {} | {} | {:.2} |",
                    s.name,
                    lp.transitions.len(),
                    lp.distinct_frames(),
                    lp.shortest_run(),
                    lp.frames.iter().filter(|f| f.is_key()).count(),
                    lp.cost
                ),
                None => writeln!(
                    md,
                    "| {} | {core} | {built:.2} | {n} | {r} | none: no acceptable loop of this length | | | | |",
                    s.name
                ),
            };
        }
    }
    let _ = writeln!(md);
}

fn median(mut xs: Vec<f64>) -> f64 {
    xs.sort_by(f64::total_cmp);
    xs[xs.len() / 2]
}

/// Analysis time (median of [`TIMING_RUNS`]) with the default parameters, and play +
/// reconstruct frames/s.
fn speed(frames: &[Vec<Vec3>]) -> anyhow::Result<(JumpMap, f64, f64)> {
    let params = JumpMapParams::default();
    let mut times = Vec::new();
    let mut map = None;
    for _ in 0..TIMING_RUNS {
        let start = Instant::now();
        map = Some(JumpMap::analyze(frames, &params)?);
        times.push(start.elapsed().as_secs_f64());
    }
    let map = map.context("no analysis run")?;
    let mut player = Player::new(
        &map,
        &PlaybackParams {
            seed: SEED,
            ..PlaybackParams::default()
        },
    )?;
    let mut weights = vec![0.0; map.components()];
    let mut mesh = vec![Vec3::ZERO; map.n_vertices()];
    let mut step = |player: &mut Player<'_>| -> anyhow::Result<()> {
        player.next_frame().weights_into(&map, &mut weights);
        map.reconstructor().reconstruct(&weights, &mut mesh)?;
        Ok(())
    };
    for _ in 0..100 {
        step(&mut player)?;
    }
    let start = Instant::now();
    let mut played = 0;
    while played < PLAYBACK_MIN_FRAMES || start.elapsed().as_secs_f64() < PLAYBACK_MIN_S {
        step(&mut player)?;
        played += 1;
    }
    let fps = played as f64 / start.elapsed().as_secs_f64();
    Ok((map, median(times), fps))
}

/// One σ / q configuration over a [`RUN_FRAMES`] run, cut and blended.
fn sweep_row(
    frames: &[Vec<Vec3>],
    sigma: f64,
    q: f64,
    q_velocity: f64,
) -> anyhow::Result<SweepRow> {
    let params = JumpMapParams {
        sigma,
        sigma_velocity: sigma,
        q,
        q_velocity,
        ..JumpMapParams::default()
    };
    let map = JumpMap::analyze(frames, &params)?;
    let run = |blend| -> anyhow::Result<_> {
        Ok(Player::new(
            &map,
            &PlaybackParams {
                blend,
                seed: SEED,
                ..PlaybackParams::default()
            },
        )?
        .generate(RUN_FRAMES))
    };
    let (cut, blended) = (run(Blend::None)?, run(Blend::Fixed(BLEND_FRAMES))?);
    let reference = clip_max_velocity_change(&map);
    let relative = |x: f64| {
        if reference > 0.0 {
            x / reference
        } else {
            f64::NAN
        }
    };
    Ok(SweepRow {
        sigma,
        q,
        q_velocity,
        stats: sequence_stats(&map, &cut),
        core_share: map.core().iter().filter(|c| **c).count() as f64 / map.n_frames() as f64,
        dv_cut: relative(transition_velocity_change(&map, &cut)),
        dv_blend: relative(transition_velocity_change(&map, &blended)),
        transitions_blend: blended.transitions.len(),
    })
}

/// A strip of [`STRIP_PANELS`] frames of a [`STRIP_RUN_FRAMES`] run with the defaults, written
/// beside the report; returns its file name.
fn strip(
    gpu: &gpu_context::GpuContext,
    sequence: &Sequence,
    map: &JumpMap,
    out: &Path,
) -> anyhow::Result<String> {
    let run = Player::new(
        map,
        &PlaybackParams {
            seed: SEED,
            ..PlaybackParams::default()
        },
    )?
    .generate(STRIP_RUN_FRAMES);
    let mut weights = vec![0.0; map.components()];
    let mut frames = Vec::with_capacity(run.frames.len());
    for frame in &run.frames {
        frame.weights_into(map, &mut weights);
        let mut mesh = vec![Vec3::ZERO; map.n_vertices()];
        map.reconstructor().reconstruct(&weights, &mut mesh)?;
        frames.push(mesh);
    }
    let name = format!("jumpmap-{}.png", sequence.slug());
    let path = out.join(&name);
    let image = figures::strip::render_strip(
        &gpu.device,
        &gpu.queue,
        &frames,
        &sequence.triangles,
        &figures::strip::StripOptions {
            count: STRIP_PANELS,
            panel_size: STRIP_PANEL,
            albedo: None,
        },
        &path,
    )?;
    figures::strip::write_png(&path, &image)?;
    Ok(name)
}

fn measure(
    sequence: &Sequence,
    gpu: Option<&gpu_context::GpuContext>,
    out: &Path,
) -> anyhow::Result<Measured> {
    let (l, n) = (sequence.l(), sequence.n());
    let compression = TABLE_3_1_COMPONENTS
        .iter()
        .filter(|&&c| c < l)
        .map(|&c| {
            Ok((
                compression_ratio(l, n, c, FrameContents::Positions)?,
                compression_ratio(l, n, c, FrameContents::PositionsAndNormals)?,
            ))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let errors = reconstruction_errors(&sequence.frames, &TABLE_3_2_COMPONENTS)?;
    let (map, analysis_s, playback_fps) = speed(&sequence.frames)?;
    let start = Instant::now();
    let configs: Vec<(f64, f64, f64)> = SIGMAS
        .iter()
        .map(|&s| (s, 0.0, 0.0))
        .chain(QS.iter().skip(1).map(|&(q, qv)| (0.05, q, qv)))
        .collect();
    let sweep = configs
        .par_iter()
        .map(|&(s, q, qv)| sweep_row(&sequence.frames, s, q, qv))
        .collect::<anyhow::Result<Vec<_>>>()?;
    eprintln!(
        "{}: analysis {:.3} s, {:.0} frames/s, sweep {:.1} s",
        sequence.name,
        analysis_s,
        playback_fps,
        start.elapsed().as_secs_f64()
    );
    let strip = match gpu {
        Some(gpu) if !sequence.triangles.is_empty() => Some(strip(gpu, sequence, &map, out)?),
        _ => None,
    };
    Ok(Measured {
        compression,
        errors,
        components: (map.components(), map.velocity_components()),
        analysis_s,
        playback_fps,
        sweep,
        strip,
        loops: loop_rows(&map)?,
    })
}

/// Run the report.
pub fn run(out: &Path) -> anyhow::Result<()> {
    let total = Instant::now();
    let mut skipped = Vec::new();
    let sequences = load_sequences(&mut skipped, MAX_CLIP_FRAMES, "jump-map")?;
    let gpu = gpu_context::GpuContext::new(&gpu_context::GpuOptions::default())
        .map_err(|e| e.to_string());
    match &gpu {
        Ok(g) => eprintln!("GPU adapter for the strips: {}", g.summary()),
        Err(e) => eprintln!("no GPU adapter ({e}): no strips"),
    }
    let mut results = Vec::new();
    for sequence in &sequences {
        match measure(sequence, gpu.as_ref().ok(), out) {
            Ok(m) => results.push((sequence, m)),
            Err(e) => skipped.push(format!("`{}`: {e:#}", sequence.name)),
        }
    }
    let elapsed = total.elapsed().as_secs_f64();
    let md = report(&results, &skipped, &gpu, elapsed);
    atomic_out::write_bytes(&out.join("jumpmap.md"), md.as_bytes())?;
    atomic_out::write_bytes(&out.join("jumpmap.svg"), plot(&results).as_bytes())?;
    println!(
        "wrote {} and jumpmap.svg in {elapsed:.0} s",
        out.join("jumpmap.md").display()
    );
    Ok(())
}

fn table_3_1(md: &mut String, results: &[(&Sequence, Measured)], normals: bool) {
    let _ = write!(md, "| c | avatar (thesis) | skeleton (thesis) |");
    for (s, _) in results {
        let _ = write!(md, " {} |", s.name);
    }
    let _ = write!(md, "\n|---:|---:|---:|");
    for _ in results {
        let _ = write!(md, "---:|");
    }
    let _ = writeln!(md);
    for &(c, a_mb, a_r, s_mb, s_r) in &THESIS_TABLE_3_1 {
        let label = if c == 0 {
            "raw".to_owned()
        } else {
            c.to_string()
        };
        let _ = write!(
            md,
            "| {label} | {a_mb:.1} MB, 1:{a_r:.0} | {s_mb:.1} MB, 1:{s_r:.0} |"
        );
        for (_, m) in results {
            let pick = |(p, n): &(Compression, Compression)| if normals { *n } else { *p };
            let cell = if c == 0 {
                // Every row carries the raw size; take the first.
                m.compression
                    .first()
                    .map(|r| format!("{:.2} MB, 1:1", pick(r).raw_megabytes()))
            } else {
                m.compression
                    .iter()
                    .find(|(p, _)| p.components == c)
                    .map(|r| {
                        let r = pick(r);
                        format!("{:.2} MB, 1:{:.1}", r.pca_megabytes(), r.ratio())
                    })
            };
            let _ = write!(md, " {} |", cell.unwrap_or_else(|| "—".to_owned()));
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md);
}

fn table_3_2(md: &mut String, results: &[(&Sequence, Measured)], per_frame: bool) {
    let (la, ls) = ((THESIS_FRAMES.0 - 2) as f64, (THESIS_FRAMES.1 - 2) as f64);
    let _ = write!(md, "| c | avatar (thesis) | skeleton (thesis) |");
    for (s, _) in results {
        let _ = write!(md, " {} |", s.name);
    }
    let _ = write!(md, "\n|---:|---:|---:|");
    for _ in results {
        let _ = write!(md, "---:|");
    }
    let _ = writeln!(md);
    for &(c, ae, aev, se, sev) in &THESIS_TABLE_3_2 {
        let (da, ds) = if per_frame { (la, ls) } else { (1.0, 1.0) };
        let _ = write!(
            md,
            "| {c} | {} / {} | {} / {} |",
            num(ae / da),
            num(aev / da),
            num(se / ds),
            num(sev / ds)
        );
        for (s, m) in results {
            let d = if per_frame { (s.l() - 2) as f64 } else { 1.0 };
            let cell = m
                .errors
                .iter()
                .find(|e| e.components == c)
                .map_or("—".to_owned(), |e| {
                    format!("{} / {}", num(e.position / d), num(e.velocity / d))
                });
            let _ = write!(md, " {cell} |");
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md);
}

/// Three significant digits, without exponent for ordinary magnitudes.
fn num(x: f64) -> String {
    if !x.is_finite() {
        return "—".to_owned();
    }
    if x == 0.0 {
        return "0".to_owned();
    }
    let a = x.abs();
    if !(1e-3..1e5).contains(&a) {
        return format!("{x:.2e}");
    }
    let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

fn report(
    results: &[(&Sequence, Measured)],
    skipped: &[String],
    gpu: &Result<gpu_context::GpuContext, String>,
    elapsed: f64,
) -> String {
    let threads = std::thread::available_parallelism().map_or(0, usize::from);
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Jump maps: compression, reconstruction error, speed and the σ, q sweeps (thesis §3.2.3)\n"
    );
    let _ = writeln!(
        md,
        "Generated by `cargo xtask repro jumpmap` (the whole run took {elapsed:.0} s) on {} — \
         {threads} hardware threads, rayon pool of {}. Strips: {}.\n",
        cpu_model().unwrap_or_else(|| "an unknown CPU".to_owned()),
        rayon::current_num_threads(),
        match gpu {
            Ok(g) => format!("rendered on {}", g.summary()),
            Err(e) => format!("**not rendered**, no GPU adapter ({e})"),
        }
    );

    let _ = writeln!(md, "## Sequences\n");
    let _ = writeln!(
        md,
        "| sequence | source | frames l | vertices N | triangles | c, c* kept | note |"
    );
    let _ = writeln!(md, "|---|---|---:|---:|---:|---|---|");
    for (s, m) in results {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {}, {} | {} |",
            s.name,
            s.source,
            s.l(),
            s.n(),
            s.triangles.len(),
            m.components.0,
            m.components.1,
            s.note
        );
    }
    let _ = writeln!(
        md,
        "\nThe thesis's sequences: avatar, 115 frames; skeleton, 190 frames (vertex counts not \
         given).\n"
    );
    if !skipped.is_empty() {
        let _ = writeln!(md, "Not in the tables:\n");
        for s in skipped {
            let _ = writeln!(md, "- {s}");
        }
        let _ = writeln!(md);
    }

    let _ = writeln!(md, "## Table 3.1: storage against c\n");
    let _ = writeln!(
        md,
        "`metrics::compression_ratio`: raw = l · N · 3 f32 (positions); PCA = (1 + c) · N · 3 \
         f32 (the mean and c eigenframes) + l · c f32 weights. MB = 10⁶ bytes. Connectivity, \
         the velocity PCA and the jump map are not counted. Each cell: PCA size, ratio 1:r \
         (the raw row: the clip's size).\n"
    );
    table_3_1(&mut md, results, false);
    let _ = writeln!(
        md,
        "With normals in A_i (6 floats per vertex, as the thesis's A_i; the weights do not \
         double):\n"
    );
    table_3_1(&mut md, results, true);
    let _ = writeln!(
        md,
        "The thesis's columns do not follow from a fixed cost per eigenframe (one avatar frame \
         is 138 MB / 115 = 1.2 MB, so c = 1 … 10 should add 10.8 MB; the column adds 6.6 MB), \
         so only the order of magnitude compares. Ours are exact counts: each component costs \
         one frame plus l weights, so the ratio falls like l / (1 + c) for N ≫ l.\n"
    );

    let _ = writeln!(md, "## Table 3.2: reconstruction errors E(c) / E*(c)\n");
    let _ = writeln!(
        md,
        "`metrics::reconstruction_errors` (eqs. 3.12, 3.13): sums over the interior frames \
         i = 1 … l − 2, as printed in the thesis; E* leaves out vertices slower than 1 % of \
         the fastest (`VELOCITY_FLOOR`). Each cell: E / E*. c = 0 is the mean frame alone.\n"
    );
    table_3_2(&mut md, results, false);
    let _ = writeln!(
        md,
        "The same per interior frame (divided by l − 2; the thesis's by 113 and 188), which \
         compares clips of different lengths:\n"
    );
    table_3_2(&mut md, results, true);
    let _ = writeln!(
        md,
        "E (eq. 3.12) divides by Σ_n ‖p_in‖² in world coordinates, so it shrinks as a clip \
         moves away from the origin (the chicken stands at x ≈ 25–27, hence its tiny E): it is \
         not translation-invariant, and compares clips only in the same frame of reference. \
         E* (velocities) is.\n"
    );

    let _ = writeln!(md, "## Speed\n");
    let _ = writeln!(
        md,
        "Defaults (c = 10, c* = 5, σ = σ* = 0.05, m = 2, b = 3). Analysis: `JumpMap::analyze` \
         (both PCAs, D, D*, P, P*, P̂, pruning), median of {TIMING_RUNS}. Playback: \
         `Player::next_frame` + `weights_into` + `Reconstructor::reconstruct` of the positions, \
         one thread, at least {PLAYBACK_MIN_FRAMES} frames and {PLAYBACK_MIN_S} s. The thesis \
         (1.5 GHz Athlon) gives no timings beyond \"interactive to real-time\".\n"
    );
    let _ = writeln!(
        md,
        "| sequence | l | N | analysis (s) | play + reconstruct (frames/s) |"
    );
    let _ = writeln!(md, "|---|---:|---:|---:|---:|");
    for (s, m) in results {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {:.3} | {:.0} |",
            s.name,
            s.l(),
            s.n(),
            m.analysis_s,
            m.playback_fps
        );
    }
    let _ = writeln!(md);

    let _ = writeln!(md, "## σ and q: Figs. 3.8–3.10 as numbers\n");
    let _ = writeln!(
        md,
        "Each row: `JumpMap::analyze` with c = 10, c* = 5 and the σ = σ*, q, q* shown; a \
         {RUN_FRAMES}-frame run with m = 2, seed {SEED}, cut (b = 0), and the same run blended \
         (b = {BLEND_FRAMES}; the key frames drawn are the same, blending does not touch the \
         random stream).\n\n\
         - *jumps*: transitions j ≠ i + 1 in the cut run, *distinct* (i, j) pairs among them;\n\
         - *mean / max jump*: the residual ‖Ã_{{i+1}} − Ã_j‖ in units of the clip's mean frame \
         step d̄ (`sequence_stats`);\n\
         - *Δv cut / b = 3*: the largest per-vertex velocity change ‖x_{{t+1}} − 2x_t + x_{{t−1}}‖ \
         over all transitions (`transition_velocity_change`), divided by the largest one inside \
         the clip itself (`clip_max_velocity_change`): ≤ 1 means no transition jerks more than \
         the clip already does;\n\
         - *coverage*: share of the clip's frames played; *core*: share of the frames in the \
         pruned graph's core (`JumpMap::core`).\n\n\
         The row σ = 0.05, q = q* = 0 (the defaults) belongs to both sweeps.\n"
    );
    let _ = writeln!(
        md,
        "| sequence | σ = σ* | q | q* | jumps | distinct | mean jump (d̄) | max jump (d̄) | Δv cut | Δv b = 3 | coverage | core |"
    );
    let _ = writeln!(
        md,
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for (s, m) in results {
        for r in &m.sweep {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.0} % | {:.0} % |",
                s.name,
                r.sigma,
                r.q,
                r.q_velocity,
                r.stats.transitions,
                r.stats.distinct_transitions,
                r.stats.mean_jump_distance,
                r.stats.max_jump_distance,
                r.dv_cut,
                r.dv_blend,
                100.0 * r.stats.coverage,
                100.0 * r.core_share
            );
        }
    }
    let _ = writeln!(
        md,
        "\n(The blended runs took {} transitions in all, the cut runs {}: a blended transition \
         spends b + 1 frames, so a run of the same length makes fewer.)\n",
        results
            .iter()
            .flat_map(|(_, m)| m.sweep.iter().map(|r| r.transitions_blend))
            .sum::<usize>(),
        results
            .iter()
            .flat_map(|(_, m)| m.sweep.iter().map(|r| r.stats.transitions))
            .sum::<usize>()
    );
    let _ = writeln!(
        md,
        "The thesis reads Figs. 3.8–3.10 by eye: σ ≈ 0.05 natural for the avatar, 0.30 for the \
         skeleton, too low or too high unstable; one criterion alone (q = 1 or q* = 1) finds \
         good transitions in the first 100–140 frames, both together need the whole clip.\n"
    );

    loop_table(&mut md, results);

    let _ = writeln!(md, "## Strips\n");
    match gpu {
        Ok(_) => {
            let _ = writeln!(
                md,
                "{STRIP_PANELS} evenly spaced frames (first to last) of a {STRIP_RUN_FRAMES}-frame \
                 run with the defaults, seed {SEED}, one camera framing the whole run \
                 (`figures::strip::render_strip`, as `cloth-vis anim jumpmap --strip`).\n"
            );
            for (s, m) in results {
                if let Some(file) = &m.strip {
                    let _ = writeln!(md, "{}:\n\n![{}]({file})\n", s.name, s.name);
                }
            }
        }
        Err(e) => {
            let _ = writeln!(md, "Not rendered: no GPU adapter ({e}).\n");
        }
    }
    let _ = writeln!(
        md,
        "`jumpmap.svg`: E per interior frame against the compression ratio 1:r (positions), \
         c = 2 … 10, with the thesis's avatar and skeleton.\n"
    );
    md
}

/// E per interior frame against the ratio r, c = 2 … 10.
fn plot(results: &[(&Sequence, Measured)]) -> String {
    let mut series = Vec::new();
    for (name, frames, column) in [
        ("avatar (thesis)", THESIS_FRAMES.0, 0),
        ("skeleton (thesis)", THESIS_FRAMES.1, 1),
    ] {
        let points = THESIS_TABLE_3_2
            .iter()
            .filter(|r| r.0 >= 2)
            .filter_map(|&(c, ae, _, se, _)| {
                let t = THESIS_TABLE_3_1.iter().find(|t| t.0 == c)?;
                let (ratio, e) = if column == 0 { (t.2, ae) } else { (t.4, se) };
                Some((ratio, e / (frames - 2) as f64))
            })
            .collect();
        series.push(Series {
            label: name.to_owned(),
            points,
        });
    }
    for (s, m) in results {
        let points = m
            .errors
            .iter()
            .filter(|e| e.components >= 2)
            .filter_map(|e| {
                let (p, _) = m
                    .compression
                    .iter()
                    .find(|(p, _)| p.components == e.components)?;
                Some((p.ratio(), e.position / (s.l() - 2) as f64))
            })
            .collect();
        series.push(Series {
            label: s.name.clone(),
            points,
        });
    }
    log_log_svg(
        "Jump maps: E per frame against compression ratio (c = 2 … 10)",
        "compression ratio r (1:r)",
        "E(c) / (l − 2)",
        &series,
    )
}
