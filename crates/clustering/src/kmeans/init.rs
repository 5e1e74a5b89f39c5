//! Initial centroids: greedy k-means++ (Arthur & Vassilvitskii 2007, with the 2 + ⌊ln k⌋ local
//! trials per step that scikit-learn uses) refined by local search (Lattanzi & Sohler 2019), or
//! k distinct random samples (the thesis, §2.7.4: "completely random chosen").

use rand::Rng;
use rayon::prelude::*;

use crate::element::Samples;
use crate::linalg::{sq_dist, uniform_index, uniform01};

/// Samples per parallel task (and per GEMM) when computing distances to candidates.
const ROWS: usize = 512;

/// Squared distances of every sample to each of the T points `pts` (row-major T × d), written
/// row-major n × T: ‖x‖² − 2⟨x, p⟩ + ‖p‖² from a faer GEMM per block of samples (runtime SIMD
/// dispatch; the samples are translated to their mean, so there is no cancellation to speak
/// of), clamped at 0. Used for seeding, where only the ranking and sums of D² matter.
fn sq_dists_to(x: &Samples, pts: &[f64], out: &mut [f64]) {
    use faer::{Accum, Mat, MatRef, Par};
    let d = x.d;
    let t = pts.len() / d;
    let p = MatRef::from_column_major_slice(pts, d, t);
    let pp: Vec<f64> = pts
        .chunks_exact(d)
        .map(|q| crate::linalg::dot(q, q))
        .collect();
    out.par_chunks_mut(ROWS * t).enumerate().for_each_init(
        || Mat::<f64>::zeros(t, ROWS),
        |dots, (b, o)| {
            let r0 = b * ROWS;
            let w = o.len() / t;
            let xb = MatRef::from_column_major_slice(&x.values[r0 * d..(r0 + w) * d], d, w);
            faer::linalg::matmul::matmul(
                dots.as_mut().subcols_mut(0, w),
                Accum::Replace,
                p.transpose(),
                xb,
                1.0,
                Par::Seq,
            );
            for (i, row) in o.chunks_exact_mut(t).enumerate() {
                let xx = x.norms2[r0 + i];
                for ((v, dot), q) in row.iter_mut().zip(dots.col_as_slice(i)).zip(&pp) {
                    *v = (xx - 2.0 * dot + q).max(0.0);
                }
            }
        },
    );
}

/// k distinct samples drawn uniformly (partial Fisher–Yates), as a row-major k × d matrix.
pub(crate) fn random_samples(x: &Samples, k: usize, rng: &mut impl Rng) -> Vec<f64> {
    let mut idx: Vec<usize> = (0..x.n).collect();
    let mut centers = Vec::with_capacity(k * x.d);
    for j in 0..k {
        let r = j + uniform_index(rng, x.n - j);
        idx.swap(j, r);
        centers.extend_from_slice(x.row(idx[j]));
    }
    centers
}

/// Index drawn with probability proportional to `weights` (prefix sums + binary search);
/// uniform when all weights are zero.
fn draw(prefix: &[f64], rng: &mut impl Rng) -> usize {
    let total = prefix.last().copied().unwrap_or(0.0);
    if total <= 0.0 {
        return uniform_index(rng, prefix.len());
    }
    let u = uniform01(rng) * total;
    prefix.partition_point(|&p| p <= u).min(prefix.len() - 1)
}

/// Greedy k-means++: each new center is the best (lowest potential) of `2 + ⌊ln k⌋`
/// candidates drawn with probability ∝ D(x)², the squared distance to the nearest center so
/// far. Returns a row-major k × d matrix.
pub(crate) fn plus_plus(x: &Samples, k: usize, rng: &mut impl Rng) -> Vec<f64> {
    let (n, d) = (x.n, x.d);
    let trials = 2 + (k as f64).ln().floor() as usize;
    let mut centers = Vec::with_capacity(k * d);
    let first = uniform_index(rng, n);
    centers.extend_from_slice(x.row(first));
    let mut closest = vec![0.0; n];
    sq_dists_to(x, x.row(first), &mut closest);
    let mut prefix = vec![0.0; n];
    let mut trial = vec![0.0; n * trials];
    let mut pts = vec![0.0; trials * d];
    for _ in 1..k {
        let mut acc = 0.0;
        for (p, c) in prefix.iter_mut().zip(&closest) {
            acc += c;
            *p = acc;
        }
        let cand: Vec<usize> = (0..trials).map(|_| draw(&prefix, rng)).collect();
        for (dst, &c) in pts.chunks_exact_mut(d).zip(&cand) {
            dst.copy_from_slice(x.row(c));
        }
        sq_dists_to(x, &pts, &mut trial);
        trial
            .par_chunks_mut(trials)
            .zip(closest.par_iter())
            .for_each(|(row, &c)| row.iter_mut().for_each(|v| *v = v.min(c)));
        let mut pots = vec![0.0; trials];
        for row in trial.chunks_exact(trials) {
            pots.iter_mut().zip(row).for_each(|(p, v)| *p += v);
        }
        let best = (0..trials).fold(0, |b, t| if pots[t] < pots[b] { t } else { b });
        closest
            .iter_mut()
            .zip(trial.chunks_exact(trials))
            .for_each(|(c, row)| *c = row[best]);
        centers.extend_from_slice(x.row(cand[best]));
    }
    centers
}

/// Nearest and second-nearest center of one sample.
#[derive(Clone, Copy)]
struct Near {
    d1: f64,
    d2: f64,
    n1: usize,
    n2: usize,
}

/// Nearest two centers from a row of squared distances.
fn top_two(dists: &[f64]) -> Near {
    let mut n = Near {
        d1: f64::INFINITY,
        d2: f64::INFINITY,
        n1: 0,
        n2: 0,
    };
    for (j, &e) in dists.iter().enumerate() {
        if e < n.d1 {
            (n.d2, n.n2) = (n.d1, n.n1);
            (n.d1, n.n1) = (e, j);
        } else if e < n.d2 {
            (n.d2, n.n2) = (e, j);
        }
    }
    n
}

/// Nearest two centers of sample `p` (exact differences).
fn near(p: &[f64], centers: &[f64], d: usize) -> Near {
    let mut n = Near {
        d1: f64::INFINITY,
        d2: f64::INFINITY,
        n1: 0,
        n2: 0,
    };
    for (j, c) in centers.chunks_exact(d).enumerate() {
        let e = sq_dist(p, c);
        if e < n.d1 {
            (n.d2, n.n2) = (n.d1, n.n1);
            (n.d1, n.n1) = (e, j);
        } else if e < n.d2 {
            (n.d2, n.n2) = (e, j);
        }
    }
    n
}

/// Local search after seeding (Lattanzi & Sohler 2019, "A better k-means++ algorithm via local
/// search"): `steps` times, draw a candidate ∝ D(x)² and swap it with the center whose
/// replacement lowers the potential most, if any does. Repairs the typical k-means++ failure of
/// two seeds in one blob and none in another, which Lloyd cannot undo. Each step costs two
/// distance passes (n·d) plus a nearest-center refresh for the samples that lost theirs.
pub(crate) fn local_search(x: &Samples, centers: &mut [f64], steps: usize, rng: &mut impl Rng) {
    let (n, d) = (x.n, x.d);
    let k = centers.len() / d;
    if k < 2 || steps == 0 {
        return;
    }
    let mut all = vec![0.0; n * k];
    sq_dists_to(x, centers, &mut all);
    let mut nears: Vec<Near> = all.par_chunks(k).map(top_two).collect();
    drop(all);
    let mut prefix = vec![0.0; n];
    let mut extra = vec![0.0; k];
    let mut dp = vec![0.0; n];
    for _ in 0..steps {
        let mut acc = 0.0;
        for (p, s) in prefix.iter_mut().zip(&nears) {
            acc += s.d1;
            *p = acc;
        }
        if acc <= 0.0 {
            return;
        }
        let cand = draw(&prefix, rng);
        sq_dists_to(x, x.row(cand), &mut dp);
        // Potential after adding the candidate, and the extra cost of then removing center i.
        let mut base = 0.0;
        extra.iter_mut().for_each(|e| *e = 0.0);
        for (s, &e) in nears.iter().zip(&dp) {
            let with = s.d1.min(e);
            base += with;
            extra[s.n1] += s.d2.min(e) - with;
        }
        let best = (0..k).fold(0, |b, i| if extra[i] < extra[b] { i } else { b });
        if base + extra[best] >= acc {
            continue;
        }
        centers[best * d..(best + 1) * d].copy_from_slice(x.row(cand));
        nears
            .par_iter_mut()
            .zip(dp.par_iter())
            .enumerate()
            .for_each(|(i, (s, &e))| {
                if s.n1 == best || s.n2 == best {
                    *s = near(x.row(i), centers, d);
                } else if e < s.d1 {
                    *s = Near {
                        d1: e,
                        d2: s.d1,
                        n1: best,
                        n2: s.n1,
                    };
                } else if e < s.d2 {
                    *s = Near {
                        d2: e,
                        n2: best,
                        ..*s
                    };
                }
            });
    }
}
