//! Environment light on a BTF garment (thesis §5.5.2; issue #16's target: an environment
//! update ≤ 100 ms for 9,000 vertices on this 2-core machine, against the seed's 38.5 s for
//! 9,208): 9,000 vertices with random tangent frames, the 258 directions of lightsphere
//! level 3 (a Fibonacci set of the same size here), 60 % of them visible per vertex, and a
//! c = 16 BTF (H1). Measured:
//!
//! - `transfer_build`: T_i(m, d) for every vertex — once per frame of a deforming garment
//!   (its visibility changes), not per environment;
//! - `update_w`: W_i = T_i · L for a new environment (the sparse product);
//! - `gamma_star_4_slots`: γ* of the four view slots of every vertex from W (eq. 5.11).
//!
//! An environment update is `update_w` + `gamma_star_4_slots`.
//!
//! The decomposition of eq. 5.13 on the same vertices, A = 30 turns (12°) of a coloured sky
//! with a sun: `decompose_build_centred` / `_uncentred` (the PCA, once per environment) and
//! `decompose_turn_e5` (W at any turn from 5 components: the runtime cost of a rotation).

use std::hint::black_box;
use std::time::Duration;

use btf::env::{EnvDecomposition, EnvLightWeights, EnvTransfer};
use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, ViewSlot};
use criterion::{Criterion, criterion_group, criterion_main};
use glam::Vec3;
use rayon::prelude::*;

const VERTICES: usize = 9_000;
const K: usize = 258;

fn rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn bench_env(c: &mut Criterion) {
    let s = Sampling::H1;
    // A rank-rich 4 × 4 BTF with c = 16: γ* does not depend on the texel count.
    let load = |j: usize| {
        let data = (0..DIRECTIONS)
            .flat_map(|i| {
                let l = s.vector(i);
                (0..48).map(move |t| {
                    (0.3 + 0.01 * t as f32) * l.z.max(0.0)
                        + 0.1 * (l.x * (t % 7) as f32).sin()
                        + 0.01 * j as f32
                })
            })
            .collect();
        ViewSlot::new(j, 4, 4, data)
    };
    let (pca, _) = BtfPca::compress_with(s, 4, 4, &BtfPcaParams::default(), load, None).unwrap();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let dirs: Vec<Vec3> = (0..K)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f32 + 1.0) / K as f32;
            let r = (1.0 - z * z).sqrt();
            Vec3::new(
                r * (golden * i as f32).cos(),
                r * (golden * i as f32).sin(),
                z,
            )
        })
        .collect();
    let omegas = vec![4.0 * std::f32::consts::PI / K as f32; K];
    let mut next = rng(5);
    let frames: Vec<[Vec3; 3]> = (0..VERTICES)
        .map(|_| {
            let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
            let t = n.any_orthonormal_vector();
            [t, n.cross(t), n]
        })
        .collect();
    let visible = |i: usize, d: usize| (i * 7919 + d * 104_729) % 10 < 6;
    let radiance: Vec<Vec3> = dirs
        .iter()
        .map(|d| Vec3::new(1.0 + d.y, 0.8, 0.6 + d.x))
        .collect();
    let view_slots: Vec<[usize; 4]> = (0..VERTICES)
        .map(|i| [i % 81, (i + 1) % 81, (i + 9) % 81, (i + 10) % 81])
        .collect();

    let mut group = c.benchmark_group("env");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(8));
    group.bench_function("transfer_build", |b| {
        b.iter(|| black_box(EnvTransfer::build(s, &frames, &dirs, &omegas, visible)))
    });
    let transfer = EnvTransfer::build(s, &frames, &dirs, &omegas, visible);
    let mut w = Vec::new();
    group.bench_function("update_w", |b| {
        b.iter(|| transfer.update(black_box(&radiance), &mut w))
    });
    transfer.update(&radiance, &mut w);
    let stride = pca.max_components() + 1;
    let mut gammas = vec![Vec3::ZERO; VERTICES * 4 * stride];
    group.bench_function("gamma_star_4_slots", |b| {
        b.iter(|| {
            gammas
                .par_chunks_mut(4 * stride)
                .zip(&w)
                .zip(&view_slots)
                .for_each(
                    |((g, w), slots): ((&mut [Vec3], &EnvLightWeights), &[usize; 4])| {
                        for (k, &j) in slots.iter().enumerate() {
                            let n = pca.gamma_len(j);
                            pca.env_gamma(j, w, &mut g[k * stride..k * stride + n]);
                        }
                    },
                );
            black_box(&gammas);
        })
    });
    let turns = 30;
    let samples: Vec<Vec<EnvLightWeights>> = (0..turns)
        .map(|a| {
            let (sin, cos) = (std::f32::consts::TAU * a as f32 / turns as f32).sin_cos();
            let sun = Vec3::new(0.6 * cos, 0.5, 0.6 * sin).normalize();
            let turned: Vec<Vec3> = dirs
                .iter()
                .map(|d| {
                    Vec3::new(1.0 + d.y, 0.8, 0.6 + d.x * cos - d.z * sin)
                        + Vec3::splat(40.0 * d.dot(sun).max(0.0).powi(32))
                })
                .collect();
            let mut out = Vec::new();
            transfer.update(&turned, &mut out);
            out
        })
        .collect();
    for centred in [true, false] {
        let name = if centred {
            "decompose_build_centred"
        } else {
            "decompose_build_uncentred"
        };
        group.bench_function(name, |b| {
            b.iter(|| black_box(EnvDecomposition::build(&samples, 5, centred).unwrap()))
        });
    }
    let dec = EnvDecomposition::build(&samples, 5, true).unwrap();
    group.bench_function("decompose_turn_e5", |b| {
        b.iter(|| dec.weights_at(black_box(0.37), &mut w))
    });
    group.finish();
}

criterion_group!(benches, bench_env);
criterion_main!(benches);
