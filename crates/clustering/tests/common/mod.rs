//! Test helpers: seeded data and f64 brute-force references that share no code with the crate.
#![allow(dead_code)]

use faer::Mat;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

pub fn uniform(r: &mut ChaCha8Rng) -> f64 {
    (r.next_u64() >> 11) as f64 / (1u64 << 53) as f64
}

pub fn normal(r: &mut ChaCha8Rng) -> f64 {
    let u1 = 1.0 - uniform(r);
    let u2 = uniform(r);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// n × d Gaussian data with per-feature scales `scale(j)`.
pub fn gaussian(n: usize, d: usize, seed: u64, scale: impl Fn(usize) -> f64) -> Mat<f64> {
    let mut r = rng(seed);
    let mut m = Mat::zeros(n, d);
    for i in 0..n {
        for j in 0..d {
            m[(i, j)] = normal(&mut r) * scale(j);
        }
    }
    m
}

/// Low-rank-plus-noise data: n samples of rank `r` structure in d dimensions, with a mean.
pub fn low_rank(n: usize, d: usize, rank: usize, noise: f64, seed: u64) -> Mat<f64> {
    let mut g = rng(seed);
    let basis = Mat::from_fn(rank, d, |_, _| normal(&mut g));
    let coef = Mat::from_fn(n, rank, |_, j| {
        normal(&mut g) * 2f64.powi(-(j as i32)) * 10.0
    });
    let mut x = &coef * &basis;
    for i in 0..n {
        for j in 0..d {
            x[(i, j)] += noise * normal(&mut g) + (j as f64) * 0.5;
        }
    }
    x
}

/// Two-pass f64 mean of the rows.
pub fn mean_rows(x: &Mat<f64>) -> Vec<f64> {
    let (n, d) = (x.nrows(), x.ncols());
    let mut m = vec![0.0; d];
    for j in 0..d {
        let s: f64 = (0..n).map(|i| x[(i, j)]).sum::<f64>() / n as f64;
        let fix: f64 = (0..n).map(|i| x[(i, j)] - s).sum::<f64>() / n as f64;
        m[j] = s + fix;
    }
    m
}

/// Brute-force covariance (eq. 2.46) in f64.
pub fn covariance(x: &Mat<f64>) -> Mat<f64> {
    let (n, d) = (x.nrows(), x.ncols());
    let m = mean_rows(x);
    let mut c = Mat::zeros(d, d);
    for a in 0..d {
        for b in 0..d {
            c[(a, b)] = (0..n)
                .map(|i| (x[(i, a)] - m[a]) * (x[(i, b)] - m[b]))
                .sum::<f64>()
                / (n.max(2) - 1) as f64;
        }
    }
    c
}

/// Cyclic Jacobi eigen-decomposition of a symmetric matrix: (eigenvalues descending,
/// eigenvectors as columns). Independent of faer's algorithms.
pub fn jacobi_eigen(a: &Mat<f64>) -> (Vec<f64>, Mat<f64>) {
    let n = a.nrows();
    let mut a = a.clone();
    let mut v = Mat::<f64>::identity(n, n);
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .filter(|(i, j)| i != j)
            .map(|(i, j)| a[(i, j)] * a[(i, j)])
            .sum();
        if off < 1e-30 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                if a[(p, q)].abs() < 1e-300 {
                    continue;
                }
                let theta = (a[(q, q)] - a[(p, p)]) / (2.0 * a[(p, q)]);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[(k, p)], a[(k, q)]);
                    a[(k, p)] = c * akp - s * akq;
                    a[(k, q)] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[(p, k)], a[(q, k)]);
                    a[(p, k)] = c * apk - s * aqk;
                    a[(q, k)] = s * apk + c * aqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[(k, p)], v[(k, q)]);
                    v[(k, p)] = c * vkp - s * vkq;
                    v[(k, q)] = s * vkp + c * vkq;
                }
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| a[(j, j)].total_cmp(&a[(i, i)]));
    let values = order.iter().map(|&i| a[(i, i)]).collect();
    let vectors = Mat::from_fn(n, n, |r, c| v[(r, order[c])]);
    (values, vectors)
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

pub fn sq_dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

pub fn row(x: &Mat<f64>, i: usize) -> Vec<f64> {
    (0..x.ncols()).map(|j| x[(i, j)]).collect()
}

pub fn col(x: faer::MatRef<'_, f64>, j: usize) -> Vec<f64> {
    (0..x.nrows()).map(|i| x[(i, j)]).collect()
}

/// |a − b| ≤ tol, with a message.
#[track_caller]
pub fn assert_close(a: f64, b: f64, tol: f64, what: &str) {
    assert!(
        (a - b).abs() <= tol,
        "{what}: {a} vs {b} (|diff| = {:e} > tol {tol:e})",
        (a - b).abs()
    );
}

/// Max |a − b| over two matrices of the same shape.
pub fn max_abs_diff(a: faer::MatRef<'_, f64>, b: faer::MatRef<'_, f64>) -> f64 {
    assert_eq!((a.nrows(), a.ncols()), (b.nrows(), b.ncols()));
    let mut m = 0.0f64;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            m = m.max((a[(i, j)] - b[(i, j)]).abs());
        }
    }
    m
}

/// Max |x| of a matrix.
pub fn max_abs(a: faer::MatRef<'_, f64>) -> f64 {
    let mut m = 0.0f64;
    for i in 0..a.nrows() {
        for j in 0..a.ncols() {
            m = m.max(a[(i, j)].abs());
        }
    }
    m
}

/// Runs `f` on a rayon pool with `threads` threads.
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool")
        .install(f)
}

/// Samples from `blobs` Gaussian blobs: (data, true labels).
pub fn blobs(
    sizes: &[usize],
    d: usize,
    spread: f64,
    separation: f64,
    seed: u64,
) -> (Mat<f64>, Vec<usize>) {
    let mut r = rng(seed);
    let centers: Vec<Vec<f64>> = sizes
        .iter()
        .map(|_| {
            (0..d)
                .map(|_| (uniform(&mut r) - 0.5) * separation)
                .collect()
        })
        .collect();
    let n: usize = sizes.iter().sum();
    let mut x = Mat::zeros(n, d);
    let mut labels = Vec::with_capacity(n);
    let mut i = 0;
    for (b, &s) in sizes.iter().enumerate() {
        for _ in 0..s {
            for j in 0..d {
                x[(i, j)] = centers[b][j] + spread * normal(&mut r);
            }
            labels.push(b);
            i += 1;
        }
    }
    (x, labels)
}

/// Whether two labelings describe the same partition.
pub fn same_partition(a: &[usize], b: &[usize]) -> bool {
    let mut map = std::collections::HashMap::new();
    let mut inv = std::collections::HashMap::new();
    a.iter()
        .zip(b)
        .all(|(x, y)| *map.entry(x).or_insert(y) == y && *inv.entry(y).or_insert(x) == x)
}
