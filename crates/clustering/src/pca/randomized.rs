//! Randomized PCA for matrices with many samples *and* many features when only c components
//! are wanted: subspace iteration ([`crate::subspace`]) from a seeded Gaussian start of c + p
//! columns, iterated until the captured energy converges.
//!
//! Each product A Q = Xcᵀ (Xc Q) is one pass over row blocks that are converted to f64 and
//! centred on the fly, so f32 input is never copied whole and the offset never enters a
//! product. Cost per step: 2·n·d·(c + p) flops plus a d × (c + p) QR.

use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::covariance::{ColumnStats, ROW_BLOCK, mean_two_pass, row_blocks, row_stripes};
use crate::element::{Element, Layout, copy_block};
use crate::error::Result;
use crate::linalg::{gaussian_matrix, rng};
use crate::subspace::{self, Ritz, Stop};

/// Random stream for the Gaussian start block.
const STREAM_START: u64 = 0x5241_4e44; // "RAND"
/// At most this many bytes of per-stripe d × b accumulators; fewer stripes beyond it.
const STRIPE_BYTES: usize = 1 << 28;
/// Most stripes (fixed, so results do not depend on the thread count).
const MAX_STRIPES: usize = 16;

/// Output of the randomized path.
pub(crate) struct RandomizedFit {
    pub mean: Vec<f64>,
    pub sum_squares: f64,
    pub ritz: Ritz,
}

/// Runs the randomized path for `c` components with block size `b = c + oversample`.
pub(crate) fn randomized<T: Element>(
    what: &'static str,
    data: MatRef<'_, T>,
    c: usize,
    b: usize,
    stop: Stop,
    seed: u64,
) -> Result<RandomizedFit> {
    let (n, d) = (data.nrows(), data.ncols());
    let ColumnStats { mean, sum_squares } = mean_two_pass(what, data)?;
    let stripes = row_stripes(n, (STRIPE_BYTES / (d * b * 8).max(1)).clamp(1, MAX_STRIPES));
    let product = |q: MatRef<'_, f64>| -> Result<Mat<f64>> {
        let parts = stripes
            .clone()
            .into_par_iter()
            .map(|s| {
                let mut y = Mat::<f64>::zeros(d, b);
                let mut buf = vec![0.0; ROW_BLOCK * d];
                let mut z = Mat::<f64>::zeros(ROW_BLOCK, b);
                for rows in row_blocks(s) {
                    let w = rows.len();
                    let blk = &mut buf[..w * d];
                    copy_block(what, data, rows, 0..d, blk, Layout::RowMajor)?;
                    for x in blk.chunks_exact_mut(d) {
                        for (v, m) in x.iter_mut().zip(&mean) {
                            *v -= m;
                        }
                    }
                    let bt = MatRef::from_column_major_slice(&*blk, d, w); // d × w = Xc_blockᵀ
                    let mut zb = z.as_mut().subrows_mut(0, w);
                    faer::linalg::matmul::matmul(
                        zb.as_mut(),
                        Accum::Replace,
                        bt.transpose(),
                        q,
                        1.0,
                        Par::Seq,
                    );
                    faer::linalg::matmul::matmul(
                        y.as_mut(),
                        Accum::Add,
                        bt,
                        zb.as_ref(),
                        1.0,
                        Par::Seq,
                    );
                }
                Ok(y)
            })
            .collect::<Result<Vec<_>>>()?;
        let mut y = Mat::<f64>::zeros(d, b);
        for p in parts {
            y += &p;
        }
        Ok(y)
    };
    let start = gaussian_matrix(d, b, &mut rng(seed, STREAM_START));
    let ritz = subspace::iterate(what, start.as_ref(), c, sum_squares, stop, product)?;
    Ok(RandomizedFit {
        mean,
        sum_squares,
        ritz,
    })
}
