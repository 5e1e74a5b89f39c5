//! The two Lloyd steps (thesis §2.7.4): assign every sample to its nearest centroid, then move
//! each centroid to the mean of its samples (reseeding empty clusters).
//!
//! Assignment ranks centroids by ‖c‖² − 2⟨x, c⟩ from a faer GEMM over blocks of samples (the
//! data was translated to its mean first, so this has no cancellation to speak of) and then
//! recomputes the winner's squared distance from differences, so the reported inertia is exact.
//! Blocks are fixed-size and run on rayon; every output element depends only on its own block,
//! and every reduction runs in block order, so results do not depend on the thread count.

use faer::{Accum, Mat, MatRef, Par};
use rayon::prelude::*;

use crate::element::Samples;
use crate::linalg::{dot, sq_dist};

/// Samples per assignment block: a 256 × d block and its 256 × k scores stay in L2.
const ASSIGN_ROWS: usize = 256;
/// Samples per partial sum in the centroid update.
const UPDATE_ROWS: usize = 4096;

/// Assigns every sample to its nearest center (ties → lowest index). `centers` is row-major
/// k × d. Writes labels and exact squared distances; returns the inertia (eq. 2.54).
pub(crate) fn assign(x: &Samples, centers: &[f64], labels: &mut [usize], dist2: &mut [f64]) -> f64 {
    let d = x.d;
    let k = centers.len() / d;
    let cmat = MatRef::from_column_major_slice(centers, d, k); // d × k
    let cc: Vec<f64> = centers.chunks_exact(d).map(|c| dot(c, c)).collect();
    labels
        .par_chunks_mut(ASSIGN_ROWS)
        .zip(dist2.par_chunks_mut(ASSIGN_ROWS))
        .enumerate()
        .for_each_init(
            || Mat::<f64>::zeros(k, ASSIGN_ROWS),
            |scores, (b, (lab, dst))| {
                let r0 = b * ASSIGN_ROWS;
                let w = lab.len();
                let xb = MatRef::from_column_major_slice(&x.values[r0 * d..(r0 + w) * d], d, w);
                faer::linalg::matmul::matmul(
                    scores.as_mut().subcols_mut(0, w),
                    Accum::Replace,
                    cmat.transpose(),
                    xb,
                    1.0,
                    Par::Seq,
                );
                for i in 0..w {
                    let col = scores.col_as_slice(i);
                    let mut best = 0;
                    let mut best_score = f64::INFINITY;
                    for (j, (&c, &s)) in cc.iter().zip(col).enumerate() {
                        let score = c - 2.0 * s;
                        if score < best_score {
                            best_score = score;
                            best = j;
                        }
                    }
                    lab[i] = best;
                    dst[i] = sq_dist(x.row(r0 + i), &centers[best * d..(best + 1) * d]);
                }
            },
        );
    dist2.iter().sum()
}

/// Per-cluster sums and counts, reduced in block order.
fn cluster_sums(x: &Samples, labels: &[usize], k: usize) -> (Vec<f64>, Vec<usize>) {
    let d = x.d;
    let parts: Vec<(Vec<f64>, Vec<usize>)> = labels
        .par_chunks(UPDATE_ROWS)
        .enumerate()
        .map(|(b, lab)| {
            let mut sums = vec![0.0; k * d];
            let mut counts = vec![0usize; k];
            for (i, &l) in lab.iter().enumerate() {
                counts[l] += 1;
                let s = &mut sums[l * d..(l + 1) * d];
                s.iter_mut()
                    .zip(x.row(b * UPDATE_ROWS + i))
                    .for_each(|(a, v)| *a += v);
            }
            (sums, counts)
        })
        .collect();
    let mut sums = vec![0.0; k * d];
    let mut counts = vec![0usize; k];
    for (s, c) in parts {
        sums.iter_mut().zip(&s).for_each(|(a, v)| *a += v);
        counts.iter_mut().zip(&c).for_each(|(a, v)| *a += v);
    }
    (sums, counts)
}

/// Moves every center to the mean of its samples. An empty cluster takes the worst-served
/// sample (largest squared distance to its center, > 0), which leaves its old cluster; with
/// several empty clusters they take the worst, second worst, … sample. A cluster that finds
/// no such sample (fewer distinct points than clusters) keeps its center and stays empty.
/// Updates `labels` for moved samples. Returns the number of reseeded clusters.
pub(crate) fn update(
    x: &Samples,
    labels: &mut [usize],
    dist2: &[f64],
    centers: &mut [f64],
) -> usize {
    let d = x.d;
    let k = centers.len() / d;
    let (mut sums, mut counts) = cluster_sums(x, labels, k);
    let empty: Vec<usize> = (0..k).filter(|&j| counts[j] == 0).collect();
    let mut reseeded = 0;
    if !empty.is_empty() {
        let mut order: Vec<usize> = (0..x.n).filter(|&i| dist2[i] > 0.0).collect();
        // Largest distance first; ties by index, so the order is deterministic.
        order.sort_by(|&a, &b| dist2[b].total_cmp(&dist2[a]).then(a.cmp(&b)));
        let mut candidates = order.into_iter();
        for j in empty {
            let Some(i) = candidates.by_ref().find(|&i| counts[labels[i]] > 1) else {
                break;
            };
            let old = labels[i];
            counts[old] -= 1;
            sums[old * d..(old + 1) * d]
                .iter_mut()
                .zip(x.row(i))
                .for_each(|(a, v)| *a -= v);
            counts[j] = 1;
            sums[j * d..(j + 1) * d].copy_from_slice(x.row(i));
            labels[i] = j;
            reseeded += 1;
        }
    }
    for j in 0..k {
        if counts[j] > 0 {
            let inv = 1.0 / counts[j] as f64;
            centers[j * d..(j + 1) * d]
                .iter_mut()
                .zip(&sums[j * d..(j + 1) * d])
                .for_each(|(c, s)| *c = s * inv);
        }
    }
    reseeded
}
