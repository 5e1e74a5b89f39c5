//! Local PCA (thesis §2.7.4 steps 1–5): fixed-point properties checked against independent
//! references.

mod common;

use clustering::{
    ComponentCount, KSearchParams, KSearchStop, LocalPca, LocalPcaInit, LocalPcaParams, Pca,
    PcaMethod, PcaParams,
};
use common::*;
use faer::Mat;

/// Samples on `k` random affine subspaces of dimension `dim` in R^d, plus noise.
fn subspaces(
    k: usize,
    per: usize,
    d: usize,
    dim: usize,
    noise: f64,
    seed: u64,
) -> (Mat<f64>, Vec<usize>) {
    let mut r = rng(seed);
    let n = k * per;
    let mut x = Mat::zeros(n, d);
    let mut truth = Vec::new();
    for j in 0..k {
        let origin: Vec<f64> = (0..d).map(|_| 20.0 * normal(&mut r)).collect();
        let dirs: Vec<Vec<f64>> = (0..dim)
            .map(|_| (0..d).map(|_| normal(&mut r)).collect())
            .collect();
        for s in 0..per {
            let i = j * per + s;
            let coef: Vec<f64> = (0..dim).map(|_| 3.0 * normal(&mut r)).collect();
            for f in 0..d {
                x[(i, f)] = origin[f]
                    + (0..dim).map(|a| coef[a] * dirs[a][f]).sum::<f64>()
                    + noise * normal(&mut r);
            }
            truth.push(j);
        }
    }
    (x, truth)
}

fn params(k: usize, c: usize) -> LocalPcaParams {
    LocalPcaParams {
        k,
        components: c,
        tolerance: 0.0,
        seed: 3,
        ..Default::default()
    }
}

#[test]
fn exact_affine_subspaces_are_recovered_with_zero_error() {
    let (x, truth) = subspaces(3, 60, 12, 2, 0.0, 1);
    let l = LocalPca::fit(x.as_ref(), &params(3, 2)).unwrap();
    let scale = max_abs(x.as_ref());
    assert!(
        l.mean_error() <= 1e-20 * scale * scale * 12.0,
        "mean error {}",
        l.mean_error()
    );
    assert!(same_partition(l.labels(), &truth));
    let back = l.reconstruct();
    assert!(max_abs_diff(back.as_ref(), x.as_ref()) <= 1e-12 * scale);
}

#[test]
fn converged_model_is_a_fixed_point_of_steps_2_to_4() {
    let (x, _) = subspaces(4, 80, 10, 3, 0.3, 2);
    let c = 2;
    let l = LocalPca::fit(
        x.as_ref(),
        &LocalPcaParams {
            subspace_tolerance: 1e-12,
            ..params(4, c)
        },
    )
    .unwrap();
    assert!(l.converged());
    let (n, d) = (x.nrows(), x.ncols());
    // Step 3–4: each cluster's mean and basis are the PCA of its members (SVD reference).
    for j in 0..l.k() {
        let members: Vec<usize> = (0..n).filter(|&i| l.labels()[i] == j).collect();
        let xm = Mat::from_fn(members.len(), d, |a, f| x[(members[a], f)]);
        let p = Pca::fit(
            xm.as_ref(),
            &PcaParams {
                components: ComponentCount::Fixed(c),
                method: PcaMethod::Svd,
                seed: 0,
            },
        )
        .unwrap();
        for f in 0..d {
            assert_close(
                l.mean(j)[f],
                p.mean()[f],
                1e-10 * (1.0 + p.mean()[f].abs()),
                "mean",
            );
        }
        for a in 0..c {
            assert_close(
                l.eigenvalues(j)[a],
                p.eigenvalues()[a],
                1e-9 * p.eigenvalues()[0],
                "eigenvalue",
            );
            assert_close(
                dot(&col(l.basis(j), a), p.component(a)),
                1.0,
                1e-7,
                "basis vector (same sign)",
            );
        }
    }
    // Step 2: every sample sits in the cluster of least reconstruction error (brute force).
    for i in 0..n {
        let xi = row(&x, i);
        let errs: Vec<f64> = (0..l.k())
            .map(|j| {
                let diff: Vec<f64> = xi.iter().zip(l.mean(j)).map(|(a, b)| a - b).collect();
                let proj: f64 = (0..c)
                    .map(|a| dot(&diff, &col(l.basis(j), a)).powi(2))
                    .sum();
                dot(&diff, &diff) - proj
            })
            .collect();
        let best = errs.iter().cloned().fold(f64::INFINITY, f64::min);
        let mine = errs[l.labels()[i]];
        assert!(
            mine <= best + 1e-9 * (1.0 + best),
            "sample {i}: {mine} vs best {best}"
        );
        assert_close(
            l.sample_errors()[i],
            mine,
            1e-9 * (1.0 + mine),
            "stored error",
        );
    }
}

#[test]
fn error_history_never_increases() {
    let (x, _) = subspaces(5, 50, 15, 4, 1.0, 4);
    for init in [LocalPcaInit::KMeans, LocalPcaInit::RandomSamples] {
        let l = LocalPca::fit(
            x.as_ref(),
            &LocalPcaParams {
                init,
                ..params(5, 2)
            },
        )
        .unwrap();
        let h = l.error_history();
        assert_eq!(h.len(), l.iterations() + 1);
        for w in h.windows(2) {
            assert!(
                w[1] <= w[0] * (1.0 + 1e-9),
                "{init:?}: error increased: {h:?}"
            );
        }
    }
}

#[test]
fn one_cluster_is_global_pca() {
    let x = low_rank(120, 20, 6, 0.2, 5);
    let l = LocalPca::fit(x.as_ref(), &params(1, 4)).unwrap();
    let p = Pca::fit(
        x.as_ref(),
        &PcaParams {
            components: ComponentCount::Fixed(4),
            method: PcaMethod::Svd,
            seed: 0,
        },
    )
    .unwrap();
    let e = p.squared_error(x.as_ref()).unwrap() / 120.0;
    assert_close(l.mean_error(), e, 1e-9 * e, "k = 1 is PCA");
}

#[test]
fn weights_and_errors_reconstruct_the_samples() {
    let (x, _) = subspaces(3, 40, 9, 3, 0.5, 6);
    let l = LocalPca::fit(x.as_ref(), &params(3, 2)).unwrap();
    let back = l.reconstruct();
    for i in 0..x.nrows() {
        let e = sq_dist(&row(&x, i), &row(&back, i));
        assert_close(
            l.sample_errors()[i],
            e,
            1e-10 * (1.0 + e),
            "error = ‖x − x̃‖²",
        );
    }
    assert_eq!(l.weights().nrows(), x.nrows());
    assert_eq!(l.model_scalars(), 3 * 9 * 3 + x.nrows() * 2);
}

#[test]
fn local_pca_beats_global_pca_at_equal_components() {
    let (x, _) = subspaces(4, 100, 30, 3, 0.05, 7);
    let l = LocalPca::fit(x.as_ref(), &params(4, 3)).unwrap();
    let p = Pca::fit(
        x.as_ref(),
        &PcaParams {
            components: ComponentCount::Fixed(3),
            ..Default::default()
        },
    )
    .unwrap();
    let global = p.squared_error(x.as_ref()).unwrap() / x.nrows() as f64;
    assert!(
        l.mean_error() < 0.01 * global,
        "local {} vs global {global}",
        l.mean_error()
    );
}

#[test]
fn deterministic_for_a_seed_and_any_thread_count() {
    let (x, _) = subspaces(4, 300, 40, 3, 0.5, 8);
    let p = LocalPcaParams {
        init: LocalPcaInit::RandomSamples,
        ..params(4, 3)
    };
    let a = with_threads(1, || LocalPca::fit(x.as_ref(), &p).unwrap());
    let b = with_threads(2, || LocalPca::fit(x.as_ref(), &p).unwrap());
    assert_eq!(a.labels(), b.labels());
    assert_eq!(a.error_history(), b.error_history());
    for j in 0..4 {
        assert_eq!(a.basis(j), b.basis(j));
    }
}

#[test]
fn search_k_stops_at_target_error() {
    let (x, _) = subspaces(3, 50, 8, 2, 0.0, 9);
    let s = KSearchParams {
        target_mean_error: Some(1e-10),
        k_max: 6,
        ..Default::default()
    };
    let r = LocalPca::search_k(x.as_ref(), &params(0, 2), &s).unwrap();
    assert_eq!(r.stop, KSearchStop::TargetReached);
    assert_eq!(r.model.k(), 3);
    assert_eq!(
        r.steps.iter().map(|s| s.k).collect::<Vec<_>>(),
        vec![1, 2, 3]
    );
}

#[test]
fn search_k_respects_the_size_budget() {
    let (x, _) = subspaces(5, 30, 8, 2, 0.0, 10);
    let n = x.nrows();
    // Room for k ≤ 2: k·8·3 + n·2.
    let budget = 2 * 8 * 3 + n * 2;
    let s = KSearchParams {
        target_mean_error: Some(0.0),
        max_model_scalars: Some(budget),
        ..Default::default()
    };
    let r = LocalPca::search_k(x.as_ref(), &params(0, 2), &s).unwrap();
    assert_eq!(r.stop, KSearchStop::BudgetReached);
    assert_eq!(r.steps.len(), 2);
    assert!(r.model.model_scalars() <= budget);
    let tiny = KSearchParams {
        max_model_scalars: Some(10),
        ..s
    };
    assert!(LocalPca::search_k(x.as_ref(), &params(0, 2), &tiny).is_err());
}
