//! PCA through the d × d covariance matrix (eq. 2.46), for d ≪ n (the thesis's "covariance
//! matrix of the smaller side").
//!
//! Samples are visited in row blocks, twice: the first pass sums the columns (a provisional
//! mean m₀), the second accumulates C₀ = Σ (x − m₀)(x − m₀)ᵀ and the residual Σ (x − m₀).
//! With δ = mean − m₀ (rounding-sized) the scatter matrix is C₀ − n δδᵀ, so an offset of 1e6 on
//! unit-variance data never enters a product. Blocks are grouped into a fixed number of
//! stripes summed in order, so the result does not depend on the thread count.

use std::ops::Range;

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use crate::element::{Element, Layout, copy_block};
use crate::error::Result;

/// Samples per row block (256 × d f64; for d = 32 that is 64 kB).
pub(crate) const ROW_BLOCK: usize = 256;
/// Fixed number of stripes (see the module docs).
const STRIPES: usize = 16;

/// Result of the two passes.
pub(crate) struct CovPass {
    pub mean: Vec<f64>,
    /// Lower triangle of Xcᵀ Xc (d × d).
    pub scatter: Mat<f64>,
    pub sum_squares: f64,
}

/// Row ranges of the stripes (whole blocks).
pub(crate) fn row_stripes(n: usize, stripes: usize) -> Vec<Range<usize>> {
    let blocks = n.div_ceil(ROW_BLOCK);
    let s = stripes.min(blocks).max(1);
    (0..s)
        .map(|i| ((i * blocks / s) * ROW_BLOCK).min(n)..(((i + 1) * blocks / s) * ROW_BLOCK).min(n))
        .collect()
}

/// Row blocks inside a stripe.
pub(crate) fn row_blocks(stripe: Range<usize>) -> impl Iterator<Item = Range<usize>> {
    stripe
        .clone()
        .step_by(ROW_BLOCK)
        .map(move |r| r..(r + ROW_BLOCK).min(stripe.end))
}

/// Column statistics from [`mean_two_pass`].
pub(crate) struct ColumnStats {
    pub mean: Vec<f64>,
    /// ‖Xc‖²_F.
    pub sum_squares: f64,
}

/// Exact column mean of `data` in two passes (provisional mean m₀, then the mean of the
/// residual) and ‖Xc‖²_F = Σ‖x − m₀‖² − n‖δ‖² with δ = mean − m₀ (rounding-sized).
/// Fails on non-finite values.
pub(crate) fn mean_two_pass<T: Element>(
    what: &'static str,
    data: MatRef<'_, T>,
) -> Result<ColumnStats> {
    let (n, d) = (data.nrows(), data.ncols());
    let sums = |shift: Option<&[f64]>| -> Result<Vec<(Vec<f64>, f64)>> {
        row_stripes(n, STRIPES)
            .into_par_iter()
            .map(|s| {
                let mut buf = vec![0.0; ROW_BLOCK * d];
                let mut acc = vec![0.0; d];
                // Σ (x − m₀)² in the second pass.
                let mut scalar = 0.0f64;
                for rows in row_blocks(s) {
                    let b = &mut buf[..rows.len() * d];
                    copy_block(what, data, rows, 0..d, b, Layout::RowMajor)?;
                    for x in b.chunks_exact(d) {
                        match shift {
                            None => acc.iter_mut().zip(x).for_each(|(a, v)| *a += v),
                            Some(m) => acc.iter_mut().zip(x).zip(m).for_each(|((a, v), m)| {
                                let t = v - m;
                                *a += t;
                                scalar += t * t;
                            }),
                        }
                    }
                }
                Ok((acc, scalar))
            })
            .collect()
    };
    let inv = 1.0 / n as f64;
    let mut mean = vec![0.0; d];
    for (s, _) in sums(None)? {
        mean.iter_mut().zip(&s).for_each(|(a, v)| *a += v);
    }
    mean.iter_mut().for_each(|m| *m *= inv);
    let mut fix = vec![0.0; d];
    let mut ss0 = 0.0;
    for (s, q) in sums(Some(&mean))? {
        fix.iter_mut().zip(&s).for_each(|(a, v)| *a += v);
        ss0 += q;
    }
    let delta2: f64 = fix.iter().map(|f| (f * inv) * (f * inv)).sum();
    mean.iter_mut().zip(&fix).for_each(|(m, f)| *m += f * inv);
    Ok(ColumnStats {
        mean,
        sum_squares: (ss0 - n as f64 * delta2).max(0.0),
    })
}

/// The scatter matrix Xcᵀ Xc of in-memory data.
pub(crate) fn covariance_pass<T: Element>(
    what: &'static str,
    data: MatRef<'_, T>,
) -> Result<CovPass> {
    let (n, d) = (data.nrows(), data.ncols());
    let ColumnStats { mean, .. } = mean_two_pass(what, data)?;
    let parts = row_stripes(n, STRIPES)
        .into_par_iter()
        .map(|s| {
            let mut buf = vec![0.0; ROW_BLOCK * d];
            let mut scatter = Mat::<f64>::zeros(d, d);
            let mut ss = 0.0;
            for rows in row_blocks(s) {
                let w = rows.len();
                let b = &mut buf[..w * d];
                copy_block(what, data, rows, 0..d, b, Layout::RowMajor)?;
                for x in b.chunks_exact_mut(d) {
                    for (v, m) in x.iter_mut().zip(&mean) {
                        *v -= m;
                        ss += *v * *v;
                    }
                }
                // b is row-major w × d = column-major d × w.
                let bt = MatRef::from_column_major_slice(&*b, d, w);
                triangular::matmul(
                    scatter.as_mut(),
                    BlockStructure::TriangularLower,
                    Accum::Add,
                    bt,
                    BlockStructure::Rectangular,
                    bt.transpose(),
                    BlockStructure::Rectangular,
                    1.0,
                    Par::Seq,
                );
            }
            Ok((scatter, ss))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut scatter = Mat::<f64>::zeros(d, d);
    let mut sum_squares = 0.0;
    for (s, ss) in parts {
        scatter += &s;
        sum_squares += ss;
    }
    Ok(CovPass {
        mean,
        scatter,
        sum_squares,
    })
}
