//! Fin extraction per frame (thesis §5.7.3; issue #17's target: ≤ 2 ms for a 10k-triangle
//! garment on one core): the synthetic drape at grid 72 (5,184 vertices, 10,082 triangles),
//! 24 frames of its fall with the eye circling it, silhouettes classified, chained and
//! extruded into reused buffers. Single-threaded code: one core.

use std::hint::black_box;
use std::time::Duration;

use btf::fins::{FinBuilder, FinMesh, FinParams, Viewer};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::Vec3;

/// Area-weighted vertex normals.
fn normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut out = vec![Vec3::ZERO; positions.len()];
    for t in triangles {
        let [a, b, c] = t.map(|v| positions[v as usize]);
        let n = (b - a).cross(c - a);
        for v in t {
            out[*v as usize] += n;
        }
    }
    out.iter().map(|n| n.normalize_or_zero()).collect()
}

fn bench_fins(c: &mut Criterion) {
    let params = synth::ClothParams {
        grid: 72,
        frames: 24,
        ..synth::ClothParams::default()
    };
    let drape = synth::simulate_cloth(&params).expect("the synthetic drape");
    let frames: Vec<(Vec<Vec3>, Vec<Vec3>)> = drape
        .frames
        .iter()
        .map(|p| (p.clone(), normals(p, &drape.triangles)))
        .collect();
    let mut builder = FinBuilder::new(&drape.triangles, frames[0].0.len()).unwrap();
    let mut fins = FinMesh::default();
    let fin = FinParams {
        material_size: 0.02,
        height: 0.4,
        offset: 0.0,
    };
    let mut group = c.benchmark_group("fins");
    group.throughput(Throughput::Elements(drape.triangles.len() as u64));
    group.measurement_time(Duration::from_secs(4));
    let mut frame = 0usize;
    group.bench_function("extract_10k_triangles", |b| {
        b.iter(|| {
            let (positions, normals) = &frames[frame % frames.len()];
            let angle = frame as f32 * 0.26;
            let eye = Vec3::new(3.0 * angle.cos(), 1.5, 3.0 * angle.sin());
            builder.build(positions, normals, Viewer::Eye(eye), &fin, &mut fins);
            frame += 1;
            black_box(fins.len())
        });
    });
    group.finish();
    eprintln!(
        "fins: {} triangles, {} fins in the last frame ({} chains)",
        drape.triangles.len(),
        fins.len(),
        fins.chains()
    );
}

criterion_group!(benches, bench_fins);
criterion_main!(benches);
