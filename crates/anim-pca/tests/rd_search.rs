//! The rate–distortion search over (k, c, c*, q_c, q_w) (issue #19): budgets are met by the
//! actual file, the answer beats the thesis's k-only search, and an exhaustive sweep of the
//! search's own coarse grid never finds a better point within the budget.

mod compress_common;
use compress_common as common;

use anim_pca::compress::{
    Compressed, CpcaModel, CpcaParams, Decoder, RateTarget, RdLimits, bpvf_from_file,
    search_clusters, search_rate_distortion,
};
use glam::Vec3;

fn limits() -> RdLimits {
    RdLimits {
        k_max: 8,
        c_max: 8,
        max_fits: 30,
        ..RdLimits::default()
    }
}

/// The chosen file's real size and decoded d_a, measured again from scratch.
fn remeasure(frames: &[Vec<Vec3>], packed: &Compressed) -> (f64, f64) {
    let bytes = Compressed::from_bytes(&packed.to_bytes()).unwrap();
    let bpvf = bpvf_from_file(packed.to_bytes().len(), frames[0].len(), frames.len());
    (bpvf, Decoder::new(&bytes).distortion(frames).unwrap().da)
}

#[test]
fn a_rate_budget_is_met_by_the_file_and_beats_the_k_only_search() {
    // Four spinning bars of 60 vertices over 40 frames.
    let frames = common::rigid_parts(4, 60, 40);
    for budget in [3.0, 6.0, 12.0] {
        let found = search_rate_distortion(
            &frames,
            &[],
            30.0,
            &CpcaParams::default(),
            RateTarget::Bpvf(budget),
            &limits(),
            &mut |_| {},
        )
        .unwrap();
        assert!(found.reached(), "budget {budget}");
        let (bpvf, da) = remeasure(&frames, &found.compressed);
        assert!(bpvf <= budget, "{bpvf} > {budget}");
        assert_eq!(bpvf, found.chosen.bpvf);
        assert_eq!(da, found.chosen.da);
        // The thesis's search (k alone, c = 20, 18 bits) at the same budget.
        let k_only = search_clusters(
            &frames,
            &[],
            30.0,
            &CpcaParams::default(),
            RateTarget::Bpvf(budget),
            8,
            &mut |_| {},
        )
        .unwrap();
        let k_da = if k_only.reached {
            k_only.chosen_step().da
        } else {
            f64::INFINITY
        };
        assert!(
            found.chosen.da <= k_da,
            "budget {budget}: full search d_a {} vs k-only {k_da}",
            found.chosen.da
        );
        // Every point judged that meets the budget is no better than the chosen one.
        for p in found.points.iter().filter(|p| p.meets) {
            assert!(p.bpvf <= budget);
            assert!(found.chosen.da <= p.da, "{p:?} beats {:?}", found.chosen);
        }
    }
}

#[test]
fn no_grid_point_of_the_coarse_lattice_beats_the_search() {
    // Exhaustive: every (k, c) of the search's coarse grid × q_c, q_w ∈ 4..=16 (169 pairs).
    let frames = common::rigid_parts(3, 40, 30);
    let budget = 5.0;
    let found = search_rate_distortion(
        &frames,
        &[],
        30.0,
        &CpcaParams::default(),
        RateTarget::Bpvf(budget),
        &limits(),
        &mut |_| {},
    )
    .unwrap();
    let mut best = f64::INFINITY;
    for k in [1, 2, 4, 8] {
        for c in [1, 2, 4, 8] {
            let base = CpcaParams {
                clusters: k,
                components: c,
                ..CpcaParams::default()
            };
            let model = CpcaModel::fit(&frames, &base).unwrap();
            for qc in 4..=16u8 {
                for qw in 4..=16u8 {
                    let p = CpcaParams {
                        bits_components: qc,
                        bits_weights: qw,
                        ..base
                    };
                    let packed = Compressed::from_model(&model, &[], 30.0, &p).unwrap();
                    let bpvf = bpvf_from_file(packed.to_bytes().len(), 120, 30);
                    if bpvf <= budget {
                        best = best.min(Decoder::new(&packed).distortion(&frames).unwrap().da);
                    }
                }
            }
        }
    }
    assert!(best.is_finite(), "the sweep found a point within {budget}");
    // The search measures every second q_c along the budget's edge and refines ±1; allow it
    // 2 % of the exhaustive sweep's d_a.
    assert!(
        found.chosen.da <= best * 1.02,
        "search d_a {} vs exhaustive {best}",
        found.chosen.da
    );
}

#[test]
fn a_distortion_target_is_met_with_no_more_bits_than_the_k_only_search() {
    let frames = common::rigid_parts(4, 60, 40);
    let target = 0.05;
    let found = search_rate_distortion(
        &frames,
        &[],
        30.0,
        &CpcaParams::default(),
        RateTarget::Distortion(target),
        &limits(),
        &mut |_| {},
    )
    .unwrap();
    assert!(found.reached());
    let (bpvf, da) = remeasure(&frames, &found.compressed);
    assert!(da <= target, "{da}");
    assert_eq!(bpvf, found.chosen.bpvf);
    let k_only = search_clusters(
        &frames,
        &[],
        30.0,
        &CpcaParams::default(),
        RateTarget::Distortion(target),
        8,
        &mut |_| {},
    )
    .unwrap();
    assert!(k_only.reached);
    assert!(
        bpvf < k_only.chosen_step().bpvf,
        "{bpvf} vs k-only {}",
        k_only.chosen_step().bpvf
    );
}

#[test]
fn an_unreachable_budget_keeps_the_smallest_file_and_says_so() {
    let frames = common::rigid_parts(2, 30, 20);
    let found = search_rate_distortion(
        &frames,
        &[],
        30.0,
        &CpcaParams::default(),
        RateTarget::Bpvf(0.01),
        &limits(),
        &mut |_| {},
    )
    .unwrap();
    assert!(!found.reached());
    let smallest = found
        .points
        .iter()
        .map(|p| p.bpvf)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(found.chosen.bpvf, smallest);
    // The grid stopped growing: every larger model is pruned once (1, 1) cannot fit.
    assert_eq!(found.fits, 1, "{:?}", found.points);
}

#[test]
fn limits_are_kept_and_the_search_is_deterministic() {
    let frames = common::rigid_parts(3, 40, 30);
    let tight = RdLimits {
        max_fits: 5,
        ..limits()
    };
    let run = || {
        search_rate_distortion(
            &frames,
            &[],
            30.0,
            &CpcaParams::default(),
            RateTarget::Bpvf(8.0),
            &tight,
            &mut |_| {},
        )
        .unwrap()
    };
    let (a, b) = (run(), run());
    assert!(a.fits <= 5, "{}", a.fits);
    assert_eq!(a.chosen, b.chosen);
    assert_eq!(a.compressed.to_bytes(), b.compressed.to_bytes());
    // A cost bound below every model but (1, 1) leaves only (1, 1) (and its c*).
    let cheap = RdLimits {
        max_cost: 1.0,
        ..limits()
    };
    let found = search_rate_distortion(
        &frames,
        &[],
        30.0,
        &CpcaParams::default(),
        RateTarget::Bpvf(8.0),
        &cheap,
        &mut |_| {},
    )
    .unwrap();
    assert!(
        found
            .points
            .iter()
            .all(|p| (p.clusters, p.components) == (1, 1))
    );
    for bad in [
        RdLimits {
            max_fits: 0,
            ..limits()
        },
        RdLimits {
            k_max: 0,
            ..limits()
        },
    ] {
        assert!(
            search_rate_distortion(
                &frames,
                &[],
                30.0,
                &CpcaParams::default(),
                RateTarget::Bpvf(8.0),
                &bad,
                &mut |_| {},
            )
            .is_err()
        );
    }
}
