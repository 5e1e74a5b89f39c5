//! The GPU CPCA decoder (`cpca_decode.wgsl`, lavapipe in CI) against the CPU [`Decoder`]:
//! the same positions within float rounding, for every vertex of every frame.
//!
//! Tolerance. Both sides sum pₘ(f) = r + Σₕ wₕEₕ in f32 in the same order; the GPU may fuse
//! a multiply-add, so each of the c + 1 roundings may differ by one ulp of the running sum:
//! |Δ| ≤ 2(c + 1)·ε·(|r| + Σₕ|wₕEₕ|) per coordinate (direct layout, bound computed per vertex
//! from the dequantized values). With time compression each Eₕ(f) = μ + Σₛ aₛBₛ adds c* + 1
//! roundings of its own, scaled by |wₕ|; that bound uses the clip-wide magnitude below.
#![cfg(feature = "gpu")]

mod compress_common;
use compress_common as common;

use anim_pca::AnimPcaError;
use anim_pca::compress::{Compressed, CpcaParams, Decoder, GpuDecoder};
use glam::Vec3;
use gpu_context::GpuContext;

/// The shared GPU-or-skip harness (fails under CI, visible skip otherwise).
use gpu_context::testing::gpu_or_skip as gpu;

/// Three independently spinning bars (k = 3 clusters), 40 vertices each, 31 frames.
fn packed(bits: u8, time_components: Option<usize>) -> Compressed {
    let frames = common::rigid_parts(3, 40, 31);
    let params = CpcaParams {
        clusters: 3,
        components: 3,
        time_components,
        bits_components: bits,
        bits_weights: bits,
        ..CpcaParams::default()
    };
    let packed = Compressed::encode(&frames, &[], 30.0, &params).unwrap();
    let sizes = (0..3)
        .map(|j| packed.labels().iter().filter(|&&l| l == j).count())
        .collect::<Vec<_>>();
    assert!(sizes.iter().all(|&n| n > 0), "clusters {sizes:?}");
    packed
}

/// Σ of the magnitudes of the terms of pₘ(f) per axis: |r| + Σₕ |wₕ Eₕ| (direct layout).
fn term_magnitude(packed: &Compressed, f: usize, m: usize) -> Vec3 {
    let j = packed.labels()[m] as usize;
    let mut sum = Vec3::ZERO;
    for a in 0..3 {
        let mut s = packed.mean(j, a).value(f).abs();
        for h in 0..packed.components() {
            let w = packed.weights(h).value(m);
            s += (w * packed.eigentrajectory(j, h).value(3 * f + a)).abs();
        }
        sum[a] = s as f32;
    }
    sum
}

/// Compares every vertex of every frame; returns the largest |Δ| and the largest |Δ|/tol.
#[track_caller]
fn compare(ctx: &GpuContext, packed: &Compressed) -> (f32, f32) {
    let cpu = Decoder::new(packed);
    let gpu = GpuDecoder::new(&ctx.device, &ctx.queue, packed).unwrap();
    assert_eq!(gpu.vertices(), packed.vertices());
    assert_eq!(gpu.frames(), packed.frames());
    let c = packed.components() as f32;
    let expected = cpu.decode_all();
    let clip_scale = expected
        .iter()
        .flatten()
        .map(|p| p.abs().max_element())
        .fold(1.0f32, f32::max);
    let (mut worst, mut worst_ratio) = (0f32, 0f32);
    // Out of order, so that each frame is decoded over a different previous one.
    let mut order: Vec<usize> = (0..packed.frames()).rev().collect();
    order.insert(1, 0);
    for f in order {
        let got = gpu.read_frame(f).unwrap();
        assert_eq!(got.len(), packed.vertices());
        for (m, (g, e)) in got.iter().zip(&expected[f]).enumerate() {
            let tol = match packed.time_components() {
                None => 2.0 * (c + 1.0) * f32::EPSILON * term_magnitude(packed, f, m),
                Some(cs) => Vec3::splat(
                    2.0 * (c + 1.0) * (cs as f32 + 2.0) * f32::EPSILON * 4.0 * clip_scale,
                ),
            };
            let d = (*g - *e).abs();
            assert!(
                d.cmple(tol).all(),
                "frame {f}, vertex {m}: gpu {g} vs cpu {e} (|Δ| {d}, tolerance {tol})"
            );
            worst = worst.max(d.max_element());
            worst_ratio =
                worst_ratio.max((d / tol.max(Vec3::splat(f32::MIN_POSITIVE))).max_element());
        }
    }
    (worst, worst_ratio)
}

#[test]
fn gpu_matches_cpu_with_4_and_16_bits() {
    let Some(ctx) = gpu() else { return };
    for bits in [4, 16] {
        let (worst, ratio) = compare(&ctx, &packed(bits, None));
        eprintln!(
            "q = {bits}: max |gpu − cpu| = {worst:e} ({:.2} of the tolerance) on {}",
            ratio,
            ctx.summary()
        );
    }
}

#[test]
fn gpu_matches_cpu_with_time_compression() {
    let Some(ctx) = gpu() else { return };
    for bits in [4, 16] {
        let packed = packed(bits, Some(4));
        assert_eq!(packed.time_components(), Some(4));
        let (worst, ratio) = compare(&ctx, &packed);
        eprintln!(
            "time c* = 4, q = {bits}: max |gpu − cpu| = {worst:e} ({ratio:.2} of the tolerance)"
        );
    }
}

#[test]
fn frame_out_of_range_is_an_error() {
    let Some(ctx) = gpu() else { return };
    let packed = packed(16, None);
    let gpu = GpuDecoder::new(&ctx.device, &ctx.queue, &packed).unwrap();
    let f = packed.frames();
    for result in [gpu.decode(f).err(), gpu.read_frame(f).err()] {
        assert!(
            matches!(
                result,
                Some(AnimPcaError::InvalidParameter { name: "frame", .. })
            ),
            "{result:?}"
        );
    }
    let buffer = gpu.positions_buffer();
    assert!(buffer.usage().contains(wgpu::BufferUsages::VERTEX));
    assert_eq!(
        buffer.size(),
        packed.vertices() as u64 * anim_pca::compress::POSITION_STRIDE
    );
    // The last frame is fine.
    assert_eq!(gpu.read_frame(f - 1).unwrap().len(), packed.vertices());
}
