//! Nearest-direction queries per second: cube-map candidate grid vs linear scan, at
//! k = 66, 1026 and 16386 (levels 2, 4, 6).

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;
use lightsphere::Lightsphere;
use std::hint::black_box;

/// Deterministic pseudo-random unit directions (splitmix64, fixed seed).
fn queries(count: usize) -> Vec<Vec3> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let z = 2.0 * next() - 1.0;
            let phi = std::f64::consts::TAU * next();
            let r = (1.0 - z * z).sqrt();
            Vec3::new((r * phi.cos()) as f32, z as f32, (r * phi.sin()) as f32)
        })
        .collect()
}

fn nearest(c: &mut Criterion) {
    let dirs = queries(4096);
    let mut group = c.benchmark_group("nearest_direction");
    group.throughput(Throughput::Elements(dirs.len() as u64));
    for level in [2u32, 4, 6] {
        let sphere = Lightsphere::new(level).expect("level within range");
        let k = sphere.len();
        group.bench_with_input(BenchmarkId::new("grid", k), &sphere, |b, s| {
            b.iter(|| dirs.iter().map(|&d| s.nearest(black_box(d))).sum::<usize>());
        });
        group.bench_with_input(BenchmarkId::new("linear", k), &sphere, |b, s| {
            b.iter(|| {
                dirs.iter()
                    .map(|&d| s.nearest_linear(black_box(d)))
                    .sum::<usize>()
            });
        });
    }
    group.finish();
}

criterion_group!(benches, nearest);
criterion_main!(benches);
