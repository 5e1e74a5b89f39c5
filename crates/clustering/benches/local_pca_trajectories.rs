//! Seconds for clustered PCA (thesis §2.7.4 / §3.3.2) of vertex-trajectory matrices, k = 10
//! clusters, c = 20 eigentrajectories: the synthetic 10,000 × 600 (200 frames) benchmark
//! (target ≤ 5 s) and the real chickenCrossing sequence, 3,030 × 510, when ../shared/data is
//! present.

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::Duration;

use clustering::{LocalPca, LocalPcaInit, LocalPcaParams};
use criterion::{Criterion, criterion_group, criterion_main};
use faer::MatRef;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("local_pca_k10_c20");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    let traj = support::trajectories(3);
    let mut cases = vec![(
        "synthetic_10000x600".to_string(),
        traj,
        support::TRAJ_V,
        3 * support::TRAJ_F,
    )];
    if let Some((x, v, d)) = support::chicken() {
        cases.push((format!("chicken_{v}x{d}"), x, v, d));
    }
    for (name, data, n, d) in &cases {
        let x = MatRef::from_row_major_slice(data, *n, *d);
        for (init_name, init) in [
            ("kmeans_init", LocalPcaInit::KMeans),
            ("random_init", LocalPcaInit::RandomSamples),
        ] {
            let params = LocalPcaParams {
                k: 10,
                components: 20,
                init,
                ..Default::default()
            };
            g.bench_function(format!("{name}/{init_name}"), |b| {
                b.iter(|| black_box(LocalPca::fit(x, &params).expect("fit")))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
