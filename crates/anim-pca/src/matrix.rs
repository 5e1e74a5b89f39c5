//! A dense square matrix of f64, row-major: the distance and probability matrices.

/// A dense n × n matrix of `f64` stored row-major (row i is frame i's outgoing row).
#[derive(Clone, Debug, PartialEq)]
pub struct SquareMatrix {
    n: usize,
    data: Vec<f64>,
}

impl SquareMatrix {
    /// An n × n matrix of zeros.
    pub fn zeros(n: usize) -> Self {
        Self {
            n,
            data: vec![0.0; n * n],
        }
    }

    /// The matrix with entries `f(i, j)`.
    pub fn from_fn(n: usize, mut f: impl FnMut(usize, usize) -> f64) -> Self {
        let mut data = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                data.push(f(i, j));
            }
        }
        Self { n, data }
    }

    /// Side length n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Entry (i, j).
    ///
    /// # Panics
    /// If i or j ≥ n.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(
            i < self.n && j < self.n,
            "index ({i}, {j}) out of {0}×{0}",
            self.n
        );
        self.data[i * self.n + j]
    }

    /// Row i.
    ///
    /// # Panics
    /// If i ≥ n.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.n..(i + 1) * self.n]
    }

    /// Row i, mutable.
    pub(crate) fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.data[i * self.n..(i + 1) * self.n]
    }

    /// All entries, row-major.
    pub fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// Largest entry (0 for an empty matrix).
    pub fn max(&self) -> f64 {
        self.data.iter().copied().fold(0.0, f64::max)
    }
}
