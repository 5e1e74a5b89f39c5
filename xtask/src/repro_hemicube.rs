//! `cargo xtask repro hemicube [--quick]`: static visibility maps (thesis §4.3, crate
//! `hemicube`) on the shared draped dress (`meshes/garments/dress-victor-iso-draped.obj`):
//!
//! - Table 4.1 rebuilt: the thesis's four map builders (triangle rasterizer with and without
//!   triangle preselection, raytracer with triangle preselection, raytracer with grid
//!   traversal) × HC 8², HC 16², SP 8², SP 16², HS 16×4, HS 32×8 beside ours (GPU atlas, exact
//!   rays with the 1/6 preselection, exact rays over the BVH): time, speed-up, rays or pixels,
//!   error against the reference;
//! - HC 64² of the whole dress by rays (and by the GPU atlas on a hardware adapter);
//! - convergence of HC, SP and HS (and HC with the seed's midpoint ΔF) against an exact HC 256²
//!   reference (HC 128² with `--quick`): time, mean and max |Δ open fraction|, bytes per vertex;
//! - the same integral discretised by `occlusion-gpu`'s `cpu` backend (a_i over lightsphere
//!   levels 2–5) and which of the two converges faster per unit of time;
//! - the runtime radiance's two environment look-ups, cube map and exact ([`lookup`]).
//!
//! On a software adapter (lavapipe/llvmpipe) the GPU atlas runs HC 8² and SP 8² only (its cost
//! grows as vertices × faces × triangles); without an adapter only the ray rows are written.
//!
//! Writes `target/repro/hemicube.md` and `target/repro/hemicube.svg` (atomically); the text
//! and the plot are made in [`report`].

use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context as _;
use hemicube::{
    BuildParams, DEFAULT_APERTURE_DEG, FormFactorRule, GpuBuilder, Model, PixelLayout, RingSpacing,
    VisibilityMaps,
};
use lightsphere::Lightsphere;
use occlusion_gpu::{RayCaster, Scene, VisibilityEngine, VisibilityParams};

mod lookup;
mod report;

use crate::repro_visibility::{REPEAT_BELOW_MS, timed};

/// The mesh, relative to the shared data root.
const MESH: &str = "meshes/garments/dress-victor-iso-draped.obj";
/// The thesis's triangle preselection distance (units of the mesh's largest side).
const PRESELECTION: f32 = 1.0 / 6.0;
/// Largest planar resolution whose ray maps are kept to compare with the GPU atlas.
const KEEP_MAPS_UP_TO: u32 = 64;
/// Lightsphere levels of the a_i comparison.
const SPHERE_LEVELS: std::ops::RangeInclusive<u32> = 2..=5;

fn hc(res: u32) -> Model {
    Model::Hemicube { res }
}

fn sp(res: u32) -> Model {
    Model::SinglePlane {
        res,
        aperture_deg: DEFAULT_APERTURE_DEG,
    }
}

fn hs(phi: u32, theta: u32) -> Model {
    Model::Hemisphere {
        phi,
        theta,
        spacing: RingSpacing::EqualTheta,
    }
}

/// The six configurations of Table 4.1, in its column order.
fn table_models() -> [Model; 6] {
    [hc(8), hc(16), sp(8), sp(16), hs(16, 4), hs(32, 8)]
}

/// Which of our builders stands for a thesis row.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Ours {
    Gpu,
    RaysPreselected,
    RaysBvh,
}

impl Ours {
    fn name(self) -> &'static str {
        match self {
            Ours::Gpu => "GPU atlas",
            Ours::RaysPreselected => "rays, max distance 1/6",
            Ours::RaysBvh => "rays over the BVH, no limit",
        }
    }
}

/// One row of the thesis's Table 4.1 (seconds on an Intel Celeron 800 MHz with a TNT2).
struct ThesisRow {
    method: &'static str,
    distance: &'static str,
    ours: Ours,
    ours_note: &'static str,
    seconds: [f64; 6],
}

const THESIS: [ThesisRow; 4] = [
    ThesisRow {
        method: "Triangle Rasterizer",
        distance: "2.0",
        ours: Ours::Gpu,
        ours_note: "GPU atlas",
        seconds: [28.4, 30.0, 4.3, 5.0, 51.5, 54.7],
    },
    ThesisRow {
        method: "Triangle Rasterizer with preselection",
        distance: "1/6",
        ours: Ours::Gpu,
        ours_note: "GPU atlas (same run)",
        seconds: [15.2, 17.0, 3.1, 3.7, 15.0, 20.6],
    },
    ThesisRow {
        method: "Raytracer with triangle preselection",
        distance: "1/6",
        ours: Ours::RaysPreselected,
        ours_note: "rays, max distance 1/6",
        seconds: [120.0, 457.9, 32.2, 104.3, 33.3, 110.6],
    },
    ThesisRow {
        method: "Raytracer with grid traversal",
        distance: "2.0",
        ours: Ours::RaysBvh,
        ours_note: "rays over the BVH, no limit",
        seconds: [27.1, 103.8, 9.3, 46.1, 7.2, 26.8],
    },
];

/// |a − b| over the vertices where both are finite.
#[derive(Clone, Copy, Default)]
struct ErrorStats {
    mean: f64,
    max: f64,
}

fn error_stats(a: &[f32], b: &[f32]) -> ErrorStats {
    let (mut sum, mut max, mut compared) = (0.0f64, 0.0f64, 0usize);
    for (x, y) in a.iter().zip(b) {
        if x.is_finite() && y.is_finite() {
            let d = (f64::from(*x) - f64::from(*y)).abs();
            sum += d;
            max = max.max(d);
            compared += 1;
        }
    }
    ErrorStats {
        mean: sum / compared.max(1) as f64,
        max,
    }
}

/// Pixels where the GPU atlas and the rays disagree.
#[derive(Clone, Copy)]
struct Disagreement {
    pixels: u64,
    total: u64,
    vertices: usize,
}

/// One built set of maps.
struct Run {
    model: Model,
    rule: FormFactorRule,
    max_distance: Option<f32>,
    gpu: bool,
    millis: f64,
    runs: usize,
    /// Rays cast or pixels rasterised.
    samples: u64,
    bytes: usize,
    ff_sum: f64,
    err: ErrorStats,
    /// GPU only: pipeline creation (ms) and the disagreement with the rays' maps.
    gpu_setup_ms: f64,
    disagreement: Option<Disagreement>,
    /// Ray maps of small planar models, kept for the GPU comparison.
    maps: Option<VisibilityMaps>,
}

fn find(
    runs: &[Run],
    model: Model,
    rule: FormFactorRule,
    max_distance: Option<f32>,
    gpu: bool,
) -> Option<&Run> {
    runs.iter().find(|r| {
        r.model == model && r.rule == rule && r.max_distance == max_distance && r.gpu == gpu
    })
}

fn exact(runs: &[Run], model: Model) -> Option<&Run> {
    find(runs, model, FormFactorRule::Exact, None, false)
}

/// Builds the maps of `model` by rays and compares them with the reference.
fn measure_rays(
    caster: &RayCaster,
    model: Model,
    rule: FormFactorRule,
    max_distance: Option<f32>,
    reference: &[f32],
) -> anyhow::Result<Run> {
    let layout = Arc::new(PixelLayout::new(model, rule)?);
    let mut params = BuildParams::default();
    params.max_distance = max_distance;
    let ((maps, stats), millis, runs) =
        timed(|| Ok(hemicube::build_with_caster(caster, layout.clone(), &params)))?;
    let err = error_stats(&maps.open_fraction(), reference);
    eprintln!(
        "rays {} {rule:?}{}: {millis:.1} ms ({runs} run(s)), {} rays, mean |Δ| {:.2e}, max {:.3}",
        model.label(),
        max_distance.map_or(String::new(), |d| format!(" max distance {d:.3}")),
        stats.samples,
        err.mean,
        err.max
    );
    let planar_res = match model {
        Model::Hemicube { res } | Model::SinglePlane { res, .. } => res,
        Model::Hemisphere { .. } => u32::MAX,
    };
    let keep =
        planar_res <= KEEP_MAPS_UP_TO && rule == FormFactorRule::Exact && max_distance.is_none();
    Ok(Run {
        model,
        rule,
        max_distance,
        gpu: false,
        millis,
        runs,
        samples: stats.samples,
        bytes: maps.bytes_per_vertex(),
        ff_sum: layout.form_factor_sum(),
        err,
        gpu_setup_ms: 0.0,
        disagreement: None,
        maps: keep.then_some(maps),
    })
}

/// Builds the maps of `model` with the GPU atlas and compares them with the reference and
/// with the rays' maps of the same model.
fn measure_gpu(
    gpu: &gpu_context::GpuContext,
    caster: &RayCaster,
    model: Model,
    reference: &[f32],
    rays: Option<&VisibilityMaps>,
) -> anyhow::Result<Run> {
    let layout = Arc::new(PixelLayout::new(model, FormFactorRule::Exact)?);
    let start = Instant::now();
    let builder = GpuBuilder::new(gpu, layout.clone())?;
    let setup = start.elapsed().as_secs_f64() * 1e3;
    let ((maps, stats), millis, runs) =
        timed(|| Ok(builder.build_with_caster(gpu, caster, &BuildParams::default())?))?;
    let err = error_stats(&maps.open_fraction(), reference);
    let disagreement = rays.map(|r| {
        let per_vertex = maps.differing_pixels(r);
        let used = (0..maps.len()).filter(|&i| maps.frame(i).is_some()).count();
        Disagreement {
            pixels: per_vertex.iter().map(|&d| u64::from(d)).sum(),
            total: (used * model.pixel_count()) as u64,
            vertices: per_vertex.iter().filter(|&&d| d > 0).count(),
        }
    });
    eprintln!(
        "gpu {}: {millis:.1} ms ({runs} run(s)), setup {setup:.0} ms, {} pixels, {} passes, mean \
         |Δ| {:.2e}",
        model.label(),
        stats.samples,
        stats.passes,
        err.mean
    );
    Ok(Run {
        model,
        rule: FormFactorRule::Exact,
        max_distance: None,
        gpu: true,
        millis,
        runs,
        samples: stats.samples,
        bytes: maps.bytes_per_vertex(),
        ff_sum: layout.form_factor_sum(),
        err,
        gpu_setup_ms: setup,
        disagreement,
        maps: None,
    })
}

/// a_i of `occlusion-gpu`'s `cpu` backend at one lightsphere level.
struct SphereRun {
    level: u32,
    k: usize,
    millis: f64,
    runs: usize,
    rays: u64,
    err: ErrorStats,
}

fn measure_lightsphere(scene: &Scene, reference: &[f32]) -> anyhow::Result<(Vec<SphereRun>, f64)> {
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    // Warm-up: builds and caches the engine's BVH.
    let start = Instant::now();
    engine.compute(scene, &Lightsphere::new(0)?)?;
    let setup = start.elapsed().as_secs_f64() * 1e3;
    let mut rows = Vec::new();
    for level in SPHERE_LEVELS {
        let sphere = Lightsphere::new(level)?;
        let (matrix, millis, runs) = timed(|| Ok(engine.compute(scene, &sphere)?))?;
        let err = error_stats(&matrix.ambient(), reference);
        eprintln!(
            "lightsphere level {level} (k {}): {millis:.1} ms, mean |Δ| {:.2e}, max {:.3}",
            sphere.len(),
            err.mean,
            err.max
        );
        rows.push(SphereRun {
            level,
            k: sphere.len(),
            millis,
            runs,
            rays: engine.last_ray_count(),
            err,
        });
    }
    Ok((rows, setup))
}

/// Everything measured.
struct Results {
    vertices: usize,
    triangles: usize,
    reference_model: Model,
    reference_millis: f64,
    reference_rays: u64,
    reference_bytes: usize,
    compared: usize,
    bvh_millis: f64,
    runs: Vec<Run>,
    spheres: Vec<SphereRun>,
    sphere_setup_ms: f64,
    gpu: Result<gpu_context::AdapterSummary, String>,
    skipped: Vec<String>,
    quick: bool,
    /// `/proc/loadavg` when the run started.
    load: Option<String>,
}

/// The convergence families: exact ΔF, no distance limit.
fn convergence_models(reference_res: u32) -> [(&'static str, Vec<Model>); 3] {
    [
        (
            "HC rays",
            [8, 16, 32, 64, 128]
                .into_iter()
                .filter(|&n| n < reference_res)
                .map(hc)
                .collect(),
        ),
        ("SP rays", [8, 16, 32, 64].into_iter().map(sp).collect()),
        (
            "HS rays",
            [(16, 4), (32, 8), (64, 16), (128, 32)]
                .into_iter()
                .map(|(p, t)| hs(p, t))
                .collect(),
        ),
    ]
}

const MIDPOINT_RES: [u32; 3] = [8, 16, 32];

/// Run the report.
pub fn run(out: &Path, quick: bool) -> anyhow::Result<()> {
    let total = Instant::now();
    let load = std::fs::read_to_string("/proc/loadavg").ok();
    let path = test_data::shared_file(MESH).with_context(|| {
        format!(
            "missing {}: the hemicube repro needs the shared dress (`../shared/data` beside the \
             workspace, or set {} to its folder)",
            test_data::data_root().join(MESH).display(),
            test_data::DATA_ENV
        )
    })?;
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default())
        .with_context(|| format!("loading {}", path.display()))?;
    let (vertices, triangles) = (mesh.positions.len(), mesh.triangles.len());
    let scene = Scene::single(mesh.positions, mesh.normals, mesh.triangles)?;
    eprintln!("dress: {vertices} vertices, {triangles} triangles");

    let (caster, bvh_millis, _) = timed(|| Ok(RayCaster::new(&scene)?))?;
    eprintln!("BVH build: {bvh_millis:.1} ms");

    let reference_res = if quick { 128 } else { 256 };
    let reference_model = hc(reference_res);
    let layout = Arc::new(PixelLayout::new(reference_model, FormFactorRule::Exact)?);
    let start = Instant::now();
    let (maps, stats) = hemicube::build_with_caster(&caster, layout, &BuildParams::default());
    let reference_millis = start.elapsed().as_secs_f64() * 1e3;
    let reference = maps.open_fraction();
    let reference_bytes = maps.bytes_per_vertex();
    drop(maps);
    eprintln!(
        "reference {}: {:.1} s, {} rays",
        reference_model.label(),
        reference_millis / 1e3,
        stats.samples
    );

    // Every ray configuration once: the convergence families, the 1/6 preselection of
    // Table 4.1 and the seed's midpoint ΔF.
    let mut jobs: Vec<(Model, FormFactorRule, Option<f32>)> = Vec::new();
    for (_, models) in convergence_models(reference_res) {
        jobs.extend(models.into_iter().map(|m| (m, FormFactorRule::Exact, None)));
    }
    for m in table_models() {
        if !jobs.contains(&(m, FormFactorRule::Exact, None)) {
            jobs.push((m, FormFactorRule::Exact, None));
        }
        jobs.push((m, FormFactorRule::Exact, Some(PRESELECTION)));
    }
    jobs.extend(MIDPOINT_RES.map(|n| (hc(n), FormFactorRule::Midpoint, None)));
    let mut runs = Vec::new();
    for (model, rule, max_distance) in jobs {
        runs.push(measure_rays(
            &caster,
            model,
            rule,
            max_distance,
            &reference,
        )?);
    }

    let (spheres, sphere_setup_ms) = measure_lightsphere(&scene, &reference)?;

    let mut skipped = Vec::new();
    let gpu = match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(gpu) => {
            eprintln!("GPU adapter: {}", gpu.summary());
            let software = gpu.summary().is_software;
            let models: Vec<Model> = if software {
                vec![hc(8), sp(8)]
            } else {
                let mut m: Vec<Model> = table_models()
                    .into_iter()
                    .filter(Model::is_planar)
                    .collect();
                m.push(hc(64));
                m
            };
            for model in models {
                let rays = exact(&runs, model).and_then(|r| r.maps.as_ref());
                match measure_gpu(&gpu, &caster, model, &reference, rays) {
                    Ok(run) => runs.push(run),
                    Err(e) => {
                        eprintln!("gpu {}: failed: {e:#}", model.label());
                        skipped.push(format!("GPU atlas {}: failed ({e:#})", model.label()));
                    }
                }
            }
            Ok(gpu.summary().clone())
        }
        Err(e) => {
            eprintln!("no GPU adapter ({e}): ray rows only");
            Err(e.to_string())
        }
    };

    let lookups = lookup::section(&caster)?;
    let results = Results {
        vertices,
        triangles,
        reference_model,
        reference_millis,
        reference_rays: stats.samples,
        reference_bytes,
        compared: reference.iter().filter(|a| a.is_finite()).count(),
        bvh_millis,
        runs,
        spheres,
        sphere_setup_ms,
        gpu,
        skipped,
        quick,
        load,
    };
    let elapsed = total.elapsed().as_secs_f64();
    let md = report::report(&results, elapsed) + "\n" + &lookups;
    let svg = report::plot(&results);
    atomic_out::write_bytes(&out.join("hemicube.md"), md.as_bytes())?;
    atomic_out::write_bytes(&out.join("hemicube.svg"), svg.as_bytes())?;
    println!(
        "wrote {} and hemicube.svg in {elapsed:.0} s",
        out.join("hemicube.md").display()
    );
    Ok(())
}
