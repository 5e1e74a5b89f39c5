//! PCA through the n × n Gram matrix of the samples (thesis §3.3.2: "the covariance matrix has
//! the size of the smaller part", after Navarrete & del Solar 2001), for n ≪ d.
//!
//! With the centred data Xc (n × d), G = Xc Xcᵀ = U Σ² Uᵀ and the principal axes are the
//! columns of V = Xcᵀ U Σ⁻¹ (the eigenvectors of eq. 2.50 written as combinations of the data,
//! eq. 2.51). The features are visited in column blocks: each block holds *every* sample for a
//! range of features, so its column means are exact and the block is centred before it enters
//! G — no cancellation however large the offset. A second pass over the same blocks forms V.
//! Neither pass copies the whole matrix, which is what lets a BTF view slot at 1024²
//! (81 × 3.1M, 1 GB in f32) be decomposed from memory or from a [`ColumnBlockSource`].
//!
//! Precision: G squares the singular values, so eigenvalues below ~ε·n·λ₁ are rounding noise
//! and are treated as zero (see [`super::numerical_rank`]), and axis i comes out orthogonal
//! only to ~ε·λ₁/λᵢ. One Cholesky-QR pass over V (d·c² flops, Gram–Schmidt order so the leading
//! axes keep their direction) restores orthonormality to working precision, so reconstruction
//! with all components is exact to rounding. Use [`super::PcaMethod::Svd`] when the *directions*
//! of tiny trailing components matter.

use std::ops::Range;

use faer::linalg::matmul::triangular::{self, BlockStructure};
use faer::{Accum, Mat, MatMut, MatRef, Par};
use rayon::prelude::*;

use crate::element::{Element, Layout, copy_block};
use crate::error::{ClusteringError, Result, SourceError};

/// Features per block. A block is n × 512 f64 (330 kB for the 81 samples of a BTF slot), which
/// stays in L2 while it is centred and multiplied.
pub(crate) const BLOCK_COLS: usize = 512;

/// Blocks are grouped into this many stripes, each accumulated on its own and summed in order,
/// so the result is the same for any thread count and for in-memory and streamed input.
const STRIPES: usize = 16;

/// Features of every sample, delivered a range of columns at a time (out-of-core PCA).
///
/// Implement this for data that does not fit in memory: a BTF view slot whose 81 light images
/// are files, each read a tile of pixels at a time. [`crate::Pca::fit_streaming`] reads every
/// feature range twice, in increasing order within each of a fixed set of stripes.
pub trait ColumnBlockSource {
    /// Number of samples n (rows): light images for a BTF slot.
    fn n_samples(&self) -> usize;
    /// Number of features d (columns): pixels × channels for a BTF slot.
    fn n_features(&self) -> usize;
    /// Writes features `features` of every sample into `out`, column-major:
    /// `out[(j - features.start) * n + i]` = feature j of sample i.
    ///
    /// # Errors
    /// Whatever the source fails with (I/O, decoding); it is returned wrapped in
    /// [`ClusteringError::Source`].
    fn read_features(&mut self, features: Range<usize>, out: &mut [f64])
    -> Result<(), SourceError>;
}

/// First pass: means, ‖Xc‖²_F and the lower triangle of G.
pub(crate) struct GramPass {
    pub mean: Vec<f64>,
    pub gram: Mat<f64>,
    pub sum_squares: f64,
}

/// Feature ranges of the stripes: whole blocks, split as evenly as possible.
fn stripes(d: usize) -> Vec<Range<usize>> {
    let blocks = d.div_ceil(BLOCK_COLS);
    let s = STRIPES.min(blocks).max(1);
    (0..s)
        .map(|i| {
            let b0 = i * blocks / s;
            let b1 = (i + 1) * blocks / s;
            (b0 * BLOCK_COLS).min(d)..(b1 * BLOCK_COLS).min(d)
        })
        .collect()
}

/// Block ranges inside a stripe.
fn blocks(stripe: Range<usize>) -> impl Iterator<Item = Range<usize>> {
    stripe
        .clone()
        .step_by(BLOCK_COLS)
        .map(move |c| c..(c + BLOCK_COLS).min(stripe.end))
}

/// Centres every column of a column-major n × w block in place; writes the means, returns
/// Σ centred². The mean is taken of the differences to the column's first value (exact data),
/// x̄ = x₀ + Σ(x − x₀)/n, so a large common offset never enters a sum.
pub(crate) fn center_block(buf: &mut [f64], n: usize, mean: &mut [f64]) -> f64 {
    let inv = 1.0 / n as f64;
    let mut ss = 0.0;
    for (col, m_out) in buf.chunks_exact_mut(n).zip(mean) {
        let x0 = col[0];
        let m = x0 + col.iter().map(|x| x - x0).sum::<f64>() * inv;
        for x in col.iter_mut() {
            *x -= m;
            ss += *x * *x;
        }
        *m_out = m;
    }
    ss
}

/// The same for a row-major n × w block (each sample's features contiguous): identical
/// arithmetic per column, in an order that vectorises across columns.
fn center_rows(buf: &mut [f64], w: usize, mean: &mut [f64]) -> f64 {
    let n = buf.len() / w;
    let inv = 1.0 / n as f64;
    let x0 = buf[..w].to_vec();
    mean.iter_mut().for_each(|m| *m = 0.0);
    for row in buf.chunks_exact(w) {
        mean.iter_mut()
            .zip(row)
            .zip(&x0)
            .for_each(|((m, x), x0)| *m += x - x0);
    }
    mean.iter_mut()
        .zip(&x0)
        .for_each(|(m, x0)| *m = x0 + *m * inv);
    let mut acc = vec![0.0; w];
    for row in buf.chunks_exact_mut(w) {
        for ((x, m), a) in row.iter_mut().zip(&*mean).zip(acc.iter_mut()) {
            *x -= m;
            *a += *x * *x;
        }
    }
    acc.iter().sum()
}

/// A block buffer viewed as the n × w matrix it holds.
fn view(buf: &[f64], n: usize, w: usize, layout: Layout) -> MatRef<'_, f64> {
    match layout {
        Layout::ColMajor => MatRef::from_column_major_slice(buf, n, w),
        Layout::RowMajor => MatRef::from_row_major_slice(buf, n, w),
    }
}

/// The block layout that reads `data` contiguously.
fn layout_for<T>(data: MatRef<'_, T>) -> Layout {
    if data.col_stride() == 1 {
        Layout::RowMajor
    } else {
        Layout::ColMajor
    }
}

type Fill<'a> = dyn FnMut(Range<usize>, &mut [f64]) -> Result<()> + 'a;

/// Accumulates one stripe: G_s = Σ_blocks Xc_b Xc_bᵀ (lower triangle). `fill` writes blocks
/// in `layout`.
fn accumulate_stripe(
    n: usize,
    stripe: Range<usize>,
    layout: Layout,
    fill: &mut Fill<'_>,
) -> Result<(GramPass, usize)> {
    let mut buf = vec![0.0; n * BLOCK_COLS];
    let mut acc = GramPass {
        mean: vec![0.0; stripe.len()],
        gram: Mat::zeros(n, n),
        sum_squares: 0.0,
    };
    for block in blocks(stripe.clone()) {
        let w = block.len();
        let b = &mut buf[..n * w];
        fill(block.clone(), b)?;
        let off = block.start - stripe.start;
        let mean = &mut acc.mean[off..off + w];
        acc.sum_squares += match layout {
            Layout::ColMajor => center_block(b, n, mean),
            Layout::RowMajor => center_rows(b, w, mean),
        };
        let x = view(b, n, w, layout);
        triangular::matmul(
            acc.gram.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Add,
            x,
            BlockStructure::Rectangular,
            x.transpose(),
            BlockStructure::Rectangular,
            1.0,
            Par::Seq,
        );
    }
    Ok((acc, stripe.start))
}

/// Sums stripe results in stripe order.
fn combine(n: usize, d: usize, parts: Vec<(GramPass, usize)>) -> GramPass {
    let mut out = GramPass {
        mean: vec![0.0; d],
        gram: Mat::zeros(n, n),
        sum_squares: 0.0,
    };
    for (p, start) in parts {
        out.mean[start..start + p.mean.len()].copy_from_slice(&p.mean);
        out.gram += &p.gram;
        out.sum_squares += p.sum_squares;
    }
    out
}

/// First pass over in-memory data, stripes in parallel.
pub(crate) fn gram_pass<T: Element>(what: &'static str, data: MatRef<'_, T>) -> Result<GramPass> {
    let (n, d) = (data.nrows(), data.ncols());
    let layout = layout_for(data);
    let parts = stripes(d)
        .into_par_iter()
        .map(|s| {
            let mut fill = |cols: Range<usize>, out: &mut [f64]| {
                copy_block(what, data, 0..n, cols, out, layout)
            };
            accumulate_stripe(n, s, layout, &mut fill)
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(combine(n, d, parts))
}

/// Wraps a source's read as a block filler that validates its output.
fn source_fill<'a>(
    what: &'static str,
    source: &'a mut dyn ColumnBlockSource,
) -> impl FnMut(Range<usize>, &mut [f64]) -> Result<()> + 'a {
    move |cols: Range<usize>, out: &mut [f64]| {
        let n = source.n_samples();
        source
            .read_features(cols.clone(), out)
            .map_err(|source| ClusteringError::Source {
                what,
                features: cols.clone(),
                source,
            })?;
        match out.iter().position(|v| !v.is_finite()) {
            None => Ok(()),
            Some(p) => Err(ClusteringError::NonFinite {
                what,
                row: p % n,
                col: cols.start + p / n,
                value: out[p],
            }),
        }
    }
}

/// First pass over a streamed source (sequential, same arithmetic as [`gram_pass`]).
pub(crate) fn gram_pass_streaming(
    what: &'static str,
    source: &mut dyn ColumnBlockSource,
) -> Result<GramPass> {
    let (n, d) = (source.n_samples(), source.n_features());
    let mut fill = source_fill(what, source);
    let parts = stripes(d)
        .into_iter()
        .map(|s| accumulate_stripe(n, s, Layout::ColMajor, &mut fill))
        .collect::<Result<Vec<_>>>()?;
    Ok(combine(n, d, parts))
}

/// Second pass for one stripe: writes V_s = Xc_sᵀ W into `out` (the stripe's rows of the
/// d × c component matrix).
fn components_stripe(
    n: usize,
    stripe: Range<usize>,
    layout: Layout,
    mean: &[f64],
    w: MatRef<'_, f64>,
    mut out: MatMut<'_, f64>,
    fill: &mut Fill<'_>,
) -> Result<()> {
    let mut buf = vec![0.0; n * BLOCK_COLS];
    for block in blocks(stripe.clone()) {
        let width = block.len();
        let b = &mut buf[..n * width];
        fill(block.clone(), b)?;
        let mean = &mean[block.clone()];
        match layout {
            Layout::ColMajor => b
                .chunks_exact_mut(n)
                .zip(mean)
                .for_each(|(col, m)| col.iter_mut().for_each(|x| *x -= m)),
            Layout::RowMajor => b
                .chunks_exact_mut(width)
                .for_each(|row| row.iter_mut().zip(mean).for_each(|(x, m)| *x -= m)),
        }
        let x = view(b, n, width, layout);
        let off = block.start - stripe.start;
        faer::linalg::matmul::matmul(
            out.rb_mut().subrows_mut(off, width),
            Accum::Replace,
            x.transpose(),
            w,
            1.0,
            Par::Seq,
        );
    }
    Ok(())
}

/// The d × c output split into the stripes' disjoint row blocks.
fn stripe_rows<'a>(out: MatMut<'a, f64>, stripes: &[Range<usize>]) -> Vec<MatMut<'a, f64>> {
    let mut parts = Vec::with_capacity(stripes.len());
    let mut rest = out;
    for s in stripes {
        let (top, bottom) = rest.split_at_row_mut(s.len());
        parts.push(top);
        rest = bottom;
    }
    parts
}

use faer::reborrow::ReborrowMut;

/// Second pass over in-memory data: the d × c matrix Xcᵀ W.
pub(crate) fn gram_components<T: Element>(
    what: &'static str,
    data: MatRef<'_, T>,
    mean: &[f64],
    w: MatRef<'_, f64>,
) -> Result<Mat<f64>> {
    let (n, d) = (data.nrows(), data.ncols());
    let layout = layout_for(data);
    let mut out = Mat::zeros(d, w.ncols());
    let s = stripes(d);
    s.clone()
        .into_par_iter()
        .zip(stripe_rows(out.as_mut(), &s))
        .try_for_each(|(s, rows)| {
            let mut fill = |cols: Range<usize>, out: &mut [f64]| {
                copy_block(what, data, 0..n, cols, out, layout)
            };
            components_stripe(n, s, layout, mean, w, rows, &mut fill)
        })?;
    Ok(out)
}

/// Second pass over a streamed source.
pub(crate) fn gram_components_streaming(
    what: &'static str,
    source: &mut dyn ColumnBlockSource,
    mean: &[f64],
    w: MatRef<'_, f64>,
) -> Result<Mat<f64>> {
    let (n, d) = (source.n_samples(), source.n_features());
    let mut fill = source_fill(what, source);
    let mut out = Mat::zeros(d, w.ncols());
    let s = stripes(d);
    for (s, rows) in s.clone().into_iter().zip(stripe_rows(out.as_mut(), &s)) {
        components_stripe(n, s, Layout::ColMajor, mean, w, rows, &mut fill)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stripes_cover_features_once_in_block_multiples() {
        for d in [1, 511, 512, 513, 5000, 512 * 40 + 7] {
            let s = stripes(d);
            assert_eq!(s.first().map(|r| r.start), Some(0));
            assert_eq!(s.last().map(|r| r.end), Some(d));
            for w in s.windows(2) {
                assert_eq!(w[0].end, w[1].start);
                assert_eq!(w[0].start % BLOCK_COLS, 0);
            }
        }
    }
}
