//! CPU decoder (§3.3.2 "Decompression", the computation of Fig. 3.18): any frame f is rebuilt
//! on its own as pₘ(f) = r_{Iₘ}(f) + Σₕ wₘₕ E_{Iₘh}(f), without decoding other frames.
//!
//! The dequantized data is laid out for that product: vertices are grouped by cluster, the
//! weights of a cluster are stored component-major, and for each frame the (c + 1) × 3 values
//! r_j(f), E_j1(f), …, E_jc(f) of a cluster are contiguous. A frame is then c multiply-adds
//! over contiguous weight rows per cluster (vectorised by the compiler), written back to the
//! caller's buffer in vertex order. With time compression the (c + 1) × 3 values of frame f
//! are first rebuilt from the c* time components (k·c·c*·3 multiply-adds per frame).

use glam::Vec3;

use super::container::Compressed;
use crate::error::{AnimPcaError, Result};

/// Dequantized, decode-ready form of a [`Compressed`] animation (`f32`).
#[derive(Clone, Debug)]
pub struct Decoder {
    vertices: usize,
    frames: usize,
    clusters: usize,
    components: usize,
    /// Vertex indices grouped by cluster (stable).
    order: Vec<u32>,
    /// Start of cluster j in `order`, k + 1 entries.
    starts: Vec<usize>,
    /// Cluster j's block at starts[j]·c: c rows of its nⱼ weights.
    weights: Vec<f32>,
    rows: Rows,
    /// Vertices in the largest cluster.
    largest: usize,
}

#[derive(Clone, Debug)]
enum Rows {
    /// [f][j][r][axis], r = 0 the mean, r = h + 1 eigentrajectory h.
    Direct(Vec<f32>),
    /// Eigentrajectories from the time basis.
    Time {
        cs: usize,
        /// [f][j][axis].
        means: Vec<f32>,
        /// [j·c + h][s].
        coef: Vec<f32>,
        /// [f][axis].
        mean: Vec<f32>,
        /// [f][s][axis].
        basis: Vec<f32>,
    },
}

/// Reusable buffers of [`Decoder::frame_into`]; make one with [`Decoder::scratch`].
#[derive(Clone, Debug, Default)]
pub struct DecodeScratch {
    rows: Vec<f32>,
    xyz: Vec<f32>,
}

impl Decoder {
    /// Dequantizes `data` into the decode layout.
    pub fn new(data: &Compressed) -> Self {
        let (v, f, k, c) = (data.vertices, data.frames, data.clusters, data.components);
        let mut starts = vec![0usize; k + 1];
        data.labels
            .iter()
            .for_each(|&l| starts[l as usize + 1] += 1);
        for j in 0..k {
            starts[j + 1] += starts[j];
        }
        let mut fill = starts.clone();
        let mut order = vec![0u32; v];
        for (m, &l) in data.labels.iter().enumerate() {
            order[fill[l as usize]] = m as u32;
            fill[l as usize] += 1;
        }
        let mut weights = vec![0f32; v * c];
        for j in 0..k {
            let (s, e) = (starts[j], starts[j + 1]);
            let n = e - s;
            for h in 0..c {
                let q = &data.weights[h];
                for (i, &m) in order[s..e].iter().enumerate() {
                    weights[s * c + h * n + i] = q.value(m as usize) as f32;
                }
            }
        }
        let means: Vec<Vec<f64>> = data.means.iter().map(|q| q.values().collect()).collect();
        let rows = match &data.time {
            None => {
                let eigen: Vec<Vec<f64>> =
                    data.eigen.iter().map(|q| q.values().collect()).collect();
                let stride = (c + 1) * 3;
                let mut rows = vec![0f32; f * k * stride];
                for t in 0..f {
                    for j in 0..k {
                        let dst = &mut rows[(t * k + j) * stride..][..stride];
                        for a in 0..3 {
                            dst[a] = means[3 * j + a][t] as f32;
                            for h in 0..c {
                                dst[3 * (h + 1) + a] = eigen[j * c + h][3 * t + a] as f32;
                            }
                        }
                    }
                }
                Rows::Direct(rows)
            }
            Some(time) => {
                let cs = time.basis.len();
                let mut m = vec![0f32; f * k * 3];
                for t in 0..f {
                    for j in 0..k {
                        for a in 0..3 {
                            m[(t * k + j) * 3 + a] = means[3 * j + a][t] as f32;
                        }
                    }
                }
                let coef = data
                    .eigen
                    .iter()
                    .flat_map(|q| q.values().map(|x| x as f32))
                    .collect();
                let mean = time.mean.values().map(|x| x as f32).collect();
                let b: Vec<Vec<f64>> = time.basis.iter().map(|q| q.values().collect()).collect();
                let mut basis = vec![0f32; f * cs * 3];
                for t in 0..f {
                    for (s, bs) in b.iter().enumerate() {
                        for a in 0..3 {
                            basis[(t * cs + s) * 3 + a] = bs[3 * t + a] as f32;
                        }
                    }
                }
                Rows::Time {
                    cs,
                    means: m,
                    coef,
                    mean,
                    basis,
                }
            }
        };
        Self {
            vertices: v,
            frames: f,
            clusters: k,
            components: c,
            order,
            weights,
            largest: starts.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0),
            rows,
            starts,
        }
    }

    /// Vertices V.
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    /// Frames F.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Buffers sized for this decoder.
    pub fn scratch(&self) -> DecodeScratch {
        DecodeScratch {
            rows: vec![0.0; self.clusters * (self.components + 1) * 3],
            xyz: vec![0.0; 3 * self.largest],
        }
    }

    /// Rebuilds frame `f` into `out` (length V) without touching other frames. Allocates
    /// nothing when `scratch` came from [`Decoder::scratch`].
    ///
    /// # Errors
    /// [`AnimPcaError::InvalidParameter`] if `f ≥ F`; [`AnimPcaError::LengthMismatch`] if
    /// `out.len() ≠ V`.
    pub fn frame_into(
        &self,
        f: usize,
        out: &mut [Vec3],
        scratch: &mut DecodeScratch,
    ) -> Result<()> {
        if f >= self.frames {
            return Err(crate::error::invalid(
                "Decoder::frame_into",
                "f",
                f,
                "the frame index must be below the frame count",
            ));
        }
        if out.len() != self.vertices {
            return Err(AnimPcaError::LengthMismatch {
                what: "Decoder::frame_into out",
                expected: self.vertices,
                found: out.len(),
            });
        }
        let (k, c) = (self.clusters, self.components);
        let stride = (c + 1) * 3;
        if scratch.rows.len() < k * stride || scratch.xyz.len() < 3 * self.largest {
            *scratch = self.scratch();
        }
        let DecodeScratch { rows: tmp, xyz } = scratch;
        let rows: &[f32] = match &self.rows {
            Rows::Direct(all) => &all[f * k * stride..(f + 1) * k * stride],
            Rows::Time {
                cs,
                means,
                coef,
                mean,
                basis,
            } => {
                let b = &basis[f * cs * 3..(f + 1) * cs * 3];
                for j in 0..k {
                    let dst = &mut tmp[j * stride..(j + 1) * stride];
                    dst[..3].copy_from_slice(&means[(f * k + j) * 3..][..3]);
                    for h in 0..c {
                        let mut e = [mean[3 * f], mean[3 * f + 1], mean[3 * f + 2]];
                        let a = &coef[(j * c + h) * cs..][..*cs];
                        for (w, bs) in a.iter().zip(b.chunks_exact(3)) {
                            e.iter_mut().zip(bs).for_each(|(x, y)| *x += w * y);
                        }
                        dst[3 * (h + 1)..3 * (h + 2)].copy_from_slice(&e);
                    }
                }
                &tmp[..k * stride]
            }
        };
        let largest = xyz.len() / 3;
        let (xs, rest) = xyz.split_at_mut(largest);
        let (ys, zs) = rest.split_at_mut(largest);
        for j in 0..k {
            let (s, e) = (self.starts[j], self.starts[j + 1]);
            let n = e - s;
            if n == 0 {
                continue;
            }
            let row = &rows[j * stride..(j + 1) * stride];
            let (x, y, z) = (&mut xs[..n], &mut ys[..n], &mut zs[..n]);
            x.fill(row[0]);
            y.fill(row[1]);
            z.fill(row[2]);
            let w = &self.weights[s * c..e * c];
            for (wh, eh) in w.chunks_exact(n).zip(row[3..].chunks_exact(3)) {
                let (ex, ey, ez) = (eh[0], eh[1], eh[2]);
                for (((xi, yi), zi), &wi) in
                    x.iter_mut().zip(y.iter_mut()).zip(z.iter_mut()).zip(wh)
                {
                    *xi += wi * ex;
                    *yi += wi * ey;
                    *zi += wi * ez;
                }
            }
            for (i, &m) in self.order[s..e].iter().enumerate() {
                out[m as usize] = Vec3::new(x[i], y[i], z[i]);
            }
        }
        Ok(())
    }

    /// Decodes every frame: `frames[f][m]`.
    pub fn decode_all(&self) -> Vec<Vec<Vec3>> {
        let mut scratch = self.scratch();
        (0..self.frames)
            .map(|f| {
                let mut out = vec![Vec3::ZERO; self.vertices];
                // In range by construction.
                let ok = self.frame_into(f, &mut out, &mut scratch);
                debug_assert!(ok.is_ok());
                out
            })
            .collect()
    }
}
