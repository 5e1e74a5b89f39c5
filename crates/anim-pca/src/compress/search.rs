//! Choosing k for a target error or a target rate (thesis §3.3.2: "The desired maximal
//! reconstruction error or the available bandwidth for transmission can be used as a stopping
//! criterium for increasing k, starting with k = 1").
//!
//! Unlike `clustering::LocalPca::search_k`, which stops on the unquantized model's mean
//! error, this search measures what a user is promised: every candidate k is encoded with the
//! caller's c, c*, q_c and q_w, serialised, decoded, and judged by the **quantized** d_a and
//! the **actual file size** in bits per vertex per frame. k rises one at a time from 1, as the
//! thesis prescribes; d_a is not monotone in k (each k is a separate local-PCA fit), so a
//! bisection could skip the first k that meets the target.

use std::time::Instant;

use glam::Vec3;

use super::CpcaParams;
use super::container::Compressed;
use super::decode::Decoder;
use super::metrics::bpvf_from_file;
use crate::error::{Result, invalid};

/// What the k search aims for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RateTarget {
    /// The smallest k whose decoded clip has d_a ≤ this (percent, Karni–Gotsman).
    Distortion(f64),
    /// The k of lowest d_a among those whose `.cpca` file needs ≤ this many bits per vertex
    /// per frame. The file grows with k (k·3F more mean and eigentrajectory codes per
    /// cluster), so the search stops at the first k over budget.
    Bpvf(f64),
}

impl RateTarget {
    /// Refuses a target that is not a positive finite number, naming `what`.
    pub(crate) fn check(self, what: &'static str) -> Result<()> {
        let value = match self {
            Self::Distortion(x) | Self::Bpvf(x) => x,
        };
        if !(value.is_finite() && value > 0.0) {
            return Err(invalid(
                what,
                "target",
                value,
                "the target d_a or bpvf must be a positive finite number",
            ));
        }
        Ok(())
    }
}

/// One k tried.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SearchStep {
    /// Clusters.
    pub k: usize,
    /// d_a of the decoded clip.
    pub da: f64,
    /// Bits per vertex per frame of the serialised file.
    pub bpvf: f64,
    /// Seconds spent encoding, serialising and measuring this k.
    pub seconds: f64,
}

/// The outcome of [`search_clusters`].
#[derive(Clone, Debug)]
pub struct ClusterSearch {
    /// The chosen compression.
    pub compressed: Compressed,
    /// Every k tried, in order.
    pub steps: Vec<SearchStep>,
    /// Index into `steps` of the chosen k.
    pub chosen: usize,
    /// Whether the chosen k meets the target. When no k does, the chosen one is the closest:
    /// for [`RateTarget::Distortion`] the lowest d_a up to `k_max`, for
    /// [`RateTarget::Bpvf`] k = 1 (the smallest file).
    pub reached: bool,
}

impl ClusterSearch {
    /// The chosen step.
    pub fn chosen_step(&self) -> &SearchStep {
        &self.steps[self.chosen]
    }
}

const WHAT: &str = "search_clusters";

/// Searches k = 1, 2, … , `k_max` (clamped to V) for `target`, with every other setting from
/// `params` (`params.clusters` is ignored). `progress` sees each step as it completes.
///
/// # Errors
/// [`crate::AnimPcaError::InvalidParameter`] for `k_max` = 0 or a target that is not a
/// positive finite number; otherwise those of [`Compressed::encode`].
///
/// # Examples
/// ```
/// use anim_pca::compress::{CpcaParams, RateTarget, search_clusters};
/// use glam::Vec3;
///
/// // Four squares, each turning at its own rate: one cluster of 2 components cannot hold
/// // all four rotations, four clusters can.
/// let frames: Vec<Vec<Vec3>> = (0..30)
///     .map(|t| {
///         (0..64)
///             .map(|m| {
///                 let (part, s) = (m / 16, (m % 16) as f32 / 4.0 - 2.0);
///                 let a = t as f32 * (0.05 + 0.07 * part as f32);
///                 Vec3::new(10.0 * part as f32 + s * a.cos(), s * a.sin(), 0.0)
///             })
///             .collect()
///     })
///     .collect();
/// let params = CpcaParams { components: 2, ..CpcaParams::default() };
/// let found = search_clusters(&frames, &[], 30.0, &params, RateTarget::Distortion(0.5), 8,
///     &mut |_| {}).unwrap();
/// assert!(found.reached);
/// assert!(found.chosen_step().da <= 0.5);
/// assert!(found.steps.len() >= 2); // k = 1 was not enough
/// ```
pub fn search_clusters(
    frames: &[Vec<Vec3>],
    triangles: &[[u32; 3]],
    frame_rate: f32,
    params: &CpcaParams,
    target: RateTarget,
    k_max: usize,
    progress: &mut dyn FnMut(&SearchStep),
) -> Result<ClusterSearch> {
    target.check(WHAT)?;
    if k_max == 0 {
        return Err(invalid(WHAT, "k_max", 0, "k_max must be at least 1"));
    }
    let vertices = frames.first().map_or(0, Vec::len);
    let k_max = k_max.min(vertices.max(1));
    let mut steps = Vec::new();
    let mut best: Option<(usize, Compressed)> = None;
    for k in 1..=k_max {
        let start = Instant::now();
        let p = CpcaParams {
            clusters: k,
            ..*params
        };
        let packed = Compressed::encode(frames, triangles, frame_rate, &p)?;
        let bytes = packed.to_bytes().len();
        let da = Decoder::new(&packed).distortion(frames)?.da;
        let step = SearchStep {
            k,
            da,
            bpvf: bpvf_from_file(bytes, packed.vertices(), packed.frames()),
            seconds: start.elapsed().as_secs_f64(),
        };
        progress(&step);
        steps.push(step);
        let index = steps.len() - 1;
        match target {
            RateTarget::Distortion(t) => {
                let better = best.as_ref().is_none_or(|(b, _)| da < steps[*b].da);
                if da <= t {
                    return Ok(ClusterSearch {
                        compressed: packed,
                        steps,
                        chosen: index,
                        reached: true,
                    });
                }
                if better {
                    best = Some((index, packed));
                }
            }
            RateTarget::Bpvf(t) => {
                if step.bpvf > t {
                    if best.is_none() {
                        best = Some((index, packed));
                    }
                    break;
                }
                let better = best.as_ref().is_none_or(|(b, _)| da < steps[*b].da);
                if better {
                    best = Some((index, packed));
                }
            }
        }
    }
    let (chosen, compressed) = best.expect("k_max ≥ 1, so at least one k was encoded");
    let reached = match target {
        RateTarget::Distortion(t) => steps[chosen].da <= t,
        RateTarget::Bpvf(t) => steps[chosen].bpvf <= t,
    };
    Ok(ClusterSearch {
        compressed,
        steps,
        chosen,
        reached,
    })
}
