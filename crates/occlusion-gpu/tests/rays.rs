//! The `rays` backend (exact ray casting in a compute shader; lavapipe in CI) against the
//! `cpu` backend: the same M up to rays within rounding of an edge or the tangent plane.

#![cfg(feature = "gpu")]

mod common;

use common::*;
use glam::Vec3;
use gpu_context::GpuContext;
use lightsphere::Lightsphere;
use occlusion_gpu::{
    Backend, BvhUpdate, CpuMethod, CpuParams, RayCaster, Scene, VisibilityEngine, VisibilityMatrix,
    VisibilityParams,
};

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
use gpu_context::testing::gpu_or_skip as gpu;

fn rays(ctx: &GpuContext, params: VisibilityParams) -> VisibilityEngine {
    VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Rays, params)
}

/// The `cpu` backend's single rays (the same Möller–Trumbore test as the shader).
fn exact(scene: &Scene, sphere: &Lightsphere, cpu: CpuParams) -> VisibilityMatrix {
    let params = VisibilityParams::default().with_cpu(cpu.with_method(CpuMethod::SingleRays));
    VisibilityEngine::cpu(params)
        .compute(scene, sphere)
        .unwrap()
}

/// Whether a ray from row `row`'s origin along `l` is within `tolerance` (barycentric, in
/// f64) of deciding otherwise: it meets some triangle's plane at t > 0 where the smallest
/// barycentric coordinate lies in [−tolerance, tolerance], or it leaves the tangent plane at
/// an angle under `tolerance` — the rays two f32 evaluations may decide differently.
fn grazing(caster: &RayCaster, row: usize, l: Vec3, max_t: f64, tolerance: f64) -> bool {
    let (p, n) = caster.receivers().nth(row).unwrap();
    let (p, n, d) = (p.as_dvec3(), n.as_dvec3(), l.as_dvec3());
    if n.dot(d).abs() <= tolerance {
        return true;
    }
    let offset = f64::from(occlusion_gpu::DEFAULT_OFFSET_RELATIVE * caster.diagonal());
    let origin = p + n * offset;
    caster.triangles().any(|t| {
        let [a, b, c] = t.map(|v| v.as_dvec3());
        let (e1, e2) = (b - a, c - a);
        let q = d.cross(e2);
        let det = e1.dot(q);
        if det == 0.0 {
            return false;
        }
        let s = origin - a;
        let u = s.dot(q) / det;
        let r = s.cross(e1);
        let v = d.dot(r) / det;
        let t = e2.dot(r) / det;
        let smallest = u.min(v).min(1.0 - u - v);
        t > 0.0 && t < max_t && smallest.abs() <= tolerance
    })
}

/// Checks the rays backend against the exact M on `scene`: every cell equal except rays that
/// graze an edge or the tangent plane (within 10⁻⁵, ten times the shaders' and the CPU's
/// `EDGE_TOLERANCE`), at most one cell in 10⁴ apart, and a_i read back from the GPU equal to
/// a_i of its own bits.
fn check(ctx: &GpuContext, scene: &Scene, level: u32, cpu: CpuParams) {
    let sphere = Lightsphere::new(level).unwrap();
    let reference = exact(scene, &sphere, cpu);
    let params = VisibilityParams::default().with_cpu(cpu);
    let mut engine = rays(ctx, params);
    let matrix = engine.compute(scene, &sphere).unwrap();
    let cells = matrix.rows() * sphere.len();
    let open = reference.visible_count();
    assert!(open > 0 && open < cells, "a scene with shadows and sky");
    let caster = RayCaster::new(scene).unwrap();
    let max_t = f64::from(cpu.max_distance);
    let mut differ = 0;
    for i in 0..matrix.rows() {
        for (j, &l) in sphere.directions().iter().enumerate() {
            if matrix.is_visible(i, j) != reference.is_visible(i, j) {
                differ += 1;
                assert!(
                    grazing(&caster, i, l, max_t, 1e-5),
                    "row {i}, direction {j}: the GPU says visible = {}, the CPU {}, and the \
                     ray grazes nothing",
                    matrix.is_visible(i, j),
                    reference.is_visible(i, j)
                );
            }
        }
    }
    eprintln!("level {level}: {differ} of {cells} cells differ from the cpu backend, all grazing");
    assert!(differ * 10_000 <= cells, "{differ} of {cells} cells differ");
    let on_gpu = engine.ambient(scene, &sphere).unwrap();
    for (i, (a, b)) in on_gpu.iter().zip(matrix.ambient()).enumerate() {
        assert!(
            (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-5,
            "row {i}: GPU a = {a}, from bits {b}"
        );
    }
}

#[test]
fn sphere_over_plane_equals_the_cpu_backend() {
    let Some(ctx) = gpu() else { return };
    check(&ctx, &sphere_over_plane(), 3, CpuParams::default());
}

#[test]
fn bunny_res4_equals_the_cpu_backend() {
    let Some(ctx) = gpu() else { return };
    let Some(scene) = shared_scene("meshes/bun_zipper_res4.ply") else {
        return;
    };
    check(&ctx, &scene, 4, CpuParams::default());
}

#[test]
fn bounded_rays_equal_the_cpu_backend() {
    let Some(ctx) = gpu() else { return };
    let cpu = CpuParams::default().with_max_distance(0.45);
    check(&ctx, &sphere_over_plane(), 2, cpu);
}

#[test]
fn refine_and_progress_agree_with_a_direct_computation() {
    let Some(ctx) = gpu() else { return };
    let scene = sphere_over_plane();
    let (coarse, fine) = (Lightsphere::new(1).unwrap(), Lightsphere::new(3).unwrap());
    let mut engine = rays(&ctx, VisibilityParams::default());
    let seen = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let last = std::sync::Arc::clone(&seen);
    engine.set_progress(Some(std::sync::Arc::new(move |done, _| {
        last.fetch_max(done, std::sync::atomic::Ordering::Relaxed);
    })));
    let direct = engine.compute(&scene, &fine).unwrap();
    let cells = (direct.rows() * fine.len()) as u64;
    assert_eq!(seen.load(std::sync::atomic::Ordering::Relaxed), cells);
    let mut refined = engine.compute(&scene, &coarse).unwrap();
    engine.refine(&scene, &mut refined, &fine).unwrap();
    assert_eq!(direct, refined);
}

/// The rays backend keeps its tree between calls: every frame of a deforming drape (and the
/// drape grown across the tracer's power-of-two scale) gives, on a refitted tree, the bits of
/// a tree built for that frame; the same scene again reuses the tree, refinement and vertex
/// filtering too; another topology rebuilds it.
#[test]
fn a_kept_tree_gives_every_frame_the_m_of_a_fresh_one() {
    let Some(ctx) = gpu() else { return };
    let drape = drape_frames(16, 24, 1);
    let sphere = Lightsphere::new(1).unwrap();
    let mut refitting = rays(&ctx, VisibilityParams::default());
    let rebuild = CpuParams::default().with_refit(false);
    let mut rebuilding = rays(&ctx, VisibilityParams::default().with_cpu(rebuild));
    let refits = refits_over_frames(&mut refitting, &mut rebuilding, &drape, &sphere, "rays");
    let (frames, triangles, ball) = drape;
    eprintln!("{refits} of 8 frames refitted");
    assert!(refits >= 4, "only {refits} refits in 8 frames");
    let last = frames.last().unwrap();
    for grow in [3.0f32, 0.2] {
        let grown = |mesh: &[Vec3]| mesh.iter().map(|p| *p * grow).collect::<Vec<_>>();
        let scene = drape_scene(&grown(last), &triangles, &(grown(&ball.0), ball.1.clone()));
        let a = refitting.compute(&scene, &sphere).unwrap();
        let b = rebuilding.compute(&scene, &sphere).unwrap();
        assert_eq!(a.bits(), b.bits(), "grown {grow}");
        assert!(
            matches!(refitting.last_bvh().update, BvhUpdate::Refitted { .. }),
            "grown {grow}: {:?}",
            refitting.last_bvh().update
        );
    }
    // The same scene: reused, for a whole matrix, a refinement and a subset of rows.
    let scene = drape_scene(last, &triangles, &ball);
    let mut matrix = refitting.compute(&scene, &sphere).unwrap();
    refitting.compute(&scene, &sphere).unwrap();
    assert_eq!(refitting.last_bvh().update, BvhUpdate::Reused);
    let finer = Lightsphere::new(2).unwrap();
    refitting.refine(&scene, &mut matrix, &finer).unwrap();
    assert_eq!(refitting.last_bvh().update, BvhUpdate::Reused);
    assert_eq!(matrix, rebuilding.compute(&scene, &finer).unwrap());
    let rows: Vec<u32> = (0..matrix.rows() as u32).step_by(7).collect();
    let mut filtered = matrix.clone();
    refitting
        .compute_rows(&scene, &mut filtered, &rows)
        .unwrap();
    assert_eq!(refitting.last_bvh().update, BvhUpdate::Reused);
    assert_eq!(filtered, matrix);
    // Another topology: built afresh, and right.
    let fewer = &triangles[..triangles.len() - 2];
    let scene = drape_scene(last, fewer, &ball);
    let a = refitting.compute(&scene, &sphere).unwrap();
    assert_eq!(refitting.last_bvh().update, BvhUpdate::Built);
    assert_eq!(
        a.bits(),
        rebuilding.compute(&scene, &sphere).unwrap().bits()
    );
}
