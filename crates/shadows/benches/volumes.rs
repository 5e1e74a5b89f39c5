//! Shadow volumes of the Stanford bunny (69,451 triangles; `../shared/data`) under a point
//! light over a ground plane: the per-frame volume build on one core (the target:
//! ≤ 5 ms, allocation-free), for the full caster and the §4.2 levels (10 %, 1 %); and the
//! whole ground mask (build + draw + read-back) by the stencil pipeline on the available
//! adapter and by exact rays, full against 1 % — the end-to-end gain of a coarse caster.
//! Skips with a message when the data is missing. `cargo bench -p shadows --bench volumes`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::{DVec3, Vec3};
use shadows::volume::{CasterTopology, Extrusion, ShadowVolume, Sides, VolumeParams};
use shadows::{
    GroundGrid, Light, LodTarget, MaskRenderer, caster_lod, exact_ground_mask, ground_extrusion,
};

const BUNNY: &str = "meshes/bun_zipper.ply";

fn bunny() -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let path = test_data::data_root().join(BUNNY);
    if !path.is_file() {
        println!("skipping: {} not found", path.display());
        return None;
    }
    let (mesh, _) = meshio::load_mesh(&path, &meshio::LoadOptions::default()).ok()?;
    Some((mesh.positions, mesh.triangles))
}

fn levels(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<(&'static str, Vec<[u32; 3]>)> {
    let mut out = vec![("full", triangles.to_vec())];
    for (name, target) in [
        ("hard-10pct", LodTarget::Hard),
        ("soft-1pct", LodTarget::Soft),
    ] {
        let level = caster_lod(positions, triangles, target, 2000, 0).expect("LOD");
        out.push((name, level.triangles));
    }
    out
}

fn bench(c: &mut Criterion) {
    let Some((positions, triangles)) = bunny() else {
        return;
    };
    let light = Light::Point(DVec3::new(0.1, 0.3, 0.15));
    let levels = levels(&positions, &triangles);
    let mut group = c.benchmark_group("volume-build");
    for (name, tris) in &levels {
        let topology = CasterTopology::new(positions.len(), tris).unwrap();
        let mut volume = ShadowVolume::new();
        let params = VolumeParams {
            sides: Sides::Two,
            extrusion: Extrusion::Infinite,
            ..Default::default()
        };
        group.throughput(Throughput::Elements(tris.len() as u64));
        group.bench_function(*name, |b| {
            b.iter(|| {
                volume
                    .build(&topology, &positions, &light, &params)
                    .unwrap()
            })
        });
    }
    group.finish();

    let grid = GroundGrid::around(&positions, 0.033, 512).unwrap();
    let mut group = c.benchmark_group("ground-mask-512");
    group.sample_size(10);
    let gpu = gpu_context::GpuContext::new(&Default::default()).ok();
    for (name, tris) in levels.iter().filter(|(n, _)| *n != "hard-10pct") {
        group.bench_function(format!("rays/{name}"), |b| {
            b.iter(|| exact_ground_mask(&positions, tris, &light, &grid).unwrap())
        });
        // Per frame, as a viewer would: pipelines built once, then volume build + draw +
        // read-back.
        if let Some(gpu) = &gpu {
            let renderer = MaskRenderer::new(&gpu.device);
            let topology = CasterTopology::new(positions.len(), tris).unwrap();
            let mut volume = ShadowVolume::new();
            let params = VolumeParams {
                sides: Sides::Two,
                extrusion: Extrusion::Finite(ground_extrusion(&positions, &grid)),
                origin: grid.centre(),
                offset: 0.0,
            };
            group.bench_function(format!("stencil/{name}"), |b| {
                b.iter(|| {
                    volume
                        .build(&topology, &positions, &light, &params)
                        .unwrap();
                    renderer.render(gpu, &volume, &grid).unwrap()
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
