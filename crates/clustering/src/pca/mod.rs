//! Principal component analysis (thesis §2.7.2–2.7.3, eq. 2.45–2.53).
//!
//! Rows are samples, columns are features. The data is mean-centred (eq. 2.47) and the
//! eigenpairs of its covariance C = XcᵀXc / (n − 1) (eq. 2.46) are found by one of four paths
//! ([`PcaMethod`]): faer's thin SVD of Xc, the n × n Gram matrix when n ≪ d and the d × d
//! covariance when d ≪ n (both the thesis's "covariance matrix of the smaller side"), or
//! randomized subspace iteration for a few components of a large matrix. A streaming variant of
//! the Gram path ([`Pca::fit_streaming`]) decomposes matrices too large for memory.
//!
//! Conventions: eigenvalues λᵢ are those of C (divided by n − 1, 1 for a single sample), in
//! descending order; each principal axis is a unit column whose entry of largest magnitude is
//! positive; components below the numerical rank are dropped, so a fit may return fewer
//! components than asked for.

mod covariance;
mod gram;
mod project;
mod randomized;
mod select;
mod svd;

pub use gram::ColumnBlockSource;
pub use select::ComponentCount;

use faer::{Mat, MatRef};

use crate::element::{Element, check_shape};
use crate::error::{ClusteringError, Result};
use crate::linalg::{fix_signs, reorthonormalize, sym_eigen_desc};
use crate::subspace::Stop;
pub(crate) use select::{numerical_rank, raw_energy};

/// Auto picks a cross-product path when one side is at least this many times the other: the
/// small matrix then costs ≤ 1/4 of the SVD's QR and the thesis prescribes it.
const CROSS_PRODUCT_RATIO: usize = 4;
/// Auto picks the randomized path for `Fixed(c)` when min(n, d) ≥ this …
const AUTO_RANDOMIZED_MIN_DIM: usize = 2000;
/// … and c · this ≤ min(n, d).
const AUTO_RANDOMIZED_RATIO: usize = 10;

/// Knobs of the randomized path.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RandomizedParams {
    /// Extra columns p beyond c in the iterated block (Halko et al. suggest 5–10; more speeds
    /// convergence when λ_c ≈ λ_{c+1}).
    pub oversample: usize,
    /// Stop when one step improves the captured energy by less than this fraction of the
    /// residual energy.
    pub tolerance: f64,
    /// Cap on subspace steps (each one pass over the data).
    pub max_iterations: usize,
}

impl Default for RandomizedParams {
    fn default() -> Self {
        Self {
            oversample: 10,
            tolerance: 1e-6,
            max_iterations: 50,
        }
    }
}

/// Which decomposition [`Pca::fit`] uses.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum PcaMethod {
    /// Gram when d ≥ 4n, covariance when n ≥ 4d, randomized for `Fixed(c)` with a small c on a
    /// large matrix, thin SVD otherwise.
    #[default]
    Auto,
    /// Thin SVD of the centred copy (most accurate; copies the data as f64).
    Svd,
    /// Eigen-decomposition of the n × n Gram matrix, in column blocks (no copy).
    Gram,
    /// Eigen-decomposition of the d × d covariance, in row blocks (no copy).
    Covariance,
    /// Subspace iteration for `Fixed(c)` components, in row blocks (no copy).
    Randomized(RandomizedParams),
}

/// Parameters of [`Pca::fit`].
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct PcaParams {
    /// How many components to keep.
    pub components: ComponentCount,
    /// Which decomposition to use.
    pub method: PcaMethod,
    /// Seed of the randomized path's start block.
    pub seed: u64,
}

/// A fitted PCA: mean, principal axes and eigenvalues.
#[derive(Clone, Debug)]
pub struct Pca {
    mean: Vec<f64>,
    /// d × c, unit columns.
    components: Mat<f64>,
    eigenvalues: Vec<f64>,
    spectrum: Vec<f64>,
    total_variance: f64,
    n_samples: usize,
    rank: usize,
    method: PcaMethod,
}

const WHAT_FIT: &str = "Pca::fit data";

impl Pca {
    /// Fits a PCA to `data` (n × d, rows are samples; f32 or f64, any strides).
    ///
    /// # Errors
    /// [`ClusteringError::TooFewSamples`] for an empty matrix, [`ClusteringError::NonFinite`]
    /// for NaN/∞ entries, [`ClusteringError::InvalidParameter`] for a bad energy fraction or a
    /// randomized fit without `Fixed(c)`, [`ClusteringError::NoConvergence`] if faer fails.
    ///
    /// # Examples
    /// ```
    /// use clustering::{ComponentCount, Pca, PcaParams};
    /// // Three samples on the line y = 2x (rank 1).
    /// let data = faer::mat![[0.0, 0.0], [1.0, 2.0], [2.0, 4.0f64]];
    /// let pca = Pca::fit(data.as_ref(), &PcaParams::default()).unwrap();
    /// assert_eq!(pca.n_components(), 1);
    /// let axis = pca.component(0);
    /// assert!((axis[1] / axis[0] - 2.0).abs() < 1e-12);
    /// assert!((pca.eigenvalues()[0] - 5.0).abs() < 1e-12); // var along the line: 5·1
    /// ```
    pub fn fit<T: Element>(data: MatRef<'_, T>, params: &PcaParams) -> Result<Self> {
        let (n, d) = (data.nrows(), data.ncols());
        check_shape(WHAT_FIT, n, d, 1)?;
        params.components.validate(WHAT_FIT)?;
        let method = resolve(params, n, d)?;
        let dof = (n.max(2) - 1) as f64;
        match method {
            PcaMethod::Gram => {
                let pass = gram::gram_pass(WHAT_FIT, data)?;
                let (sigma2, u) = sym_eigen_desc(WHAT_FIT, pass.gram.as_ref())?;
                let fit = Self::select(
                    params.components,
                    pass.mean,
                    sigma2,
                    pass.sum_squares,
                    n,
                    d,
                    true,
                    method,
                );
                let w = gram_weights(&u, &fit.spectrum, fit.eigenvalues.len(), dof);
                let mut comps = gram::gram_components(WHAT_FIT, data, &fit.mean, w.as_ref())?;
                reorthonormalize(&mut comps);
                Ok(fit.with_components(comps))
            }
            PcaMethod::Covariance => {
                let pass = covariance::covariance_pass(WHAT_FIT, data)?;
                let (sigma2, v) = sym_eigen_desc(WHAT_FIT, pass.scatter.as_ref())?;
                let fit = Self::select(
                    params.components,
                    pass.mean,
                    sigma2,
                    pass.sum_squares,
                    n,
                    d,
                    true,
                    method,
                );
                let c = fit.eigenvalues.len();
                Ok(fit.with_components(v.as_ref().subcols(0, c).to_owned()))
            }
            PcaMethod::Svd | PcaMethod::Auto => {
                let centered = svd::centered_copy(WHAT_FIT, data)?;
                let (sigma2, v) = svd::svd_path(WHAT_FIT, &centered, n, d)?;
                let fit = Self::select(
                    params.components,
                    centered.mean,
                    sigma2,
                    centered.sum_squares,
                    n,
                    d,
                    false,
                    PcaMethod::Svd,
                );
                let c = fit.eigenvalues.len();
                Ok(fit.with_components(v.as_ref().subcols(0, c).to_owned()))
            }
            PcaMethod::Randomized(rp) => {
                let ComponentCount::Fixed(c) = params.components else {
                    unreachable!("resolve checks it")
                };
                let b = (c + rp.oversample).min(n.min(d)).max(c.min(n.min(d)));
                let stop = Stop {
                    tolerance: rp.tolerance,
                    max_steps: rp.max_iterations.max(1),
                };
                let r =
                    randomized::randomized(WHAT_FIT, data, c.min(b), b.max(1), stop, params.seed)?;
                let fit = Self::select(
                    params.components,
                    r.mean,
                    r.ritz.values,
                    r.sum_squares,
                    n,
                    d,
                    true,
                    method,
                );
                let c = fit.eigenvalues.len();
                Ok(fit.with_components(r.ritz.vectors.as_ref().subcols(0, c).to_owned()))
            }
        }
    }

    /// Fits a PCA to data delivered in column blocks by `source` (out-of-core; the Gram path).
    /// Memory: n² + d·(c + 1) f64 plus one n × 512 block per stripe; the source is read twice.
    /// The result is bit-identical to [`Pca::fit`] with [`PcaMethod::Gram`] on the same data.
    ///
    /// # Errors
    /// As [`Pca::fit`]; [`ClusteringError::Source`] when the source fails;
    /// [`ClusteringError::InvalidParameter`] when `params.method` is neither `Auto` nor `Gram`.
    pub fn fit_streaming(source: &mut dyn ColumnBlockSource, params: &PcaParams) -> Result<Self> {
        const WHAT: &str = "Pca::fit_streaming source";
        let (n, d) = (source.n_samples(), source.n_features());
        check_shape(WHAT, n, d, 1)?;
        params.components.validate(WHAT)?;
        if !matches!(params.method, PcaMethod::Auto | PcaMethod::Gram) {
            return Err(ClusteringError::InvalidParameter {
                what: WHAT,
                name: "method",
                value: format!("{:?}", params.method),
                reason: "streaming PCA uses the Gram path; pass PcaMethod::Auto or PcaMethod::Gram",
            });
        }
        let dof = (n.max(2) - 1) as f64;
        let pass = gram::gram_pass_streaming(WHAT, source)?;
        let (sigma2, u) = sym_eigen_desc(WHAT, pass.gram.as_ref())?;
        let fit = Self::select(
            params.components,
            pass.mean,
            sigma2,
            pass.sum_squares,
            n,
            d,
            true,
            PcaMethod::Gram,
        );
        let w = gram_weights(&u, &fit.spectrum, fit.eigenvalues.len(), dof);
        let mut comps = gram::gram_components_streaming(WHAT, source, &fit.mean, w.as_ref())?;
        reorthonormalize(&mut comps);
        Ok(fit.with_components(comps))
    }

    /// Rank, component count and eigenvalues from the squared singular values.
    #[allow(clippy::too_many_arguments)]
    fn select(
        rule: ComponentCount,
        mean: Vec<f64>,
        mut sigma2: Vec<f64>,
        sum_squares: f64,
        n: usize,
        d: usize,
        cross: bool,
        method: PcaMethod,
    ) -> Self {
        let dof = (n.max(2) - 1) as f64;
        sigma2.iter_mut().for_each(|s| *s = s.max(0.0));
        let rank = numerical_rank(&sigma2, n, d, raw_energy(sum_squares, &mean, n), cross);
        sigma2[rank..].iter_mut().for_each(|s| *s = 0.0);
        let spectrum: Vec<f64> = sigma2.iter().map(|s| s / dof).collect();
        let total_variance = sum_squares / dof;
        let c = rule.select(&spectrum, rank, total_variance, (n.max(2) - 1).min(d));
        Self {
            mean,
            components: Mat::zeros(d, 0),
            eigenvalues: spectrum[..c].to_vec(),
            spectrum,
            total_variance,
            n_samples: n,
            rank,
            method,
        }
    }

    fn with_components(mut self, mut components: Mat<f64>) -> Self {
        fix_signs(&mut components);
        self.components = components;
        self
    }

    /// The mean sample x̄ (eq. 2.47), length d.
    pub fn mean(&self) -> &[f64] {
        &self.mean
    }

    /// Principal axes as the columns of a d × c matrix (orthonormal).
    pub fn components(&self) -> MatRef<'_, f64> {
        self.components.as_ref()
    }

    /// Principal axis `i` (length d).
    ///
    /// # Panics
    /// If `i ≥ n_components()`.
    pub fn component(&self, i: usize) -> &[f64] {
        self.components.col_as_slice(i)
    }

    /// Eigenvalues λ₁ ≥ … ≥ λ_c of the covariance (eq. 2.48) for the kept components.
    pub fn eigenvalues(&self) -> &[f64] {
        &self.eigenvalues
    }

    /// Every eigenvalue the decomposition produced (min(n, d) of them, or c + p for the
    /// randomized path), descending; those below the numerical rank are 0.
    pub fn spectrum(&self) -> &[f64] {
        &self.spectrum
    }

    /// Total variance trace(C) = Σ all eigenvalues, computed directly from the centred data.
    pub fn total_variance(&self) -> f64 {
        self.total_variance
    }

    /// λᵢ / trace(C) for the kept components (0 for constant data).
    pub fn explained_variance_ratio(&self) -> Vec<f64> {
        let t = self.total_variance;
        self.eigenvalues
            .iter()
            .map(|l| if t > 0.0 { l / t } else { 0.0 })
            .collect()
    }

    /// Number of kept components c.
    pub fn n_components(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Number of features d.
    pub fn n_features(&self) -> usize {
        self.mean.len()
    }

    /// Number of samples the PCA was fitted on.
    pub fn n_samples(&self) -> usize {
        self.n_samples
    }

    /// Numerical rank of the centred data (components above rounding noise).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// The path that ran (`Auto` resolved).
    pub fn method(&self) -> PcaMethod {
        self.method
    }

    /// Keeps only the leading `c` components (no-op if `c ≥ n_components()`).
    pub fn truncate(&mut self, c: usize) {
        if c < self.n_components() {
            self.eigenvalues.truncate(c);
            self.components = self.components.as_ref().subcols(0, c).to_owned();
        }
    }
}

/// W = U_c Σ_c⁻¹ (n × c), so that V = Xcᵀ W.
fn gram_weights(u: &Mat<f64>, spectrum: &[f64], c: usize, dof: f64) -> Mat<f64> {
    Mat::from_fn(u.nrows(), c, |i, j| {
        *u.get(i, j) / (spectrum[j] * dof).sqrt()
    })
}

/// Resolves `Auto` and checks the randomized path's requirements.
fn resolve(params: &PcaParams, n: usize, d: usize) -> Result<PcaMethod> {
    let (small, large) = (n.min(d), n.max(d));
    match params.method {
        PcaMethod::Auto => Ok(if large >= CROSS_PRODUCT_RATIO * small {
            if n <= d {
                PcaMethod::Gram
            } else {
                PcaMethod::Covariance
            }
        } else {
            match params.components {
                ComponentCount::Fixed(c)
                    if small >= AUTO_RANDOMIZED_MIN_DIM && c * AUTO_RANDOMIZED_RATIO <= small =>
                {
                    PcaMethod::Randomized(RandomizedParams::default())
                }
                _ => PcaMethod::Svd,
            }
        }),
        PcaMethod::Randomized(rp) => {
            if !matches!(params.components, ComponentCount::Fixed(_)) {
                return Err(ClusteringError::InvalidParameter {
                    what: WHAT_FIT,
                    name: "components",
                    value: format!("{:?}", params.components),
                    reason: "the randomized path computes only c + p eigenpairs; use ComponentCount::Fixed(c)",
                });
            }
            if rp.tolerance.is_nan() || rp.tolerance < 0.0 {
                return Err(ClusteringError::InvalidParameter {
                    what: WHAT_FIT,
                    name: "method.tolerance",
                    value: rp.tolerance.to_string(),
                    reason: "the tolerance must be ≥ 0",
                });
            }
            Ok(params.method)
        }
        m => Ok(m),
    }
}
