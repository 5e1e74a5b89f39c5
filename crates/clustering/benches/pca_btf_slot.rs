//! Seconds to fit the PCA of one BTF view slot: 81 light images × 256² RGB texels (f32), the
//! per-view eigen-texture decomposition of thesis §2.1 / §5.3 (Gram path, f64 accumulation).
//! Target: ≤ 0.5 s on the 2-core development machine.

#[path = "support/mod.rs"]
mod support;

use std::hint::black_box;
use std::time::Duration;

use clustering::{ComponentCount, Pca, PcaParams};
use criterion::{Criterion, criterion_group, criterion_main};
use faer::MatRef;

fn bench(c: &mut Criterion) {
    let slot = support::btf_slot(1);
    let x = MatRef::from_row_major_slice(&slot, support::BTF_LIGHTS, support::BTF_FEATURES);
    let mut g = c.benchmark_group("pca_btf_slot_81x196608_f32");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for (name, components) in [
        ("c16", ComponentCount::Fixed(16)),
        ("all_80", ComponentCount::All),
        ("energy_0.999", ComponentCount::EnergyFraction(0.999)),
    ] {
        let params = PcaParams {
            components,
            ..Default::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| black_box(Pca::fit(x, &params).expect("fit")))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
