//! Error and rate measures of §3.3.2 "Error Measurement" and §3.3.3 (eqs. 3.16–3.18).

use glam::Vec3;

use super::decode::Decoder;
use super::model::check_clip;
use crate::error::{AnimPcaError, Result};

/// Bits per cluster index in eq. 3.16.
pub const EQ_3_16_INDEX_BITS: f64 = 5.0;
/// Connectivity bits per vertex in eqs. 3.16–3.18 (Edgebreaker's worst case, 6V).
pub const EQ_3_16_CONNECTIVITY_BITS: f64 = 6.0;

/// Distortion of a reconstruction: d_a over the whole clip and d_f per frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Distortion {
    /// d_a = 100·‖B − B̂‖/‖B − E(B)‖ (Karni–Gotsman), where E(B) replaces every vertex of a
    /// frame by that frame's centroid; Frobenius norms over all 3V·F coordinates. When
    /// ‖B − E(B)‖ = 0 (every frame a single point) it is 0 for an exact reconstruction and
    /// +∞ otherwise.
    pub da: f64,
    /// d_f(f) = ‖B_f − B̂_f‖, the L2 norm over the 3V coordinates of frame f (same unit as
    /// the positions).
    pub df: Vec<f64>,
}

impl Distortion {
    /// The largest d_f.
    pub fn worst_df(&self) -> f64 {
        self.df.iter().copied().fold(0.0, f64::max)
    }
}

/// Accumulates d_a and d_f one frame at a time, in f64.
#[derive(Default)]
struct Accumulator {
    num: f64,
    den: f64,
    df: Vec<f64>,
}

impl Accumulator {
    fn frame(&mut self, b: &[Vec3], b_hat: &[Vec3]) {
        let n = b.len() as f64;
        let centroid = b.iter().fold([0f64; 3], |mut s, p| {
            s.iter_mut()
                .zip(p.to_array())
                .for_each(|(s, x)| *s += f64::from(x));
            s
        });
        let centroid = centroid.map(|s| s / n);
        let (mut num, mut den) = (0.0, 0.0);
        for (p, q) in b.iter().zip(b_hat) {
            for a in 0..3 {
                let x = f64::from(p[a]);
                num += (x - f64::from(q[a])).powi(2);
                den += (x - centroid[a]).powi(2);
            }
        }
        self.num += num;
        self.den += den;
        self.df.push(num.sqrt());
    }

    fn finish(self) -> Distortion {
        let da = if self.den > 0.0 {
            100.0 * (self.num / self.den).sqrt()
        } else if self.num == 0.0 {
            0.0
        } else {
            f64::INFINITY
        };
        Distortion { da, df: self.df }
    }
}

/// d_a and d_f of `reconstructed` against `original` (both `frames[f][m]`).
///
/// # Errors
/// [`AnimPcaError::EmptyClip`], [`AnimPcaError::VertexCountMismatch`],
/// [`AnimPcaError::NonFinite`] for the original; [`AnimPcaError::LengthMismatch`] when the
/// reconstruction has another frame or vertex count.
pub fn distortion(original: &[Vec<Vec3>], reconstructed: &[Vec<Vec3>]) -> Result<Distortion> {
    let (f, v) = check_clip("distortion original", original)?;
    if reconstructed.len() != f {
        return Err(AnimPcaError::LengthMismatch {
            what: "distortion reconstructed frames",
            expected: f,
            found: reconstructed.len(),
        });
    }
    let mut acc = Accumulator::default();
    for (b, b_hat) in original.iter().zip(reconstructed) {
        if b_hat.len() != v {
            return Err(AnimPcaError::LengthMismatch {
                what: "distortion reconstructed vertices",
                expected: v,
                found: b_hat.len(),
            });
        }
        acc.frame(b, b_hat);
    }
    Ok(acc.finish())
}

impl Decoder {
    /// d_a and d_f of this decoder's frames against `original`, decoding one frame at a time.
    ///
    /// # Errors
    /// As [`distortion`].
    pub fn distortion(&self, original: &[Vec<Vec3>]) -> Result<Distortion> {
        let (f, v) = check_clip("Decoder::distortion original", original)?;
        if (f, v) != (self.frames(), self.vertices()) {
            return Err(AnimPcaError::LengthMismatch {
                what: "Decoder::distortion original (frames × vertices)",
                expected: self.frames() * self.vertices(),
                found: f * v,
            });
        }
        let mut scratch = self.scratch();
        let mut out = vec![Vec3::ZERO; v];
        let mut acc = Accumulator::default();
        for (t, b) in original.iter().enumerate() {
            self.frame_into(t, &mut out, &mut scratch)?;
            acc.frame(b, &out);
        }
        Ok(acc.finish())
    }
}

/// The quantities of eqs. 3.16–3.18.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RateParams {
    /// Vertices V.
    pub vertices: usize,
    /// Frames F.
    pub frames: usize,
    /// Clusters k.
    pub clusters: usize,
    /// Eigentrajectories per cluster c.
    pub components: usize,
    /// Time components c* (eq. 3.18), if any.
    pub time_components: Option<usize>,
    /// q_c.
    pub bits_components: u8,
    /// q_w.
    pub bits_weights: u8,
}

impl RateParams {
    fn terms(&self) -> (f64, f64, f64, f64, f64, f64) {
        (
            self.vertices as f64,
            self.frames as f64,
            self.clusters as f64,
            self.components as f64,
            f64::from(self.bits_components),
            f64::from(self.bits_weights),
        )
    }

    /// Eq. 3.16: bpvf = (6V + q_c·k·c·3F + q_w·c·V + 5V)/(F·V) — connectivity, components,
    /// weights and a 5-bit cluster index. As printed it does not count the k cluster means
    /// (k·3F values) nor the quantization ranges; [`bpvf_from_file`] does.
    pub fn eq_3_16(&self) -> f64 {
        let (v, _, _, _, _, _) = self.terms();
        self.eq_3_17() + EQ_3_16_INDEX_BITS * v / (v * self.frames as f64)
    }

    /// Eq. 3.17: eq. 3.16 without the cluster index (vertices ordered by cluster).
    pub fn eq_3_17(&self) -> f64 {
        let (v, f, k, c, qc, qw) = self.terms();
        (EQ_3_16_CONNECTIVITY_BITS * v + qc * k * c * 3.0 * f + qw * c * v) / (f * v)
    }

    /// Eq. 3.18: bpvf* = (6V + q_c·k·c·c* + q_w·3F·c* + q_w·c·V)/(F·V) with time compression;
    /// `None` without it.
    pub fn eq_3_18(&self) -> Option<f64> {
        let (v, f, k, c, qc, qw) = self.terms();
        let cs = self.time_components? as f64;
        Some(
            (EQ_3_16_CONNECTIVITY_BITS * v + qc * k * c * cs + qw * 3.0 * f * cs + qw * c * v)
                / (f * v),
        )
    }
}

/// Bits per vertex per frame of a file of `bytes` bytes holding V vertices and F frames:
/// 8·bytes/(V·F). Everything is counted: header, ranges, means, labels, connectivity,
/// checksum.
pub fn bpvf_from_file(bytes: usize, vertices: usize, frames: usize) -> f64 {
    8.0 * bytes as f64 / (vertices as f64 * frames as f64)
}
