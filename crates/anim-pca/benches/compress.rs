//! CPCA compression (thesis §3.3, Tab. 3.5): encode time for 3,000 vertices × 400 frames at
//! k = 10, c = 20 (issue #6 target ≤ 5 s on the 2-core machine), and CPU decode frames per
//! second for 10,000 vertices at c = 20 (target ≥ 2,000 frames/s on one core).

use std::hint::black_box;

use anim_pca::compress::{Compressed, CpcaParams, Decoder};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Quat, Vec3};

/// `parts` parts of a lattice, each rotating at its own rate with a travelling wave on top:
/// not exactly low-rank, so the local PCA has real work to do.
fn clip(vertices: usize, frames: usize, parts: usize) -> Vec<Vec<Vec3>> {
    let per = vertices.div_ceil(parts);
    (0..frames)
        .map(|t| {
            (0..vertices)
                .map(|m| {
                    let (p, i) = (m / per, m % per);
                    let local = Vec3::new(
                        (i % 20) as f32 * 0.1,
                        (i / 20 % 15) as f32 * 0.1,
                        (i / 300) as f32 * 0.1,
                    );
                    let a = t as f32 * (0.03 + 0.011 * p as f32);
                    let wave = 0.05 * (a * 3.0 + local.x * 4.0).sin();
                    Vec3::new(3.0 * p as f32, 0.0, 0.0)
                        + Quat::from_rotation_y(a) * (local + Vec3::new(0.0, wave, 0.0))
                })
                .collect()
        })
        .collect()
}

fn encode(c: &mut Criterion) {
    let frames = clip(3000, 400, 10);
    let p = CpcaParams {
        clusters: 10,
        components: 20,
        ..CpcaParams::default()
    };
    let mut g = c.benchmark_group("cpca_encode");
    g.sample_size(10);
    g.bench_function("3000v_400f_k10_c20", |b| {
        b.iter(|| Compressed::encode(black_box(&frames), &[], 30.0, &p).unwrap())
    });
    g.finish();
}

fn decode(c: &mut Criterion) {
    let frames = clip(10_000, 60, 10);
    let p = CpcaParams {
        clusters: 10,
        components: 20,
        max_iterations: 5,
        ..CpcaParams::default()
    };
    let packed = Compressed::encode(&frames, &[], 30.0, &p).unwrap();
    let decoder = Decoder::new(&packed);
    let mut scratch = decoder.scratch();
    let mut out = vec![Vec3::ZERO; 10_000];
    let mut g = c.benchmark_group("cpca_decode");
    g.throughput(criterion::Throughput::Elements(1));
    let mut f = 0;
    g.bench_function("frame_10000v_c20", |b| {
        b.iter(|| {
            f = (f + 7) % 60;
            decoder.frame_into(f, &mut out, &mut scratch).unwrap();
            black_box(&out);
        })
    });
    g.finish();
}

criterion_group!(benches, encode, decode);
criterion_main!(benches);
