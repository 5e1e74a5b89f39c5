//! CPCA compression (thesis §3.3): defining identities of the encoder, quantization,
//! container, decoder and metrics.

mod compress_common;
use compress_common as common;

use anim_pca::AnimPcaError;
use anim_pca::compress::{
    Compressed, CpcaModel, CpcaParams, Decoder, Distortion, bpvf_from_file, distortion,
    trajectory_matrix,
};
use clustering::LocalPca;
use glam::{DVec3, Vec3};

fn exact(k: usize, c: usize) -> CpcaParams {
    CpcaParams {
        clusters: k,
        components: c,
        bits_components: 32,
        bits_weights: 32,
        ..CpcaParams::default()
    }
}

#[track_caller]
fn assert_close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() <= tol, "{a} vs {b} (tolerance {tol})");
}

#[test]
fn unquantized_model_reconstructs_like_local_pca() {
    let frames = common::rigid_parts(3, 60, 25);
    let params = CpcaParams {
        clusters: 3,
        components: 2,
        ..CpcaParams::default()
    };
    let model = CpcaModel::fit(&frames, &params).unwrap();
    // The same local PCA run directly on the trajectory matrix built here by hand.
    let (v, f) = (frames[0].len(), frames.len());
    let a = faer::Mat::from_fn(v, 3 * f, |m, col| f64::from(frames[col / 3][m][col % 3]));
    assert_eq!(trajectory_matrix(&frames).unwrap(), a);
    let direct = LocalPca::fit(a.as_ref(), &params.local_pca_params(v, f)).unwrap();
    assert_eq!(direct.labels(), model.local_pca().labels());
    let mut out = vec![DVec3::ZERO; v];
    let mut sq = 0.0;
    for (t, frame) in frames.iter().enumerate() {
        model.reconstruct_frame(t, &mut out).unwrap();
        for (p, q) in frame.iter().zip(&out) {
            sq += (p.as_dvec3() - *q).length_squared();
        }
    }
    let expected: f64 = direct.sample_errors().iter().sum();
    assert!(expected > 1e-3, "c = 2 < 3 leaves an error");
    assert_close(sq, expected, 1e-9 * expected + 1e-6);
}

#[test]
fn quantization_error_is_within_the_bit_bound() {
    let frames = common::rigid_parts(2, 70, 30);
    for (qc, qw) in [(8, 8), (12, 16), (16, 10)] {
        let params = CpcaParams {
            clusters: 2,
            components: 3,
            bits_components: qc,
            bits_weights: qw,
            ..CpcaParams::default()
        };
        let model = CpcaModel::fit(&frames, &params).unwrap();
        let packed = Compressed::from_model(&model, &[], 24.0, &params).unwrap();
        let decoder = Decoder::new(&packed);
        let l = model.local_pca();
        let mut scratch = decoder.scratch();
        let mut out = vec![Vec3::ZERO; frames[0].len()];
        let mut exact_out = vec![DVec3::ZERO; frames[0].len()];
        for t in 0..frames.len() {
            decoder.frame_into(t, &mut out, &mut scratch).unwrap();
            model.reconstruct_frame(t, &mut exact_out).unwrap();
            for m in 0..out.len() {
                let j = l.labels()[m];
                let w = l.weight(m);
                for a in 0..3 {
                    let i = 3 * t + a;
                    // |Δ(r + Σ w e)| ≤ Δr + Σ (|w| Δe + |e| Δw + Δw Δe)
                    let mut bound = packed.mean(j, a).max_error();
                    let mut magnitude = l.mean(j)[i].abs();
                    for (h, wh) in w.iter().enumerate() {
                        let (de, dw) = (
                            packed.eigentrajectory(j, h).max_error(),
                            packed.weights(h).max_error(),
                        );
                        let e = l.basis(j)[(i, h)];
                        bound += wh.abs() * de + e.abs() * dw + de * dw;
                        magnitude += (wh * e).abs();
                    }
                    // Plus f32 rounding of the stored values and of the sum.
                    bound += 8.0 * f64::from(f32::EPSILON) * (magnitude + bound);
                    let err = (f64::from(out[m][a]) - exact_out[m][a]).abs();
                    assert!(
                        err <= bound,
                        "q = ({qc}, {qw}) frame {t} vertex {m}: {err} > {bound}"
                    );
                }
            }
        }
    }
}

#[test]
fn more_bits_less_error() {
    let frames = common::rigid_parts(2, 50, 20);
    let da = |q: u8| {
        let p = CpcaParams {
            clusters: 2,
            components: 3,
            bits_components: q,
            bits_weights: q,
            ..CpcaParams::default()
        };
        let packed = Compressed::encode(&frames, &[], 24.0, &p).unwrap();
        Decoder::new(&packed).distortion(&frames).unwrap().da
    };
    let (d6, d10, d16) = (da(6), da(10), da(16));
    assert!(d6 > d10 && d10 > d16, "{d6} {d10} {d16}");
}

#[test]
fn da_matches_a_direct_computation() {
    // Two vertices at ±(1, 2, 2) about a moving centroid; the reconstruction is off by
    // (δ, δ, δ) everywhere. ‖B − E(B)‖² = F·2·9, ‖B − B̂‖² = F·2·3δ².
    let (f, delta) = (7, 0.01f32);
    let frames: Vec<Vec<Vec3>> = (0..f)
        .map(|t| {
            let c = Vec3::new(t as f32, 0.5 * t as f32, -1.0);
            vec![c + Vec3::new(1.0, 2.0, 2.0), c - Vec3::new(1.0, 2.0, 2.0)]
        })
        .collect();
    let shifted: Vec<Vec<Vec3>> = frames
        .iter()
        .map(|fr| fr.iter().map(|p| *p + Vec3::splat(delta)).collect())
        .collect();
    let Distortion { da, df } = distortion(&frames, &shifted).unwrap();
    // The shift as stored after f32 rounding of p + δ.
    let mut num = 0.0f64;
    for (a, b) in frames.iter().flatten().zip(shifted.iter().flatten()) {
        num += (a.as_dvec3() - b.as_dvec3()).length_squared();
    }
    let direct = 100.0 * (num / (f as f64 * 18.0)).sqrt();
    assert_close(da, direct, 1e-12 * direct);
    let nominal = 100.0 * (3.0 * f64::from(delta).powi(2) / 9.0).sqrt();
    assert_close(da, nominal, 1e-3 * nominal);
    assert_eq!(df.len(), f);
    assert_close(df[0], (6.0 * f64::from(delta).powi(2)).sqrt(), 1e-6);
    assert_eq!(distortion(&frames, &frames).unwrap().da, 0.0);
}

#[test]
fn clusters_beat_one_pca_at_equal_parameter_count() {
    // 4 rigid parts, V = 4·140 ≫ F = 30: CPCA k = 4, c = 3 stores 4·90·4 + 560·3 = 3120
    // scalars; plain PCA (k = 1) with c = 4 stores 90·5 + 560·4 = 2690, c = 5 stores 3250.
    let frames = common::rigid_parts(4, 140, 30);
    let scalars = |m: &CpcaModel| m.local_pca().model_scalars();
    let cpca = CpcaModel::fit(&frames, &exact(4, 3)).unwrap();
    let pca = CpcaModel::fit(&frames, &exact(1, 5)).unwrap();
    assert!(
        scalars(&pca) >= scalars(&cpca),
        "{} vs {}",
        scalars(&pca),
        scalars(&cpca)
    );
    let da = |m: &CpcaModel, k, c| {
        let p = exact(k, c);
        let packed = Compressed::from_model(m, &[], 24.0, &p).unwrap();
        Decoder::new(&packed).distortion(&frames).unwrap().da
    };
    let (d_cpca, d_pca) = (da(&cpca, 4, 3), da(&pca, 1, 5));
    println!("rigid parts: CPCA d_a = {d_cpca:.2e}, PCA d_a = {d_pca:.2e}");
    assert!(d_cpca < 1e-3, "each part is exactly rank 3: d_a = {d_cpca}");
    assert!(d_cpca * 100.0 < d_pca, "CPCA {d_cpca} vs PCA {d_pca}");
}

#[test]
fn file_round_trip_and_random_access() {
    let frames = common::rigid_parts(3, 40, 21);
    let tris: Vec<[u32; 3]> = (0..100).map(|i| [i, i + 1, (i * 7 + 3) % 120]).collect();
    for time in [None, Some(6)] {
        let p = CpcaParams {
            clusters: 3,
            components: 3,
            time_components: time,
            bits_components: 20,
            bits_weights: 20,
            ..CpcaParams::default()
        };
        let packed = Compressed::encode(&frames, &tris, 25.0, &p).unwrap();
        let bytes = packed.to_bytes();
        let read = Compressed::from_bytes(&bytes).unwrap();
        assert_eq!(read, packed);
        // The same triangles (as a multiset, each up to a rotation that keeps its winding);
        // the codec orders them for the vertex cache.
        assert_eq!(
            common::canonical_triangles(read.triangles()),
            common::canonical_triangles(&tris)
        );
        assert_eq!(read.time_components(), time);
        let d = Decoder::new(&read);
        let all = d.decode_all();
        let mut scratch = d.scratch();
        let mut one = vec![Vec3::ZERO; 120];
        for t in [20, 0, 13] {
            d.frame_into(t, &mut one, &mut scratch).unwrap();
            assert_eq!(one, all[t]);
        }
        let da = distortion(&frames, &all).unwrap().da;
        assert!(da < 0.05, "{time:?}: d_a = {da}");
        let rate = read.rate();
        let file = bpvf_from_file(bytes.len(), 120, 21);
        println!(
            "{time:?}: eq 3.16 {:.2}, 3.18 {:?}, file {file:.2}",
            rate.eq_3_16(),
            rate.eq_3_18()
        );
        assert!(file > 0.0 && rate.eq_3_17() < rate.eq_3_16());
        assert_eq!(rate.eq_3_18().is_some(), time.is_some());
    }
}

#[test]
fn time_compression_with_all_components_is_lossless_up_to_rounding() {
    let frames = common::rigid_parts(2, 30, 12);
    let base = exact(2, 3);
    let full = CpcaParams {
        time_components: Some(6),
        ..base
    };
    let model = CpcaModel::fit(&frames, &base).unwrap();
    let d0 = Decoder::new(&Compressed::from_model(&model, &[], 1.0, &base).unwrap())
        .distortion(&frames)
        .unwrap()
        .da;
    let d1 = Decoder::new(&Compressed::from_model(&model, &[], 1.0, &full).unwrap())
        .distortion(&frames)
        .unwrap()
        .da;
    assert!((d1 - d0).abs() < 1e-3, "{d0} vs {d1}");
    let few = CpcaParams {
        time_components: Some(2),
        ..base
    };
    let d2 = Decoder::new(&Compressed::from_model(&model, &[], 1.0, &few).unwrap())
        .distortion(&frames)
        .unwrap()
        .da;
    assert!(d2 > d1, "{d2} vs {d1}");
}

#[test]
fn bad_parameters_name_the_field() {
    let frames = common::rigid_parts(1, 10, 3);
    for (p, name) in [
        (
            CpcaParams {
                clusters: 0,
                ..CpcaParams::default()
            },
            "clusters",
        ),
        (
            CpcaParams {
                components: 0,
                ..CpcaParams::default()
            },
            "components",
        ),
        (
            CpcaParams {
                bits_weights: 0,
                ..CpcaParams::default()
            },
            "bits_weights",
        ),
        (
            CpcaParams {
                bits_components: 33,
                ..CpcaParams::default()
            },
            "bits_components",
        ),
        (
            CpcaParams {
                time_components: Some(0),
                ..CpcaParams::default()
            },
            "time_components",
        ),
    ] {
        match Compressed::encode(&frames, &[], 1.0, &p) {
            Err(AnimPcaError::InvalidParameter { name: n, .. }) => assert_eq!(n, name),
            other => panic!("{name}: {other:?}"),
        }
    }
    let err = Compressed::encode(&frames, &[[0, 1, 10]], 1.0, &CpcaParams::default());
    assert!(matches!(
        err,
        Err(AnimPcaError::InvalidParameter {
            name: "triangles",
            ..
        })
    ));
}

#[test]
fn cluster_search_returns_the_first_k_meeting_the_target_and_matches_direct_encoding() {
    use anim_pca::compress::{RateTarget, search_clusters};
    // Four rigid parts moving independently, c = 3: one rigid motion per cluster fits.
    let frames = common::rigid_parts(4, 48, 20);
    let params = CpcaParams {
        components: 3,
        ..CpcaParams::default()
    };
    let mut seen = Vec::new();
    let target = 0.05;
    let found = search_clusters(
        &frames,
        &[],
        30.0,
        &params,
        RateTarget::Distortion(target),
        10,
        &mut |s| seen.push(s.k),
    )
    .unwrap();
    assert!(found.reached);
    let chosen = *found.chosen_step();
    assert!(chosen.da <= target);
    // Every k before the chosen one missed the target, and k rose one at a time from 1.
    assert_eq!(seen, (1..=chosen.k).collect::<Vec<_>>());
    assert!(found.steps[..found.chosen].iter().all(|s| s.da > target));
    // The chosen file is exactly what a direct encode with that k gives.
    let direct = Compressed::encode(
        &frames,
        &[],
        30.0,
        &CpcaParams {
            clusters: chosen.k,
            ..params
        },
    )
    .unwrap();
    assert_eq!(found.compressed, direct);
    let bytes = direct.to_bytes().len();
    assert_eq!(
        chosen.bpvf,
        bpvf_from_file(bytes, direct.vertices(), frames.len())
    );

    // A rate budget: the file size grows with k, so the search stops at the first k over
    // budget and keeps the lowest d_a below it.
    let budget = found.steps[1].bpvf + 1e-9;
    let by_rate = search_clusters(
        &frames,
        &[],
        30.0,
        &params,
        RateTarget::Bpvf(budget),
        10,
        &mut |_| {},
    )
    .unwrap();
    assert!(by_rate.reached);
    assert!(
        by_rate
            .steps
            .iter()
            .take(by_rate.steps.len() - 1)
            .all(|s| s.bpvf <= budget)
    );
    assert!(by_rate.chosen_step().bpvf <= budget);
    assert_eq!(
        by_rate.steps.last().unwrap().k,
        3,
        "k = 3 is the first over budget"
    );

    // An unreachable d_a keeps the best k tried and says so.
    let never = search_clusters(
        &frames,
        &[],
        30.0,
        &CpcaParams {
            bits_components: 4,
            bits_weights: 4,
            ..params
        },
        RateTarget::Distortion(1e-9),
        3,
        &mut |_| {},
    )
    .unwrap();
    assert!(!never.reached);
    assert_eq!(never.steps.len(), 3);
    let best = never
        .steps
        .iter()
        .map(|s| s.da)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(never.chosen_step().da, best);

    // Bad targets are refused by name.
    for bad in [RateTarget::Distortion(0.0), RateTarget::Bpvf(f64::NAN)] {
        let e = search_clusters(&frames, &[], 30.0, &params, bad, 3, &mut |_| {}).unwrap_err();
        assert!(e.to_string().contains("target"), "{e}");
    }
    let e = search_clusters(
        &frames,
        &[],
        30.0,
        &params,
        RateTarget::Bpvf(10.0),
        0,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("k_max"), "{e}");
}
