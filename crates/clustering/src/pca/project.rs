//! Projection onto the principal axes and reconstruction (thesis eq. 3.15 with the mean:
//! x ≈ x̄ + Σᵢ wᵢ eᵢ, wᵢ = ⟨x − x̄, eᵢ⟩).

use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::Pca;
use crate::element::{Element, Layout, copy_block};
use crate::error::{ClusteringError, Result};

/// Samples per parallel task.
const ROWS: usize = 256;

impl Pca {
    fn check_features(&self, what: &'static str, d: usize) -> Result<()> {
        if d != self.n_features() {
            return Err(ClusteringError::DimensionMismatch {
                what,
                expected: self.n_features(),
                found: d,
            });
        }
        Ok(())
    }

    /// Runs `f(first_row, centred block (row-major w × d), weights block (w × c))` over row
    /// blocks in parallel and collects the results in order.
    fn blocks<T: Element, R: Send>(
        &self,
        what: &'static str,
        data: MatRef<'_, T>,
        f: impl Fn(usize, &[f64], MatRef<'_, f64>) -> R + Sync,
    ) -> Result<Vec<R>> {
        let (n, d) = (data.nrows(), data.ncols());
        self.check_features(what, d)?;
        let c = self.n_components();
        (0..n.div_ceil(ROWS))
            .into_par_iter()
            .map(|b| {
                let rows = b * ROWS..((b + 1) * ROWS).min(n);
                let w = rows.len();
                let mut buf = vec![0.0; w * d];
                copy_block(what, data, rows, 0..d, &mut buf, Layout::RowMajor)?;
                for x in buf.chunks_exact_mut(d) {
                    x.iter_mut().zip(&self.mean).for_each(|(v, m)| *v -= m);
                }
                let mut weights = Mat::<f64>::zeros(w, c);
                let xt = MatRef::from_column_major_slice(&buf, d, w);
                faer::linalg::matmul::matmul(
                    weights.as_mut(),
                    Accum::Replace,
                    xt.transpose(),
                    self.components(),
                    1.0,
                    Par::Seq,
                );
                Ok(f(b * ROWS, &buf, weights.as_ref()))
            })
            .collect()
    }

    /// Weights wᵢ = ⟨x − x̄, eᵢ⟩ of every row of `data` (n × d) on the kept axes: n × c.
    ///
    /// # Errors
    /// [`ClusteringError::DimensionMismatch`] if `data` has not d columns,
    /// [`ClusteringError::NonFinite`] for NaN/∞ entries.
    pub fn project<T: Element>(&self, data: MatRef<'_, T>) -> Result<Mat<f64>> {
        let parts = self.blocks("Pca::project data", data, |_, _, w| w.to_owned())?;
        let mut out = Mat::<f64>::zeros(data.nrows(), self.n_components());
        let mut row = 0;
        for p in parts {
            out.as_mut().subrows_mut(row, p.nrows()).copy_from(&p);
            row += p.nrows();
        }
        Ok(out)
    }

    /// Samples x̃ = x̄ + W Eᵀ from weights `weights` (n × c′ with c′ ≤ c: the leading c′ axes).
    ///
    /// # Errors
    /// [`ClusteringError::DimensionMismatch`] if `weights` has more columns than components.
    pub fn reconstruct(&self, weights: MatRef<'_, f64>) -> Result<Mat<f64>> {
        let c = weights.ncols();
        if c > self.n_components() {
            return Err(ClusteringError::DimensionMismatch {
                what: "Pca::reconstruct weights",
                expected: self.n_components(),
                found: c,
            });
        }
        let n = weights.nrows();
        let mut out = Mat::from_fn(n, self.n_features(), |_, j| self.mean[j]);
        faer::linalg::matmul::matmul(
            out.as_mut(),
            Accum::Add,
            weights,
            self.components().subcols(0, c).transpose(),
            1.0,
            Par::rayon(0),
        );
        Ok(out)
    }

    /// Σᵢ ‖xᵢ − x̃ᵢ‖², the squared reconstruction error of `data` with the kept components,
    /// computed from explicit residuals in f64 (not as total minus captured variance).
    ///
    /// # Errors
    /// As [`Pca::project`].
    pub fn squared_error<T: Element>(&self, data: MatRef<'_, T>) -> Result<f64> {
        let d = data.ncols();
        let comps = self.components();
        let parts = self.blocks("Pca::squared_error data", data, |_, buf, w| {
            let mut resid = buf.to_vec();
            let mut r = faer::MatMut::from_column_major_slice_mut(&mut resid, d, w.nrows());
            faer::linalg::matmul::matmul(
                r.as_mut(),
                Accum::Add,
                comps,
                w.transpose(),
                -1.0,
                Par::Seq,
            );
            crate::linalg::dot(&resid, &resid)
        })?;
        Ok(parts.iter().sum())
    }
}
