//! PCA: defining identities and comparison with an independent f64 reference.

mod common;

use clustering::{
    ColumnBlockSource, ComponentCount, Pca, PcaMethod, PcaParams, RandomizedParams, SourceError,
};
use common::*;
use faer::Mat;

const EPS: f64 = f64::EPSILON;

fn fit(x: &Mat<f64>, method: PcaMethod, components: ComponentCount) -> Pca {
    Pca::fit(
        x.as_ref(),
        &PcaParams {
            components,
            method,
            seed: 7,
        },
    )
    .expect("fit")
}

/// Components orthonormal to ε·f(d, c), times κ² = (λ₁/λ_c) for the cross-product paths,
/// whose axes come from a squared matrix (the documented precision of the Gram trick).
#[track_caller]
fn assert_orthonormal(p: &Pca) {
    let c = p.n_components();
    let d = p.n_features() as f64;
    let kappa2 = match p.method() {
        PcaMethod::Svd => 1.0,
        _ => p.eigenvalues()[0] / p.eigenvalues()[c - 1],
    };
    for a in 0..c {
        for b in 0..c {
            let want = if a == b { 1.0 } else { 0.0 };
            assert_close(
                dot(p.component(a), p.component(b)),
                want,
                64.0 * EPS * d.sqrt() * c as f64 * kappa2,
                "VᵀV",
            );
        }
    }
}

#[test]
fn all_components_reconstruct_the_input_on_every_path() {
    let cases = [
        (
            Mat::from_fn(30, 8, |i, j| {
                ((i * 7 + j * 3) % 11) as f64 + 0.1 * j as f64 * i as f64
            }),
            PcaMethod::Svd,
        ),
        (low_rank(12, 300, 5, 0.01, 1), PcaMethod::Gram),
        (low_rank(400, 6, 3, 0.1, 2), PcaMethod::Covariance),
        (low_rank(40, 30, 4, 0.05, 3), PcaMethod::Auto),
    ];
    for (x, method) in cases {
        let p = fit(&x, method, ComponentCount::All);
        let w = p.project(x.as_ref()).unwrap();
        let back = p.reconstruct(w.as_ref()).unwrap();
        let scale = max_abs(x.as_ref());
        let (n, d) = (x.nrows() as f64, x.ncols() as f64);
        let tol = 1e3 * EPS * scale * (n * d).sqrt();
        let err = max_abs_diff(back.as_ref(), x.as_ref());
        assert!(
            err <= tol,
            "{method:?}: reconstruction error {err:e} > {tol:e}"
        );
        assert_orthonormal(&p);
    }
}

#[test]
fn eigenpairs_match_a_jacobi_reference_on_every_path() {
    let x = gaussian(60, 6, 11, |j| 1.0 + j as f64);
    let (ref_vals, ref_vecs) = jacobi_eigen(&covariance(&x));
    for method in [PcaMethod::Svd, PcaMethod::Gram, PcaMethod::Covariance] {
        let p = fit(&x, method, ComponentCount::All);
        assert_eq!(p.n_components(), 6, "{method:?}");
        for i in 0..6 {
            assert_close(
                p.eigenvalues()[i],
                ref_vals[i],
                1e-10 * ref_vals[0],
                "eigenvalue",
            );
            let r = col(ref_vecs.as_ref(), i);
            assert_close(dot(p.component(i), &r).abs(), 1.0, 1e-8, "axis alignment");
        }
        assert_close(
            p.total_variance(),
            ref_vals.iter().sum(),
            1e-12 * ref_vals[0] * 6.0,
            "trace",
        );
    }
}

#[test]
fn sign_convention_largest_entry_positive() {
    let x = low_rank(50, 12, 4, 0.1, 5);
    for method in [PcaMethod::Svd, PcaMethod::Gram, PcaMethod::Covariance] {
        let p = fit(&x, method, ComponentCount::All);
        for i in 0..p.n_components() {
            let v = p.component(i);
            let (imax, _) =
                v.iter().enumerate().fold(
                    (0, -1.0),
                    |b, (k, x)| if x.abs() > b.1 { (k, x.abs()) } else { b },
                );
            assert!(v[imax] > 0.0, "{method:?} component {i}");
        }
    }
}

#[test]
fn squared_error_equals_discarded_variance() {
    // Σ‖x − x̃‖² = (n − 1) Σ_{i>c} λᵢ: the optimality identity of PCA.
    let x = gaussian(80, 10, 3, |j| 0.5 + j as f64 * 0.3);
    let full = fit(&x, PcaMethod::Svd, ComponentCount::All);
    for c in [0, 1, 4, 9, 10] {
        let p = fit(&x, PcaMethod::Svd, ComponentCount::Fixed(c));
        let discarded: f64 = full.eigenvalues()[c..].iter().sum::<f64>() * 79.0;
        let err = p.squared_error(x.as_ref()).unwrap();
        assert_close(
            err,
            discarded,
            1e-11 * full.total_variance() * 79.0,
            "discarded variance",
        );
    }
}

#[test]
fn all_paths_agree() {
    let x = low_rank(150, 120, 8, 0.05, 9);
    let reference = fit(&x, PcaMethod::Svd, ComponentCount::Fixed(6));
    let randomized = PcaMethod::Randomized(RandomizedParams {
        tolerance: 1e-12,
        ..Default::default()
    });
    for method in [PcaMethod::Gram, PcaMethod::Covariance, randomized] {
        let p = fit(&x, method, ComponentCount::Fixed(6));
        for i in 0..6 {
            assert_close(
                p.eigenvalues()[i],
                reference.eigenvalues()[i],
                1e-9 * reference.eigenvalues()[0],
                "eigenvalue",
            );
            assert_close(
                dot(p.component(i), reference.component(i)),
                1.0,
                1e-7,
                "same axis and sign",
            );
        }
    }
}

#[test]
fn f32_input_gives_the_f64_result_of_the_same_values() {
    let x = low_rank(20, 700, 4, 0.1, 4);
    let x32 = Mat::<f32>::from_fn(20, 700, |i, j| x[(i, j)] as f32);
    let x64 = Mat::<f64>::from_fn(20, 700, |i, j| f64::from(x32[(i, j)]));
    for method in [PcaMethod::Gram, PcaMethod::Svd] {
        let params = PcaParams {
            method,
            ..Default::default()
        };
        let a = Pca::fit(x32.as_ref(), &params).unwrap();
        let b = Pca::fit(x64.as_ref(), &params).unwrap();
        assert_eq!(a.eigenvalues(), b.eigenvalues(), "{method:?}");
        assert_eq!(a.components(), b.components());
    }
}

#[test]
fn row_major_and_column_major_views_give_identical_results() {
    let x = low_rank(30, 50, 3, 0.1, 8);
    let data: Vec<f64> = (0..30)
        .flat_map(|i| (0..50).map(move |j| (i, j)))
        .map(|(i, j)| x[(i, j)])
        .collect();
    let rm = faer::MatRef::from_row_major_slice(&data, 30, 50);
    let a = Pca::fit(rm, &PcaParams::default()).unwrap();
    let b = Pca::fit(x.as_ref(), &PcaParams::default()).unwrap();
    assert_eq!(a.eigenvalues(), b.eigenvalues());
    assert_eq!(a.components(), b.components());
}

/// A column-block source over an in-memory matrix, counting reads.
struct VecSource {
    x: Mat<f64>,
    reads: usize,
}

impl ColumnBlockSource for VecSource {
    fn n_samples(&self) -> usize {
        self.x.nrows()
    }
    fn n_features(&self) -> usize {
        self.x.ncols()
    }
    fn read_features(
        &mut self,
        features: std::ops::Range<usize>,
        out: &mut [f64],
    ) -> Result<(), SourceError> {
        let n = self.x.nrows();
        for (jj, j) in features.enumerate() {
            for i in 0..n {
                out[jj * n + i] = self.x[(i, j)];
            }
        }
        self.reads += 1;
        Ok(())
    }
}

#[test]
fn streaming_is_bit_identical_to_in_memory_gram() {
    let x = low_rank(9, 5000, 4, 0.2, 12);
    let params = PcaParams {
        components: ComponentCount::Fixed(5),
        method: PcaMethod::Gram,
        seed: 0,
    };
    let a = Pca::fit(x.as_ref(), &params).unwrap();
    let mut src = VecSource {
        x: x.clone(),
        reads: 0,
    };
    let b = Pca::fit_streaming(&mut src, &params).unwrap();
    assert_eq!(a.mean(), b.mean());
    assert_eq!(a.eigenvalues(), b.eigenvalues());
    assert_eq!(a.components(), b.components());
    assert_eq!(
        src.reads,
        2 * 5000usize.div_ceil(512),
        "two passes of 512-feature blocks"
    );
}

#[test]
fn component_count_rules() {
    // Spectrum 5, 3, 1, 0.5, 0.5: total 10.
    let l = [5.0, 3.0, 1.0, 0.5, 0.5];
    assert_eq!(ComponentCount::All.select(&l, 5, 10.0, 5), 5);
    assert_eq!(ComponentCount::All.select(&l, 3, 10.0, 5), 3, "rank caps");
    assert_eq!(ComponentCount::Fixed(2).select(&l, 5, 10.0, 5), 2);
    assert_eq!(
        ComponentCount::EnergyFraction(0.8).select(&l, 5, 10.0, 5),
        2
    );
    assert_eq!(
        ComponentCount::EnergyFraction(0.81).select(&l, 5, 10.0, 5),
        3
    );
    assert_eq!(
        ComponentCount::EnergyFraction(1.0).select(&l, 5, 10.0, 5),
        5
    );
    // eq. 2.52: λ̄ = 10 / 5 = 2, eq. 2.53 discards 1, 0.5, 0.5.
    assert_eq!(
        ComponentCount::AboveMeanEigenvalue.select(&l, 5, 10.0, 5),
        2
    );
}

#[test]
fn energy_fraction_and_mean_rule_on_real_fits() {
    let x = gaussian(500, 8, 21, |j| 8.0 / (1 << j) as f64);
    let p = fit(&x, PcaMethod::Auto, ComponentCount::EnergyFraction(0.9));
    let r = p.explained_variance_ratio();
    let kept: f64 = r.iter().sum();
    assert!(
        kept >= 0.9 && kept - r[r.len() - 1] < 0.9,
        "fewest components reaching 90 %: {r:?}"
    );
    let m = fit(&x, PcaMethod::Auto, ComponentCount::AboveMeanEigenvalue);
    let mean = m.total_variance() / 8.0;
    assert!(m.eigenvalues().iter().all(|&l| l >= mean));
    assert!(m.spectrum()[m.n_components()] < mean);
    let all = fit(&x, PcaMethod::Auto, ComponentCount::All);
    assert_close(
        all.explained_variance_ratio().iter().sum(),
        1.0,
        1e-12,
        "ratios sum to 1",
    );
}

#[test]
fn randomized_matches_exact_leading_components() {
    let x = low_rank(600, 400, 30, 0.01, 31);
    let exact = fit(&x, PcaMethod::Svd, ComponentCount::Fixed(10));
    let r = fit(
        &x,
        PcaMethod::Randomized(RandomizedParams {
            tolerance: 1e-10,
            ..Default::default()
        }),
        ComponentCount::Fixed(10),
    );
    let e_exact = exact.squared_error(x.as_ref()).unwrap();
    let e_r = r.squared_error(x.as_ref()).unwrap();
    assert!(
        e_r <= e_exact * (1.0 + 1e-8),
        "randomized error {e_r} vs exact {e_exact}"
    );
    for i in 0..10 {
        assert_close(
            r.eigenvalues()[i],
            exact.eigenvalues()[i],
            1e-8 * exact.eigenvalues()[0],
            "eigenvalue",
        );
    }
}

#[test]
fn project_checks_dimensions() {
    let x = gaussian(20, 4, 1, |_| 1.0);
    let p = fit(&x, PcaMethod::Auto, ComponentCount::All);
    let wrong = gaussian(3, 5, 2, |_| 1.0);
    assert!(matches!(
        p.project(wrong.as_ref()),
        Err(clustering::ClusteringError::DimensionMismatch {
            expected: 4,
            found: 5,
            ..
        })
    ));
    let too_many = Mat::<f64>::zeros(3, 5);
    assert!(p.reconstruct(too_many.as_ref()).is_err());
}

#[test]
fn truncate_keeps_leading_components() {
    let x = gaussian(40, 6, 4, |j| 1.0 + j as f64);
    let mut p = fit(&x, PcaMethod::Svd, ComponentCount::All);
    let full = p.clone();
    p.truncate(2);
    assert_eq!(p.n_components(), 2);
    assert_eq!(p.component(1), full.component(1));
}
