//! The speed targets as a benchmark: analysis of a 20k-vertex, 200-frame clip
//! (target ≤ 2 s on the development machine) and playback with reconstruction from c = 10
//! weights (target ≥ 1,000 frames/s on the CPU), and the loop table of every length up to
//! 200 frames over the same clip. Run with
//! `cargo bench -p anim-pca --bench jumpmap`.

use std::f32::consts::TAU;

use anim_pca::{Blend, JumpMap, JumpMapParams, LoopTable, PlaybackParams, Player};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;

/// A 142 × 142 grid (20,164 vertices) waving for 200 frames, with a little per-frame noise so
/// the clip is full-rank and c = 10, c* = 5 are all used.
fn clip() -> Vec<Vec<Vec3>> {
    let (side, frames) = (142usize, 200usize);
    (0..frames)
        .map(|t| {
            let amp = 1.0 + 0.2 * t as f32 / frames as f32;
            let ph = t as f32 / 23.0 * TAU;
            (0..side * side)
                .map(|n| {
                    let (x, y) = ((n % side) as f32, (n / side) as f32);
                    let h = ((t as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ n as u64)
                        .wrapping_mul(0xBF58_476D_1CE4_E5B9);
                    let noise = 1e-3 * ((h >> 40) as f32 / (1u64 << 24) as f32 - 0.5);
                    let z = amp * (ph + 0.5 * x).sin() + 0.3 * (2.0 * ph + 0.7 * y).cos();
                    Vec3::new(x, y, z + noise)
                })
                .collect()
        })
        .collect()
}

fn jumpmap(c: &mut Criterion) {
    let clip = clip();
    let params = JumpMapParams::default();
    let mut group = c.benchmark_group("anim-pca/jumpmap");
    group.sample_size(10);
    group.bench_function("analyze 20164 v x 200 frames, c=10, c*=5", |b| {
        b.iter(|| JumpMap::analyze(&clip, &params).expect("valid clip"));
    });
    let map = JumpMap::analyze(&clip, &params).expect("valid clip");
    let mut player = Player::new(&map, &PlaybackParams::default()).expect("valid params");
    let mut weights = vec![0.0; map.components()];
    let mut mesh = vec![Vec3::ZERO; map.n_vertices()];
    group.bench_function("loop table, lengths 2..=200, b=3, 200 frames", |b| {
        b.iter(|| LoopTable::build(&map, 0, 200, Blend::Fixed(3)).expect("valid"));
    });
    group.throughput(Throughput::Elements(1));
    group.bench_function("play + reconstruct one frame, 20164 v, c=10", |b| {
        b.iter(|| {
            let frame = player.next_frame();
            frame.weights_into(&map, &mut weights);
            map.reconstructor()
                .reconstruct(&weights, &mut mesh)
                .expect("sizes match");
        });
    });
    group.finish();
}

criterion_group!(benches, jumpmap);
criterion_main!(benches);
