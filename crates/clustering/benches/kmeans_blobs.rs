//! Seconds for k-means on 50,000 × 32 samples (32 Gaussian blobs of unequal size and spread),
//! k = 32, one initialisation, Lloyd to a stable assignment (≤ 300 iterations): this crate
//! (k-means++ with local search, and plain greedy k-means++ as scikit-learn seeds) against
//! linfa-clustering 0.8 with the same budget. Target: no slower than scikit-learn
//! (xtask/scripts/sklearn_compare.py measures that side).

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::Duration;

use clustering::{KMeans, KMeansParams};
use criterion::{Criterion, criterion_group, criterion_main};
use faer::MatRef;
use linfa::traits::Fit;
use rand_xoshiro::rand_core::SeedableRng;

fn bench(c: &mut Criterion) {
    let (blobs, _) = support::kmeans_blobs(2);
    let x = MatRef::from_row_major_slice(&blobs, support::BLOB_N, support::BLOB_D);
    let mut g = c.benchmark_group("kmeans_50000x32_k32");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for (name, steps) in [
        ("clustering_local_search", None),
        ("clustering_plain_kmeanspp", Some(0)),
    ] {
        let params = KMeansParams {
            k: support::BLOB_K,
            tolerance: 0.0,
            local_search_steps: steps,
            ..Default::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| black_box(KMeans::fit(x, &params).expect("fit")))
        });
    }
    let arr = ndarray::Array2::from_shape_vec((support::BLOB_N, support::BLOB_D), blobs.clone())
        .expect("shape");
    let ds = linfa::DatasetBase::from(arr);
    g.bench_function("linfa_clustering", |b| {
        b.iter(|| {
            let rng = rand_xoshiro::Xoshiro256Plus::seed_from_u64(0);
            let p = linfa_clustering::KMeans::params_with_rng(support::BLOB_K, rng)
                .n_runs(1)
                .max_n_iterations(300)
                .tolerance(f64::MIN_POSITIVE);
            black_box(p.fit(&ds).expect("linfa fit"))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
