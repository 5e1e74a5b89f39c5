//! Clustered (local) PCA, thesis §2.7.4 "Clustered Principal Component Analysis" and §3.3.2
//! (Kambhatla & Leen 1997), steps 1–5:
//!
//! 1. initialise k centers rⱼ with random samples and c unit basis vectors eᵢⱼ per cluster
//!    ([`LocalPcaInit::RandomSamples`], as published), or from k-means
//!    ([`LocalPcaInit::KMeans`]: k-means++ and Lloyd, then one PCA per cluster);
//! 2. assign every sample to the cluster of least squared reconstruction error
//!    ‖x − rⱼ − Σᵢ⟨x − rⱼ, eᵢⱼ⟩eᵢⱼ‖²;
//! 3. new centers rⱼ = mean of region j;
//! 4. new basis per region by PCA;
//! 5. iterate 2–4 until the relative change of the average reconstruction error falls to
//!    `tolerance` (or the assignment is stable, or `max_iterations`).
//!
//! Deviations, each for a stated reason: the weights are taken about the cluster mean,
//! x ≈ rⱼ + Σᵢ wᵢ eᵢⱼ with wᵢ = ⟨x − rⱼ, eᵢⱼ⟩ (eq. 3.15 writes ⟨Tₘ, E⟩ without the mean, which
//! is only exact for centred clusters); a region left empty by step 2 takes the worst-served
//! sample (otherwise it would stay dead); the loop ends after an assignment, so the returned
//! labels are optimal for the returned bases and the reported errors are consistent.

mod assign;
mod model;
mod search;
mod update;

pub use search::{KSearch, KSearchParams, KSearchStep, KSearchStop};

use faer::{Mat, MatRef};

use crate::element::{Element, Samples, check_shape};
use crate::error::{ClusteringError, Result};
use crate::kmeans::{KMeans, KMeansInit, KMeansParams, initial_centers, random_samples};
use crate::linalg::rng;
use assign::{Codes, assign, exact_codes};
use model::Model;
use update::{RegionPca, empty_model, random_bases, update};

/// Random stream of the random-sample initialisation.
const STREAM_INIT: u64 = 0x4c49_4e49; // "LINI"

/// How step 1 initialises the clusters.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum LocalPcaInit {
    /// k-means (k-means++ seeding, Lloyd to convergence), then one PCA per cluster. Usually
    /// converges faster and lower than the published start.
    #[default]
    KMeans,
    /// As published: k random samples as centers and c random orthonormal vectors per cluster.
    RandomSamples,
}

/// Parameters of [`LocalPca::fit`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalPcaParams {
    /// Number of clusters k (1 ≤ k ≤ n).
    pub k: usize,
    /// Basis vectors per cluster c (≤ d).
    pub components: usize,
    /// Initialisation (step 1).
    pub init: LocalPcaInit,
    /// Cap on iterations of steps 2–4.
    pub max_iterations: usize,
    /// Step 5: stop when |ē_{t−1} − ē_t| ≤ tolerance · ē_{t−1} for the mean error ē.
    pub tolerance: f64,
    /// Extra columns p of the per-cluster subspace iteration (see [`crate::RandomizedParams`]).
    pub oversample: usize,
    /// Per-cluster PCA accuracy: subspace iteration stops when a step improves the captured
    /// energy by less than this fraction of the cluster's residual energy.
    pub subspace_tolerance: f64,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for LocalPcaParams {
    /// k = 10 and c = 20 (the thesis's chicken setting, Fig. 3.12, with a typical c), k-means
    /// start, 100 iterations, tolerance 1e-4 on the mean error, per-cluster PCA converged to
    /// 1e-6 of the residual energy with 10 extra columns.
    fn default() -> Self {
        Self {
            k: 10,
            components: 20,
            init: LocalPcaInit::KMeans,
            max_iterations: 100,
            tolerance: 1e-4,
            oversample: 10,
            subspace_tolerance: 1e-6,
            seed: 0,
        }
    }
}

/// A fitted local PCA: labels, per-cluster means, bases and eigenvalues, per-sample weights
/// and errors, and the error history.
#[derive(Clone, Debug)]
pub struct LocalPca {
    /// d × k, original coordinates.
    means: Mat<f64>,
    bases: Vec<Mat<f64>>,
    eigenvalues: Vec<Vec<f64>>,
    labels: Vec<usize>,
    /// c × n (column i = weights of sample i).
    weights: Mat<f64>,
    errors: Vec<f64>,
    history: Vec<f64>,
    iterations: usize,
    converged: bool,
    sizes: Vec<usize>,
}

const WHAT: &str = "LocalPca::fit data";

impl LocalPca {
    /// Runs clustered PCA on the rows of `data` (n × d, f32 or f64).
    ///
    /// # Errors
    /// [`ClusteringError::TooFewSamples`], [`ClusteringError::NonFinite`],
    /// [`ClusteringError::TooManyClusters`] (k > n), [`ClusteringError::InvalidParameter`]
    /// (k = 0, c > d, negative tolerances), [`ClusteringError::NoConvergence`].
    ///
    /// # Examples
    /// ```
    /// use clustering::{LocalPca, LocalPcaParams};
    /// // Two parallel lines 20 apart: one mean + one axis per cluster reproduce them exactly.
    /// let data = faer::Mat::from_fn(20, 2, |i, j| if j == 0 { (i % 10) as f64 } else { (i / 10) as f64 * 20.0 });
    /// let p = LocalPcaParams { k: 2, components: 1, ..Default::default() };
    /// let l = LocalPca::fit(data.as_ref(), &p).unwrap();
    /// assert!(l.mean_error() < 1e-20);
    /// assert_ne!(l.labels()[0], l.labels()[10]);
    /// ```
    pub fn fit<T: Element>(data: MatRef<'_, T>, params: &LocalPcaParams) -> Result<Self> {
        check_shape(WHAT, data.nrows(), data.ncols(), 1)?;
        validate(params, data.nrows(), data.ncols())?;
        let x = Samples::new(WHAT, data)?;
        Self::fit_samples(&x, params)
    }

    pub(crate) fn fit_samples(x: &Samples, p: &LocalPcaParams) -> Result<Self> {
        let (n, d, k, c) = (x.n, x.d, p.k, p.components);
        let region = RegionPca {
            oversample: p.oversample,
            tolerance: p.subspace_tolerance,
            seed: p.seed,
        };
        let mut model = empty_model(d, c, k);
        match p.init {
            LocalPcaInit::RandomSamples => {
                model.means = random_samples(x, k, &mut rng(p.seed, STREAM_INIT));
                random_bases(&mut model, p.seed);
            }
            LocalPcaInit::KMeans => {
                let kp = KMeansParams {
                    k,
                    init: KMeansInit::PlusPlus,
                    seed: p.seed,
                    ..KMeansParams::default()
                };
                let km =
                    KMeans::lloyd(x, initial_centers(x, &kp)?, kp.max_iterations, kp.tolerance);
                // Empty k-means clusters (fewer distinct points than k) keep their center.
                for j in 0..k {
                    let dst = &mut model.means[j * d..(j + 1) * d];
                    dst.iter_mut()
                        .zip(km.center(j))
                        .zip(&x.offset)
                        .for_each(|((m, c), o)| *m = c - o);
                }
                update(x, km.labels(), &mut model, region, 0)?;
            }
        }
        let mut codes = Codes::new(n, c);
        let mut err = assign(x, &model, &mut codes);
        let mut history = vec![err];
        let mut prev = vec![0usize; n];
        let (mut iterations, mut converged) = (0, false);
        while iterations < p.max_iterations {
            reseed_empty(&mut codes, k);
            iterations += 1;
            update(x, &codes.labels, &mut model, region, iterations)?;
            prev.copy_from_slice(&codes.labels);
            let e = assign(x, &model, &mut codes);
            history.push(e);
            let stable = codes.labels == prev;
            let small = (err - e).abs() <= p.tolerance * err;
            err = e;
            if stable || small {
                converged = true;
                break;
            }
        }
        exact_codes(x, &model, &mut codes);
        Ok(Self::from_model(
            x, model, codes, history, iterations, converged,
        ))
    }

    fn from_model(
        x: &Samples,
        m: Model,
        codes: Codes,
        history: Vec<f64>,
        iterations: usize,
        converged: bool,
    ) -> Self {
        let (n, d, c, k) = (x.n, x.d, m.c, m.k());
        let stride = c.max(1);
        let means = Mat::from_fn(d, k, |i, j| m.mean(j)[i] + x.offset[i]);
        let weights = Mat::from_fn(c, n, |l, i| codes.weights[i * stride + l]);
        let mut sizes = vec![0usize; k];
        codes.labels.iter().for_each(|&l| sizes[l] += 1);
        Self {
            means,
            bases: m.bases,
            eigenvalues: m.eigenvalues,
            labels: codes.labels,
            weights,
            errors: codes.errors,
            history,
            iterations,
            converged,
            sizes,
        }
    }

    /// Number of clusters k.
    pub fn k(&self) -> usize {
        self.bases.len()
    }

    /// Basis vectors per cluster c.
    pub fn n_components(&self) -> usize {
        self.weights.nrows()
    }

    /// Number of features d.
    pub fn n_features(&self) -> usize {
        self.means.nrows()
    }

    /// Cluster index of every sample (the thesis's index Iₘ).
    pub fn labels(&self) -> &[usize] {
        &self.labels
    }

    /// Samples per cluster.
    pub fn cluster_sizes(&self) -> &[usize] {
        &self.sizes
    }

    /// Cluster means as a k × d matrix (original coordinates).
    pub fn means(&self) -> MatRef<'_, f64> {
        self.means.as_ref().transpose()
    }

    /// Mean rⱼ of cluster `j`.
    ///
    /// # Panics
    /// If `j ≥ k`.
    pub fn mean(&self, j: usize) -> &[f64] {
        self.means.col_as_slice(j)
    }

    /// Basis of cluster `j` as d × c columns (orthonormal, zero beyond the cluster's rank;
    /// the thesis's eigentrajectories).
    ///
    /// # Panics
    /// If `j ≥ k`.
    pub fn basis(&self, j: usize) -> MatRef<'_, f64> {
        self.bases[j].as_ref()
    }

    /// Eigenvalues of cluster `j`'s covariance for its c axes (descending, 0 beyond its rank).
    ///
    /// # Panics
    /// If `j ≥ k`.
    pub fn eigenvalues(&self, j: usize) -> &[f64] {
        &self.eigenvalues[j]
    }

    /// Weights of every sample in its cluster's basis: n × c.
    pub fn weights(&self) -> MatRef<'_, f64> {
        self.weights.as_ref().transpose()
    }

    /// Weights of sample `i` (length c).
    ///
    /// # Panics
    /// If `i ≥ n`.
    pub fn weight(&self, i: usize) -> &[f64] {
        self.weights.col_as_slice(i)
    }

    /// Squared reconstruction error of every sample, from explicit residuals.
    pub fn sample_errors(&self) -> &[f64] {
        &self.errors
    }

    /// Mean squared reconstruction error over samples (the quantity of step 5).
    pub fn mean_error(&self) -> f64 {
        self.errors.iter().sum::<f64>() / self.errors.len().max(1) as f64
    }

    /// Mean error after the initial assignment and after every iteration of steps 2–4.
    pub fn error_history(&self) -> &[f64] {
        &self.history
    }

    /// Iterations of steps 2–4 run.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    /// Whether step 5's rule (or a stable assignment) stopped the loop.
    pub fn converged(&self) -> bool {
        self.converged
    }

    /// Scalars a compressed representation stores: k·d·(c + 1) for means and bases plus n·c
    /// weights (labels not counted).
    pub fn model_scalars(&self) -> usize {
        model_scalars(
            self.k(),
            self.n_features(),
            self.n_components(),
            self.labels.len(),
        )
    }

    /// Reconstructs sample `i`: rⱼ + Eⱼ wᵢ into `out` (length d).
    ///
    /// # Panics
    /// If `i ≥ n` or `out.len() ≠ d`.
    pub fn reconstruct_sample(&self, i: usize, out: &mut [f64]) {
        assert_eq!(
            out.len(),
            self.n_features(),
            "reconstruct_sample: output length"
        );
        let j = self.labels[i];
        out.copy_from_slice(self.mean(j));
        for (l, w) in self.weight(i).iter().enumerate() {
            out.iter_mut()
                .zip(self.bases[j].col_as_slice(l))
                .for_each(|(o, e)| *o += w * e);
        }
    }

    /// All reconstructed samples, n × d.
    pub fn reconstruct(&self) -> Mat<f64> {
        let (n, d) = (self.labels.len(), self.n_features());
        let mut t = Mat::<f64>::zeros(d, n);
        for i in 0..n {
            self.reconstruct_sample(i, t.col_as_slice_mut(i));
        }
        t.transpose().to_owned()
    }
}

/// k·d·(c + 1) + n·c.
pub(crate) fn model_scalars(k: usize, d: usize, c: usize, n: usize) -> usize {
    k * d * (c + 1) + n * c
}

/// Moves the worst-served samples (largest error > 0, from clusters with > 1 member) into
/// empty clusters, worst first.
fn reseed_empty(codes: &mut Codes, k: usize) {
    let mut counts = vec![0usize; k];
    codes.labels.iter().for_each(|&l| counts[l] += 1);
    let empty: Vec<usize> = (0..k).filter(|&j| counts[j] == 0).collect();
    if empty.is_empty() {
        return;
    }
    let mut order: Vec<usize> = (0..codes.labels.len())
        .filter(|&i| codes.errors[i] > 0.0)
        .collect();
    order.sort_by(|&a, &b| codes.errors[b].total_cmp(&codes.errors[a]).then(a.cmp(&b)));
    let mut candidates = order.into_iter();
    for j in empty {
        let Some(i) = candidates.by_ref().find(|&i| counts[codes.labels[i]] > 1) else {
            break;
        };
        counts[codes.labels[i]] -= 1;
        counts[j] = 1;
        codes.labels[i] = j;
    }
}

pub(crate) fn validate(p: &LocalPcaParams, n: usize, d: usize) -> Result<()> {
    let bad = |name, value: String, reason| {
        Err(ClusteringError::InvalidParameter {
            what: WHAT,
            name,
            value,
            reason,
        })
    };
    if p.k == 0 {
        return bad("k", "0".into(), "k must be at least 1");
    }
    if p.k > n {
        return Err(ClusteringError::TooManyClusters {
            what: WHAT,
            k: p.k,
            samples: n,
        });
    }
    if p.components > d {
        return bad(
            "components",
            p.components.to_string(),
            "c must not exceed the number of features d",
        );
    }
    if p.tolerance.is_nan() || p.tolerance < 0.0 {
        return bad(
            "tolerance",
            p.tolerance.to_string(),
            "the tolerance must be a number ≥ 0",
        );
    }
    if p.subspace_tolerance.is_nan() || p.subspace_tolerance <= 0.0 {
        return bad(
            "subspace_tolerance",
            p.subspace_tolerance.to_string(),
            "the subspace tolerance must be a number > 0",
        );
    }
    Ok(())
}
