//! Dead-end avoidance: the "core" of the jump map and the pruned sampling matrix.
//!
//! Video textures (Schödl et al. 2000, cited in thesis §3.2.1) avoid dead ends by anticipating
//! future cost. Here the same goal is reached with a reachability pass, which is exact for the
//! question that matters ("can the run always get back to the rest of the clip?"):
//!
//! 1. The *significant* graph has an edge i → j when P̂_ij ≥ [`SIGNIFICANT_FRACTION`] · max_j P̂_ij.
//!    Natural successors are always in it (their probability is the row maximum).
//! 2. Its largest strongly connected component is the *core* (ties: the one holding the
//!    lowest frame). From every core frame every other core frame is reachable, so a run
//!    inside the core can never be trapped in a corner of the clip (e.g. the last few frames).
//! 3. Sampling matrix: a core frame may only jump into the core; a frame outside the core may
//!    only jump to frames from which the core is reachable (so every run enters the core and
//!    stays); a frame with no such significant edge jumps straight into the core, to its most
//!    probable core target (or, if all those probabilities underflowed, uniformly).
//!
//! Frames outside the core (a lead-in before a cycle, a clip end that matches nothing) are
//! therefore played only on the way into the core, never again.

use super::cells::Layout;
use crate::matrix::SquareMatrix;

/// An edge i → j is significant when P̂_ij is at least this fraction of row i's maximum.
/// Chosen, not tuned: 1e-3 ≈ e^{−6.9}, so with q = q* = 0 an edge counts when its shifted
/// distances exceed the row's best by at most about 6.9·σ in total (0.35 mean distances at
/// σ = 0.05). The horse gallop's closing jump (distance 0) is far inside this.
pub const SIGNIFICANT_FRACTION: f64 = 1e-3;

/// Result of the reachability pass.
pub(crate) struct Pruned {
    pub sampling: SquareMatrix,
    pub in_core: Vec<bool>,
}

/// [`prune`] cell by cell (see [`JumpMap::analyze_cells`](super::JumpMap::analyze_cells)): each cell gets its own core and the
/// sampling matrix is block-diagonal, so random play stays inside its cell. Crossing into
/// another cell is the player's motion control, never a random draw.
pub(crate) fn prune_cells(p_hat: &SquareMatrix, layout: &Layout) -> Pruned {
    if layout.ranges().len() == 1 {
        return prune(p_hat);
    }
    let l = p_hat.n();
    let mut sampling = SquareMatrix::zeros(l);
    let mut in_core = vec![false; l];
    for r in layout.ranges() {
        let mut sub = SquareMatrix::from_fn(r.len(), |a, b| p_hat.get(r.start + a, r.start + b));
        for a in 0..r.len() {
            super::probability::normalise_row(sub.row_mut(a));
        }
        let part = prune(&sub);
        for a in 0..r.len() {
            sampling.row_mut(r.start + a)[r.clone()].copy_from_slice(part.sampling.row(a));
            in_core[r.start + a] = part.in_core[a];
        }
    }
    Pruned { sampling, in_core }
}

/// Computes the core and the pruned sampling matrix of the row-normalised jump map `p_hat`.
pub(crate) fn prune(p_hat: &SquareMatrix) -> Pruned {
    let l = p_hat.n();
    let adj: Vec<Vec<usize>> = (0..l)
        .map(|i| {
            let row = p_hat.row(i);
            let max = row.iter().copied().fold(0.0, f64::max);
            (0..l)
                .filter(|&j| row[j] > 0.0 && row[j] >= SIGNIFICANT_FRACTION * max)
                .collect()
        })
        .collect();
    let comp = strongly_connected(&adj);
    let n_comp = comp.iter().max().map_or(0, |m| m + 1);
    let mut size = vec![0usize; n_comp];
    let mut lowest = vec![usize::MAX; n_comp];
    for (i, &c) in comp.iter().enumerate() {
        size[c] += 1;
        lowest[c] = lowest[c].min(i);
    }
    let core_id = (0..n_comp)
        .max_by(|&a, &b| size[a].cmp(&size[b]).then(lowest[b].cmp(&lowest[a])))
        .unwrap_or(0);
    let in_core: Vec<bool> = comp.iter().map(|&c| c == core_id).collect();

    // Frames from which the core is reachable over significant edges (reverse BFS).
    let mut radj = vec![Vec::new(); l];
    for (i, out) in adj.iter().enumerate() {
        for &j in out {
            radj[j].push(i);
        }
    }
    let mut reaches = in_core.clone();
    let mut queue: Vec<usize> = (0..l).filter(|&i| in_core[i]).collect();
    while let Some(j) = queue.pop() {
        for &i in &radj[j] {
            if !reaches[i] {
                reaches[i] = true;
                queue.push(i);
            }
        }
    }

    let mut sampling = SquareMatrix::zeros(l);
    for i in 0..l {
        let allowed: &[bool] = if in_core[i] { &in_core } else { &reaches };
        let src = p_hat.row(i);
        let row = sampling.row_mut(i);
        for j in 0..l {
            if allowed[j] {
                row[j] = src[j];
            }
        }
        if row.iter().sum::<f64>() <= 0.0 {
            let best = (0..l)
                .filter(|&j| in_core[j] && j != i)
                .max_by(|&a, &b| src[a].total_cmp(&src[b]).then(b.cmp(&a)));
            match best {
                Some(j) if src[j] > 0.0 => row[j] = 1.0,
                _ => {
                    for j in (0..l).filter(|&j| in_core[j] && j != i) {
                        row[j] = 1.0;
                    }
                }
            }
        }
        super::probability::normalise_row(row);
    }
    Pruned { sampling, in_core }
}

/// Component id of every node (Kosaraju, iterative: no recursion depth limit on long clips).
fn strongly_connected(adj: &[Vec<usize>]) -> Vec<usize> {
    let n = adj.len();
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    for s in 0..n {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        let mut stack = vec![(s, 0usize)];
        while let Some((v, k)) = stack.pop() {
            if k < adj[v].len() {
                stack.push((v, k + 1));
                let w = adj[v][k];
                if !seen[w] {
                    seen[w] = true;
                    stack.push((w, 0));
                }
            } else {
                order.push(v);
            }
        }
    }
    let mut radj = vec![Vec::new(); n];
    for (v, out) in adj.iter().enumerate() {
        for &w in out {
            radj[w].push(v);
        }
    }
    let mut comp = vec![usize::MAX; n];
    let mut next = 0;
    for &s in order.iter().rev() {
        if comp[s] != usize::MAX {
            continue;
        }
        comp[s] = next;
        let mut stack = vec![s];
        while let Some(v) = stack.pop() {
            for &w in &radj[v] {
                if comp[w] == usize::MAX {
                    comp[w] = next;
                    stack.push(w);
                }
            }
        }
        next += 1;
    }
    comp
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scc_of_chain_with_back_edge() {
        // 0 → 1 → 2 → 3 → 1, 3 → 4 (4 has no way back).
        let adj = vec![vec![1], vec![2], vec![3], vec![1, 4], vec![4]];
        let c = strongly_connected(&adj);
        assert_eq!(c[1], c[2]);
        assert_eq!(c[2], c[3]);
        assert_ne!(c[0], c[1]);
        assert_ne!(c[4], c[1]);
    }
}
