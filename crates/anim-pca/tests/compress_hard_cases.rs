//! Hard cases of CPCA compression (issue #6): finite, documented results.

mod compress_common;

use anim_pca::compress::{Compressed, CpcaParams, Decoder};
use glam::Vec3;

fn params(k: usize, c: usize, q: u8) -> CpcaParams {
    CpcaParams {
        clusters: k,
        components: c,
        bits_components: q,
        bits_weights: q,
        ..CpcaParams::default()
    }
}

/// Encodes, writes, reads and decodes; returns (packed, d_a).
#[track_caller]
fn round_trip(frames: &[Vec<Vec3>], p: &CpcaParams) -> (Compressed, f64) {
    let packed = Compressed::encode(frames, &[], 30.0, p).unwrap();
    let read = Compressed::from_bytes(&packed.to_bytes()).unwrap();
    assert_eq!(read, packed);
    let decoder = Decoder::new(&read);
    let all = decoder.decode_all();
    assert!(all.iter().flatten().all(|v| v.is_finite()));
    let da = decoder.distortion(frames).unwrap().da;
    assert!(da.is_finite(), "d_a = {da}");
    (read, da)
}

#[test]
fn few_frames_many_vertices() {
    // F ≪ V: 3F = 6 features, c clamped to 6 — exact.
    let frames = compress_common::rigid_parts(3, 200, 2);
    let (packed, da) = round_trip(&frames, &params(3, 20, 32));
    assert_eq!(packed.components(), 6);
    assert!(da < 1e-3, "{da}");
}

#[test]
fn many_frames_few_vertices() {
    // F ≫ V: 8 vertices, 600 frames; k = 2 clusters of 3 axes.
    let frames = compress_common::rigid_parts(2, 4, 600);
    let (_, da) = round_trip(&frames, &params(2, 3, 24));
    assert!(da < 1e-2, "{da}");
    let time = CpcaParams {
        time_components: Some(4),
        ..params(2, 3, 24)
    };
    let (packed, _) = round_trip(&frames, &time);
    assert_eq!(packed.time_components(), Some(4));
}

#[test]
fn static_animation() {
    let frame: Vec<Vec3> = (0..50)
        .map(|i| Vec3::new(i as f32, (i * i) as f32 * 0.01, 1.0))
        .collect();
    let frames = vec![frame; 30];
    let (_, da) = round_trip(&frames, &params(4, 5, 12));
    // Every component is zero (zero-range arrays): only the means' quantization remains.
    assert!(da < 0.1, "{da}");
    let (_, da) = round_trip(
        &frames,
        &CpcaParams {
            time_components: Some(3),
            ..params(2, 2, 16)
        },
    );
    assert!(da < 0.01, "{da}");
}

#[test]
fn one_cluster_is_plain_pca() {
    let frames = compress_common::rigid_parts(1, 60, 20);
    let (packed, da) = round_trip(&frames, &params(1, 3, 32));
    assert_eq!(packed.clusters(), 1);
    assert!(da < 1e-3, "{da}");
}

#[test]
fn more_clusters_than_vertices_is_clamped() {
    let frames = compress_common::rigid_parts(1, 5, 10);
    let (packed, da) = round_trip(&frames, &params(50, 2, 20));
    assert_eq!(packed.clusters(), 5, "k is clamped to V");
    assert!(da < 1e-2, "{da}");
}

#[test]
fn four_and_thirty_two_bits() {
    let frames = compress_common::rigid_parts(2, 40, 16);
    let (_, d4) = round_trip(&frames, &params(2, 3, 4));
    let (_, d32) = round_trip(&frames, &params(2, 3, 32));
    let (_, dmix) = round_trip(
        &frames,
        &CpcaParams {
            bits_weights: 4,
            ..params(2, 3, 32)
        },
    );
    assert!(d32 < 1e-3 && d4 > d32 && dmix > d32, "{d4} {d32} {dmix}");
}

#[test]
fn zero_range_component() {
    // Vertices move along x only: every trajectory's y and z are constant, and with c = 3 > the
    // rank (1 per cluster) the extra eigentrajectories are zero arrays.
    let frames: Vec<Vec<Vec3>> = (0..12)
        .map(|t| {
            (0..30)
                .map(|m| Vec3::new(m as f32 + (t as f32 * 0.3).sin(), 2.0, 0.0))
                .collect()
        })
        .collect();
    let (packed, da) = round_trip(&frames, &params(1, 3, 10));
    assert!((0..3).any(|h| packed.eigentrajectory(0, h).step() == 0.0));
    assert!(da < 0.5, "{da}");
}

#[test]
fn rate_distortion_search_on_a_static_clip_and_a_single_frame() {
    // Issue #19's search on the degenerate clips: a clip that never moves (zero motion, every
    // component zero-range) and a single frame. Both targets end finite and within budget.
    use anim_pca::compress::{RateTarget, RdLimits, search_rate_distortion};
    let frame: Vec<Vec3> = (0..40)
        .map(|i| Vec3::new(i as f32, (i * i) as f32 * 0.01, 1.0))
        .collect();
    let limits = RdLimits {
        k_max: 4,
        c_max: 4,
        max_fits: 12,
        ..RdLimits::default()
    };
    for frames in [vec![frame.clone(); 20], vec![frame]] {
        for target in [RateTarget::Bpvf(40.0), RateTarget::Distortion(0.5)] {
            let found = search_rate_distortion(
                &frames,
                &[],
                30.0,
                &CpcaParams::default(),
                target,
                &limits,
                &mut |_| {},
            )
            .unwrap();
            let p = found.chosen;
            assert!(p.da.is_finite() && p.bpvf.is_finite(), "{target:?}: {p:?}");
            assert!(
                found.reached(),
                "{} frames, {target:?}: {p:?}",
                frames.len()
            );
        }
    }
}
