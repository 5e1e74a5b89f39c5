//! The environment decomposition for interactive rotation (thesis §5.5.2, eq. 5.13;
//! SEED-NOTES §4.6): the per-vertex binned environment W of every vertex, computed for A turns
//! δ_a = 2πa/A of the environment about the world's vertical axis, compressed by PCA into a
//! mean and e components, so that the environment at any δ costs one e-term sum per vertex:
//!
//! ```text
//! U(δ) ≈ Ū + Σ_k o_k(δ) E_k        (eq. 5.13; U = the W of all vertices, 243 numbers each)
//! ```
//!
//! The thesis decomposes U = γ* (3·c·n·N numbers); γ* is linear in W (eq. 5.11), so decomposing
//! W is the same decomposition, 81·3 numbers per vertex instead of 3·c·4, and γ* of the four
//! view slots follows per frame as it does without rotation.
//!
//! **Between the samples.** The seed leaves open how o_ak is interpolated between its 12°
//! samples. o_k(δ) is periodic in δ, and for an environment whose radiance has azimuthal
//! frequencies below A/2 every entry of U(δ) is a trigonometric polynomial of that degree
//! (W is linear in the radiance, and turning the map shifts each frequency's phase), so
//! **trigonometric interpolation** of the A samples (the DFT's series, [`EnvDecomposition::coefficient`])
//! reconstructs it exactly; with e = A (uncentred) or e = A − 1 (centred) the decomposition
//! then returns U(δ) to float rounding for every δ, not only at the samples. Real maps are not
//! band-limited; the error between the samples is measured in `cargo xtask repro btf-env`.
//!
//! **Centred or not.** The centred PCA keeps the mean over turns — the azimuthally averaged
//! environment, the series' constant term — exactly and spends the e components on what the
//! turn changes; the uncentred one spends its first component on the mean. Both are offered;
//! the repro measures both and the CLI uses the centred one (smaller error at every e there).
//!
//! ```
//! use btf::env::{EnvDecomposition, EnvLightWeights};
//! use glam::Vec3;
//!
//! // One vertex whose W(0) follows 1 + cos δ (a band-limited environment), A = 8 turns.
//! let turns = 8;
//! let samples: Vec<Vec<EnvLightWeights>> = (0..turns)
//!     .map(|a| {
//!         let delta = std::f32::consts::TAU * a as f32 / turns as f32;
//!         let mut w = EnvLightWeights::default();
//!         w.weights[0] = Vec3::splat(1.0 + delta.cos());
//!         vec![w]
//!     })
//!     .collect();
//! let dec = EnvDecomposition::build(&samples, 2, true)?;
//! let mut out = Vec::new();
//! dec.weights_at(1.0, &mut out); // between two samples
//! assert!((out[0].weights[0].x - (1.0 + 1f32.cos())).abs() < 1e-5);
//! # Ok::<(), btf::BtfError>(())
//! ```

use faer::{Mat, Side};
use glam::Vec3;
use rayon::prelude::*;

use super::EnvLightWeights;
use crate::error::{BtfError, Result};
use crate::sampling::DIRECTIONS;

/// Numbers per vertex in U: 81 measured directions × RGB.
const PER_VERTEX: usize = DIRECTIONS * 3;

/// Components whose eigenvalue is below this fraction of the largest carry only rounding noise
/// and are dropped (a turn-invariant environment has none in the centred PCA).
const RANK_EPS: f64 = 1e-12;

/// Entries of U per parallel chunk (all A rows of a chunk stay in cache).
const CHUNK: usize = 4096;

/// Ū, E_k and the samples o_ak of eq. 5.13 for one mesh (frames, visibility) and environment;
/// see the [module docs](self).
#[derive(Clone, Debug)]
pub struct EnvDecomposition {
    vertices: usize,
    turns: usize,
    centred: bool,
    /// Ū (zero when uncentred), N·243.
    mean: Vec<f32>,
    /// E_k, each N·243, unit length.
    components: Vec<Vec<f32>>,
    /// o_ak: `samples[k][a]`.
    samples: Vec<Vec<f32>>,
    /// λ_k of every component found (descending), kept or not: the energy e leaves out.
    eigenvalues: Vec<f64>,
    /// Fourier series of o_k: (a_f, b_f) for f = 0..=A/2 (b_0 = 0).
    series: Vec<Vec<(f64, f64)>>,
}

impl EnvDecomposition {
    /// Decomposes `samples[a]` = W of every vertex under the environment turned by
    /// δ_a = 2πa/A (A = `samples.len()`), keeping at most `components` (e) components;
    /// `centred` subtracts the mean over turns first. The PCA runs on the A × A Gram matrix
    /// (f64), so its cost is A² dot products of N·243 numbers.
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for fewer than 2 turns or e = 0,
    /// [`BtfError::LengthMismatch`] when the turns have different vertex counts, and
    /// [`BtfError::NonFinite`] for a NaN or infinite W.
    pub fn build(
        samples: &[Vec<EnvLightWeights>],
        components: usize,
        centred: bool,
    ) -> Result<Self> {
        const WHAT: &str = "EnvDecomposition::build";
        let turns = samples.len();
        if turns < 2 {
            return Err(BtfError::InvalidParameter {
                what: WHAT,
                name: "turns",
                value: turns.to_string(),
                reason: "needs at least 2 turns of the environment",
            });
        }
        if components == 0 {
            return Err(BtfError::InvalidParameter {
                what: WHAT,
                name: "components",
                value: "0".to_owned(),
                reason: "keep at least 1 component",
            });
        }
        let vertices = samples[0].len();
        if let Some(bad) = samples.iter().find(|s| s.len() != vertices) {
            return Err(BtfError::LengthMismatch {
                what: "EnvDecomposition::build: W of a turn",
                expected: vertices,
                found: bad.len(),
                hint: "every turn needs W of the same vertices",
            });
        }
        let mut rows: Vec<Vec<f32>> = samples.iter().map(|s| flatten(s)).collect();
        for (a, row) in rows.iter().enumerate() {
            if let Some(index) = row.iter().position(|x| !x.is_finite()) {
                return Err(BtfError::NonFinite {
                    what: format!("{WHAT}: W of turn {a}"),
                    index,
                    value: row[index],
                });
            }
        }
        let len = vertices * PER_VERTEX;
        let mut mean = vec![0.0f32; len];
        if centred {
            mean.par_iter_mut().enumerate().for_each(|(i, m)| {
                let sum: f64 = rows.iter().map(|r| f64::from(r[i])).sum();
                *m = (sum / turns as f64) as f32;
            });
            rows.par_iter_mut().for_each(|r| {
                r.iter_mut().zip(&mean).for_each(|(x, m)| *x -= m);
            });
        }
        // The Gram matrix in f64, chunk by chunk so that all A rows of a chunk stay in cache
        // (one pass over U instead of A²/2).
        let partial: Vec<Vec<f64>> = (0..len)
            .into_par_iter()
            .step_by(CHUNK)
            .map(|lo| {
                let hi = (lo + CHUNK).min(len);
                let mut g = vec![0.0f64; turns * turns];
                let mut col = vec![0.0f64; turns];
                for i in lo..hi {
                    for (c, r) in col.iter_mut().zip(&rows) {
                        *c = f64::from(r[i]);
                    }
                    for a in 0..turns {
                        let ca = col[a];
                        for b in 0..=a {
                            g[a * turns + b] += ca * col[b];
                        }
                    }
                }
                g
            })
            .collect();
        let mut gram = Mat::<f64>::zeros(turns, turns);
        for a in 0..turns {
            for b in 0..=a {
                let d: f64 = partial.iter().map(|g| g[a * turns + b]).sum();
                gram[(a, b)] = d;
                gram[(b, a)] = d;
            }
        }
        let evd = gram
            .self_adjoint_eigen(Side::Lower)
            .map_err(|_| BtfError::InvalidParameter {
                what: WHAT,
                name: "samples",
                value: format!("{turns} turns"),
                reason: "the eigendecomposition of their Gram matrix did not converge",
            })?;
        let s = evd.S().column_vector();
        let u = evd.U();
        // Descending.
        let order: Vec<usize> = (0..turns).rev().collect();
        let eigenvalues: Vec<f64> = order.iter().map(|&i| s.get(i).max(0.0)).collect();
        let largest = eigenvalues[0];
        let kept: Vec<usize> = order
            .iter()
            .copied()
            .zip(&eigenvalues)
            .filter(|&(_, &l)| l > RANK_EPS * largest && l > 0.0)
            .map(|(i, _)| i)
            .take(components)
            .collect();
        // E_k = Σ_a v_ak X_a / √λ_k, all k of a chunk at once.
        let scale: Vec<Vec<f32>> = kept
            .iter()
            .map(|&col| {
                let sqrt_l = s.get(col).sqrt();
                (0..turns)
                    .map(|a| (*u.get(a, col) / sqrt_l) as f32)
                    .collect()
            })
            .collect();
        let per_chunk: Vec<Vec<Vec<f32>>> = (0..len.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let span = c * CHUNK..((c + 1) * CHUNK).min(len);
                scale
                    .iter()
                    .map(|w| {
                        let mut e = vec![0.0f32; span.len()];
                        for (wa, r) in w.iter().zip(&rows) {
                            for (x, y) in e.iter_mut().zip(&r[span.clone()]) {
                                *x += wa * y;
                            }
                        }
                        e
                    })
                    .collect()
            })
            .collect();
        let mut comps: Vec<Vec<f32>> = (0..kept.len()).map(|_| Vec::with_capacity(len)).collect();
        for chunk in per_chunk {
            for (c, e) in comps.iter_mut().zip(chunk) {
                c.extend_from_slice(&e);
            }
        }
        let coeffs: Vec<Vec<f32>> = kept
            .iter()
            .map(|&col| {
                let sqrt_l = s.get(col).sqrt();
                (0..turns)
                    .map(|a| (*u.get(a, col) * sqrt_l) as f32)
                    .collect()
            })
            .collect();
        let series = coeffs.iter().map(|o| fourier_series(o)).collect();
        Ok(Self {
            vertices,
            turns,
            centred,
            mean,
            components: comps,
            samples: coeffs,
            eigenvalues,
            series,
        })
    }

    /// Vertices.
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// A: the turns sampled.
    pub fn turns(&self) -> usize {
        self.turns
    }

    /// Whether the mean over turns was subtracted.
    pub fn centred(&self) -> bool {
        self.centred
    }

    /// e: the components kept (at most the number asked for; fewer when U has lower rank).
    pub fn components(&self) -> usize {
        self.components.len()
    }

    /// λ_k of all A components (descending, kept or not): Σ_{k ≥ e} λ_k is the squared error
    /// the decomposition leaves at the samples.
    pub fn eigenvalues(&self) -> &[f64] {
        &self.eigenvalues
    }

    /// o_ak, a = 0..A, of component k (Fig. 5.14's curves).
    ///
    /// # Panics
    /// If `k ≥ e`.
    pub fn coefficient_samples(&self, k: usize) -> &[f32] {
        &self.samples[k]
    }

    /// o_k(δ) by trigonometric interpolation of the A samples (δ in radians, any real).
    ///
    /// # Panics
    /// If `k ≥ e`.
    pub fn coefficient(&self, k: usize, delta: f32) -> f32 {
        let d = f64::from(delta);
        self.series[k]
            .iter()
            .enumerate()
            .map(|(f, &(a, b))| {
                let x = f as f64 * d;
                a * x.cos() + b * x.sin()
            })
            .sum::<f64>() as f32
    }

    /// W of every vertex under the environment turned by δ (radians): Ū + Σ_k o_k(δ) E_k.
    /// `out` is resized to the vertex count and overwritten. Parallel over vertices.
    pub fn weights_at(&self, delta: f32, out: &mut Vec<EnvLightWeights>) {
        self.weights_with(delta, self.components(), out);
    }

    /// [`EnvDecomposition::weights_at`] with only the first `components` components (at most
    /// e): the error of a smaller e without building again.
    pub fn weights_with(&self, delta: f32, components: usize, out: &mut Vec<EnvLightWeights>) {
        let o: Vec<f32> = (0..components.min(self.components()))
            .map(|k| self.coefficient(k, delta))
            .collect();
        out.resize(self.vertices, EnvLightWeights::default());
        out.par_iter_mut().enumerate().for_each(|(i, w)| {
            let span = i * PER_VERTEX..(i + 1) * PER_VERTEX;
            let mut acc = [0.0f32; PER_VERTEX];
            acc.copy_from_slice(&self.mean[span.clone()]);
            for (e, ok) in self.components.iter().zip(&o) {
                for (x, c) in acc.iter_mut().zip(&e[span.clone()]) {
                    *x += ok * c;
                }
            }
            for (m, v) in w.weights.iter_mut().enumerate() {
                *v = Vec3::new(acc[3 * m], acc[3 * m + 1], acc[3 * m + 2]);
            }
        });
    }

    /// Bytes held (Ū, the E_k and the o_ak).
    pub fn bytes(&self) -> usize {
        4 * (self.mean.len() + self.components.iter().map(Vec::len).sum::<usize>())
            + 4 * self.samples.iter().map(Vec::len).sum::<usize>()
    }
}

/// ‖a − b‖ / ‖b‖ over every vertex, direction and channel (f64): the relative RMS error of W.
/// Returns 0 when both are zero.
///
/// # Panics
/// If the slices differ in length.
pub fn relative_error(a: &[EnvLightWeights], b: &[EnvLightWeights]) -> f64 {
    assert_eq!(a.len(), b.len(), "W of the same vertices");
    let (num, den) = a
        .par_iter()
        .zip(b)
        .map(|(x, y)| {
            x.weights
                .iter()
                .zip(&y.weights)
                .fold((0.0f64, 0.0f64), |(n, d), (p, q)| {
                    let diff = (*p - *q).as_dvec3();
                    (n + diff.length_squared(), d + q.as_dvec3().length_squared())
                })
        })
        .reduce(|| (0.0, 0.0), |(a, b), (c, d)| (a + c, b + d));
    if den == 0.0 {
        if num == 0.0 { 0.0 } else { f64::INFINITY }
    } else {
        (num / den).sqrt()
    }
}

/// W of every vertex as one row of N·243 numbers.
fn flatten(w: &[EnvLightWeights]) -> Vec<f32> {
    w.iter()
        .flat_map(|v| v.weights.iter().flat_map(|c| c.to_array()))
        .collect()
}

/// The trigonometric interpolant of `o` sampled at δ_a = 2πa/A: (a_f, b_f) for f = 0..=⌊A/2⌋
/// with o(δ) = Σ_f a_f cos fδ + b_f sin fδ passing through every sample. For even A the
/// Nyquist term keeps its cosine at half weight (its sine vanishes at the samples).
fn fourier_series(o: &[f32]) -> Vec<(f64, f64)> {
    let n = o.len();
    let nf = n as f64;
    (0..=n / 2)
        .map(|f| {
            let (mut a, mut b) = (0.0f64, 0.0f64);
            for (i, &v) in o.iter().enumerate() {
                let x = std::f64::consts::TAU * (f * i) as f64 / nf;
                a += f64::from(v) * x.cos();
                b += f64::from(v) * x.sin();
            }
            let nyquist = n.is_multiple_of(2) && f == n / 2;
            if f == 0 || nyquist {
                (a / nf, 0.0)
            } else {
                (2.0 * a / nf, 2.0 * b / nf)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_series_passes_through_every_sample_for_odd_and_even_a() {
        for n in [2usize, 3, 7, 8, 30] {
            let o: Vec<f32> = (0..n).map(|i| ((i * 7919) % 13) as f32 - 6.0).collect();
            let series = fourier_series(&o);
            for (i, &v) in o.iter().enumerate() {
                let d = std::f64::consts::TAU * i as f64 / n as f64;
                let got: f64 = series
                    .iter()
                    .enumerate()
                    .map(|(f, &(a, b))| a * (f as f64 * d).cos() + b * (f as f64 * d).sin())
                    .sum();
                assert!((got - f64::from(v)).abs() < 1e-9, "A = {n}, a = {i}");
            }
        }
    }
}
