//! Texels reconstructed per second (eq. 5.4, c = 16) and the compression time of one view slot
//! (eq. 5.1: 81 light images, Gram-path PCA, quantization) at 64² and 256².

use std::hint::black_box;
use std::time::Duration;

use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, SlotPca, Storage, ViewSlot};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;

fn hash(x: usize, y: usize, c: usize) -> f32 {
    let h = (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (c as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    ((h ^ (h >> 31)) % 1000) as f32 / 1000.0
}

/// A view slot with texture-dependent shadows so that its rank is high.
fn slot(s: Sampling, j: usize, res: usize) -> ViewSlot {
    let mut data = Vec::with_capacity(DIRECTIONS * 3 * res * res);
    for i in 0..DIRECTIONS {
        let l = s.vector(i);
        for y in 0..res {
            for x in 0..res {
                let shadow = if hash(x, y, 7) < 1.0 - l.z { 0.2 } else { 1.0 };
                for c in 0..3 {
                    data.push((0.1 + 0.7 * hash(x, y, c)) * l.z.max(0.0) * shadow);
                }
            }
        }
    }
    ViewSlot::new(j, res, res, data).expect("slot")
}

fn bench(c: &mut Criterion) {
    let s = Sampling::H1;
    let mut g = c.benchmark_group("slot_compression_c16");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for res in [64, 256] {
        let slot = slot(s, 0, res);
        g.bench_function(format!("{res}x{res}"), |b| {
            b.iter(|| black_box(SlotPca::fit(&slot, 16, Storage::U8, Storage::U16).expect("fit")))
        });
    }
    g.finish();

    let res = 64;
    let params = BtfPcaParams::default();
    let (pca, _) = BtfPca::compress_with(s, res, res, &params, |j| Ok(slot(s, j, res)), None)
        .expect("compress");
    let gamma = pca.gamma(0, Vec3::new(0.3, 0.2, 0.9));
    let mut g = c.benchmark_group("texels_reconstructed_per_second_c16");
    g.throughput(Throughput::Elements((res * res) as u64));
    g.bench_function("texel", |b| {
        b.iter(|| {
            let mut acc = 0.0f32;
            for y in 0..res {
                for x in 0..res {
                    acc += pca.texel(0, black_box(&gamma), x, y)[0];
                }
            }
            black_box(acc)
        })
    });
    g.bench_function("image_from_gamma", |b| {
        b.iter(|| black_box(pca.image_from_gamma(0, black_box(&gamma))))
    });
    g.bench_function("eval_view_and_light_interpolated", |b| {
        let (v, l) = (Vec3::new(0.4, 0.1, 0.9), Vec3::new(-0.2, 0.5, 0.8));
        b.iter(|| {
            let mut acc = 0.0f32;
            for y in 0..res {
                for x in 0..res {
                    let uv = ((x as f32 + 0.5) / res as f32, (y as f32 + 0.5) / res as f32);
                    acc += pca.eval(black_box(v), l, uv.0, uv.1)[0];
                }
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
