//! Reconstruction of a frame from its PCA weights: Ã = F_0 + Σ_k w_k F_k (eq. 3.1).
//!
//! The eigenframes are stored once as f32, component-major, so one frame costs c + 1 passes of
//! an `axpy` over 3N floats that the compiler vectorises: about 0.7 MFLOP for N = 20k, c = 10
//! (thousands of frames per second on one core). Weights arrive as f64 and are rounded to f32
//! once per call.

use clustering::Pca;
use glam::Vec3;

use crate::error::{AnimPcaError, Result};

/// Rebuilds vertex positions (and normals, when the map was analysed with them) from PCA
/// weights. Cheap to call per frame; allocates nothing.
#[derive(Clone, Debug)]
pub struct Reconstructor {
    n_vertices: usize,
    c: usize,
    /// Mean positions F_0 (3N).
    mean: Vec<f32>,
    /// Eigenframes' position parts, component-major (c × 3N).
    components: Vec<f32>,
    /// Mean and eigenframes of the normal part, already divided by the normal scale.
    normals: Option<(Vec<f32>, Vec<f32>)>,
}

impl Reconstructor {
    /// From a PCA of frame vectors [positions (3N) | normals·scale (3N)].
    pub(crate) fn from_pca(pca: &Pca, n_vertices: usize, normal_scale: Option<f64>) -> Self {
        let dp = 3 * n_vertices;
        let c = pca.n_components();
        let part = |from: usize, scale: f64| -> (Vec<f32>, Vec<f32>) {
            let mean = pca.mean()[from..from + dp]
                .iter()
                .map(|x| (x / scale) as f32)
                .collect();
            let mut comps = Vec::with_capacity(c * dp);
            for k in 0..c {
                comps.extend(
                    pca.component(k)[from..from + dp]
                        .iter()
                        .map(|x| (x / scale) as f32),
                );
            }
            (mean, comps)
        };
        let (mean, components) = part(0, 1.0);
        let normals = normal_scale.map(|s| part(dp, if s > 0.0 { s } else { 1.0 }));
        Self {
            n_vertices,
            c,
            mean,
            components,
            normals,
        }
    }

    /// Number of components c the weights must have.
    pub fn components(&self) -> usize {
        self.c
    }

    /// Vertices N per frame.
    pub fn n_vertices(&self) -> usize {
        self.n_vertices
    }

    /// Whether normals can be reconstructed ([`Reconstructor::reconstruct_normals`]).
    pub fn has_normals(&self) -> bool {
        self.normals.is_some()
    }

    /// Positions p̃_n = F_0 + Σ_k w_k F_k (eq. 3.1) into `out` (length N). `weights` may be
    /// shorter than c: the leading components only.
    ///
    /// # Errors
    /// [`AnimPcaError::LengthMismatch`] if `weights` has more than c entries or `out` is not N
    /// long.
    pub fn reconstruct(&self, weights: &[f64], out: &mut [Vec3]) -> Result<()> {
        self.check(weights, out)?;
        combine(&self.mean, &self.components, weights, out);
        Ok(())
    }

    /// Normals from the same weights, renormalised to unit length (zero vectors stay zero).
    ///
    /// # Errors
    /// As [`Reconstructor::reconstruct`]; also [`AnimPcaError::LengthMismatch`] with expected
    /// 0 when the map was analysed without normals.
    pub fn reconstruct_normals(&self, weights: &[f64], out: &mut [Vec3]) -> Result<()> {
        self.check(weights, out)?;
        let Some((mean, comps)) = &self.normals else {
            return Err(AnimPcaError::LengthMismatch {
                what: "Reconstructor::reconstruct_normals (the map has no normals)",
                expected: 0,
                found: out.len(),
            });
        };
        combine(mean, comps, weights, out);
        for n in out {
            *n = n.normalize_or_zero();
        }
        Ok(())
    }

    fn check(&self, weights: &[f64], out: &[Vec3]) -> Result<()> {
        if weights.len() > self.c {
            return Err(AnimPcaError::LengthMismatch {
                what: "Reconstructor weights",
                expected: self.c,
                found: weights.len(),
            });
        }
        if out.len() != self.n_vertices {
            return Err(AnimPcaError::LengthMismatch {
                what: "Reconstructor output vertices",
                expected: self.n_vertices,
                found: out.len(),
            });
        }
        Ok(())
    }
}

/// out = mean + Σ_k w_k comps_k over flat f32 arrays.
fn combine(mean: &[f32], comps: &[f32], weights: &[f64], out: &mut [Vec3]) {
    combine_flat(mean, comps, weights, bytemuck::cast_slice_mut(out));
}

/// out = mean + Σ_k w_k comps_k.
fn combine_flat(mean: &[f32], comps: &[f32], weights: &[f64], flat: &mut [f32]) {
    flat.copy_from_slice(mean);
    let d = mean.len();
    for (k, &w) in weights.iter().enumerate() {
        let w = w as f32;
        for (o, f) in flat.iter_mut().zip(&comps[k * d..(k + 1) * d]) {
            *o += w * f;
        }
    }
}

/// Rebuilds a frame's attribute vector R̃_i = R̄ + Σ_k r_k G_k from its attribute weights (the
/// separate vector of thesis §3.2.2 "Adding vertex attributes"; see
/// [`JumpMap::analyze_cells`](super::JumpMap::analyze_cells)). Allocates nothing per call.
#[derive(Clone, Debug)]
pub struct AttributeReconstructor {
    len: usize,
    c: usize,
    mean: Vec<f32>,
    components: Vec<f32>,
}

impl AttributeReconstructor {
    pub(crate) fn from_pca(pca: &Pca) -> Self {
        let len = pca.mean().len();
        let c = pca.n_components();
        let mut components = Vec::with_capacity(c * len);
        for k in 0..c {
            components.extend(pca.component(k).iter().map(|&x| x as f32));
        }
        Self {
            len,
            c,
            mean: pca.mean().iter().map(|&x| x as f32).collect(),
            components,
        }
    }

    /// Number of attribute components the weights must have.
    pub fn components(&self) -> usize {
        self.c
    }

    /// Length of an attribute vector R_i.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether R_i is empty (never, for a map built from attributes).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// R̃ = R̄ + Σ_k r_k G_k into `out` (length [`AttributeReconstructor::len`]); `weights` may
    /// be shorter than c.
    ///
    /// # Errors
    /// [`AnimPcaError::LengthMismatch`] if `weights` has more than c entries or `out` has the
    /// wrong length.
    pub fn reconstruct(&self, weights: &[f64], out: &mut [f32]) -> Result<()> {
        if weights.len() > self.c {
            return Err(AnimPcaError::LengthMismatch {
                what: "AttributeReconstructor weights",
                expected: self.c,
                found: weights.len(),
            });
        }
        if out.len() != self.len {
            return Err(AnimPcaError::LengthMismatch {
                what: "AttributeReconstructor output",
                expected: self.len,
                found: out.len(),
            });
        }
        combine_flat(&self.mean, &self.components, weights, out);
        Ok(())
    }
}
