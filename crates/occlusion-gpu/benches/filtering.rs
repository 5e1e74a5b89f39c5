//! Per-frame visibility time of the synthetic cloth animation (deforming, fixed camera) at
//! k = 66 with and without vertex filtering (paper 000 §4.1, Table 1's trousers row), `cpu`
//! backend and the CPU id rasteriser (no adapter needed). Throughput counts frames.
//!
//! Run with `cargo bench -p occlusion-gpu --bench filtering`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use lightsphere::Lightsphere;
use occlusion_gpu::{
    Camera, FilterParams, FilteredVisibility, Scene, SceneObject, TriangleVisibility,
    VisibilityEngine, VisibilityParams,
};

/// Frames per iteration (the first frames of a short drop).
const FRAMES: usize = 4;

fn cloth_scenes() -> Vec<Scene> {
    let params = synth::ClothParams {
        frames: FRAMES,
        ..Default::default()
    };
    let animation = synth::simulate_cloth(&params).expect("default cloth parameters are valid");
    animation
        .frames
        .iter()
        .map(|p| {
            let normals =
                meshio::compute_normals(p, &animation.triangles, meshio::NormalWeighting::Area);
            let mut scene = Scene::new();
            scene
                .push(SceneObject::new(
                    p.clone(),
                    normals,
                    animation.triangles.clone(),
                ))
                .expect("simulated cloth is finite");
            scene
        })
        .collect()
}

fn cloth(c: &mut Criterion) {
    let scenes = cloth_scenes();
    let sphere = Lightsphere::new(2).expect("level 2 exists");
    let camera = Camera::look_at(
        Vec3::new(3.0, 1.2, 1.0),
        Vec3::new(0.0, 0.4, 0.0),
        Vec3::Y,
        0.8,
        512,
        512,
    )
    .expect("valid camera");
    let mut group = c.benchmark_group("filtering/cloth/cpu/k=66");
    group.sample_size(10);
    group.throughput(Throughput::Elements(FRAMES as u64));
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    group.bench_function("full", |b| {
        b.iter(|| {
            for scene in &scenes {
                engine.compute(scene, &sphere).expect("valid scene");
            }
        });
    });
    let mut driver = FilteredVisibility::new(
        VisibilityEngine::cpu(VisibilityParams::default()),
        TriangleVisibility::Cpu,
        FilterParams::default(),
    )
    .expect("default filter parameters are valid");
    group.bench_function("filtered", |b| {
        b.iter(|| {
            for scene in &scenes {
                driver
                    .frame(scene, &sphere, &camera, true)
                    .expect("valid scene");
            }
        });
    });
    group.finish();
}

criterion_group!(benches, cloth);
criterion_main!(benches);
