//! The seed's Table 1 bunny row, per backend: the full Stanford bunny (35,947 vertices) at
//! k = 6, 18, 66, 258, 1026 (paper 000 Table 1, time1: 445, 1082, 3606, 13715, 60304 ms on a
//! Radeon 9800 XT in 2005).
//!
//! * `visibility/cpu/bunny`: the packet and the fan traversals at every k (the default,
//!   `CpuMethod::Auto`, runs packets below k = 128 and fans above), throughput = rays cast
//!   after n·l culling; and the single-ray traversal at k = 258 for the ratio.
//! * `visibility/depth/bunny`: the `depth` backend at 1024² on the available adapter,
//!   throughput = vertex-direction tests.
//! * `visibility/query/...`: the published `query` backend (one occlusion query per vertex
//!   and direction). On a software adapter (lavapipe) a draw costs tens of µs, so there it
//!   runs on `bun_zipper_res4.ply` (453 vertices) only; on hardware, on the full bunny.
//!
//! Skips with a message when `../shared/data` is missing or no adapter exists. Run with
//! `cargo bench -p occlusion-gpu --bench visibility`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use lightsphere::Lightsphere;
use occlusion_gpu::{
    Backend, CpuMethod, CpuParams, DepthParams, Scene, VisibilityEngine, VisibilityParams,
};

/// Levels of the seed's Table 1 bunny row (k = 6 … 1026).
const LEVELS: std::ops::RangeInclusive<u32> = 0..=4;

fn load(relative: &str) -> Option<Scene> {
    let path = test_data::data_root().join(relative);
    if !path.is_file() {
        println!("skipping: {} not found", path.display());
        return None;
    }
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).ok()?;
    Scene::single(mesh.positions, mesh.normals, mesh.triangles).ok()
}

fn cpu(c: &mut Criterion) {
    let Some(scene) = load("meshes/bun_zipper.ply") else {
        return;
    };
    let mut group = c.benchmark_group("visibility/cpu/bunny");
    group.sample_size(10);
    let mut run = |method: CpuMethod, level: u32| {
        let sphere = Lightsphere::new(level).expect("levels 0-4 exist");
        let params = VisibilityParams::default().with_cpu(CpuParams::default().with_method(method));
        let mut engine = VisibilityEngine::cpu(params);
        let _ = engine.compute(&scene, &sphere);
        group.throughput(Throughput::Elements(engine.last_ray_count()));
        group.bench_function(format!("{method:?} k={}", sphere.len()), |b| {
            // A fresh engine per iteration: the BVH build is part of a frame's cost (a
            // deforming mesh rebuilds it every frame).
            b.iter(|| {
                VisibilityEngine::cpu(params)
                    .compute(&scene, &sphere)
                    .expect("valid scene")
            });
        });
    };
    for level in LEVELS {
        run(CpuMethod::Packets, level);
    }
    run(CpuMethod::SingleRays, 3);
    for level in LEVELS {
        run(CpuMethod::Fans, level);
    }
    group.finish();
}

fn gpu(c: &mut Criterion) {
    let ctx = match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(ctx) => ctx,
        Err(e) => {
            println!("skipping the GPU benches: no adapter ({e})");
            return;
        }
    };
    println!("GPU backends on {}", ctx.summary());
    let software = ctx.summary().is_software;
    let params =
        VisibilityParams::default().with_depth(DepthParams::default().with_resolution(1024));
    if let Some(scene) = load("meshes/bun_zipper.ply") {
        let mut group = c.benchmark_group("visibility/depth/bunny");
        group.sample_size(10);
        for level in LEVELS {
            let sphere = Lightsphere::new(level).expect("levels 0-4 exist");
            let mut engine =
                VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Depth, params);
            group.throughput(Throughput::Elements(
                (scene.receiver_count() * sphere.len()) as u64,
            ));
            group.bench_function(format!("k={} res=1024", sphere.len()), |b| {
                b.iter(|| engine.ambient(&scene, &sphere).expect("valid scene"));
            });
        }
        group.finish();
    }
    let (name, mesh, levels) = if software {
        ("bunny_res4", "meshes/bun_zipper_res4.ply", 0..=2)
    } else {
        ("bunny", "meshes/bun_zipper.ply", LEVELS)
    };
    if let Some(scene) = load(mesh) {
        let mut group = c.benchmark_group(format!("visibility/query/{name}"));
        group.sample_size(10);
        for level in levels {
            let sphere = Lightsphere::new(level).expect("levels 0-4 exist");
            let mut engine =
                VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Query, params);
            group.throughput(Throughput::Elements(
                (scene.receiver_count() * sphere.len()) as u64,
            ));
            group.bench_function(format!("k={} res=1024", sphere.len()), |b| {
                b.iter(|| engine.ambient(&scene, &sphere).expect("valid scene"));
            });
        }
        group.finish();
    }
}

criterion_group!(benches, cpu, gpu);
criterion_main!(benches);
