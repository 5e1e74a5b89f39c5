//! k-means: Lloyd fixed-point properties checked by brute force.

mod common;

use clustering::{KMeans, KMeansInit, KMeansParams};
use common::*;
use faer::Mat;

fn params(k: usize, seed: u64) -> KMeansParams {
    KMeansParams {
        k,
        seed,
        tolerance: 0.0,
        ..Default::default()
    }
}

#[test]
fn recovers_well_separated_blobs() {
    let (x, truth) = blobs(&[50, 120, 30, 80, 20], 6, 0.5, 100.0, 1);
    for init in [KMeansInit::PlusPlus, KMeansInit::RandomSamples] {
        let km = KMeans::fit(
            x.as_ref(),
            &KMeansParams {
                init: init.clone(),
                ..params(5, 3)
            },
        )
        .unwrap();
        if init == KMeansInit::PlusPlus {
            assert!(
                same_partition(km.labels(), &truth),
                "k-means++ finds the blobs"
            );
        }
        assert!(km.converged());
    }
}

#[test]
fn converged_result_is_a_lloyd_fixed_point() {
    let (x, _) = blobs(&[200, 150, 100, 50], 5, 3.0, 10.0, 2);
    let km = KMeans::fit(x.as_ref(), &params(6, 4)).unwrap();
    assert!(km.converged());
    let (n, d) = (x.nrows(), x.ncols());
    // Every center is the f64 mean of its members.
    for j in 0..km.k() {
        let members: Vec<usize> = (0..n).filter(|&i| km.labels()[i] == j).collect();
        assert!(!members.is_empty());
        for f in 0..d {
            let m = members.iter().map(|&i| x[(i, f)]).sum::<f64>() / members.len() as f64;
            assert_close(
                km.center(j)[f],
                m,
                1e-12 * (1.0 + m.abs()),
                "center = mean of members",
            );
        }
    }
    // Every label is the nearest center (brute force), and the inertia is their sum.
    let mut inertia = 0.0;
    for i in 0..n {
        let r = row(&x, i);
        let dists: Vec<f64> = (0..km.k()).map(|j| sq_dist(&r, km.center(j))).collect();
        let best = dists.iter().cloned().fold(f64::INFINITY, f64::min);
        let mine = dists[km.labels()[i]];
        assert!(
            mine <= best * (1.0 + 1e-12) + 1e-12,
            "sample {i} not at its nearest center"
        );
        assert_close(
            km.sq_distances()[i],
            mine,
            1e-12 * (1.0 + mine),
            "stored distance",
        );
        inertia += mine;
    }
    assert_close(km.inertia(), inertia, 1e-12 * inertia, "inertia (eq. 2.54)");
    assert_eq!(km.cluster_sizes().iter().sum::<usize>(), n);
}

#[test]
fn inertia_history_never_increases() {
    let (x, _) = blobs(&[300, 200, 100], 8, 4.0, 6.0, 5);
    for init in [KMeansInit::PlusPlus, KMeansInit::RandomSamples] {
        let km = KMeans::fit(
            x.as_ref(),
            &KMeansParams {
                init,
                ..params(9, 6)
            },
        )
        .unwrap();
        let h = km.inertia_history();
        assert_eq!(h.len(), km.iterations() + 1);
        for w in h.windows(2) {
            assert!(w[1] <= w[0] * (1.0 + 1e-12), "Lloyd increased E: {h:?}");
        }
    }
}

#[test]
fn deterministic_for_a_seed_and_any_thread_count() {
    let (x, _) = blobs(&[500, 400, 300, 2000], 7, 2.0, 8.0, 7);
    let a = with_threads(1, || KMeans::fit(x.as_ref(), &params(12, 42)).unwrap());
    let b = with_threads(2, || KMeans::fit(x.as_ref(), &params(12, 42)).unwrap());
    let c = with_threads(3, || KMeans::fit(x.as_ref(), &params(12, 42)).unwrap());
    for o in [&b, &c] {
        assert_eq!(a.labels(), o.labels());
        assert_eq!(a.centers(), o.centers());
        assert_eq!(a.inertia().to_bits(), o.inertia().to_bits());
    }
}

#[test]
fn tolerance_stops_early_and_cap_is_respected() {
    let (x, _) = blobs(&[400, 400, 400], 4, 5.0, 4.0, 8);
    let loose = KMeans::fit(
        x.as_ref(),
        &KMeansParams {
            tolerance: 0.5,
            ..params(10, 1)
        },
    )
    .unwrap();
    assert!(loose.converged());
    let h = loose.inertia_history();
    let last = h.len() - 1;
    assert!((h[last - 1] - h[last]).abs() <= 0.5 * h[last - 1]);
    let capped = KMeans::fit(
        x.as_ref(),
        &KMeansParams {
            max_iterations: 1,
            ..params(10, 1)
        },
    )
    .unwrap();
    assert_eq!(capped.iterations(), 1);
}

#[test]
fn given_centers_are_used() {
    let (x, _) = blobs(&[30, 30], 2, 0.1, 50.0, 9);
    let init = Mat::from_fn(2, 2, |i, j| x[(i * 30, j)]);
    let km = KMeans::fit(
        x.as_ref(),
        &KMeansParams {
            init: KMeansInit::Given(init.clone()),
            max_iterations: 0,
            ..params(2, 0)
        },
    )
    .unwrap();
    assert_eq!(km.iterations(), 0);
    for j in 0..2 {
        for f in 0..2 {
            assert_close(
                km.center(j)[f],
                init[(j, f)],
                1e-12 * (1.0 + init[(j, f)].abs()),
                "given center",
            );
        }
    }
}

#[test]
fn predict_agrees_with_labels() {
    let (x, _) = blobs(&[100, 100, 100], 3, 1.0, 20.0, 10);
    let km = KMeans::fit(x.as_ref(), &params(3, 2)).unwrap();
    assert_eq!(km.predict(x.as_ref()).unwrap(), km.labels());
}

#[test]
fn f32_input_matches_f64_of_the_same_values() {
    let (x, _) = blobs(&[100, 60, 40], 5, 1.0, 10.0, 11);
    let x32 = Mat::<f32>::from_fn(x.nrows(), x.ncols(), |i, j| x[(i, j)] as f32);
    let x64 = Mat::<f64>::from_fn(x.nrows(), x.ncols(), |i, j| f64::from(x32[(i, j)]));
    let a = KMeans::fit(x32.as_ref(), &params(3, 5)).unwrap();
    let b = KMeans::fit(x64.as_ref(), &params(3, 5)).unwrap();
    assert_eq!(a.labels(), b.labels());
    assert_eq!(a.inertia().to_bits(), b.inertia().to_bits());
}

#[test]
fn local_search_never_raises_the_seeding_potential() {
    // Same k-means++ seeds (the local search draws after them); its swaps only lower E.
    let (x, _) = blobs(&[400, 300, 200, 100, 50, 25, 600], 6, 1.5, 12.0, 12);
    for seed in 0..5 {
        let p = |steps| KMeansParams {
            local_search_steps: Some(steps),
            max_iterations: 0,
            ..params(7, seed)
        };
        let plain = KMeans::fit(x.as_ref(), &p(0)).unwrap();
        let searched = KMeans::fit(x.as_ref(), &p(14)).unwrap();
        assert!(
            searched.inertia() <= plain.inertia(),
            "seed {seed}: {} > {}",
            searched.inertia(),
            plain.inertia()
        );
    }
}
