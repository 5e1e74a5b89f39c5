//! The `depth` backend (GPU, lavapipe in CI) against the exact `cpu` backend.

#![cfg(feature = "gpu")]

mod common;

use common::*;
use gpu_context::GpuContext;
use lightsphere::Lightsphere;
use occlusion_gpu::{Backend, DepthParams, Scene, VisibilityEngine, VisibilityParams};

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
use gpu_context::testing::gpu_or_skip as gpu;

fn depth_engine(ctx: &GpuContext, resolution: u32) -> VisibilityEngine {
    let params =
        VisibilityParams::default().with_depth(DepthParams::default().with_resolution(resolution));
    VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Depth, params)
}

/// Mean |Δa| and the share of vertices off by > 0.05 between depth and cpu.
fn compare(ctx: &GpuContext, scene: &Scene, level: u32, resolution: u32) -> (f64, f64) {
    let sphere = Lightsphere::new(level).unwrap();
    let exact = VisibilityEngine::cpu(VisibilityParams::default())
        .compute(scene, &sphere)
        .unwrap()
        .ambient();
    let depth = depth_engine(ctx, resolution)
        .ambient(scene, &sphere)
        .unwrap();
    let (mean, share) = ambient_difference(&depth, &exact);
    eprintln!("level {level} at {resolution}²: mean |Δa| = {mean:.4}, share > 0.05 = {share:.4}");
    (mean, share)
}

/// Tolerance on mean |Δa|: a floor for the bias (which hides occluders closer than a few
/// texels) plus a term shrinking with the texel size.
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
    for resolution in [512, 2048] {
        let (mean, share) = compare(&ctx, &scene, 2, resolution);
        assert!(
            mean <= mean_tolerance(resolution),
            "{resolution}: mean {mean}"
        );
        assert!(
            share <= 0.02 + 16.0 / f64::from(resolution),
            "{resolution}: share {share}"
        );
    }
}

/// GPU-side a_i equals a_i derived from the read-back bits, and refine equals direct.
#[test]
fn gpu_ambient_bits_and_refine_are_consistent() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    let (coarse, fine) = (Lightsphere::new(1).unwrap(), Lightsphere::new(2).unwrap());
    let mut engine = depth_engine(&ctx, 256);
    let direct = engine.compute(&scene, &fine).unwrap();
    let mut refined = engine.compute(&scene, &coarse).unwrap();
    engine.refine(&scene, &mut refined, &fine).unwrap();
    assert_eq!(direct, refined);
    let on_gpu = engine.ambient(&scene, &fine).unwrap();
    for (a, b) in on_gpu.iter().zip(direct.ambient()) {
        assert!((a - b).abs() <= 1e-5, "GPU a = {a}, from bits {b}");
    }
}

/// The issue's accuracy target: full bunny, level 3, 2048²: mean |Δa| ≤ 0.01 and ≤ 1% of
/// vertices off by > 0.05. Slow on lavapipe (258 depth passes of 69k triangles at 2048²):
/// run with `cargo test -p occlusion-gpu --release -- --ignored`.
#[test]
#[ignore = "slow on software Vulkan; run explicitly"]
fn bunny_full_level3_meets_issue_target() {
    let Some(ctx) = gpu() else { return };
    let Some(scene) = shared_scene("meshes/bun_zipper.ply") else {
        return;
    };
    let (mean, share) = compare(&ctx, &scene, 3, 2048);
    assert!(mean <= 0.01, "mean {mean}");
    assert!(share <= 0.01, "share {share}");
}

/// Hard cases on the GPU: the scene 1e5 from the origin and scaled by 1e3, and a two-sided
/// sheet (both faces rasterised, coincident sides open towards their own normals).
#[test]
fn depth_backend_offsets_scales_and_two_sided_sheets() {
    let Some(ctx) = gpu() else { return };
    let placement = glam::Mat4::from_translation(glam::Vec3::splat(1e5))
        * glam::Mat4::from_scale(glam::Vec3::splat(1e3));
    let mut placed = Scene::new();
    for object in sphere_over_plane().objects() {
        placed
            .push(object.clone().with_transform(placement))
            .unwrap();
    }
    let (mean, share) = compare(&ctx, &placed, 2, 1024);
    assert!(mean <= mean_tolerance(1024), "placed: mean {mean}");
    assert!(share <= 0.02, "placed: share {share}");

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

/// A finite `max_distance` is refused by the depth-map backends on every path (`compute`,
/// `ambient`, `compute_resident`): they cannot bound their rays, and `ambient` used to skip
/// the check and silently return unbounded a_i. `rays` bounds them like `cpu`.
#[test]
fn depth_map_backends_refuse_a_max_distance_on_every_path() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    let sphere = Lightsphere::new(1).unwrap();
    let params = VisibilityParams::default()
        .with_cpu(occlusion_gpu::CpuParams::default().with_max_distance(0.45));
    for backend in [Backend::Depth, Backend::Query] {
        let mut engine = VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, backend, params);
        let refused = |e: &occlusion_gpu::OcclusionError| {
            matches!(
                e,
                occlusion_gpu::OcclusionError::InvalidParameter {
                    what: "max_distance",
                    ..
                }
            )
        };
        assert!(refused(&engine.compute(&scene, &sphere).unwrap_err()));
        assert!(refused(&engine.ambient(&scene, &sphere).unwrap_err()));
        assert!(refused(
            &engine.compute_resident(&scene, &sphere).err().unwrap()
        ));
    }
    // On `rays` the bound takes effect on the a_i-only path too: only occluders beyond 0.45
    // are dropped, so no vertex sees less sky and some see more.
    let rays = |params| {
        VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Rays, params)
            .ambient(&scene, &sphere)
            .unwrap()
    };
    let (bounded, unbounded) = (rays(params), rays(VisibilityParams::default()));
    assert!(
        bounded
            .iter()
            .zip(&unbounded)
            .all(|(b, u)| b >= u || b.is_nan())
    );
    assert!(bounded.iter().zip(&unbounded).any(|(b, u)| b > u));
}
