//! The per-cluster affine subspaces of local PCA, in the translated frame of [`Samples`].

use faer::Mat;

/// k centers rⱼ and k bases Eⱼ (d × c, orthonormal columns, or zero columns beyond a
/// cluster's rank), with the eigenvalues of each cluster's covariance.
#[derive(Clone, Debug)]
pub(crate) struct Model {
    pub d: usize,
    pub c: usize,
    /// Row-major k × d.
    pub means: Vec<f64>,
    pub bases: Vec<Mat<f64>>,
    pub eigenvalues: Vec<Vec<f64>>,
    /// Ritz vectors (d × (c + p)) of the last per-cluster PCA, the warm start of the next.
    pub warm: Vec<Option<Mat<f64>>>,
    /// Members each region had at its last update: an unchanged region keeps its PCA.
    pub members: Vec<Vec<usize>>,
}

impl Model {
    pub fn k(&self) -> usize {
        self.bases.len()
    }

    pub fn mean(&self, j: usize) -> &[f64] {
        &self.means[j * self.d..(j + 1) * self.d]
    }
}
