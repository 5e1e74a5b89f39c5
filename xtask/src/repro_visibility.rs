//! `cargo xtask repro visibility [--quick] [--max-level L]`: the visibility engine of
//! `occlusion-gpu` against the seed's Table 1 (paper 000): for the full Stanford bunny and the
//! last frame of the synthetic cloth,
//!
//! - `cpu` (exact ray casting) at levels 0..=L: time, rays, rays/s, and the error of the
//!   ambient term a_i against an exact level-6 `cpu` reference (level 5 with `--quick`): what
//!   more directions buy;
//! - `depth` and `query` (GPU) at levels 0..=L × depth-map resolutions: time, mean and max
//!   |Δa| against `cpu` at the same level, share of vertices off by more than 0.05, and the
//!   error against the reference.
//!
//! On a software adapter (lavapipe/llvmpipe) `query` costs one draw per (vertex, direction),
//! so it runs only where N·k stays under a draw budget, at fewer resolutions; the report lists
//! what was skipped. Without an adapter only the `cpu` rows are written.
//!
//! Writes `target/repro/visibility.md` and `target/repro/visibility.svg` (atomically).

use std::path::Path;
use std::time::Instant;

use anyhow::Context as _;
use lightsphere::Lightsphere;
use occlusion_gpu::{Backend, DepthParams, Scene, VisibilityEngine, VisibilityParams};

mod report;

/// A measurement whose first run is shorter than this is repeated twice more and the median
/// of the three runs is reported; longer ones are run once.
pub(crate) const REPEAT_BELOW_MS: f64 = 1000.0;
/// Vertices whose a_i differs by more than this count as "off".
pub(crate) const OFF_THRESHOLD: f32 = 0.05;
/// On a software adapter, `query` (one draw per vertex and direction) runs a level only when
/// its predicted time — N·k × the time per draw measured at the previous level (at first the
/// warm-up's) — is at most this many seconds.
const SOFTWARE_QUERY_BUDGET_S: f64 = 60.0;
/// The same with `--quick`.
const SOFTWARE_QUERY_BUDGET_S_QUICK: f64 = 10.0;
/// The seed's Table 1, bunny (35k vertices), time₁ (ms, without vertex filtering), k = 6…1026.
const SEED_BUNNY_TIME1_MS: [(usize, f64); 5] = [
    (6, 445.0),
    (18, 1082.0),
    (66, 3606.0),
    (258, 13715.0),
    (1026, 60304.0),
];

/// What one run measures.
struct Plan {
    levels: Vec<u32>,
    reference_level: u32,
    resolutions: Vec<u32>,
    quick: bool,
}

/// One mesh of the report.
struct Case {
    name: &'static str,
    source: String,
    scene: Scene,
    vertices: usize,
    triangles: usize,
}

struct CpuRow {
    level: u32,
    k: usize,
    millis: f64,
    runs: usize,
    rays: u64,
    ambient: Vec<f32>,
}

struct GpuRow {
    backend: Backend,
    resolution: u32,
    level: u32,
    k: usize,
    millis: f64,
    runs: usize,
    vs_cpu: ErrorStats,
    vs_reference: ErrorStats,
    /// `query` only: against `depth` at the same resolution and level, when measured.
    vs_depth: Option<ErrorStats>,
}

/// Everything measured on one mesh.
struct CaseResult {
    cpu: Vec<CpuRow>,
    /// Error of each `cpu` level against the reference, in the order of `cpu`.
    cpu_vs_reference: Vec<ErrorStats>,
    reference_millis: f64,
    reference_rays: u64,
    cpu_setup_millis: f64,
    gpu: Vec<GpuRow>,
    gpu_setup_millis: Vec<(Backend, u32, f64)>,
}

/// |a − b| over the vertices where both are finite.
#[derive(Clone, Copy, Default)]
pub(crate) struct ErrorStats {
    pub(crate) mean: f64,
    pub(crate) max: f64,
    /// Fraction of compared vertices with |a − b| > [`OFF_THRESHOLD`].
    pub(crate) off: f64,
    /// Compared vertices with a ≠ b.
    differ: usize,
    compared: usize,
}

pub(crate) fn error_stats(a: &[f32], b: &[f32]) -> ErrorStats {
    let (mut sum, mut max, mut off, mut differ, mut compared) =
        (0.0f64, 0.0f64, 0usize, 0usize, 0usize);
    for (x, y) in a.iter().zip(b) {
        if x.is_finite() && y.is_finite() {
            let d = (x - y).abs();
            sum += f64::from(d);
            max = max.max(f64::from(d));
            off += usize::from(d > OFF_THRESHOLD);
            differ += usize::from(d > 0.0);
            compared += 1;
        }
    }
    let n = compared.max(1) as f64;
    ErrorStats {
        mean: sum / n,
        max,
        off: off as f64 / n,
        differ,
        compared,
    }
}

/// Runs `f` once; when that took less than [`REPEAT_BELOW_MS`], twice more. Returns the last
/// result, the median time (ms) and the number of runs.
pub(crate) fn timed<T>(
    mut f: impl FnMut() -> anyhow::Result<T>,
) -> anyhow::Result<(T, f64, usize)> {
    let start = Instant::now();
    let mut result = f()?;
    let first = start.elapsed().as_secs_f64() * 1e3;
    if first >= REPEAT_BELOW_MS {
        return Ok((result, first, 1));
    }
    let mut times = vec![first];
    for _ in 0..2 {
        let start = Instant::now();
        result = f()?;
        times.push(start.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    Ok((result, times[1], 3))
}

fn runs_label(runs: usize) -> &'static str {
    if runs == 1 { "1 run" } else { "median of 3" }
}

/// The full bunny and the synthetic cloth's last frame.
fn load_cases() -> anyhow::Result<Vec<Case>> {
    let root = test_data::data_root();
    let bunny_path = root.join("meshes/bun_zipper.ply");
    if !bunny_path.is_file() {
        anyhow::bail!(
            "missing {}: the visibility repro needs the shared data (`../shared/data` beside \
             the workspace, or set {} to its folder)",
            bunny_path.display(),
            test_data::DATA_ENV
        );
    }
    let (bunny, _) = meshio::load_mesh(&bunny_path, &meshio::LoadOptions::default())
        .with_context(|| format!("loading {}", bunny_path.display()))?;
    let bunny_case = Case {
        name: "bunny",
        source: "`meshes/bun_zipper.ply`".to_owned(),
        vertices: bunny.positions.len(),
        triangles: bunny.triangles.len(),
        scene: Scene::single(bunny.positions, bunny.normals, bunny.triangles)?,
    };

    eprintln!("simulating the synthetic cloth (synth::ClothParams::default()) …");
    let params = synth::ClothParams::default();
    let start = Instant::now();
    let cloth = synth::simulate_cloth(&params)?;
    let positions = cloth
        .frames
        .last()
        .context("the cloth simulation returned no frames")?
        .clone();
    let normals =
        meshio::compute_normals(&positions, &cloth.triangles, meshio::NormalWeighting::Angle);
    eprintln!(
        "cloth: {} frames in {:.1} s",
        cloth.frames.len(),
        start.elapsed().as_secs_f64()
    );
    let cloth_case = Case {
        name: "cloth",
        source: format!(
            "`synth::simulate_cloth(&ClothParams::default())`, frame {} of {} (grid {}², the \
             cloth alone: the sphere it fell on does not occlude)",
            cloth.frames.len() - 1,
            cloth.frames.len(),
            cloth.grid
        ),
        vertices: positions.len(),
        triangles: cloth.triangles.len(),
        scene: Scene::single(positions, normals, cloth.triangles.clone())?,
    };
    Ok(vec![bunny_case, cloth_case])
}

/// `cpu` at every level of the plan and the reference level.
/// What [`measure_cpu`] returns.
struct CpuMeasured {
    rows: Vec<CpuRow>,
    /// a_i at the reference level.
    reference: Vec<f32>,
    reference_millis: f64,
    reference_rays: u64,
    setup_millis: f64,
}

fn measure_cpu(case: &Case, plan: &Plan) -> anyhow::Result<CpuMeasured> {
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    // Warm-up: builds and caches the BVH (reused while the geometry is unchanged).
    let start = Instant::now();
    engine.compute(&case.scene, &Lightsphere::new(0)?)?;
    let setup = start.elapsed().as_secs_f64() * 1e3;
    eprintln!(
        "[{}] cpu setup (BVH build + level 0): {setup:.1} ms",
        case.name
    );
    let mut rows = Vec::new();
    let mut last = None;
    for &level in &plan.levels {
        let sphere = Lightsphere::new(level)?;
        let (matrix, millis, runs) = timed(|| Ok(engine.compute(&case.scene, &sphere)?))?;
        let rays = engine.last_ray_count();
        eprintln!(
            "[{}] cpu level {level} (k {}): {millis:.1} ms ({}), {rays} rays, {:.3e} rays/s",
            case.name,
            sphere.len(),
            runs_label(runs),
            rays as f64 / (millis / 1e3)
        );
        rows.push(CpuRow {
            level,
            k: sphere.len(),
            millis,
            runs,
            rays,
            ambient: matrix.ambient(),
        });
        last = Some(matrix);
    }
    // The reference: refine the finest measured matrix (its directions are the reference's
    // first ones), or compute it when the plan measured nothing coarser.
    let sphere = Lightsphere::new(plan.reference_level)?;
    let start = Instant::now();
    let (reference, rays) = match last {
        Some(mut matrix) if matrix.directions_len() < sphere.len() => {
            engine.refine(&case.scene, &mut matrix, &sphere)?;
            let rays = engine.last_ray_count();
            (matrix, rays)
        }
        Some(matrix) if matrix.directions_len() == sphere.len() => (matrix, 0),
        _ => {
            let matrix = engine.compute(&case.scene, &sphere)?;
            (matrix, engine.last_ray_count())
        }
    };
    let millis = start.elapsed().as_secs_f64() * 1e3;
    eprintln!(
        "[{}] cpu reference level {} (k {}): {:.1} s, {rays} more rays",
        case.name,
        plan.reference_level,
        sphere.len(),
        millis / 1e3
    );
    Ok(CpuMeasured {
        rows,
        reference: reference.ambient(),
        reference_millis: millis,
        reference_rays: rays,
        setup_millis: setup,
    })
}

/// The GPU backend grid; skipped measurements are described in `skipped`.
#[allow(clippy::too_many_arguments)]
fn measure_gpu(
    case: &Case,
    plan: &Plan,
    gpu: &gpu_context::GpuContext,
    cpu: &[CpuRow],
    reference: &[f32],
    skipped: &mut Vec<String>,
    rows: &mut Vec<GpuRow>,
    setups: &mut Vec<(Backend, u32, f64)>,
) -> anyhow::Result<()> {
    let software = gpu.summary().is_software;
    let budget_s = if plan.quick {
        SOFTWARE_QUERY_BUDGET_S_QUICK
    } else {
        SOFTWARE_QUERY_BUDGET_S
    };
    let mut depth_ambient = std::collections::HashMap::new();
    for backend in [Backend::Depth, Backend::Query] {
        for &resolution in &plan.resolutions {
            let query_software_resolutions: &[u32] =
                if plan.quick { &[1024] } else { &[512, 1024] };
            if backend == Backend::Query
                && software
                && !query_software_resolutions.contains(&resolution)
            {
                skipped.push(format!(
                    "{}: `query` at {resolution}² (software adapter: `query` runs at {} only)",
                    case.name,
                    query_software_resolutions
                        .iter()
                        .map(|r| format!("{r}²"))
                        .collect::<Vec<_>>()
                        .join(" and ")
                ));
                continue;
            }
            let params = VisibilityParams::default()
                .with_depth(DepthParams::default().with_resolution(resolution));
            let mut engine = VisibilityEngine::with_gpu(&gpu.device, &gpu.queue, backend, params);
            let start = Instant::now();
            if let Err(e) = engine.compute(&case.scene, &Lightsphere::new(0)?) {
                skipped.push(format!(
                    "{}: `{}` at {resolution}²: failed at level 0 ({e})",
                    case.name,
                    backend.name()
                ));
                eprintln!(
                    "[{}] {} {resolution}: failed: {e}",
                    case.name,
                    backend.name()
                );
                continue;
            }
            let setup = start.elapsed().as_secs_f64() * 1e3;
            setups.push((backend, resolution, setup));
            // Seconds per (vertex, direction), from the last run of this engine.
            let mut per_draw_s = setup / 1e3 / (case.vertices * 6) as f64;
            for (&level, cpu_row) in plan.levels.iter().zip(cpu) {
                let sphere = Lightsphere::new(level)?;
                let draws = case.vertices * sphere.len();
                let predicted = per_draw_s * draws as f64;
                if backend == Backend::Query && software && predicted > budget_s {
                    let last = plan.levels.last().copied().unwrap_or(level);
                    let levels = if last > level {
                        format!("levels {level}–{last}")
                    } else {
                        format!("level {level}")
                    };
                    skipped.push(format!(
                        "{}: `query` at {resolution}², {levels}: level {level} needs N·k = \
                         {draws} draws, ≈ {:.0} s at the {:.1} µs per draw measured at the \
                         previous level, over the software budget of {budget_s:.0} s per \
                         measurement",
                        case.name,
                        predicted,
                        per_draw_s * 1e6
                    ));
                    eprintln!(
                        "[{}] query {resolution} level {level}: skipped (≈ {predicted:.0} s \
                         predicted)",
                        case.name
                    );
                    break;
                }
                let result = timed(|| Ok(engine.compute(&case.scene, &sphere)?));
                let (matrix, millis, runs) = match result {
                    Ok(r) => r,
                    Err(e) => {
                        skipped.push(format!(
                            "{}: `{}` at {resolution}², level {level}: failed ({e})",
                            case.name,
                            backend.name()
                        ));
                        eprintln!(
                            "[{}] {} {resolution} level {level}: failed: {e}",
                            case.name,
                            backend.name()
                        );
                        continue;
                    }
                };
                per_draw_s = millis / 1e3 / draws as f64;
                let ambient = matrix.ambient();
                let vs_cpu = error_stats(&ambient, &cpu_row.ambient);
                let vs_reference = error_stats(&ambient, reference);
                let vs_depth = if backend == Backend::Query {
                    depth_ambient
                        .get(&(resolution, level))
                        .map(|d: &Vec<f32>| error_stats(&ambient, d))
                } else {
                    depth_ambient.insert((resolution, level), ambient);
                    None
                };
                eprintln!(
                    "[{}] {} {resolution} level {level} (k {}): {millis:.1} ms ({}), mean |Δa| \
                     {:.2e}, max {:.3}, off {:.2}%",
                    case.name,
                    backend.name(),
                    sphere.len(),
                    runs_label(runs),
                    vs_cpu.mean,
                    vs_cpu.max,
                    vs_cpu.off * 100.0
                );
                rows.push(GpuRow {
                    backend,
                    resolution,
                    level,
                    k: sphere.len(),
                    millis,
                    runs,
                    vs_cpu,
                    vs_reference,
                    vs_depth,
                });
            }
        }
    }
    Ok(())
}

/// First "model name" of /proc/cpuinfo, when there is one.
/// The CPU's model name from `/proc/cpuinfo` (Linux), for reports.
pub(crate) fn cpu_model() -> Option<String> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    info.lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split_once(':'))
        .map(|(_, v)| v.trim().to_owned())
}

/// Run the report.
pub fn run(out: &Path, quick: bool, max_level: u32) -> anyhow::Result<()> {
    let total = Instant::now();
    let max_level = if quick { max_level.min(3) } else { max_level };
    let plan = Plan {
        levels: (0..=max_level).collect(),
        reference_level: if quick { 5 } else { 6 }.max(max_level),
        resolutions: if quick {
            vec![256, 1024]
        } else {
            vec![256, 512, 1024, 2048]
        },
        quick,
    };
    // Fail on a bad level before any long computation.
    Lightsphere::new(plan.reference_level)?;
    let cases = load_cases()?;

    let gpu = match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(gpu) => {
            eprintln!("GPU adapter: {}", gpu.summary());
            Ok(gpu)
        }
        Err(e) => {
            eprintln!("no GPU adapter ({e}): cpu rows only");
            Err(e.to_string())
        }
    };

    let mut skipped = Vec::new();
    let mut results = Vec::new();
    for case in &cases {
        let CpuMeasured {
            rows: cpu,
            reference,
            reference_millis,
            reference_rays,
            setup_millis: cpu_setup_millis,
        } = measure_cpu(case, &plan)?;
        let cpu_vs_reference = cpu
            .iter()
            .map(|r| error_stats(&r.ambient, &reference))
            .collect();
        let mut gpu_rows = Vec::new();
        let mut gpu_setup_millis = Vec::new();
        if let Ok(gpu) = &gpu {
            measure_gpu(
                case,
                &plan,
                gpu,
                &cpu,
                &reference,
                &mut skipped,
                &mut gpu_rows,
                &mut gpu_setup_millis,
            )?;
        }
        results.push(CaseResult {
            cpu,
            cpu_vs_reference,
            reference_millis,
            reference_rays,
            cpu_setup_millis,
            gpu: gpu_rows,
            gpu_setup_millis,
        });
    }
    let elapsed = total.elapsed().as_secs_f64();

    let md = report::report(&plan, &cases, &results, &gpu, &skipped, elapsed);
    let svg = report::plot(&plan, &cases[0], &results[0]);
    atomic_out::write_bytes(&out.join("visibility.md"), md.as_bytes())?;
    atomic_out::write_bytes(&out.join("visibility.svg"), svg.as_bytes())?;
    println!(
        "wrote {} and visibility.svg in {elapsed:.0} s",
        out.join("visibility.md").display()
    );
    Ok(())
}
