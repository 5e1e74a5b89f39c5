//! The compressed animation: the clustered PCA of [`CpcaModel`], optionally compressed along
//! time (§3.3.2 "Compression of Eigentrajectories"), quantized (§"Quantization"), with the
//! connectivity.

use clustering::{ComponentCount, Pca, PcaParams};
use faer::Mat;
use glam::Vec3;

use super::model::{CpcaModel, check_clip};
use super::quantize::Quantized;
use super::{CpcaParams, RateParams};
use crate::error::Result;

/// The second PCA over the k·c eigentrajectories (§3.3.2 "Compression of
/// Eigentrajectories"): Eⱼₕ ≈ μ + Σₛ aⱼₕₛ Bₛ with c* time components Bₛ of length 3F.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeBasis {
    /// μ, length 3F (quantized with q_w as eq. 3.18 does for the time basis).
    pub(crate) mean: Quantized,
    /// B₁ … B_{c*}, each of length 3F (q_w bits, eq. 3.18).
    pub(crate) basis: Vec<Quantized>,
}

/// A compressed animation, as stored in a `.cpca` file: header values, cluster index,
/// quantized means, eigentrajectories (or their time coefficients), time basis, weights and
/// triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct Compressed {
    pub(crate) vertices: usize,
    pub(crate) frames: usize,
    pub(crate) clusters: usize,
    pub(crate) components: usize,
    pub(crate) bits_components: u8,
    pub(crate) bits_weights: u8,
    pub(crate) frame_rate: f32,
    /// Iₘ, length V.
    pub(crate) labels: Vec<u32>,
    /// rⱼ per axis: array 3j + a holds axis a of cluster j's mean over the F frames (q_c bits).
    /// Each axis has its own range, so a clip far from the origin (the chicken sits at
    /// x ≈ 25) does not spend the bits on its offset.
    pub(crate) means: Vec<Quantized>,
    /// Eⱼₕ at index j·c + h: length 3F, or c* time coefficients with a time basis (q_c).
    pub(crate) eigen: Vec<Quantized>,
    pub(crate) time: Option<TimeBasis>,
    /// Weights of component h for all V vertices at index h (q_w bits).
    pub(crate) weights: Vec<Quantized>,
    pub(crate) triangles: Vec<[u32; 3]>,
}

const WHAT: &str = "Compressed::encode";

impl Compressed {
    /// Encodes an animation: [`CpcaModel::fit`], then [`Compressed::from_model`].
    ///
    /// # Errors
    /// Those of [`CpcaModel::fit`] and [`Compressed::from_model`].
    pub fn encode(
        frames: &[Vec<Vec3>],
        triangles: &[[u32; 3]],
        frame_rate: f32,
        params: &CpcaParams,
    ) -> Result<Self> {
        check_clip(WHAT, frames)?;
        let model = CpcaModel::fit(frames, params)?;
        Self::from_model(&model, triangles, frame_rate, params)
    }

    /// Compresses a fitted model: optional time PCA with `params.time_components` components
    /// (clamped to min(k·c, 3F)), then quantization of means and eigentrajectories with q_c
    /// bits and of the weights with q_w bits, each array over its own range.
    ///
    /// # Errors
    /// [`crate::AnimPcaError::InvalidParameter`] for bit counts outside 1..=32, c* = 0, a triangle
    /// index ≥ V, a frame rate that is not finite, or more than 2³² − 1 vertices or frames;
    /// [`crate::AnimPcaError::Pca`] if the time PCA fails.
    pub fn from_model(
        model: &CpcaModel,
        triangles: &[[u32; 3]],
        frame_rate: f32,
        params: &CpcaParams,
    ) -> Result<Self> {
        params.validate(WHAT)?;
        let (v, f, k, c) = (
            model.vertices(),
            model.frames(),
            model.clusters(),
            model.components(),
        );
        if u32::try_from(v).is_err() || u32::try_from(3 * f).is_err() {
            return Err(crate::error::invalid(
                WHAT,
                "frames",
                format!("{v} vertices × {f} frames"),
                "the format stores V and 3F as 32-bit counts",
            ));
        }
        if !frame_rate.is_finite() {
            return Err(crate::error::invalid(
                WHAT,
                "frame_rate",
                frame_rate,
                "the frame rate must be finite",
            ));
        }
        if let Some((t, tri)) = triangles
            .iter()
            .enumerate()
            .find(|(_, tri)| tri.iter().any(|&i| i as usize >= v))
        {
            return Err(crate::error::invalid(
                WHAT,
                "triangles",
                format!("triangle {t} = {tri:?}"),
                "every vertex index must be below the vertex count",
            ));
        }
        let l = model.local_pca();
        let (qc, qw) = (params.bits_components, params.bits_weights);
        let means = (0..k)
            .flat_map(|j| {
                (0..3).map(move |a| {
                    let axis: Vec<f64> = l.mean(j).iter().skip(a).step_by(3).copied().collect();
                    Quantized::new(&axis, qc)
                })
            })
            .collect();
        let rows: Vec<Vec<f64>> = (0..k)
            .flat_map(|j| (0..c).map(move |h| l.basis(j).col(h).iter().copied().collect()))
            .collect();
        let (eigen, time) = match params.time_components {
            None => (rows.iter().map(|r| Quantized::new(r, qc)).collect(), None),
            Some(cs) => {
                // ‖w_·h‖ over cluster j's vertices: how much E_jh moves the mesh.
                let mut importance = vec![0f64; k * c];
                for (m, &j) in l.labels().iter().enumerate() {
                    for (h, w) in l.weight(m).iter().enumerate() {
                        importance[j * c + h] += w * w;
                    }
                }
                importance.iter_mut().for_each(|s| *s = s.sqrt());
                let (coef, time) = time_pca(&rows, &importance, 3 * f, cs, qc, qw)?;
                (coef, Some(time))
            }
        };
        let weights = (0..c)
            .map(|h| {
                let w: Vec<f64> = (0..v).map(|m| l.weight(m)[h]).collect();
                Quantized::new(&w, qw)
            })
            .collect();
        Ok(Self {
            vertices: v,
            frames: f,
            clusters: k,
            components: c,
            bits_components: qc,
            bits_weights: qw,
            frame_rate,
            labels: l.labels().iter().map(|&j| j as u32).collect(),
            means,
            eigen,
            time,
            weights,
            triangles: coded_triangles(triangles, v)?,
        })
    }

    /// Vertices V.
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// Frames F.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Clusters k.
    pub fn clusters(&self) -> usize {
        self.clusters
    }

    /// Eigentrajectories per cluster c.
    pub fn components(&self) -> usize {
        self.components
    }

    /// Time components c* (`None` without time compression).
    pub fn time_components(&self) -> Option<usize> {
        self.time.as_ref().map(|t| t.basis.len())
    }

    /// Bits of the means and eigentrajectories q_c.
    pub fn bits_components(&self) -> u8 {
        self.bits_components
    }

    /// Bits of the weights q_w.
    pub fn bits_weights(&self) -> u8 {
        self.bits_weights
    }

    /// Frames per second of the source.
    pub fn frame_rate(&self) -> f32 {
        self.frame_rate
    }

    /// Cluster index Iₘ of every vertex.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// Triangles (shared by all frames).
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Axis `axis` (0 = x, 1 = y, 2 = z) of the quantized mean rⱼ of cluster `j`: F values,
    /// one per frame.
    ///
    /// # Panics
    /// If `j ≥ k` or `axis ≥ 3`.
    pub fn mean(&self, j: usize, axis: usize) -> &Quantized {
        assert!(axis < 3, "axis {axis} ≥ 3");
        &self.means[3 * j + axis]
    }

    /// Quantized eigentrajectory Eⱼₕ (length 3F), or its c* time coefficients when the
    /// animation was compressed along time.
    ///
    /// # Panics
    /// If `j ≥ k` or `h ≥ c`.
    pub fn eigentrajectory(&self, j: usize, h: usize) -> &Quantized {
        assert!(h < self.components, "component {h} ≥ c");
        &self.eigen[j * self.components + h]
    }

    /// Quantized weights of component `h` for every vertex (length V).
    ///
    /// # Panics
    /// If `h ≥ c`.
    pub fn weights(&self, h: usize) -> &Quantized {
        &self.weights[h]
    }

    /// The parameters of eqs. 3.16–3.18 for this animation.
    pub fn rate(&self) -> RateParams {
        RateParams {
            vertices: self.vertices,
            frames: self.frames,
            clusters: self.clusters,
            components: self.components,
            time_components: self.time_components(),
            bits_components: self.bits_components,
            bits_weights: self.bits_weights,
        }
    }
}

/// PCA of the k·c eigentrajectories (rows of length `d` = 3F) keeping `cs` components;
/// returns the quantized coefficients (one array of c* per eigentrajectory) and time basis.
///
/// The thesis runs a plain PCA over the eigentrajectories. That spends the c* components on
/// every Eⱼₕ alike, although the last components of a cluster barely move the mesh. Here row
/// i = (j, h) is weighted by sᵢ = ‖w_·h‖ over cluster j's vertices: within a cluster the
/// local-PCA weight columns are orthogonal, so the position error of an eigentrajectory error
/// ΔEⱼₕ is Σₕ ‖w_·h‖²‖ΔEⱼₕ‖², and the PCA of the rows sᵢ(Eᵢ − μ) minimises exactly that
/// (before quantization). μ is the s-weighted mean, which makes the weighted rows centred,
/// so `Pca::fit`'s own centring leaves them alone. The coefficients are the projections of
/// the unweighted Eᵢ − μ. When every sᵢ is 0 (a static clip) the rows are weighted equally.
fn time_pca(
    rows: &[Vec<f64>],
    importance: &[f64],
    d: usize,
    cs: usize,
    qc: u8,
    qw: u8,
) -> Result<(Vec<Quantized>, TimeBasis)> {
    let total: f64 = importance.iter().sum();
    let s: Vec<f64> = if total > 0.0 && total.is_finite() {
        importance.to_vec()
    } else {
        vec![1.0; rows.len()]
    };
    let total: f64 = s.iter().sum();
    let mut mean = vec![0f64; d];
    for (r, &si) in rows.iter().zip(&s) {
        for (m, x) in mean.iter_mut().zip(r) {
            *m += si * x / total;
        }
    }
    let data = Mat::from_fn(rows.len(), d, |i, t| s[i] * (rows[i][t] - mean[t]));
    let cs = cs.min(rows.len()).min(d).max(1);
    let pca = Pca::fit(
        data.as_ref(),
        &PcaParams {
            components: ComponentCount::Fixed(cs),
            ..PcaParams::default()
        },
    )?;
    // Rank-deficient data (e.g. a static clip) can give fewer axes than asked: pad with zero
    // axes so that the stored c* is the requested one.
    let got = pca.n_components();
    let axis = |k: usize| -> Vec<f64> {
        if k < got {
            pca.component(k).to_vec()
        } else {
            vec![0.0; d]
        }
    };
    let axes: Vec<Vec<f64>> = (0..cs).map(axis).collect();
    let coef = rows
        .iter()
        .map(|r| {
            let a: Vec<f64> = axes
                .iter()
                .map(|b| {
                    r.iter()
                        .zip(&mean)
                        .zip(b)
                        .map(|((x, m), e)| (x - m) * e)
                        .sum()
                })
                .collect();
            Quantized::new(&a, qc)
        })
        .collect();
    let time = TimeBasis {
        mean: Quantized::new(&mean, qw),
        basis: axes.iter().map(|b| Quantized::new(b, qw)).collect(),
    };
    Ok((coef, time))
}

/// The triangles as the file will hold them: ordered for the vertex cache
/// (`meshopt::optimize_vertex_cache`, which the index codec compresses best) and passed through
/// the codec once, so that each triangle has the corner rotation a decoder returns and
/// `Compressed::from_bytes(&c.to_bytes()) == c`.
fn coded_triangles(triangles: &[[u32; 3]], v: usize) -> Result<Vec<[u32; 3]>> {
    if triangles.is_empty() {
        return Ok(Vec::new());
    }
    let flat: Vec<u32> = triangles.iter().flatten().copied().collect();
    let ordered = meshopt::optimize_vertex_cache(&flat, v);
    let ordered: Vec<[u32; 3]> = ordered
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let bytes = super::connectivity::encode_triangles(&ordered, v);
    super::connectivity::decode_triangles(&bytes, ordered.len(), v)
}
