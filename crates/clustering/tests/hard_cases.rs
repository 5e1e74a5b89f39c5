//! Named adversarial cases (DESIGN.md "Hard cases stay numerically stable"): results are
//! finite, deterministic for a seed and within a stated error of an f64 reference.

mod common;

use clustering::{
    ClusteringError, ColumnBlockSource, ComponentCount, KMeans, KMeansInit, KMeansParams,
    KSearchParams, LocalPca, LocalPcaInit, LocalPcaParams, Pca, PcaMethod, PcaParams,
    RandomizedParams, SourceError,
};
use common::*;
use faer::Mat;

const EXACT_PATHS: [PcaMethod; 3] = [PcaMethod::Svd, PcaMethod::Gram, PcaMethod::Covariance];

fn pca(x: &Mat<f64>, method: PcaMethod, components: ComponentCount) -> Pca {
    Pca::fit(
        x.as_ref(),
        &PcaParams {
            components,
            method,
            seed: 1,
        },
    )
    .expect("pca")
}

fn kmeans_params(k: usize) -> KMeansParams {
    KMeansParams {
        k,
        tolerance: 0.0,
        seed: 5,
        ..Default::default()
    }
}

fn lpca_params(k: usize, c: usize) -> LocalPcaParams {
    LocalPcaParams {
        k,
        components: c,
        tolerance: 0.0,
        seed: 5,
        ..Default::default()
    }
}

/// Every value of a fitted PCA is finite.
#[track_caller]
fn assert_finite_pca(p: &Pca) {
    assert!(
        p.mean()
            .iter()
            .chain(p.eigenvalues())
            .chain(p.spectrum())
            .all(|v| v.is_finite())
    );
    assert!(p.total_variance().is_finite());
    for i in 0..p.n_components() {
        assert!(p.component(i).iter().all(|v| v.is_finite()));
    }
}

#[test]
fn rank_deficient_wide_data_with_repeated_rows() {
    // 6 distinct rows in 50-D, each twice (n = 12 < d = 50): affine rank 5.
    let base = gaussian(6, 50, 1, |j| 1.0 + (j % 7) as f64);
    let x = Mat::from_fn(12, 50, |i, j| base[(i % 6, j)]);
    let scale = max_abs(x.as_ref());
    for method in EXACT_PATHS {
        let p = pca(&x, method, ComponentCount::All);
        assert_eq!(p.rank(), 5, "{method:?}");
        assert_eq!(p.n_components(), 5);
        assert_finite_pca(&p);
        let back = p
            .reconstruct(p.project(x.as_ref()).unwrap().as_ref())
            .unwrap();
        let err = max_abs_diff(back.as_ref(), x.as_ref());
        assert!(
            err <= 1e3 * f64::EPSILON * scale * (12.0f64 * 50.0).sqrt(),
            "{method:?}: {err:e}"
        );
    }
    let km = KMeans::fit(x.as_ref(), &kmeans_params(6)).unwrap();
    assert!(
        km.inertia() <= 1e-20 * scale * scale,
        "six distinct points, six clusters: {}",
        km.inertia()
    );
    let l = LocalPca::fit(x.as_ref(), &lpca_params(2, 3)).unwrap();
    assert!(l.sample_errors().iter().all(|e| e.is_finite() && *e >= 0.0));
}

#[test]
fn cluster_with_fewer_members_than_components() {
    // Two tight far-away pairs next to a big 3-D cloud; c = 4 > pair size.
    let cloud = gaussian(60, 6, 2, |j| if j < 3 { 1.0 } else { 0.0 });
    let mut x = Mat::zeros(62, 6);
    for i in 0..60 {
        for j in 0..6 {
            x[(i, j)] = cloud[(i, j)];
        }
    }
    for j in 0..6 {
        x[(60, j)] = 1000.0 + j as f64;
        x[(61, j)] = 1000.0 + 2.0 * j as f64;
    }
    let l = LocalPca::fit(x.as_ref(), &lpca_params(2, 4)).unwrap();
    let small = l.labels()[60];
    assert_eq!(l.labels()[61], small);
    assert_eq!(l.cluster_sizes()[small], 2);
    // The pair spans a line: one axis, three zero columns with zero eigenvalues.
    let b = l.basis(small);
    let norms: Vec<f64> = (0..4).map(|a| dot(&col(b, a), &col(b, a))).collect();
    assert_close(norms[0], 1.0, 1e-12, "first axis is a unit vector");
    assert_eq!(&norms[1..], &[0.0, 0.0, 0.0]);
    assert_eq!(&l.eigenvalues(small)[1..], &[0.0, 0.0, 0.0]);
    assert!(l.sample_errors()[60] < 1e-18 && l.sample_errors()[61] < 1e-18);
    // The cloud (rank 3 ≤ c) is reproduced too.
    assert!(l.mean_error() < 1e-20, "{}", l.mean_error());
}

#[test]
fn more_clusters_than_distinct_points() {
    // 30 samples on 3 distinct points, k = 5.
    let pts = [[0.0, 1.0], [4.0, -2.0], [9.0, 9.0]];
    let x = Mat::from_fn(30, 2, |i, j| pts[i % 3][j]);
    // Zero up to the rounding of the translation to the data mean: (4ε·max|x|)² per entry.
    let tol = (4.0 * f64::EPSILON * 9.0f64).powi(2) * 60.0;
    for init in [KMeansInit::PlusPlus, KMeansInit::RandomSamples] {
        let p = KMeansParams {
            init: init.clone(),
            ..kmeans_params(5)
        };
        let a = KMeans::fit(x.as_ref(), &p).unwrap();
        let b = KMeans::fit(x.as_ref(), &p).unwrap();
        assert!(a.inertia() <= tol, "{init:?}: {}", a.inertia());
        assert_eq!(
            a.cluster_sizes().iter().filter(|&&s| s == 0).count(),
            2,
            "two clusters stay empty"
        );
        assert_eq!(a.labels(), b.labels(), "deterministic");
        assert!(
            a.centers()
                .col_iter()
                .all(|c| c.iter().all(|v| v.is_finite()))
        );
    }
    for init in [LocalPcaInit::KMeans, LocalPcaInit::RandomSamples] {
        let l = LocalPca::fit(
            x.as_ref(),
            &LocalPcaParams {
                init,
                ..lpca_params(5, 1)
            },
        )
        .unwrap();
        assert!(l.mean_error() <= tol, "{init:?}: {}", l.mean_error());
        assert!(
            l.means()
                .col_iter()
                .all(|c| c.iter().all(|v| v.is_finite()))
        );
    }
}

#[test]
fn all_samples_identical() {
    // 0.1 and 1e6 + 0.1 are not representable, so their means are not either.
    for value in [0.1, 1e6 + 0.1, -3.0] {
        let x = Mat::from_fn(25, 7, |_, j| value * (1.0 + j as f64));
        for method in EXACT_PATHS {
            let p = pca(&x, method, ComponentCount::All);
            assert_eq!(p.n_components(), 0, "{method:?} on constant data {value}");
            assert_eq!(p.rank(), 0);
            assert!(p.total_variance() <= 1e-28 * value * value * 49.0);
            let w = p.project(x.as_ref()).unwrap();
            assert_eq!(w.ncols(), 0);
            let back = p.reconstruct(w.as_ref()).unwrap();
            assert!(
                max_abs_diff(back.as_ref(), x.as_ref()) <= 4.0 * f64::EPSILON * value.abs() * 7.0
            );
        }
        let tol = (4.0 * f64::EPSILON * value.abs() * 7.0).powi(2) * 25.0 * 7.0;
        let km = KMeans::fit(x.as_ref(), &kmeans_params(3)).unwrap();
        assert!(km.inertia() <= tol, "{}", km.inertia());
        let l = LocalPca::fit(x.as_ref(), &lpca_params(2, 2)).unwrap();
        assert!(l.mean_error() <= tol, "{}", l.mean_error());
    }
}

#[test]
fn data_offset_by_1e6_with_unit_variance_matches_f64_reference() {
    const OFFSET: f64 = 1e6;
    // Correlated unit-scale data; the shifted matrix is stored exactly as x − 1e6 would be.
    let z = low_rank(300, 6, 3, 0.3, 7);
    let zc = Mat::from_fn(300, 6, |i, j| z[(i, j)] * 0.2);
    let x = Mat::from_fn(300, 6, |i, j| zc[(i, j)] + OFFSET);
    // Reference: the same values, shifted back exactly (|x − 1e6| < 1e6 ⇒ exact subtraction).
    let shifted = Mat::from_fn(300, 6, |i, j| x[(i, j)] - OFFSET);
    let (ref_vals, _) = jacobi_eigen(&covariance(&shifted));
    for method in [
        PcaMethod::Svd,
        PcaMethod::Gram,
        PcaMethod::Covariance,
        PcaMethod::Randomized(RandomizedParams {
            tolerance: 1e-14,
            ..Default::default()
        }),
    ] {
        let components = if matches!(method, PcaMethod::Randomized(_)) {
            ComponentCount::Fixed(6)
        } else {
            ComponentCount::All
        };
        let p = pca(&x, method, components);
        for i in 0..6 {
            assert_close(
                p.eigenvalues()[i],
                ref_vals[i],
                1e-9 * ref_vals[0],
                &format!("{method:?} eigenvalue {i}"),
            );
        }
    }
    // f32 input: the reference is the exact f64 value of each f32 minus the offset.
    let x32 = Mat::<f32>::from_fn(300, 6, |i, j| (zc[(i, j)] * 50.0 + OFFSET) as f32);
    let s32 = Mat::from_fn(300, 6, |i, j| f64::from(x32[(i, j)]) - OFFSET);
    let (ref32, _) = jacobi_eigen(&covariance(&s32));
    let p = Pca::fit(
        x32.as_ref(),
        &PcaParams {
            method: PcaMethod::Gram,
            ..Default::default()
        },
    )
    .unwrap();
    for i in 0..p.n_components() {
        assert_close(
            p.eigenvalues()[i],
            ref32[i],
            1e-9 * ref32[0],
            "f32 eigenvalue",
        );
    }
    // k-means and local PCA see the same problem as on the shifted data.
    let a = KMeans::fit(x.as_ref(), &kmeans_params(4)).unwrap();
    let b = KMeans::fit(shifted.as_ref(), &kmeans_params(4)).unwrap();
    assert_eq!(a.labels(), b.labels());
    assert_close(a.inertia(), b.inertia(), 1e-9 * b.inertia(), "inertia");
    let brute: f64 = (0..300)
        .map(|i| {
            sq_dist(
                &row(&shifted, i),
                &a.center(a.labels()[i])
                    .iter()
                    .map(|c| c - OFFSET)
                    .collect::<Vec<_>>(),
            )
        })
        .sum();
    assert_close(
        a.inertia(),
        brute,
        1e-8 * brute,
        "inertia vs f64 brute force on shifted data",
    );
    let la = LocalPca::fit(x.as_ref(), &lpca_params(3, 1)).unwrap();
    let lb = LocalPca::fit(shifted.as_ref(), &lpca_params(3, 1)).unwrap();
    assert_eq!(la.labels(), lb.labels());
    assert_close(
        la.mean_error(),
        lb.mean_error(),
        1e-8 * lb.mean_error(),
        "local PCA error",
    );
}

/// A source that injects a value at one element.
struct Poisoned {
    x: Mat<f64>,
}

impl ColumnBlockSource for Poisoned {
    fn n_samples(&self) -> usize {
        self.x.nrows()
    }
    fn n_features(&self) -> usize {
        self.x.ncols()
    }
    fn read_features(
        &mut self,
        f: std::ops::Range<usize>,
        out: &mut [f64],
    ) -> Result<(), SourceError> {
        let n = self.x.nrows();
        for (jj, j) in f.enumerate() {
            for i in 0..n {
                out[jj * n + i] = self.x[(i, j)];
            }
        }
        Ok(())
    }
}

#[track_caller]
fn assert_non_finite<T: std::fmt::Debug>(r: Result<T, ClusteringError>, row: usize, col: usize) {
    match r {
        Err(ClusteringError::NonFinite {
            row: r,
            col: c,
            value,
            ..
        }) => {
            assert_eq!((r, c), (row, col));
            assert!(!value.is_finite());
        }
        other => panic!("expected NonFinite at ({row}, {col}), got {other:?}"),
    }
}

#[test]
fn nan_or_infinite_input_is_an_error_not_a_panic() {
    let clean = gaussian(40, 9, 3, |_| 1.0);
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut x = clean.clone();
        x[(17, 5)] = bad;
        for method in [
            PcaMethod::Auto,
            PcaMethod::Svd,
            PcaMethod::Gram,
            PcaMethod::Covariance,
            PcaMethod::Randomized(RandomizedParams::default()),
        ] {
            let c = if matches!(method, PcaMethod::Randomized(_)) {
                ComponentCount::Fixed(2)
            } else {
                ComponentCount::All
            };
            assert_non_finite(
                Pca::fit(
                    x.as_ref(),
                    &PcaParams {
                        components: c,
                        method,
                        seed: 0,
                    },
                ),
                17,
                5,
            );
        }
        assert_non_finite(
            Pca::fit_streaming(&mut Poisoned { x: x.clone() }, &PcaParams::default()),
            17,
            5,
        );
        let x32 = Mat::<f32>::from_fn(40, 9, |i, j| x[(i, j)] as f32);
        assert_non_finite(Pca::fit(x32.as_ref(), &PcaParams::default()), 17, 5);
        let fitted = Pca::fit(clean.as_ref(), &PcaParams::default()).unwrap();
        assert_non_finite(fitted.project(x.as_ref()), 17, 5);
        assert_non_finite(fitted.squared_error(x.as_ref()), 17, 5);
        assert_non_finite(KMeans::fit(x.as_ref(), &kmeans_params(3)), 17, 5);
        let km = KMeans::fit(clean.as_ref(), &kmeans_params(3)).unwrap();
        assert_non_finite(km.predict(x.as_ref()), 17, 5);
        assert_non_finite(LocalPca::fit(x.as_ref(), &lpca_params(2, 2)), 17, 5);
        assert_non_finite(
            LocalPca::search_k(x.as_ref(), &lpca_params(2, 2), &KSearchParams::default()),
            17,
            5,
        );
        let mut given = Mat::zeros(3, 9);
        given[(1, 2)] = bad;
        let p = KMeansParams {
            init: KMeansInit::Given(given),
            ..kmeans_params(3)
        };
        assert_non_finite(KMeans::fit(clean.as_ref(), &p), 1, 2);
    }
}

#[test]
fn invalid_parameters_are_errors() {
    let x = gaussian(10, 4, 4, |_| 1.0);
    let empty = Mat::<f64>::zeros(0, 4);
    assert!(matches!(
        Pca::fit(empty.as_ref(), &PcaParams::default()),
        Err(ClusteringError::TooFewSamples { .. })
    ));
    assert!(matches!(
        KMeans::fit(x.as_ref(), &kmeans_params(0)),
        Err(ClusteringError::InvalidParameter { name: "k", .. })
    ));
    assert!(matches!(
        KMeans::fit(x.as_ref(), &kmeans_params(11)),
        Err(ClusteringError::TooManyClusters {
            k: 11,
            samples: 10,
            ..
        })
    ));
    let nan_tol = KMeansParams {
        tolerance: f64::NAN,
        ..kmeans_params(2)
    };
    assert!(KMeans::fit(x.as_ref(), &nan_tol).is_err());
    assert!(matches!(
        LocalPca::fit(x.as_ref(), &lpca_params(2, 5)),
        Err(ClusteringError::InvalidParameter {
            name: "components",
            ..
        })
    ));
    let frac = PcaParams {
        components: ComponentCount::EnergyFraction(1.5),
        ..Default::default()
    };
    assert!(Pca::fit(x.as_ref(), &frac).is_err());
    let rand_all = PcaParams {
        method: PcaMethod::Randomized(RandomizedParams::default()),
        ..Default::default()
    };
    assert!(Pca::fit(x.as_ref(), &rand_all).is_err());
    let stream_svd = PcaParams {
        method: PcaMethod::Svd,
        ..Default::default()
    };
    assert!(Pca::fit_streaming(&mut Poisoned { x: x.clone() }, &stream_svd).is_err());
    let msg = KMeans::fit(x.as_ref(), &kmeans_params(11))
        .unwrap_err()
        .to_string();
    assert!(
        msg.contains("k = 11") && msg.contains("10 samples"),
        "{msg}"
    );
}

#[test]
fn single_sample_and_k_equal_to_n() {
    let one = Mat::from_fn(1, 5, |_, j| j as f64);
    let p = pca(&one, PcaMethod::Auto, ComponentCount::All);
    assert_eq!(p.n_components(), 0);
    assert_eq!(p.mean(), &[0.0, 1.0, 2.0, 3.0, 4.0]);
    assert_eq!(
        KMeans::fit(one.as_ref(), &kmeans_params(1))
            .unwrap()
            .inertia(),
        0.0
    );
    assert_eq!(
        LocalPca::fit(one.as_ref(), &lpca_params(1, 2))
            .unwrap()
            .mean_error(),
        0.0
    );
    let x = gaussian(12, 3, 5, |_| 1.0);
    let km = KMeans::fit(x.as_ref(), &kmeans_params(12)).unwrap();
    assert!(km.inertia() <= 1e-28, "{}", km.inertia());
    assert!(km.cluster_sizes().iter().all(|&s| s == 1));
}

#[test]
fn extreme_aspect_ratios_f_much_smaller_and_larger_than_v() {
    for (n, d) in [(3, 5000), (5000, 3), (2, 2)] {
        let x = gaussian(n, d, 6, |j| 1.0 + (j % 3) as f64);
        let reference = pca(&x, PcaMethod::Svd, ComponentCount::All);
        let auto = pca(&x, PcaMethod::Auto, ComponentCount::All);
        assert_eq!(auto.n_components(), reference.n_components(), "{n}×{d}");
        for i in 0..auto.n_components() {
            assert_close(
                auto.eigenvalues()[i],
                reference.eigenvalues()[i],
                1e-10 * reference.eigenvalues()[0],
                "eigenvalue",
            );
            assert_close(
                dot(auto.component(i), reference.component(i)),
                1.0,
                1e-8,
                "axis",
            );
        }
    }
}

#[test]
fn zero_components_local_pca_is_the_kmeans_objective() {
    let (x, _) = blobs(&[40, 50, 60], 4, 1.0, 30.0, 8);
    let l = LocalPca::fit(x.as_ref(), &lpca_params(3, 0)).unwrap();
    let km = KMeans::fit(x.as_ref(), &kmeans_params(3)).unwrap();
    assert!(same_partition(l.labels(), km.labels()));
    assert_close(
        l.mean_error() * 150.0,
        km.inertia(),
        1e-10 * km.inertia(),
        "c = 0 error is E of eq. 2.54",
    );
    assert_eq!(l.weights().ncols(), 0);
}

#[test]
fn results_are_deterministic_for_a_seed() {
    let (x, _) = blobs(&[300, 200, 500], 12, 3.0, 6.0, 9);
    for init in [KMeansInit::PlusPlus, KMeansInit::RandomSamples] {
        let p = KMeansParams {
            init,
            ..kmeans_params(7)
        };
        let a = KMeans::fit(x.as_ref(), &p).unwrap();
        let b = KMeans::fit(x.as_ref(), &p).unwrap();
        assert_eq!(a.labels(), b.labels());
        assert_eq!(a.inertia_history(), b.inertia_history());
    }
    let r = PcaParams {
        components: ComponentCount::Fixed(3),
        method: PcaMethod::Randomized(RandomizedParams::default()),
        seed: 3,
    };
    let (a, b) = (
        Pca::fit(x.as_ref(), &r).unwrap(),
        Pca::fit(x.as_ref(), &r).unwrap(),
    );
    assert_eq!(a.components(), b.components());
    for init in [LocalPcaInit::KMeans, LocalPcaInit::RandomSamples] {
        let p = LocalPcaParams {
            init,
            ..lpca_params(4, 2)
        };
        let (a, b) = (
            LocalPca::fit(x.as_ref(), &p).unwrap(),
            LocalPca::fit(x.as_ref(), &p).unwrap(),
        );
        assert_eq!(a.labels(), b.labels());
        assert_eq!(a.error_history(), b.error_history());
        assert_eq!(a.weights(), b.weights());
    }
}
