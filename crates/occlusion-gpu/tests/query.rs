//! The published `query` backend (one hardware occlusion query per vertex and direction;
//! GPU, lavapipe in CI) against the exact `cpu` backend and the `depth` backend, and the
//! GPU-resident result handle of both GPU backends.

#![cfg(feature = "gpu")]

mod common;

use std::time::Instant;

use common::*;
use gpu_context::GpuContext;
use lightsphere::Lightsphere;
use occlusion_gpu::{
    Backend, DepthParams, OcclusionError, Scene, VisibilityEngine, VisibilityMatrix,
    VisibilityParams,
};

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
use gpu_context::testing::gpu_or_skip as gpu;

fn engine(ctx: &GpuContext, backend: Backend, resolution: u32) -> VisibilityEngine {
    let params =
        VisibilityParams::default().with_depth(DepthParams::default().with_resolution(resolution));
    VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, params)
}

fn cpu_ambient(scene: &Scene, sphere: &Lightsphere) -> Vec<f32> {
    VisibilityEngine::cpu(VisibilityParams::default())
        .compute(scene, sphere)
        .unwrap()
        .ambient()
}

/// Mean |Δa| and the share of vertices off by > 0.05 between query and cpu.
fn compare(ctx: &GpuContext, scene: &Scene, level: u32, resolution: u32) -> (f64, f64) {
    let sphere = Lightsphere::new(level).unwrap();
    let exact = cpu_ambient(scene, &sphere);
    let start = Instant::now();
    let query = engine(ctx, Backend::Query, resolution)
        .ambient(scene, &sphere)
        .unwrap();
    let seconds = start.elapsed().as_secs_f64();
    let (mean, share) = ambient_difference(&query, &exact);
    let max = max_difference(&query, &exact);
    eprintln!(
        "query vs cpu, level {level} at {resolution}²: mean |Δa| = {mean:.4}, max {max:.4}, \
         share > 0.05 = {share:.4} ({seconds:.2} s)"
    );
    (mean, share)
}

fn max_difference(a: &[f32], b: &[f32]) -> f64 {
    a.iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| f64::from((x - y).abs()))
        .fold(0.0, f64::max)
}

/// Share of (i, j) entries where two matrices of the same shape disagree.
fn bit_disagreement(a: &VisibilityMatrix, b: &VisibilityMatrix) -> f64 {
    assert_eq!(
        (a.rows(), a.directions_len()),
        (b.rows(), b.directions_len())
    );
    let differing: u32 = a
        .bits()
        .iter()
        .zip(b.bits())
        .map(|(x, y)| (x ^ y).count_ones())
        .sum();
    f64::from(differing) / (a.rows() * a.directions_len()) as f64
}

/// The depth backend's tolerance on mean |Δa| (the same bias formula): a floor for the bias
/// plus a term shrinking with the texel size; the issue's 0.01 is met at the finest size.
fn mean_tolerance(resolution: u32) -> f64 {
    0.01 + 4.0 / f64::from(resolution)
}

#[test]
fn sphere_over_plane_agrees_with_cpu() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    for resolution in [256, 1024] {
        let (mean, share) = compare(&ctx, &scene, 2, resolution);
        assert!(
            mean <= mean_tolerance(resolution),
            "{resolution}: mean {mean}"
        );
        assert!(
            share <= 0.02 + 8.0 / f64::from(resolution),
            "{resolution}: share {share}"
        );
    }
}

#[test]
fn bunny_res4_agrees_with_cpu() {
    let Some(ctx) = gpu() else { return };
    let Some(scene) = shared_scene("meshes/bun_zipper_res4.ply") else {
        return;
    };
    for (level, resolution) in [(2, 512), (2, 2048), (3, 2048)] {
        let (mean, share) = compare(&ctx, &scene, level, resolution);
        assert!(
            mean <= mean_tolerance(resolution),
            "level {level}, {resolution}: mean {mean}"
        );
        assert!(
            share <= 0.02 + 16.0 / f64::from(resolution),
            "level {level}, {resolution}: share {share}"
        );
    }
}

/// With the same bias formula, texel choice and depth maps, the two GPU backends make the
/// same decision for (nearly) every (i, j): a point's rasterised depth and the compute
/// shader's comparison may round differently only for a vertex exactly at the stored depth.
#[test]
fn query_matches_depth_backend() {
    let Some(ctx) = gpu() else { return };
    let mut scenes = vec![("sphere over plane", sphere_over_plane())];
    if let Some(bunny) = shared_scene("meshes/bun_zipper_res4.ply") {
        scenes.push(("bunny res4", bunny));
    }
    let sphere = Lightsphere::new(2).unwrap();
    for (name, scene) in &scenes {
        for resolution in [256, 1024] {
            let query = engine(&ctx, Backend::Query, resolution)
                .compute(scene, &sphere)
                .unwrap();
            let depth = engine(&ctx, Backend::Depth, resolution)
                .compute(scene, &sphere)
                .unwrap();
            let disagreement = bit_disagreement(&query, &depth);
            let (mean, _) = ambient_difference(&query.ambient(), &depth.ambient());
            let max = max_difference(&query.ambient(), &depth.ambient());
            eprintln!(
                "{name} at {resolution}²: query vs depth bits differ on {disagreement:.2e} of \
                 entries, mean |Δa| = {mean:.2e}, max {max:.2e}"
            );
            // Measured on lavapipe: 0 differing entries. Allow rounding ties elsewhere.
            assert!(
                disagreement <= 1e-4,
                "{name} at {resolution}: {disagreement}"
            );
            assert!(mean <= 1e-4, "{name} at {resolution}: mean {mean}");
        }
    }
}

/// Refining level 2 → 3 computes only the new columns and equals computing level 3; the
/// GPU-side a_i equals a_i derived from the read-back bits.
#[test]
fn refine_and_gpu_ambient_are_consistent() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    let (coarse, fine) = (Lightsphere::new(2).unwrap(), Lightsphere::new(3).unwrap());
    let mut engine = engine(&ctx, Backend::Query, 256);
    let direct = engine.compute(&scene, &fine).unwrap();
    let mut refined = engine.compute(&scene, &coarse).unwrap();
    engine.refine(&scene, &mut refined, &fine).unwrap();
    assert_eq!(direct, refined);
    let on_gpu = engine.ambient(&scene, &fine).unwrap();
    for (a, b) in on_gpu.iter().zip(direct.ambient()) {
        assert!((a - b).abs() <= 1e-5, "GPU a = {a}, from bits {b}");
    }
}

/// The resident handle reads back exactly what `compute` and `ambient` return, on every GPU
/// backend, and exposes buffers of the documented size; `cpu` has no resident result.
#[test]
fn resident_results_equal_compute_and_ambient() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(2).unwrap();
    for backend in [Backend::Query, Backend::Depth, Backend::Rays] {
        let mut engine = engine(&ctx, backend, 256);
        let resident = engine.compute_resident(&scene, &sphere).unwrap();
        let matrix = engine.compute(&scene, &sphere).unwrap();
        let ambient = engine.ambient(&scene, &sphere).unwrap();
        assert_eq!(resident.rows(), scene.receiver_count());
        assert_eq!(resident.directions_len(), sphere.len());
        assert_eq!(resident.words_per_row(), sphere.len().div_ceil(32));
        assert!(
            resident.bits_buffer().size()
                >= (resident.rows() * resident.words_per_row() * 4) as u64
        );
        assert!(resident.ambient_buffer().size() >= resident.rows() as u64 * 4);
        assert_eq!(resident.read_matrix().unwrap(), matrix, "{backend:?}");
        let read = resident.read_ambient().unwrap();
        assert_eq!(read.len(), ambient.len());
        for (a, b) in read.iter().zip(&ambient) {
            assert!((a - b).abs() <= 1e-6, "{backend:?}: resident {a} vs {b}");
        }
    }
    let mut cpu = VisibilityEngine::cpu(VisibilityParams::default());
    assert!(matches!(
        cpu.compute_resident(&scene, &sphere),
        Err(OcclusionError::NotGpuResident { backend: "cpu" })
    ));
}

/// A vertex used by no triangle (zero normal): all-zero row and a_i = NaN; the open grid
/// around it gets the open quadrature of the cosine.
#[test]
fn zero_normal_vertices_have_empty_rows() {
    let Some(ctx) = gpu() else { return };
    let mut mesh = grid(4, 2.0);
    mesh.positions.push(glam::Vec3::new(0.5, 0.5, 0.5));
    mesh.normals.push(glam::Vec3::ZERO);
    let scene = Scene::single(mesh.positions, mesh.normals, mesh.triangles).unwrap();
    let sphere = Lightsphere::new(2).unwrap();
    for backend in [Backend::Query, Backend::Rays] {
        let mut engine = engine(&ctx, backend, 256);
        let matrix = engine.compute(&scene, &sphere).unwrap();
        let last = matrix.rows() - 1;
        assert!((0..sphere.len()).all(|j| !matrix.is_visible(last, j)));
        let ambient = engine.ambient(&scene, &sphere).unwrap();
        assert!(ambient[last].is_nan());
        let up = open_ambient(&sphere, glam::DVec3::Y);
        for a in &ambient[..last] {
            assert_close(f64::from(*a), up, 1e-5, "open grid vertex");
        }
    }
}

/// Hard cases on the GPU for `query`: the scene 1e5 from the origin and scaled by 1e-3 and
/// 1e3, and a two-sided sheet (both faces rasterised, coincident sides open towards their own
/// normals).
#[test]
fn query_backend_offsets_scales_and_two_sided_sheets() {
    let Some(ctx) = gpu() else { return };
    let placements = [
        glam::Mat4::from_translation(glam::Vec3::splat(1e5))
            * glam::Mat4::from_scale(glam::Vec3::splat(1e3)),
        glam::Mat4::from_scale(glam::Vec3::splat(1e-3)),
    ];
    for placement in placements {
        let mut placed = Scene::new();
        for object in sphere_over_plane().objects() {
            let world_from_object = object.world_from_object;
            placed
                .push(object.clone().with_transform(placement * world_from_object))
                .unwrap();
        }
        let (mean, share) = compare(&ctx, &placed, 2, 1024);
        assert!(mean <= mean_tolerance(1024), "{placement}: mean {mean}");
        assert!(share <= 0.02, "{placement}: share {share}");
    }

    let sheet = grid(8, 4.0);
    let flipped: Vec<glam::Vec3> = sheet.normals.iter().map(|n| -*n).collect();
    let mut scene = Scene::new();
    scene.push(sheet.object()).unwrap();
    scene
        .push(occlusion_gpu::SceneObject::new(
            sheet.positions.clone(),
            flipped,
            sheet.triangles.clone(),
        ))
        .unwrap();
    let (mean, share) = compare(&ctx, &scene, 2, 512);
    assert!(
        mean <= 1e-4 && share == 0.0,
        "two-sided sheet: mean {mean}, share {share}"
    );
}

/// The issue's accuracy target for the query backend: full bunny, level 3, 2048², mean
/// |Δa| ≤ 0.01 against cpu and ≤ 1 % of vertices off by > 0.05. Slow on lavapipe (9.3 M
/// point draws, each in its own query): run with
/// `cargo test -p occlusion-gpu --test query -- --ignored`.
#[test]
#[ignore = "slow on software Vulkan; run explicitly"]
fn bunny_full_level3_meets_issue_target() {
    let Some(ctx) = gpu() else { return };
    let Some(scene) = shared_scene("meshes/bun_zipper.ply") else {
        return;
    };
    let (mean, share) = compare(&ctx, &scene, 3, 2048);
    eprintln!("query vs cpu, full bunny, level 3, 2048²: mean {mean:.2e}, share {share:.4}");
    assert!(mean <= 0.01, "mean {mean}");
    assert!(share <= 0.01, "share {share}");
}
