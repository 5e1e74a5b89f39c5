//! Input element types and the one place where user matrices are read.
//!
//! Every fit accepts a faer `MatRef<'_, T>` with `T` = `f32` or `f64` (rows are samples,
//! columns are features, any strides). Values are converted to `f64` block by block while they
//! are read, so f32 data (a BTF view slot) is never copied whole and all accumulation is f64.

use faer::MatRef;

use crate::error::{ClusteringError, Result};

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A scalar type accepted as input data: `f32` or `f64` (sealed).
pub trait Element: Copy + Send + Sync + 'static + sealed::Sealed {
    /// Widen to f64 (exact for both types).
    fn to_f64(self) -> f64;
}

impl Element for f32 {
    #[inline]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
}

impl Element for f64 {
    #[inline]
    fn to_f64(self) -> f64 {
        self
    }
}

/// Layout of a destination block written by [`copy_block`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Layout {
    /// `dst[i * ncols + j]`: each sample contiguous.
    RowMajor,
    /// `dst[j * nrows + i]`: each feature contiguous.
    ColMajor,
}

/// Copies `src[rows, cols]` into `dst` as f64 in `layout`, failing on the first non-finite
/// value (reported with its global row and column).
///
/// # Panics
/// If `dst.len()` differs from the block size or the ranges fall outside `src` (internal bugs).
pub(crate) fn copy_block<T: Element>(
    what: &'static str,
    src: MatRef<'_, T>,
    rows: std::ops::Range<usize>,
    cols: std::ops::Range<usize>,
    dst: &mut [f64],
    layout: Layout,
) -> Result<()> {
    let (nr, nc) = (rows.len(), cols.len());
    assert_eq!(dst.len(), nr * nc, "copy_block: destination size");
    let sub = src.submatrix(rows.start, cols.start, nr, nc);
    let put = |dst: &mut [f64], i: usize, j: usize, v: f64| match layout {
        Layout::RowMajor => dst[i * nc + j] = v,
        Layout::ColMajor => dst[j * nr + i] = v,
    };
    if let Some(rm) = sub.try_as_row_major() {
        for i in 0..nr {
            let row = rm.row(i).as_slice();
            if layout == Layout::RowMajor {
                for (d, s) in dst[i * nc..(i + 1) * nc].iter_mut().zip(row) {
                    *d = s.to_f64();
                }
            } else {
                for (j, s) in row.iter().enumerate() {
                    put(dst, i, j, s.to_f64());
                }
            }
        }
    } else if let Some(cm) = sub.try_as_col_major() {
        for j in 0..nc {
            let col = cm.col(j).as_slice();
            if layout == Layout::ColMajor {
                for (d, s) in dst[j * nr..(j + 1) * nr].iter_mut().zip(col) {
                    *d = s.to_f64();
                }
            } else {
                for (i, s) in col.iter().enumerate() {
                    put(dst, i, j, s.to_f64());
                }
            }
        }
    } else {
        for i in 0..nr {
            for j in 0..nc {
                put(dst, i, j, sub.get(i, j).to_f64());
            }
        }
    }
    if dst.iter().all(|v| v.is_finite()) {
        return Ok(());
    }
    let pos = dst.iter().position(|v| !v.is_finite()).unwrap_or(0);
    let (i, j) = match layout {
        Layout::RowMajor => (pos / nc.max(1), pos % nc.max(1)),
        Layout::ColMajor => (pos % nr.max(1), pos / nr.max(1)),
    };
    Err(ClusteringError::NonFinite {
        what,
        row: rows.start + i,
        col: cols.start + j,
        value: dst[pos],
    })
}

/// Checks the data shape: at least `min_rows` rows and one column.
pub(crate) fn check_shape(
    what: &'static str,
    rows: usize,
    cols: usize,
    min_rows: usize,
) -> Result<()> {
    if rows < min_rows.max(1) || cols == 0 {
        return Err(ClusteringError::TooFewSamples {
            what,
            rows,
            cols,
            min_rows: min_rows.max(1),
        });
    }
    Ok(())
}

/// A dense, translated f64 copy of a data matrix with each sample contiguous (row-major
/// n × d, i.e. a column-major d × n faer matrix).
///
/// The translation (the column mean, computed in two passes) makes every later
/// distance computation free of cancellation: data offset by 1e6 with unit spread behaves like
/// data at the origin. All algorithms here are translation invariant.
pub(crate) struct Samples {
    /// `n * d` values, sample `i` at `[i * d .. (i + 1) * d]`.
    pub values: Vec<f64>,
    /// Squared norm of each translated sample.
    pub norms2: Vec<f64>,
    /// What was subtracted from every sample.
    pub offset: Vec<f64>,
    /// Samples.
    pub n: usize,
    /// Features.
    pub d: usize,
}

/// Rows per block when copying samples (each block converted on its own thread).
const COPY_ROWS: usize = 1024;

impl Samples {
    /// Copies and translates `data`; fails on non-finite values.
    pub fn new<T: Element>(what: &'static str, data: MatRef<'_, T>) -> Result<Self> {
        use rayon::prelude::*;
        let (n, d) = (data.nrows(), data.ncols());
        let mut values = vec![0.0; n * d];
        values
            .par_chunks_mut(COPY_ROWS * d)
            .enumerate()
            .try_for_each(|(b, chunk)| {
                let r0 = b * COPY_ROWS;
                copy_block(
                    what,
                    data,
                    r0..r0 + chunk.len() / d,
                    0..d,
                    chunk,
                    Layout::RowMajor,
                )
            })?;
        let offset = column_mean_row_major(&values, n, d);
        values.par_chunks_mut(d).for_each(|x| {
            for (v, m) in x.iter_mut().zip(&offset) {
                *v -= m;
            }
        });
        let norms2 = values
            .par_chunks(d)
            .map(|x| crate::linalg::dot(x, x))
            .collect();
        Ok(Self {
            values,
            norms2,
            offset,
            n,
            d,
        })
    }

    /// Sample `i`.
    #[inline]
    pub fn row(&self, i: usize) -> &[f64] {
        &self.values[i * self.d..(i + 1) * self.d]
    }
}

/// Column mean of a row-major n × d buffer, in two passes (mean, then the mean of the
/// residual added back) so that a large common offset does not leave rounding error.
pub(crate) fn column_mean_row_major(values: &[f64], n: usize, d: usize) -> Vec<f64> {
    let inv = 1.0 / n as f64;
    let mut mean = vec![0.0; d];
    for x in values.chunks_exact(d) {
        for (m, v) in mean.iter_mut().zip(x) {
            *m += v;
        }
    }
    mean.iter_mut().for_each(|m| *m *= inv);
    let mut fix = vec![0.0; d];
    for x in values.chunks_exact(d) {
        for ((f, v), m) in fix.iter_mut().zip(x).zip(&mean) {
            *f += v - m;
        }
    }
    for (m, f) in mean.iter_mut().zip(&fix) {
        *m += f * inv;
    }
    mean
}
