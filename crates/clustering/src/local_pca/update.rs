//! Steps 3–4 of clustered PCA (thesis §2.7.4): new centers rⱼ = mean of region j, and a new
//! basis per region by PCA.
//!
//! Each region's centred members are gathered into a d × nⱼ matrix Xⱼ and decomposed exactly
//! whenever that is affordable: thin SVD when one side is tiny (≤ 2(c + p)), otherwise the
//! eigen-decomposition of the cross-product matrix of the smaller side (the thesis's
//! "covariance matrix of the smaller part", §3.3.2) while that side is ≤ 1024. Larger regions
//! use subspace iteration on XⱼXⱼᵀ warm-started from the previous iteration's Ritz vectors and
//! converged to `subspace_tolerance` of the region's residual energy (see [`crate::subspace`]).
//!
//! Axes beyond a region's numerical rank (a region with ≤ c members, duplicate samples) are
//! zero columns with eigenvalue 0: the region then represents only its own affine hull, and
//! the error of any sample against it stays a true distance to that hull.

use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use super::model::Model;
use crate::element::Samples;
use crate::error::Result;
use crate::linalg::{fix_sign, gaussian_matrix, rng, thin_svd};
use crate::pca::numerical_rank;
use crate::subspace::{self, Stop};

/// Random stream of cold starts; the cluster index and iteration are mixed in.
const STREAM_COLD: u64 = 0x4c50_4341; // "LPCA"
/// Cap on subspace steps from a random start.
const COLD_STEPS: usize = 200;
/// Cap on subspace steps from a warm start (memberships changed little).
const WARM_STEPS: usize = 50;

/// Knobs of the per-region PCA.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RegionPca {
    pub oversample: usize,
    pub tolerance: f64,
    pub seed: u64,
}

/// Result for one region.
struct Region {
    mean: Vec<f64>,
    basis: Mat<f64>,
    eigenvalues: Vec<f64>,
    warm: Option<Mat<f64>>,
}

/// Recomputes the mean and basis of every region whose members changed since its last update
/// (an unchanged region's PCA would come out the same); empty regions keep their model.
/// `iteration` only salts cold-start seeds.
pub(crate) fn update(
    x: &Samples,
    labels: &[usize],
    m: &mut Model,
    p: RegionPca,
    iteration: usize,
) -> Result<()> {
    let k = m.k();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); k];
    for (i, &l) in labels.iter().enumerate() {
        members[l].push(i);
    }
    let warm = std::mem::take(&mut m.warm);
    let previous = std::mem::take(&mut m.members);
    let regions = members
        .par_iter()
        .zip(warm.into_par_iter())
        .enumerate()
        .map(|(j, (idx, warm))| {
            if idx.is_empty() || previous.get(j) == Some(idx) {
                return Ok(Err(warm));
            }
            region_pca(x, idx, m.c, warm, p, (j as u64) << 32 | iteration as u64).map(Ok)
        })
        .collect::<Result<Vec<_>>>()?;
    m.warm = vec![None; k];
    m.members = members;
    for (j, r) in regions.into_iter().enumerate() {
        // Err: the region kept its model (and its warm start).
        let r = match r {
            Ok(r) => r,
            Err(warm) => {
                m.warm[j] = warm;
                continue;
            }
        };
        m.means[j * m.d..(j + 1) * m.d].copy_from_slice(&r.mean);
        m.bases[j] = r.basis;
        m.eigenvalues[j] = r.eigenvalues;
        m.warm[j] = r.warm;
    }
    Ok(())
}

/// Mean (two-pass) and PCA of one region.
fn region_pca(
    x: &Samples,
    idx: &[usize],
    c: usize,
    warm: Option<Mat<f64>>,
    p: RegionPca,
    salt: u64,
) -> Result<Region> {
    const WHAT: &str = "LocalPca::fit region PCA";
    let (d, nj) = (x.d, idx.len());
    let inv = 1.0 / nj as f64;
    let mut mean = vec![0.0; d];
    idx.iter()
        .for_each(|&i| mean.iter_mut().zip(x.row(i)).for_each(|(m, v)| *m += v));
    mean.iter_mut().for_each(|m| *m *= inv);
    let mut fix = vec![0.0; d];
    idx.iter().for_each(|&i| {
        fix.iter_mut()
            .zip(x.row(i))
            .zip(&mean)
            .for_each(|((f, v), m)| *f += v - m)
    });
    mean.iter_mut().zip(&fix).for_each(|(m, f)| *m += f * inv);
    let mut xj = vec![0.0; d * nj];
    for (col, &i) in xj.chunks_exact_mut(d).zip(idx) {
        for ((o, v), m) in col.iter_mut().zip(x.row(i)).zip(&mean) {
            *o = v - m;
        }
    }
    let total = crate::linalg::dot(&xj, &xj);
    let raw = crate::pca::raw_energy(total, &mean, nj);
    let xm = MatRef::from_column_major_slice(&xj, d, nj);
    let b = (c + p.oversample).min(d).min(nj).max(c.min(d));
    let (sigma2, vectors, warm, cross) = if c == 0 || total == 0.0 {
        (vec![0.0; c], Mat::zeros(d, c), None, false)
    } else if nj.min(d) <= 2 * b {
        let (s, u, _) = thin_svd(WHAT, xm)?;
        let r = s.len().min(c);
        (
            s.iter().map(|s| s * s).collect(),
            u.as_ref().subcols(0, r).to_owned(),
            None,
            false,
        )
    } else if nj.min(d) <= EXACT_EIG_MAX_DIM {
        let (s2, v) = cross_product_pca(xm, c)?;
        (s2, v, None, true)
    } else {
        let (start, steps) = match warm {
            Some(w) if w.ncols() == b => (w, WARM_STEPS),
            _ => (
                gaussian_matrix(d, b, &mut rng(p.seed ^ salt, STREAM_COLD)),
                COLD_STEPS,
            ),
        };
        let stop = Stop {
            tolerance: p.tolerance,
            max_steps: steps,
        };
        let ritz = subspace::iterate(WHAT, start.as_ref(), c, total, stop, |q| {
            // XⱼXⱼᵀQ = Xⱼ (XⱼᵀQ).
            let mut z = Mat::<f64>::zeros(nj, q.ncols());
            faer::linalg::matmul::matmul(
                z.as_mut(),
                Accum::Replace,
                xm.transpose(),
                q,
                1.0,
                Par::Seq,
            );
            let mut y = Mat::<f64>::zeros(d, q.ncols());
            faer::linalg::matmul::matmul(y.as_mut(), Accum::Replace, xm, z.as_ref(), 1.0, Par::Seq);
            Ok(y)
        })?;
        let v = ritz.vectors.as_ref().subcols(0, c).to_owned();
        (ritz.values, v, Some(ritz.vectors), true)
    };
    let rank = numerical_rank(&sigma2, nj, d, raw, cross)
        .min(c)
        .min(vectors.ncols());
    let dof = (nj.max(2) - 1) as f64;
    let mut basis = Mat::<f64>::zeros(d, c);
    let mut eigenvalues = vec![0.0; c];
    for l in 0..rank {
        basis
            .col_as_slice_mut(l)
            .copy_from_slice(vectors.col_as_slice(l));
        fix_sign(basis.col_as_slice_mut(l));
        eigenvalues[l] = sigma2[l] / dof;
    }
    Ok(Region {
        mean,
        basis,
        eigenvalues,
        warm,
    })
}

/// Regions whose smaller side is at most this use the exact cross-product eigen-decomposition
/// (faer: ~50 ms for 600 × 600 on one core); larger ones use subspace iteration.
const EXACT_EIG_MAX_DIM: usize = 1024;

/// Exact PCA of the centred d × nⱼ region matrix through the cross-product matrix of its
/// smaller side (thesis §3.3.2): squared singular values (descending) and the leading c axes.
fn cross_product_pca(xm: MatRef<'_, f64>, c: usize) -> Result<(Vec<f64>, Mat<f64>)> {
    use faer::linalg::matmul::triangular::{self, BlockStructure};
    const WHAT: &str = "LocalPca::fit region PCA";
    let (d, nj) = (xm.nrows(), xm.ncols());
    let small = if nj <= d { xm.transpose() } else { xm };
    let s = small.nrows();
    let mut g = Mat::<f64>::zeros(s, s);
    triangular::matmul(
        g.as_mut(),
        BlockStructure::TriangularLower,
        Accum::Replace,
        small,
        BlockStructure::Rectangular,
        small.transpose(),
        BlockStructure::Rectangular,
        1.0,
        Par::Seq,
    );
    let (sigma2, u) = crate::linalg::sym_eigen_desc(WHAT, g.as_ref())?;
    let c = c.min(s);
    if nj > d {
        return Ok((sigma2, u.as_ref().subcols(0, c).to_owned()));
    }
    // Axes V = Xⱼ U Σ⁻¹ for positive σ²; zero columns beyond (cut by the rank test anyway).
    let mut v = Mat::<f64>::zeros(d, c);
    faer::linalg::matmul::matmul(
        v.as_mut(),
        Accum::Replace,
        xm,
        u.as_ref().subcols(0, c),
        1.0,
        Par::Seq,
    );
    for (l, s2) in sigma2.iter().enumerate().take(c) {
        let inv = if *s2 > 0.0 { 1.0 / s2.sqrt() } else { 0.0 };
        v.col_as_slice_mut(l).iter_mut().for_each(|x| *x *= inv);
    }
    Ok((sigma2, v))
}

/// Fills `m` with an empty model: zero bases (used before the first update).
pub(crate) fn empty_model(d: usize, c: usize, k: usize) -> Model {
    Model {
        d,
        c,
        means: vec![0.0; k * d],
        bases: vec![Mat::zeros(d, c); k],
        eigenvalues: vec![vec![0.0; c]; k],
        warm: vec![None; k],
        members: Vec::new(),
    }
}

/// Random orthonormal bases (the published initialisation: "c unity basis vectors" per
/// cluster), seeded.
pub(crate) fn random_bases(m: &mut Model, seed: u64) {
    let c = m.c.min(m.d);
    for (j, basis) in m.bases.iter_mut().enumerate() {
        if c == 0 {
            continue;
        }
        let g = gaussian_matrix(m.d, c, &mut rng(seed ^ ((j as u64) << 32), STREAM_COLD + 1));
        let q = crate::linalg::orthonormalize(g.as_ref());
        basis.as_mut().subcols_mut(0, c).copy_from(&q);
    }
}
