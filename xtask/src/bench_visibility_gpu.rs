//! `cargo xtask bench visibility-gpu [--quick] [--runs N] [--only MESH]`: occlusion-gpu's GPU
//! backends on the adapter at hand — `depth` (issue #20's GPU target: the full bunny at
//! k = 1026 in ≤ 5 ms, depth passes included) and the exact `rays` — beside the `cpu` backend
//! on the same machine.
//!
//! Per case: the median and the fastest of `--runs` calls of [`VisibilityEngine::ambient`] on one
//! engine (pipelines built once; each call uploads the scene, renders every depth map or builds and
//! uploads the BVH, tests every vertex and reads a_i back, as a deforming frame pays — `rays` keeps
//! its tree for an unchanged scene, so its calls alternate between the scene and a copy 1 + 2⁻²⁰
//! times larger, with refitting off), after three warm-up calls; the CPU time the calling thread
//! spent per call (recording, submission, driver, and `rays`' BVH build: when it is close to the
//! wall time the host is the limit, not the GPU); and what the speed costs in accuracy: the share
//! of M's cells that differ from the `cpu` backend's exact M, and max |Δa_i|. The `cpu` backend's
//! time (BVH build + trace, all threads) is measured on the same machine for the ratio.
//!
//! Cases: `depth` on the bunny at k = 6 … 1026 (depth maps of 1024²), the bunny at
//! k = 1026 at 256² … 2048² and with batches of 16 and 256 layers, the dragon and igea at
//! k = 258, a frame of the synthetic drape with its ball at k = 258 and 1026; `rays` beside
//! every 1024² row. `--quick` (for a software adapter): the bunny at k = 66 and 258, `depth`
//! at 256² and 1024², and `rays`. Writes `target/repro/bench-visibility-gpu.md`.
//! `--only MESH` keeps one mesh's rows.

use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

use anyhow::Context as _;
use lightsphere::Lightsphere;
use occlusion_gpu::{Backend, DepthParams, VisibilityEngine, VisibilityParams};

use crate::bench_visibility::{Case, drape_case, median, mesh_case};
use crate::repro_visibility::{ErrorStats, error_stats};

/// Calls before the timed ones (shader compilation, first allocations).
const WARM_UP_RUNS: usize = 3;

/// One measured configuration of a GPU backend.
#[derive(Clone, Copy)]
struct Setting {
    case: usize,
    backend: Backend,
    resolution: u32,
    /// Layers per batch (`DepthParams::max_array_bytes` / layer bytes); `None`: the default.
    layers: Option<u64>,
}

/// The exact answer for one (mesh, level), computed once.
struct Exact {
    case: usize,
    level: u32,
    millis: f64,
    matrix: occlusion_gpu::VisibilityMatrix,
}

/// CPU time the calling thread has used, in nanoseconds (`/proc/thread-self/schedstat`);
/// `None` where the file does not exist.
fn thread_cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

/// Share of the cells of `a` that differ from `b` (same shape).
fn differing_cells(
    a: &occlusion_gpu::VisibilityMatrix,
    b: &occlusion_gpu::VisibilityMatrix,
) -> f64 {
    let differ: u64 = a
        .bits()
        .iter()
        .zip(b.bits())
        .map(|(x, y)| u64::from((x ^ y).count_ones()))
        .sum();
    differ as f64 / (a.rows() * a.directions_len()).max(1) as f64
}

fn exact<'a>(
    cache: &'a mut Vec<Exact>,
    cases: &[Case],
    case: usize,
    level: u32,
) -> anyhow::Result<&'a Exact> {
    if let Some(index) = cache
        .iter()
        .position(|e| e.case == case && e.level == level)
    {
        return Ok(&cache[index]);
    }
    let sphere = Lightsphere::new(level)?;
    let mut times = Vec::new();
    let mut matrix = None;
    for _ in 0..3 {
        let start = Instant::now();
        let m = VisibilityEngine::cpu(VisibilityParams::default())
            .compute(&cases[case].scene, &sphere)?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
        matrix = Some(m);
    }
    cache.push(Exact {
        case,
        level,
        millis: median(times),
        matrix: matrix.context("three runs")?,
    });
    cache.last().context("just pushed")
}

/// Runs the benchmark and writes the report under `repro`.
pub fn run(repro: &Path, quick: bool, runs: usize, only: Option<&str>) -> anyhow::Result<()> {
    let runs = runs.max(1);
    let ctx = gpu_context::GpuContext::new(&gpu_context::GpuOptions::default())
        .context("the GPU benchmark needs an adapter")?;
    let adapter = ctx.summary();
    eprintln!("adapter: {adapter}");
    if adapter.is_software && !quick {
        eprintln!(
            "warning: {} is a software rasteriser; its times prove nothing about a GPU \
             (use --quick to check the benchmark runs)",
            adapter.name
        );
    }
    let max_layers = ctx.device.limits().max_texture_array_layers;
    let mut cases = vec![mesh_case("bunny", "meshes/bun_zipper.ply", 0)?];
    let mut settings: Vec<(Setting, u32)> = Vec::new();
    if quick {
        for level in [2, 3] {
            for resolution in [256, 1024] {
                let s = Setting {
                    case: 0,
                    backend: Backend::Depth,
                    resolution,
                    layers: None,
                };
                settings.push((s, level));
            }
        }
    } else {
        for level in 0..=4 {
            let s = Setting {
                case: 0,
                backend: Backend::Depth,
                resolution: 1024,
                layers: None,
            };
            settings.push((s, level));
        }
        for resolution in [256, 512, 2048] {
            let s = Setting {
                case: 0,
                backend: Backend::Depth,
                resolution,
                layers: None,
            };
            settings.push((s, 4));
        }
        for layers in [16, 256] {
            let s = Setting {
                case: 0,
                backend: Backend::Depth,
                resolution: 1024,
                layers: Some(layers),
            };
            settings.push((s, 4));
        }
        let wants = |mesh: &str| only.is_none_or(|only| only == mesh);
        let mut extra: Vec<(Case, &[u32])> = Vec::new();
        if wants("dragon") {
            extra.push((mesh_case("dragon", "meshes/dragon_vrip_res2.ply", 0)?, &[3]));
        }
        if wants("igea") {
            extra.push((mesh_case("igea", "meshes/igea.ply", 0)?, &[3]));
        }
        if wants("drape") {
            extra.push((drape_case(0)?, &[3, 4]));
        }
        for (case, levels) in extra {
            cases.push(case);
            for &level in levels {
                let s = Setting {
                    case: cases.len() - 1,
                    backend: Backend::Depth,
                    resolution: 1024,
                    layers: None,
                };
                settings.push((s, level));
            }
        }
    }
    // The exact `rays` backend beside every default `depth` row.
    let rays: Vec<(Setting, u32)> = settings
        .iter()
        .filter(|(s, _)| s.resolution == 1024 && s.layers.is_none())
        .map(|&(s, level)| {
            let s = Setting {
                backend: Backend::Rays,
                ..s
            };
            (s, level)
        })
        .collect();
    settings.extend(rays);
    let mut table = String::new();
    writeln!(
        table,
        "| mesh | N | k | backend | depth map | maps per batch | median ms | fastest ms | host \
         CPU ms | ms per direction | `cpu` ms (same machine) | `cpu` ÷ GPU | cells ≠ exact | \
         max \\|Δa\\| | vertices \\|Δa\\| > 0.05 |"
    )?;
    writeln!(
        table,
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )?;
    let mut cache = Vec::new();
    for (setting, level) in &settings {
        let case = &cases[setting.case];
        let sphere = Lightsphere::new(*level)?;
        let k = sphere.len();
        let mesh = case.name.split('-').next().unwrap_or(&case.name);
        if only.is_some_and(|only| mesh != only) {
            continue;
        }
        let mut depth = DepthParams::default().with_resolution(setting.resolution);
        let layer_bytes = u64::from(setting.resolution).pow(2) * 4;
        if let Some(layers) = setting.layers {
            depth.max_array_bytes = layers * layer_bytes;
        }
        // As occlusion-gpu batches: layers of one 2D array, within the byte budget and the
        // device's layer limit.
        let layers = (depth.max_array_bytes / layer_bytes)
            .clamp(1, u64::from(max_layers))
            .min(k as u64);
        // `rays` reuses its tree while the scene is unchanged and refits it when only
        // positions move: off, and every other call on a copy scaled by 1 + 2⁻²⁰, so that each
        // call builds its tree as a deforming frame without refits would.
        let cpu = occlusion_gpu::CpuParams::default().with_refit(false);
        let params = VisibilityParams::default().with_depth(depth).with_cpu(cpu);
        let backend = setting.backend;
        let twin = rebuilt_twin(&case.scene);
        let scenes = [&case.scene, &twin];
        let mut engine = VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, params);
        let (map, batch) = if backend == Backend::Depth {
            (format!("{}²", setting.resolution), layers.to_string())
        } else {
            ("—".to_owned(), "—".to_owned())
        };
        eprint!(
            "{mesh} k = {k}, {}, {map}, {batch} maps per batch: ",
            backend.name()
        );
        for run in 0..WARM_UP_RUNS {
            engine.ambient(scenes[run % 2], &sphere)?;
        }
        let (mut wall, mut host) = (Vec::new(), Vec::new());
        for run in 0..runs {
            let cpu_before = thread_cpu_ns();
            let start = Instant::now();
            let ambient = engine.ambient(scenes[(WARM_UP_RUNS + run) % 2], &sphere)?;
            wall.push(start.elapsed().as_secs_f64() * 1e3);
            if let (Some(a), Some(b)) = (cpu_before, thread_cpu_ns()) {
                host.push(b.saturating_sub(a) as f64 * 1e-6);
            }
            std::hint::black_box(ambient);
        }
        let fastest = wall.iter().copied().fold(f64::INFINITY, f64::min);
        let wall_median = median(wall);
        let host_median = (!host.is_empty()).then(|| median(host));
        let matrix = engine.compute(&case.scene, &sphere)?;
        let exact = exact(&mut cache, &cases, setting.case, *level)?;
        let cells = differing_cells(&matrix, &exact.matrix);
        let ErrorStats { max, off, .. } = error_stats(&matrix.ambient(), &exact.matrix.ambient());
        eprintln!("{wall_median:.2} ms (cpu {:.1} ms)", exact.millis);
        let n = case.scene.receiver_count();
        let name = backend.name();
        let host = host_median.map_or("—".to_owned(), |h| format!("{h:.2}"));
        let per_direction = wall_median / k as f64;
        let ratio = exact.millis / wall_median;
        let (cpu_ms, cells, off) = (exact.millis, cells * 100.0, off * 100.0);
        writeln!(
            table,
            "| {mesh} | {n} | {k} | `{name}` | {map} | {batch} | {wall_median:.2} | \
             {fastest:.2} | {host} | {per_direction:.4} | {cpu_ms:.1} | {ratio:.2}× | \
             {cells:.3} % | {max:.3} | {off:.2} % |"
        )?;
    }
    let threads = std::thread::available_parallelism().map_or(1, usize::from);
    let report = format!(
        "# Visibility on the GPU: occlusion-gpu's `depth` and `rays` backends\n\n\
         Adapter: {adapter}. `cpu` (exact, BVH build + trace) on the same machine's {threads} \
         threads. Each GPU time is the median of {runs} calls of `ambient` after \
         {WARM_UP_RUNS} warm-up calls on one engine: scene upload (and for `rays` the BVH \
         build: its calls alternate between the scene and a copy 1 + 2⁻²⁰ times larger, \
         refits off, so that none reuses the last tree), every depth map or ray, the \
         read-back of a_i. Host CPU: what the calling \
         thread spent per call (building, recording and submitting). Cells ≠ exact: the share \
         of M's cells decided differently from the `cpu` backend's ray cast.\n\n{table}\n\
         Written by `cargo xtask bench visibility-gpu{}{}`.\n",
        if quick { " --quick" } else { "" },
        only.map_or(String::new(), |m| format!(" --only {m}"))
    );
    print!("\n{report}");
    let path = repro.join("bench-visibility-gpu.md");
    atomic_out::write_bytes(&path, report.as_bytes())
        .with_context(|| format!("writing {}", path.display()))?;
    eprintln!("wrote {}", path.display());
    Ok(())
}

/// `scene` with every position 1 + 2⁻²⁰ times farther from the origin: another geometry for
/// the `rays` backend's tree cache (so a call on it builds a tree), the same work to trace.
fn rebuilt_twin(scene: &occlusion_gpu::Scene) -> occlusion_gpu::Scene {
    let mut twin = scene.clone();
    for index in 0..twin.objects().len() {
        if let Some(object) = twin.object_mut(index) {
            for p in &mut object.positions {
                *p *= 1.0 + f32::EPSILON * 8.0;
            }
        }
    }
    twin
}
