//! Visibility tests per second: the `cpu` backend on the full Stanford bunny at k = 6, 18,
//! 66, 258 (the seed's Table 1 rows; throughput counts rays cast after n·l culling), and the
//! `depth` backend on the available adapter (throughput counts vertex-direction tests).
//!
//! Skips with a message when `../shared/data` is missing. Run with
//! `cargo bench -p occlusion-gpu --bench visibility`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use lightsphere::Lightsphere;
use occlusion_gpu::{Backend, DepthParams, Scene, VisibilityEngine, VisibilityParams};

fn bunny() -> Option<Scene> {
    let path = test_data::data_root().join("meshes/bun_zipper.ply");
    if !path.is_file() {
        println!(
            "skipping the visibility bench: {} not found",
            path.display()
        );
        return None;
    }
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).ok()?;
    Scene::single(mesh.positions, mesh.normals, mesh.triangles).ok()
}

fn cpu(c: &mut Criterion) {
    let Some(scene) = bunny() else { return };
    let mut group = c.benchmark_group("visibility/cpu/bunny");
    group.sample_size(10);
    for level in 0..4 {
        let sphere = Lightsphere::new(level).expect("levels 0-3 exist");
        let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
        let _ = engine.compute(&scene, &sphere);
        group.throughput(Throughput::Elements(engine.last_ray_count()));
        group.bench_function(format!("k={}", sphere.len()), |b| {
            b.iter(|| engine.compute(&scene, &sphere).expect("valid scene"));
        });
    }
    group.finish();
}

fn depth(c: &mut Criterion) {
    let Some(scene) = bunny() else { return };
    let ctx = match gpu_context::GpuContext::new(&gpu_context::GpuOptions::default()) {
        Ok(ctx) => ctx,
        Err(e) => {
            println!("skipping the depth bench: no GPU adapter ({e})");
            return;
        }
    };
    println!("depth backend on {}", ctx.summary());
    let mut group = c.benchmark_group("visibility/depth/bunny");
    group.sample_size(10);
    for (level, resolution) in [(2, 1024), (3, 1024)] {
        let sphere = Lightsphere::new(level).expect("levels 2-3 exist");
        let params = VisibilityParams::default()
            .with_depth(DepthParams::default().with_resolution(resolution));
        let mut engine =
            VisibilityEngine::with_gpu(&ctx.device, &ctx.queue, Backend::Depth, params);
        group.throughput(Throughput::Elements(
            (scene.receiver_count() * sphere.len()) as u64,
        ));
        group.bench_function(format!("k={} res={resolution}", sphere.len()), |b| {
            b.iter(|| engine.ambient(&scene, &sphere).expect("valid scene"));
        });
    }
    group.finish();
}

criterion_group!(benches, cpu, depth);
criterion_main!(benches);
