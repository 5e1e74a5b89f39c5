//! The visibility matrix M (paper 000 §3.2) and what is derived from it: vertex radiance
//! c_i = Σ_j M_ij I_j (§3.3) and the ambient term a_i = (1/π) Σ_j ω_j M_ij.
//!
//! M_ij = n_i·l_j when vertex i is unoccluded towards l_j and n_i·l_j > 0, else 0. It is stored
//! as one visibility bit per (i, j), row-major, 32 directions per word; n_i·l_j is recomputed
//! on demand, which is what the seed stores but 32× smaller.

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use lightsphere::Lightsphere;

use crate::OcclusionError;

/// Bits per storage word.
pub(crate) const WORD_BITS: usize = 32;

/// The visibility of N receiver vertices towards k light directions.
#[derive(Clone, Debug, PartialEq)]
pub struct VisibilityMatrix {
    rows: usize,
    words_per_row: usize,
    bits: Vec<u32>,
    normals: Vec<Vec3>,
    directions: Vec<Vec3>,
    weights: Vec<f64>,
}

impl VisibilityMatrix {
    /// An all-occluded matrix for the given receiver normals and lightsphere.
    pub(crate) fn zeros(normals: Vec<Vec3>, sphere: &Lightsphere) -> Self {
        let rows = normals.len();
        let words_per_row = sphere.len().div_ceil(WORD_BITS);
        Self {
            rows,
            words_per_row,
            bits: vec![0; rows * words_per_row],
            normals,
            directions: sphere.directions().to_vec(),
            weights: sphere.solid_angles().to_vec(),
        }
    }

    /// Grows the matrix to the directions of `sphere`, keeping the computed columns (the
    /// nested order of the lightsphere makes the first `k` directions identical).
    pub(crate) fn grow(&mut self, sphere: &Lightsphere) -> Result<(), OcclusionError> {
        let k = self.directions.len();
        let nested = sphere.len() >= k && sphere.directions()[..k] == self.directions[..];
        if !nested {
            return Err(OcclusionError::NotARefinement {
                have: k,
                requested: sphere.len(),
            });
        }
        let words_per_row = sphere.len().div_ceil(WORD_BITS);
        if words_per_row != self.words_per_row {
            let mut bits = vec![0; self.rows * words_per_row];
            for (new, old) in bits
                .chunks_exact_mut(words_per_row)
                .zip(self.bits.chunks_exact(self.words_per_row))
            {
                new[..old.len()].copy_from_slice(old);
            }
            self.bits = bits;
            self.words_per_row = words_per_row;
        }
        self.directions = sphere.directions().to_vec();
        // The Voronoi cells shrink when directions are added: the weights are the new level's.
        self.weights = sphere.solid_angles().to_vec();
        Ok(())
    }

    /// Number of rows N (receiver vertices).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of columns k (light directions).
    pub fn directions_len(&self) -> usize {
        self.directions.len()
    }

    /// The light directions l_j (unit, world space).
    pub fn directions(&self) -> &[Vec3] {
        &self.directions
    }

    /// The solid-angle weights ω_j of the directions (the lightsphere's Voronoi areas).
    pub fn solid_angles(&self) -> &[f64] {
        &self.weights
    }

    /// The receivers' unit world normals (zero for vertices used by no triangle).
    pub fn normals(&self) -> &[Vec3] {
        &self.normals
    }

    /// Storage words per row (32 directions per word).
    pub fn words_per_row(&self) -> usize {
        self.words_per_row
    }

    /// The raw visibility bits, row-major: bit `j % 32` of word `i * words_per_row + j / 32`
    /// is set when vertex i sees direction j unoccluded with n_i·l_j > 0.
    pub fn bits(&self) -> &[u32] {
        &self.bits
    }

    pub(crate) fn bits_mut(&mut self) -> &mut [u32] {
        &mut self.bits
    }

    /// Whether vertex `i` sees direction `j` (false out of range).
    pub fn is_visible(&self, i: usize, j: usize) -> bool {
        if i >= self.rows || j >= self.directions.len() {
            return false;
        }
        self.bits[i * self.words_per_row + j / WORD_BITS] >> (j % WORD_BITS) & 1 == 1
    }

    /// M_ij = n_i·l_j when visible, else 0 (0 out of range).
    pub fn value(&self, i: usize, j: usize) -> f32 {
        if self.is_visible(i, j) {
            self.normals[i].dot(self.directions[j])
        } else {
            0.0
        }
    }

    /// Number of visible (i, j) pairs.
    pub fn visible_count(&self) -> usize {
        self.bits.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// M as a dense row-major N×k array of f32 (the `--matrix` output).
    pub fn to_dense(&self) -> Vec<f32> {
        let k = self.directions.len();
        let mut dense = vec![0.0f32; self.rows * k];
        for (i, row) in dense.chunks_exact_mut(k.max(1)).enumerate().take(self.rows) {
            for (j, m) in row.iter_mut().enumerate() {
                *m = self.value(i, j);
            }
        }
        dense
    }

    /// The ambient term a_i = (1/π) Σ_j ω_j M_ij (1 for a fully open vertex up to quadrature),
    /// accumulated in f64 and clamped to [0, 1] ([`clamp_ambient`]). Vertices with a zero
    /// normal (used by no triangle) get NaN.
    pub fn ambient(&self) -> Vec<f32> {
        (0..self.rows)
            .map(|i| {
                if self.normals[i] == Vec3::ZERO {
                    return f32::NAN;
                }
                let n = self.normals[i].as_dvec3();
                let sum: f64 = self
                    .visible_columns(i)
                    .map(|j| self.weights[j] * n.dot(self.directions[j].as_dvec3()))
                    .sum();
                clamp_ambient((sum / PI) as f32)
            })
            .collect()
    }

    /// Bent normals: the mean unoccluded direction, cosine-weighted as the ambient term is,
    /// b_i = normalize(Σ_j ω_j M_ij l_j), accumulated in f64 — what AO bakers (Blender,
    /// xNormal, Substance) write beside AO for shading with a shifted normal. A vertex that
    /// sees no direction keeps its normal; a vertex used by no triangle gets zero.
    pub fn bent_normals(&self) -> Vec<Vec3> {
        (0..self.rows)
            .map(|i| {
                let n = self.normals[i];
                let sum: DVec3 = self
                    .visible_columns(i)
                    .map(|j| {
                        let l = self.directions[j].as_dvec3();
                        l * (self.weights[j] * n.as_dvec3().dot(l))
                    })
                    .sum();
                sum.try_normalize().map_or(n, DVec3::as_vec3)
            })
            .collect()
    }

    /// Vertex radiance c_i = Σ_j M_ij I_j (paper 000 §3.3), accumulated in f64. `radiance[j]`
    /// is I_j, e.g. from `lightsphere::Environment::radiance_per_direction`. Vertices with a
    /// zero normal get NaN.
    ///
    /// # Errors
    /// [`OcclusionError::RadianceCountMismatch`] when `radiance.len() != k`.
    pub fn radiance(&self, radiance: &[Vec3]) -> Result<Vec<Vec3>, OcclusionError> {
        if radiance.len() != self.directions.len() {
            return Err(OcclusionError::RadianceCountMismatch {
                given: radiance.len(),
                expected: self.directions.len(),
            });
        }
        Ok((0..self.rows)
            .map(|i| {
                if self.normals[i] == Vec3::ZERO {
                    return Vec3::NAN;
                }
                let n = self.normals[i].as_dvec3();
                let sum: DVec3 = self
                    .visible_columns(i)
                    .map(|j| radiance[j].as_dvec3() * n.dot(self.directions[j].as_dvec3()))
                    .sum();
                sum.as_vec3()
            })
            .collect())
    }

    /// The columns j visible from row i.
    fn visible_columns(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let row = &self.bits[i * self.words_per_row..(i + 1) * self.words_per_row];
        row.iter().enumerate().flat_map(|(w, &word)| {
            let mut word = word;
            std::iter::from_fn(move || {
                if word == 0 {
                    return None;
                }
                let bit = word.trailing_zeros() as usize;
                word &= word - 1;
                Some(w * WORD_BITS + bit)
            })
        })
    }
}

/// Row-subset helpers of [`crate::VisibilityEngine::compute_rows`] (crate-internal: the
/// matrix's fields are private to this module).
impl VisibilityMatrix {
    /// An all-occluded matrix with this matrix's directions and weights and one row per
    /// normal.
    pub(crate) fn zeros_like(&self, normals: Vec<Vec3>) -> Self {
        Self {
            rows: normals.len(),
            words_per_row: self.words_per_row,
            bits: vec![0; normals.len() * self.words_per_row],
            normals,
            directions: self.directions.clone(),
            weights: self.weights.clone(),
        }
    }

    /// Copies row `r` of `subset` (bits and normal) into row `rows[r]` of `self`; the other
    /// rows are left as they are.
    pub(crate) fn scatter_rows(&mut self, subset: &Self, rows: &[u32]) {
        assert_eq!(subset.rows, rows.len(), "one target row per subset row");
        assert_eq!(subset.words_per_row, self.words_per_row, "same directions");
        let w = self.words_per_row;
        for (r, &target) in rows.iter().enumerate() {
            let target = target as usize;
            self.bits[target * w..(target + 1) * w]
                .copy_from_slice(&subset.bits[r * w..(r + 1) * w]);
            self.normals[target] = subset.normals[r];
        }
    }
}

/// a_i into [0, 1], NaN kept: the lightsphere's quadrature of ∫ cos θ dω / π over an open
/// hemisphere is 1 only up to its error (up to 1.0031 at level 3), and a fully occluded vertex
/// sums nothing, which Rust's float `sum` returns as −0.0; both are written as what a_i means,
/// an open fraction in [0, 1], with +0.0 for "fully occluded".
pub fn clamp_ambient(a: f32) -> f32 {
    if a.is_nan() {
        a
    } else if a <= 0.0 {
        0.0
    } else {
        a.min(1.0)
    }
}
