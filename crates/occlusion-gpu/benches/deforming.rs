//! Deforming meshes on the `cpu` backend (#20 item 3): per frame, refitting the BVH of the
//! previous frame against building it afresh — the BVH time and the traversal cost each tree
//! leaves — on the synthetic drape (4,356 vertices, 120 frames, with its ball) at k = 66 and
//! 258, and on the chicken (`../shared/data/anim/chickenCrossing`, skipped when missing).
//! First a table from one pass over all frames (medians per frame), then criterion's
//! per-sequence times. `cargo bench -p occlusion-gpu --bench deforming`.

use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use lightsphere::Lightsphere;
use occlusion_gpu::{BvhUpdate, CpuParams, Scene, SceneObject, VisibilityEngine, VisibilityParams};

struct Clip {
    name: &'static str,
    frames: Vec<Vec<Vec3>>,
    triangles: Vec<[u32; 3]>,
    occluder: Option<(Vec<Vec3>, Vec<[u32; 3]>)>,
}

fn drape() -> Clip {
    let params = synth::ClothParams::default();
    let cloth = synth::simulate_cloth(&params).expect("drape");
    Clip {
        name: "drape",
        frames: cloth.frames,
        triangles: cloth.triangles,
        occluder: Some(synth::obstacle_mesh(&params.obstacle, 3)),
    }
}

fn chicken() -> Option<Clip> {
    let path = test_data::data_root().join("anim/chickenCrossing");
    if !path.is_dir() {
        println!("skipping the chicken: {} not found", path.display());
        return None;
    }
    let (anim, _) = meshio::load_animation(&path, &Default::default()).ok()?;
    Some(Clip {
        name: "chicken",
        frames: anim.frames,
        triangles: anim.triangles,
        occluder: None,
    })
}

fn scene(clip: &Clip, f: usize) -> Scene {
    let positions = &clip.frames[f];
    let normals =
        meshio::compute_normals(positions, &clip.triangles, meshio::NormalWeighting::Angle);
    let mut scene = Scene::new();
    scene
        .push(SceneObject::new(
            positions.clone(),
            normals,
            clip.triangles.clone(),
        ))
        .expect("scene");
    if let Some((p, t)) = &clip.occluder {
        scene
            .push(SceneObject::new(p.clone(), vec![Vec3::Y; p.len()], t.clone()).occluder_only())
            .expect("occluder");
    }
    scene
}

fn engine(refit: bool) -> VisibilityEngine {
    VisibilityEngine::cpu(
        VisibilityParams::default().with_cpu(CpuParams::default().with_refit(refit)),
    )
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench(c: &mut Criterion) {
    let clips: Vec<Clip> = std::iter::once(drape()).chain(chicken()).collect();
    println!(
        "clip     k    tree     bvh ms/frame  trace ms/frame  total ms/frame  refits  rebuilds  max SAH ratio"
    );
    for clip in &clips {
        let scenes: Vec<Scene> = (0..clip.frames.len()).map(|f| scene(clip, f)).collect();
        for level in [2u32, 3] {
            let sphere = Lightsphere::new(level).expect("sphere");
            for refit in [true, false] {
                let mut e = engine(refit);
                let (mut bvh, mut total) = (Vec::new(), Vec::new());
                let (mut refits, mut builds, mut worst) = (0, 0, 0.0f32);
                for s in &scenes {
                    let t = Instant::now();
                    e.compute(s, &sphere).expect("compute");
                    total.push(t.elapsed().as_secs_f64() * 1e3);
                    let stats = e.last_bvh();
                    bvh.push(stats.millis);
                    match stats.update {
                        BvhUpdate::Refitted { sah_ratio } => {
                            refits += 1;
                            worst = worst.max(sah_ratio);
                        }
                        BvhUpdate::Built => builds += 1,
                        _ => {}
                    }
                }
                let trace: Vec<f64> = total.iter().zip(&bvh).map(|(t, b)| t - b).collect();
                println!(
                    "{:8} {:4} {:8} {:12.2} {:15.2} {:15.2} {:7} {:9} {:14.3}",
                    clip.name,
                    sphere.len(),
                    if refit { "refit" } else { "rebuild" },
                    median(bvh),
                    median(trace),
                    median(total),
                    refits,
                    builds,
                    worst
                );
            }
        }
    }
    let mut group = c.benchmark_group("deforming-k258");
    group.sample_size(10);
    let sphere = Lightsphere::new(3).expect("sphere");
    for clip in &clips {
        let scenes: Vec<Scene> = (0..clip.frames.len()).map(|f| scene(clip, f)).collect();
        for refit in [true, false] {
            let name = format!("{}/{}", clip.name, if refit { "refit" } else { "rebuild" });
            group.bench_function(name, |b| {
                b.iter(|| {
                    let mut e = engine(refit);
                    for s in &scenes {
                        e.compute(s, &sphere).expect("compute");
                    }
                })
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
