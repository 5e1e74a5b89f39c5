//! Distances and transition probabilities: thesis §3.2.2, eqs. 3.2, 3.3, 3.5, 3.6, 3.8.
//!
//! * D_ij = Σ_k |w_ik − w_jk| (eq. 3.2, L1 on the PCA weights), likewise D*_ij on the velocity
//!   weights (eq. 3.5). Both are divided by their mean off-diagonal entry (see
//!   `normalise_by_mean_off_diagonal`), so σ = 0.05 means "5 % of a typical frame distance"
//!   on every sequence.
//! * P_ij ∝ exp(−D_{i+1,j}/σ) (eq. 3.3, 3.6): the jump i → j is likely when frame i+1, the
//!   frame that would naturally follow i, looks like j. The natural successor j = i+1 gets
//!   D_{i+1,i+1} = 0 and so the largest probability of its row.
//! * The last frame l−1 has no successor. Its row uses the *predecessor* of the target
//!   instead: P_{l−1,j} ∝ exp(−D_{l−1,j−1}/σ) for j ∈ 1..=l−2, "go on at j if the frame before
//!   j looks like the last frame" (j = 0 has no predecessor and j = l−1 would be a standstill,
//!   so both get 0). A cyclic clip whose last frame repeats frame 0 thus continues at frame 1.
//!   A 2-frame clip has no such j; its last row restarts at frame 0 with probability 1.
//!   With several cells ([`JumpMap::analyze_cells`](super::JumpMap::analyze_cells)) the last
//!   frame of every cell follows this rule, with "any j ≠ i whose predecessor is in j's own
//!   cell" in place of 1..=l−2, and D_{i,j−1} in place of D_{l−1,j−1}.
//! * Rows are computed as exp(−(D − D_min)/σ) before normalising, so σ → 0 leaves the best
//!   candidates (probability 1/#ties) and σ → ∞ (σ = +∞ is accepted) gives a uniform row;
//!   nothing overflows or divides by zero.

use super::cells::Layout;
use crate::matrix::SquareMatrix;

/// D_ij = Σ_k |w_ik − w_jk| for `weights` (l × c, row-major), accumulated in f64 (eq. 3.2).
pub(crate) fn l1_distances(weights: &[f64], l: usize, c: usize) -> SquareMatrix {
    let mut d = SquareMatrix::zeros(l);
    for i in 0..l {
        let wi = &weights[i * c..(i + 1) * c];
        for j in (i + 1)..l {
            let wj = &weights[j * c..(j + 1) * c];
            let s: f64 = wi.iter().zip(wj).map(|(a, b)| (a - b).abs()).sum();
            d.row_mut(i)[j] = s;
            d.row_mut(j)[i] = s;
        }
    }
    d
}

/// Divides `d` by its mean off-diagonal entry and returns that mean (the distance unit).
///
/// A clip whose frames are all equal (or a single-frame clip) has mean 0; `d` is then left all
/// zero and 0 is returned, so every transition becomes equally likely.
pub(crate) fn normalise_by_mean_off_diagonal(d: &mut SquareMatrix) -> f64 {
    let l = d.n();
    if l < 2 {
        return 0.0;
    }
    let sum: f64 = d.as_slice().iter().sum(); // the diagonal is 0
    let mean = sum / (l * (l - 1)) as f64;
    if mean > 0.0 && mean.is_finite() {
        for i in 0..l {
            for x in d.row_mut(i) {
                *x /= mean;
            }
        }
        mean
    } else {
        0.0
    }
}

/// The cost whose exponential gives P_ij (eq. 3.3): D_{i+1,j}, or D_{i,j−1} from the last
/// frame of a cell (the predecessor rule, see the module docs); 0 where neither exists.
pub(crate) fn shifted_cost(layout: &Layout, d: &SquareMatrix, i: usize, j: usize) -> f64 {
    if let Some(s) = layout.successor(i) {
        d.get(s, j)
    } else if let Some(p) = layout.predecessor(j) {
        d.get(i, p)
    } else {
        0.0
    }
}

/// P (eq. 3.3) or P* (eq. 3.6) from a normalised distance matrix and σ > 0 (may be +∞),
/// row-normalised, zero outside the candidates.
pub(crate) fn transition_probabilities(
    layout: &Layout,
    d: &SquareMatrix,
    sigma: f64,
) -> SquareMatrix {
    let l = d.n();
    let mut p = SquareMatrix::zeros(l);
    for i in 0..l {
        let min = (0..l)
            .filter(|&j| layout.is_candidate(i, j))
            .map(|j| shifted_cost(layout, d, i, j))
            .fold(f64::INFINITY, f64::min);
        let row = p.row_mut(i);
        for (j, x) in row.iter_mut().enumerate() {
            if layout.is_candidate(i, j) {
                let excess = shifted_cost(layout, d, i, j) - min;
                // excess ≥ 0 is finite; excess/∞ = 0 and 0/σ = 0, so this is never NaN.
                *x = (-(excess / sigma)).exp();
            }
        }
        normalise_row(row);
    }
    p
}

/// P̂_ij = [q + (1−q)P_ij][q* + (1−q*)P*_ij] (eq. 3.8), restricted to the candidates and
/// row-normalised for sampling (eq. 3.8's entries lie in [0, 1] but do not sum to 1).
pub(crate) fn jump_map(
    layout: &Layout,
    p: &SquareMatrix,
    pv: &SquareMatrix,
    q: f64,
    qv: f64,
) -> SquareMatrix {
    let l = p.n();
    let mut out = SquareMatrix::from_fn(l, |i, j| {
        if layout.is_candidate(i, j) {
            (q + (1.0 - q) * p.get(i, j)) * (qv + (1.0 - qv) * pv.get(i, j))
        } else {
            0.0
        }
    });
    for i in 0..l {
        let row = out.row_mut(i);
        if row.iter().sum::<f64>() > 0.0 {
            normalise_row(row);
        } else {
            // P and P* favour disjoint targets and q = q* = 0: fall back to P alone, whose
            // row always has mass (its best candidate has probability > 0).
            row.copy_from_slice(p.row(i));
        }
    }
    out
}

/// Scales a non-negative row to sum 1 (left as is when its sum is 0).
pub(crate) fn normalise_row(row: &mut [f64]) {
    let s: f64 = row.iter().sum();
    if s > 0.0 {
        for x in row {
            *x /= s;
        }
    }
}
