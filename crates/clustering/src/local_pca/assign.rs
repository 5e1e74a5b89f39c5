//! Step 2 of clustered PCA (thesis §2.7.4): assign each sample to the cluster with the smallest
//! squared reconstruction error ‖x − rⱼ − Σᵢ⟨x − rⱼ, eᵢⱼ⟩eᵢⱼ‖².
//!
//! For all clusters at once one GEMM forms ⟨x, eᵢⱼ⟩ and ⟨x, rⱼ⟩ for a block of samples
//! (P = Mᵀ X with M = [E₁ … E_k | r₁ … r_k]); then
//! errⱼ(x) = ‖x − rⱼ‖² − Σᵢ (⟨x, eᵢⱼ⟩ − ⟨rⱼ, eᵢⱼ⟩)², the Pythagorean form of the error for an
//! orthonormal (or zero-padded) basis. The winner's ‖x − rⱼ‖² is then recomputed from
//! differences. [`exact_codes`] recomputes weights and errors of the final model from explicit
//! residuals.

use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::model::Model;
use crate::element::Samples;
use crate::linalg::{dot, sq_dist};

/// Samples per GEMM block (256 samples × k(c + 1) scores).
const ROWS: usize = 256;

/// Labels, per-sample squared errors and weights (row-major n × max(c, 1), so that c = 0
/// keeps one dummy column and the parallel chunks stay aligned).
#[derive(Clone, Debug, Default)]
pub(crate) struct Codes {
    pub labels: Vec<usize>,
    pub errors: Vec<f64>,
    pub weights: Vec<f64>,
}

impl Codes {
    pub fn new(n: usize, c: usize) -> Self {
        Self {
            labels: vec![0; n],
            errors: vec![0.0; n],
            weights: vec![0.0; n * c.max(1)],
        }
    }

    pub fn mean_error(&self) -> f64 {
        self.errors.iter().sum::<f64>() / self.errors.len().max(1) as f64
    }
}

/// Assigns every sample (step 2); returns the mean squared reconstruction error.
pub(crate) fn assign(x: &Samples, m: &Model, out: &mut Codes) -> f64 {
    let (d, c, k) = (m.d, m.c, m.k());
    let stride = c.max(1);
    let cols = k * c + k;
    let mut big = Mat::<f64>::zeros(d, cols);
    for j in 0..k {
        big.as_mut().subcols_mut(j * c, c).copy_from(&m.bases[j]);
        big.col_as_slice_mut(k * c + j).copy_from_slice(m.mean(j));
    }
    // ⟨rⱼ, eᵢⱼ⟩ and ‖rⱼ‖².
    let re: Vec<f64> = (0..k)
        .flat_map(|j| (0..c).map(move |i| (j, i)))
        .map(|(j, i)| dot(m.mean(j), m.bases[j].col_as_slice(i)))
        .collect();
    let rr: Vec<f64> = (0..k).map(|j| dot(m.mean(j), m.mean(j))).collect();
    let big = big.as_ref();
    out.labels
        .par_chunks_mut(ROWS)
        .zip(out.errors.par_chunks_mut(ROWS))
        .zip(out.weights.par_chunks_mut(ROWS * stride))
        .enumerate()
        .for_each_init(
            || Mat::<f64>::zeros(cols, ROWS),
            |p, (b, ((lab, err), wts))| {
                let r0 = b * ROWS;
                let w = lab.len();
                let xb = MatRef::from_column_major_slice(&x.values[r0 * d..(r0 + w) * d], d, w);
                faer::linalg::matmul::matmul(
                    p.as_mut().subcols_mut(0, w),
                    Accum::Replace,
                    big.transpose(),
                    xb,
                    1.0,
                    Par::Seq,
                );
                for i in 0..w {
                    let col = p.col_as_slice(i);
                    let xx = x.norms2[r0 + i];
                    let (mut best, mut best_err) = (0, f64::INFINITY);
                    for j in 0..k {
                        let dist2 = xx - 2.0 * col[k * c + j] + rr[j];
                        let proj: f64 = col[j * c..(j + 1) * c]
                            .iter()
                            .zip(&re[j * c..(j + 1) * c])
                            .map(|(a, b)| (a - b) * (a - b))
                            .sum();
                        if dist2 - proj < best_err {
                            best_err = dist2 - proj;
                            best = j;
                        }
                    }
                    lab[i] = best;
                    let mut proj = 0.0;
                    for l in 0..c {
                        let t = col[best * c + l] - re[best * c + l];
                        wts[i * stride + l] = t;
                        proj += t * t;
                    }
                    err[i] = (sq_dist(x.row(r0 + i), m.mean(best)) - proj).max(0.0);
                }
            },
        );
    out.mean_error()
}

/// Weights wᵢ = ⟨x − r, eᵢ⟩ and errors ‖(x − r) − E w‖² of every sample in its labelled
/// cluster, from explicit differences and residuals.
pub(crate) fn exact_codes(x: &Samples, m: &Model, codes: &mut Codes) {
    let c = m.c;
    codes
        .errors
        .par_iter_mut()
        .zip(codes.weights.par_chunks_mut(c.max(1)))
        .enumerate()
        .for_each(|(i, (err, w))| {
            let j = codes.labels[i];
            let diff: Vec<f64> = x.row(i).iter().zip(m.mean(j)).map(|(a, b)| a - b).collect();
            let basis = &m.bases[j];
            let mut resid = diff.clone();
            for (l, wl) in w.iter_mut().enumerate().take(c) {
                let e = basis.col_as_slice(l);
                *wl = dot(&diff, e);
                resid.iter_mut().zip(e).for_each(|(r, e)| *r -= *wl * e);
            }
            *err = dot(&resid, &resid);
        });
}
