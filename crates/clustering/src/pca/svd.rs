//! PCA by the thin SVD of the centred data (eq. 2.45): Xc = U D Vᵀ, principal axes = columns of
//! V, eigenvalues λᵢ = dᵢ² / (n − 1). The most accurate path (singular values are not squared);
//! used when neither side of the matrix is much smaller than the other.

use std::ops::Range;

use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::gram::center_block;
use crate::element::{Element, Layout, copy_block};
use crate::error::Result;
use crate::linalg::thin_svd;

/// Features per parallel copy task.
const COPY_COLS: usize = 256;

/// A centred f64 copy of the data with its statistics.
pub(crate) struct Centered {
    /// Column-major n × d.
    pub values: Vec<f64>,
    pub mean: Vec<f64>,
    pub sum_squares: f64,
}

/// Copies `data` to f64 column by column, centring each column with its exact two-pass mean.
pub(crate) fn centered_copy<T: Element>(
    what: &'static str,
    data: MatRef<'_, T>,
) -> Result<Centered> {
    let (n, d) = (data.nrows(), data.ncols());
    let mut values = vec![0.0; n * d];
    let mut mean = vec![0.0; d];
    let stats = values
        .par_chunks_mut(n * COPY_COLS)
        .zip(mean.par_chunks_mut(COPY_COLS))
        .enumerate()
        .map(|(b, (chunk, m))| {
            let cols: Range<usize> = b * COPY_COLS..b * COPY_COLS + m.len();
            copy_block(what, data, 0..n, cols, chunk, Layout::ColMajor)?;
            Ok(center_block(chunk, n, m))
        })
        .collect::<Result<Vec<_>>>()?;
    let sum_squares = stats.iter().sum();
    Ok(Centered {
        values,
        mean,
        sum_squares,
    })
}

/// Squared singular values (descending) and right singular vectors (d × min(n, d)).
pub(crate) fn svd_path(
    what: &'static str,
    c: &Centered,
    n: usize,
    d: usize,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let x = MatRef::from_column_major_slice(&c.values, n, d);
    let (s, _u, v) = thin_svd(what, x)?;
    Ok((s.iter().map(|s| s * s).collect(), v))
}
