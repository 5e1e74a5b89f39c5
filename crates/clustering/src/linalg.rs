//! Small dense kernels shared by the algorithms: dot products, the component sign convention,
//! and faer decompositions wrapped to return errors and descending order.

use faer::{Mat, MatRef, Side};

use crate::error::{ClusteringError, Result};

/// Dot product with eight independent accumulators (vectorizes; fixed summation order, so the
/// result is deterministic).
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += x * y;
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

/// Squared Euclidean distance, computed from differences (no cancellation).
#[inline]
pub(crate) fn sq_dist(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let mut acc = [0.0f64; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            let t = x[l] - y[l];
            acc[l] += t * t;
        }
    }
    let mut tail = 0.0;
    for (x, y) in ra.iter().zip(rb) {
        tail += (x - y) * (x - y);
    }
    ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7])) + tail
}

/// The sign convention for principal axes: flips `v` so that its entry of largest magnitude
/// (the first one on ties) is positive. Returns whether it flipped.
pub(crate) fn fix_sign(v: &mut [f64]) -> bool {
    let mut best = 0usize;
    let mut best_abs = -1.0f64;
    for (i, x) in v.iter().enumerate() {
        if x.abs() > best_abs {
            best_abs = x.abs();
            best = i;
        }
    }
    if v.get(best).is_some_and(|x| *x < 0.0) {
        v.iter_mut().for_each(|x| *x = -*x);
        return true;
    }
    false
}

/// Applies [`fix_sign`] to every column of `m`.
pub(crate) fn fix_signs(m: &mut Mat<f64>) {
    for j in 0..m.ncols() {
        fix_sign(m.col_as_slice_mut(j));
    }
}

/// Eigen-decomposition of a symmetric matrix (its lower triangle is read), eigenvalues in
/// descending order with matching eigenvector columns.
pub(crate) fn sym_eigen_desc(
    what: &'static str,
    a: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>)> {
    let n = a.nrows();
    let evd = a
        .self_adjoint_eigen(Side::Lower)
        .map_err(|_| ClusteringError::NoConvergence {
            what,
            decomposition: "self-adjoint eigendecomposition",
            rows: n,
            cols: n,
        })?;
    let s = evd.S().column_vector();
    let u = evd.U();
    let values: Vec<f64> = (0..n).rev().map(|i| *s.get(i)).collect();
    let vectors = Mat::from_fn(n, n, |i, j| *u.get(i, n - 1 - j));
    Ok((values, vectors))
}

/// Thin SVD of `a` (m × n): singular values descending, U (m × r), V (n × r), r = min(m, n).
pub(crate) fn thin_svd(
    what: &'static str,
    a: MatRef<'_, f64>,
) -> Result<(Vec<f64>, Mat<f64>, Mat<f64>)> {
    let svd = a.thin_svd().map_err(|_| ClusteringError::NoConvergence {
        what,
        decomposition: "thin SVD",
        rows: a.nrows(),
        cols: a.ncols(),
    })?;
    let s = svd.S().column_vector();
    let values = (0..s.nrows()).map(|i| *s.get(i)).collect();
    Ok((values, svd.U().to_owned(), svd.V().to_owned()))
}

/// An orthonormal basis (d × b) of the column space of `y` (Householder QR, so the result is
/// orthonormal to working precision even when `y` is rank deficient).
pub(crate) fn orthonormalize(y: MatRef<'_, f64>) -> Mat<f64> {
    y.qr().compute_thin_Q()
}

/// Uniform `[0, 1)` with 53 random bits.
#[inline]
pub(crate) fn uniform01(rng: &mut impl rand::Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// Standard normal deviate (Box–Muller; deterministic for a seeded generator on every
/// platform, unlike library samplers whose algorithm may change between versions).
pub(crate) fn gaussian(rng: &mut impl rand::Rng) -> f64 {
    let u1 = 1.0 - uniform01(rng); // (0, 1]
    let u2 = uniform01(rng);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A d × b matrix of standard normal deviates.
pub(crate) fn gaussian_matrix(d: usize, b: usize, rng: &mut impl rand::Rng) -> Mat<f64> {
    let mut m = Mat::<f64>::zeros(d, b);
    for j in 0..b {
        for v in m.col_as_slice_mut(j) {
            *v = gaussian(rng);
        }
    }
    m
}

/// Uniform index in `0..n` (n > 0), via 64-bit arithmetic so the stream is the same on every
/// platform.
#[inline]
pub(crate) fn uniform_index(rng: &mut impl rand::Rng, n: usize) -> usize {
    // Multiply-shift (Lemire) without rejection: bias ≤ n / 2^64, irrelevant here.
    ((u128::from(rng.next_u64()) * n as u128) >> 64) as usize
}

/// The seeded generator used everywhere: ChaCha8 from `seed`, with `stream` separating the
/// independent uses of one seed (initialisation, random bases, …).
pub(crate) fn rng(seed: u64, stream: u64) -> rand_chacha::ChaCha8Rng {
    use rand::SeedableRng;
    let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream);
    r
}

/// Rows per parallel task of [`reorthonormalize`].
const REORTH_ROWS: usize = 4096;

/// One Cholesky-QR pass on the columns of `v` (d × c): V ← V L⁻ᵀ with L Lᵀ = VᵀV. Column j
/// becomes a combination of columns 0..=j only (Gram–Schmidt order), so leading columns keep
/// their direction while the loss of orthogonality of the Gram path (≈ ε·λ₁/λᵢ) is removed.
/// VᵀV is summed over fixed row blocks in order (thread-count independent). Leaves `v` as is
/// when VᵀV is not numerically positive definite.
pub(crate) fn reorthonormalize(v: &mut Mat<f64>) {
    use faer::linalg::matmul::triangular::{self, BlockStructure};
    use rayon::prelude::*;
    let (d, c) = (v.nrows(), v.ncols());
    if c == 0 || d == 0 {
        return;
    }
    let parts: Vec<Mat<f64>> = row_chunks(v.as_mut())
        .into_par_iter()
        .map(|b| {
            let mut g = Mat::<f64>::zeros(c, c);
            let b = faer::reborrow::IntoConst::into_const(b);
            triangular::matmul(
                g.as_mut(),
                BlockStructure::TriangularLower,
                faer::Accum::Replace,
                b.transpose(),
                BlockStructure::Rectangular,
                b,
                BlockStructure::Rectangular,
                1.0,
                faer::Par::Seq,
            );
            g
        })
        .collect();
    let mut g = Mat::<f64>::zeros(c, c);
    for p in parts {
        g += &p;
    }
    let Ok(llt) = g.as_ref().llt(Side::Lower) else {
        return;
    };
    let l = llt.L().to_owned();
    row_chunks(v.as_mut()).into_par_iter().for_each(|b| {
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(
            l.as_ref(),
            b.transpose_mut(),
            faer::Par::Seq,
        );
    });
}

/// Disjoint row blocks of `REORTH_ROWS` rows.
fn row_chunks(m: faer::MatMut<'_, f64>) -> Vec<faer::MatMut<'_, f64>> {
    let mut out = Vec::new();
    let mut rest = m;
    while rest.nrows() > REORTH_ROWS {
        let (top, bottom) = rest.split_at_row_mut(REORTH_ROWS);
        out.push(top);
        rest = bottom;
    }
    out.push(rest);
    out
}
