//! The trajectory matrix (eq. 3.14) and its clustered PCA (§3.3.2 "Mesh Segmentation and
//! Linear Basis Decomposition", eq. 3.15), unquantized and in f64.

use faer::Mat;
use glam::{DVec3, Vec3};

use clustering::{LocalPca, LocalPcaInit, LocalPcaParams};

use super::CpcaParams;
use crate::error::{AnimPcaError, Result};

const WHAT: &str = "CpcaModel::fit";

/// The trajectory matrix Aᵀ of eq. 3.14: one row per vertex m, the trajectory
/// Tₘ = (x₀, y₀, z₀, x₁, …, z_{F−1}) of length 3F (frame-major, so frame f is columns
/// 3f..3f + 3).
///
/// # Errors
/// [`AnimPcaError::EmptyClip`], [`AnimPcaError::VertexCountMismatch`],
/// [`AnimPcaError::NonFinite`].
pub fn trajectory_matrix(frames: &[Vec<Vec3>]) -> Result<Mat<f64>> {
    let (f, v) = check_clip("trajectory_matrix", frames)?;
    Ok(Mat::from_fn(v, 3 * f, |m, col| {
        f64::from(frames[col / 3][m][col % 3])
    }))
}

/// Checks a clip and returns (F, V).
pub(crate) fn check_clip(what: &'static str, frames: &[Vec<Vec3>]) -> Result<(usize, usize)> {
    let v = frames.first().map_or(0, Vec::len);
    if v == 0 {
        return Err(AnimPcaError::EmptyClip {
            what,
            frames: frames.len(),
            vertices: v,
        });
    }
    for (fi, frame) in frames.iter().enumerate() {
        if frame.len() != v {
            return Err(AnimPcaError::VertexCountMismatch {
                what,
                frame: fi,
                expected: v,
                found: frame.len(),
            });
        }
        for (vi, p) in frame.iter().enumerate() {
            if let Some(&value) = p.to_array().iter().find(|x| !x.is_finite()) {
                return Err(AnimPcaError::NonFinite {
                    what,
                    frame: fi,
                    vertex: vi,
                    value,
                });
            }
        }
    }
    Ok((frames.len(), v))
}

/// The clustered PCA of an animation before quantization: k clusters of c eigentrajectories
/// Eⱼₕ (length 3F), cluster means rⱼ, the cluster index Iₘ and per-vertex weights wₘₕ, so
/// that Tₘ ≈ r_{Iₘ} + Σₕ wₘₕ E_{Iₘh} (eq. 3.15, taken about the cluster mean; see
/// [`clustering::LocalPca`]).
#[derive(Clone, Debug)]
pub struct CpcaModel {
    frames: usize,
    lpca: LocalPca,
}

impl CpcaModel {
    /// Clusters the trajectories of `frames` (`frames[f][m]`) with Kambhatla–Leen local PCA.
    ///
    /// k is clamped to V and c to 3F (a clip cannot use more clusters than it has vertices,
    /// nor more axes than a trajectory has coordinates); [`CpcaModel::clusters`] and
    /// [`CpcaModel::components`] give the values used.
    ///
    /// # Errors
    /// Those of [`trajectory_matrix`]; [`AnimPcaError::InvalidParameter`] for k = 0 or c = 0;
    /// [`AnimPcaError::Pca`] if the local PCA fails.
    pub fn fit(frames: &[Vec<Vec3>], params: &CpcaParams) -> Result<Self> {
        params.validate(WHAT)?;
        let a = trajectory_matrix(frames)?;
        let lp = params.local_pca_params(a.nrows(), frames.len());
        let lpca = LocalPca::fit(a.as_ref(), &lp)?;
        Ok(Self {
            frames: frames.len(),
            lpca,
        })
    }

    /// Vertices V.
    pub fn vertices(&self) -> usize {
        self.lpca.labels().len()
    }

    /// Frames F.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Clusters k (after clamping).
    pub fn clusters(&self) -> usize {
        self.lpca.k()
    }

    /// Eigentrajectories per cluster c (after clamping).
    pub fn components(&self) -> usize {
        self.lpca.n_components()
    }

    /// The underlying local PCA (labels Iₘ, means rⱼ, bases Eⱼ, weights, errors).
    pub fn local_pca(&self) -> &LocalPca {
        &self.lpca
    }

    /// Rebuilds frame `f` from the unquantized model (eq. 3.15) into `out` (length V).
    ///
    /// # Errors
    /// [`AnimPcaError::InvalidParameter`] if `f ≥ F`, [`AnimPcaError::LengthMismatch`] if
    /// `out.len() ≠ V`.
    pub fn reconstruct_frame(&self, f: usize, out: &mut [DVec3]) -> Result<()> {
        if f >= self.frames {
            return Err(crate::error::invalid(
                "CpcaModel::reconstruct_frame",
                "f",
                f,
                "the frame index must be below the frame count",
            ));
        }
        if out.len() != self.vertices() {
            return Err(AnimPcaError::LengthMismatch {
                what: "CpcaModel::reconstruct_frame out",
                expected: self.vertices(),
                found: out.len(),
            });
        }
        let l = &self.lpca;
        for (m, o) in out.iter_mut().enumerate() {
            let j = l.labels()[m];
            let (mean, basis) = (l.mean(j), l.basis(j));
            let mut p = [mean[3 * f], mean[3 * f + 1], mean[3 * f + 2]];
            for (h, w) in l.weight(m).iter().enumerate() {
                for (a, pa) in p.iter_mut().enumerate() {
                    *pa += w * basis[(3 * f + a, h)];
                }
            }
            *o = DVec3::from_array(p);
        }
        Ok(())
    }
}

impl CpcaParams {
    /// The local PCA run by [`CpcaModel::fit`] on V trajectories of F frames (k and c
    /// clamped).
    pub fn local_pca_params(&self, vertices: usize, frames: usize) -> LocalPcaParams {
        LocalPcaParams {
            k: self.clusters.min(vertices).max(1),
            components: self.components.min(3 * frames).max(1),
            init: LocalPcaInit::KMeans,
            max_iterations: self.max_iterations,
            tolerance: self.tolerance,
            seed: self.seed,
            ..LocalPcaParams::default()
        }
    }
}
