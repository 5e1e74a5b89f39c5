//! Choosing the number of components c (thesis §2.7.3, eq. 2.52–2.53) and the numerical rank.

use crate::error::{ClusteringError, Result};

/// How many principal components to keep.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum ComponentCount {
    /// Every component above the numerical rank threshold.
    #[default]
    All,
    /// The leading `c` components (fewer if the data has lower numerical rank).
    Fixed(usize),
    /// The fewest leading components whose eigenvalues sum to at least this fraction, in
    /// (0, 1], of the total variance.
    EnergyFraction(f64),
    /// The thesis's rule: discard every component with λᵢ < λ̄ (eq. 2.53), where λ̄ (eq. 2.52)
    /// is the mean of the min(n − 1, d) eigenvalues that centred data can have — for d ≪ n the
    /// mean over all d eigenvalues of the covariance matrix, for n ≪ d the mean over those of
    /// the smaller-side (Gram) matrix that the thesis decomposes.
    AboveMeanEigenvalue,
}

impl ComponentCount {
    /// Checks the parameter.
    pub(crate) fn validate(self, what: &'static str) -> Result<()> {
        if let Self::EnergyFraction(f) = self {
            if !(f > 0.0 && f <= 1.0) {
                return Err(ClusteringError::InvalidParameter {
                    what,
                    name: "components",
                    value: format!("EnergyFraction({f})"),
                    reason: "the energy fraction must lie in (0, 1]",
                });
            }
        }
        Ok(())
    }

    /// The number of components to keep given eigenvalues sorted in descending order (only the
    /// first `rank` are numerically non-zero), the total variance (trace of the covariance) and
    /// the number of eigenvalues λ̄ averages over.
    pub fn select(
        self,
        eigenvalues: &[f64],
        rank: usize,
        total_variance: f64,
        mean_over: usize,
    ) -> usize {
        let rank = rank.min(eigenvalues.len());
        match self {
            Self::All => rank,
            Self::Fixed(c) => c.min(rank),
            Self::EnergyFraction(f) => {
                let target = f * total_variance;
                let mut sum = 0.0;
                for (i, l) in eigenvalues[..rank].iter().enumerate() {
                    sum += l;
                    if sum >= target {
                        return i + 1;
                    }
                }
                rank
            }
            Self::AboveMeanEigenvalue => {
                let mean = total_variance / mean_over.max(1) as f64;
                eigenvalues[..rank]
                    .iter()
                    .take_while(|&&l| l >= mean)
                    .count()
            }
        }
    }
}

/// Relative eigenvalue threshold per dimension for paths that form a cross-product matrix
/// (Gram, covariance, Rayleigh–Ritz): their eigenvalues carry absolute error ≈ ε·size·λ₁.
const CROSS_PRODUCT_SAFETY: f64 = 8.0;
/// Safety factor on the rounding error of the centred data itself (each entry is off by a few
/// ε·|x| after centring).
const ROUNDOFF_SAFETY: f64 = 4.0;

/// Σ xᵢⱼ² of the uncentred data from its centred energy and mean: ‖Xc‖²_F + n‖x̄‖².
pub(crate) fn raw_energy(sum_squares: f64, mean: &[f64], n: usize) -> f64 {
    sum_squares + n as f64 * mean.iter().map(|m| m * m).sum::<f64>()
}

/// Number of squared singular values (descending) of the centred n × d data that are above
/// rounding noise. `cross_product` is true when they came from Xc Xcᵀ or Xcᵀ Xc.
///
/// Two floors, the larger wins: relative to σ₁² (the decomposition's own accuracy) and
/// absolute, a bound on ‖E‖²_F for the centring error E (|Eᵢⱼ| ≲ 4ε·|xᵢⱼ|, so
/// ‖E‖²_F ≲ (4ε)² Σ xᵢⱼ² = (4ε)² `raw_energy`), so that identical samples give rank 0 even
/// when their mean is not exactly representable.
pub(crate) fn numerical_rank(
    sigma2: &[f64],
    n: usize,
    d: usize,
    raw_energy: f64,
    cross_product: bool,
) -> usize {
    let Some(&top) = sigma2.first() else { return 0 };
    let size = n.max(d) as f64;
    let relative = if cross_product {
        top * size * f64::EPSILON * CROSS_PRODUCT_SAFETY
    } else {
        top * (size * f64::EPSILON).powi(2)
    };
    let e = ROUNDOFF_SAFETY * f64::EPSILON;
    let absolute = e * e * raw_energy;
    let floor = relative.max(absolute);
    sigma2.iter().take_while(|&&s| s > floor).count()
}
