//! Choosing the quantization bits q_c and q_w (thesis §3.3.2 "Quantization") so that they cost
//! a stated fraction of accuracy and not a bit more.
//!
//! The thesis advises "at least 18 bits for both q_c and q_w"; on real clips that spends bits
//! for nothing (issue #19: at k = 5, c = 20 a 204-frame soft-body clip takes 3.90 bpvf at 18
//! bits and 3.07 at 14 for the same d_a). [`choose_bits`] measures instead: it encodes the
//! fitted model with 32-bit codes (below f32 precision: the unquantized d_a, d₀), then finds
//! by bisection the fewest q_c bits whose decoded d_a stays within d₀·(1 + tol/2) with q_w
//! still at 32, then the fewest q_w bits with that q_c whose d_a stays within d₀·(1 + tol).
//! Each candidate is judged by the decoded clip's d_a, never by a model of it, so the
//! returned pair always meets the bound; one bit fewer of q_w (when above 1) was measured to
//! break it. About 2·log₂ 32 + 1 = 11 encodings of an already fitted model.

use glam::Vec3;

use super::CpcaParams;
use super::container::Compressed;
use super::decode::Decoder;
use super::model::CpcaModel;
use super::quantize::{MAX_BITS, MIN_BITS};
use crate::error::{Result, invalid};

/// The share of the unquantized d_a that quantization may add by default: 1 %.
pub const DEFAULT_BITS_TOLERANCE: f64 = 0.01;

/// What quantization may always add to d_a, however exact the model: 10⁻⁴ (d_a is a
/// percentage of the clip's motion, so this is a millionth of it — below the f32 rounding of
/// the input positions on a clip far from its origin). Without it a model that reproduces the
/// clip exactly (d₀ ≈ 0) would need 26 bits to stay within 1 % of nothing.
pub const DA_FLOOR: f64 = 1e-4;

/// The outcome of [`choose_bits`].
#[derive(Clone, Debug)]
pub struct BitsChoice {
    /// The model encoded with the chosen bits.
    pub compressed: Compressed,
    /// d_a with 32-bit codes (the unquantized model).
    pub da_unquantized: f64,
    /// d_a with the chosen bits (≤ `da_unquantized` + max(`da_unquantized` · tolerance,
    /// [`DA_FLOOR`])).
    pub da: f64,
    /// Encodings tried.
    pub tried: usize,
}

impl BitsChoice {
    /// q_c chosen.
    pub fn bits_components(&self) -> u8 {
        self.compressed.bits_components
    }

    /// q_w chosen.
    pub fn bits_weights(&self) -> u8 {
        self.compressed.bits_weights
    }
}

/// The fewest q_c, then q_w, bits whose decoded clip stays within `tolerance` (a fraction,
/// e.g. [`DEFAULT_BITS_TOLERANCE`]) of the unquantized d_a. `params` gives c* (its bit counts
/// are ignored); `frames` is the clip `model` was fitted to.
///
/// The model is encoded with 32-bit codes (below f32 precision: the unquantized d_a, d₀);
/// then bisection finds the fewest q_c bits whose decoded d_a stays within d₀ + a/2 with q_w
/// still at 32, and the fewest q_w bits with that q_c within d₀ + a, where the allowance
/// a = max(d₀·tolerance, [`DA_FLOOR`]). Each candidate is judged by its decoded d_a, so the
/// returned pair always meets the bound, and one bit fewer of q_w (when above 1) was measured
/// to break it. About 11 encodings of the fitted model (§3.3.2 "Quantization" advises 18 bits
/// for both, which spends bits for nothing on lossy models: issue #19).
///
/// # Errors
/// [`crate::AnimPcaError::InvalidParameter`] for a tolerance that is not finite and ≥ 0;
/// those of [`Compressed::from_model`] and of the decoder's distortion.
///
/// # Examples
/// ```
/// use anim_pca::compress::{CpcaModel, CpcaParams, choose_bits, DEFAULT_BITS_TOLERANCE};
/// use glam::Vec3;
/// let frames: Vec<Vec<Vec3>> = (0..30)
///     .map(|t| (0..50).map(|v| Vec3::new(v as f32, (0.2 * t as f32 + 0.1 * v as f32).sin(), 0.0)).collect())
///     .collect();
/// let params = CpcaParams { clusters: 2, components: 3, ..CpcaParams::default() };
/// let model = CpcaModel::fit(&frames, &params).unwrap();
/// let chosen = choose_bits(&model, &frames, &[], 30.0, &params, DEFAULT_BITS_TOLERANCE).unwrap();
/// assert!(chosen.da <= chosen.da_unquantized + (0.01 * chosen.da_unquantized).max(1e-4));
/// assert!(chosen.bits_components() < 32 && chosen.bits_weights() < 32);
/// ```
pub fn choose_bits(
    model: &CpcaModel,
    frames: &[Vec<Vec3>],
    triangles: &[[u32; 3]],
    frame_rate: f32,
    params: &CpcaParams,
    tolerance: f64,
) -> Result<BitsChoice> {
    if !(tolerance.is_finite() && tolerance >= 0.0) {
        return Err(invalid(
            "choose_bits",
            "tolerance",
            tolerance,
            "the tolerance must be a finite fraction ≥ 0",
        ));
    }
    let mut tried = 0;
    let mut encode = |qc: u8, qw: u8| -> Result<(Compressed, f64)> {
        tried += 1;
        encode_measured(model, frames, triangles, frame_rate, params, qc, qw)
    };
    let (full, d0) = encode(MAX_BITS, MAX_BITS)?;
    // An exact model (d₀ ≈ 0) may still lose DA_FLOOR to quantization.
    let allowance = (d0 * tolerance).max(DA_FLOOR);
    let best = fewest_bits_within(&mut encode, MAX_BITS, (full, d0), allowance)?;
    Ok(BitsChoice {
        compressed: best.0,
        da_unquantized: d0,
        da: best.1,
        tried,
    })
}

/// `model` encoded with q_c = `qc`, q_w = `qw` (c* from `params`) and the d_a of its decoded
/// clip against `frames`.
pub(crate) fn encode_measured(
    model: &CpcaModel,
    frames: &[Vec<Vec3>],
    triangles: &[[u32; 3]],
    frame_rate: f32,
    params: &CpcaParams,
    qc: u8,
    qw: u8,
) -> Result<(Compressed, f64)> {
    let p = CpcaParams {
        bits_components: qc,
        bits_weights: qw,
        ..*params
    };
    let packed = Compressed::from_model(model, triangles, frame_rate, &p)?;
    let da = Decoder::new(&packed).distortion(frames)?.da;
    Ok((packed, da))
}

/// The bisection of [`choose_bits`]: `top` is (the encoding at `ceiling` bits for both, its
/// d_a d₀); returns the encoding with the fewest q_c whose d_a ≤ d₀ + allowance/2 with q_w at
/// `ceiling`, then the fewest q_w with that q_c within d₀ + allowance, and its d_a.
pub(crate) fn fewest_bits_within(
    encode: &mut dyn FnMut(u8, u8) -> Result<(Compressed, f64)>,
    ceiling: u8,
    top: (Compressed, f64),
    allowance: f64,
) -> Result<(Compressed, f64)> {
    let d0 = top.1;
    let bound = |share: f64| d0 + share * allowance;
    // Fewest q_c with q_w at the ceiling within half the allowance.
    let mut pass = (ceiling, top.0, d0);
    let (mut lo, mut hi) = (MIN_BITS - 1, ceiling); // lo: fails (or below range), hi: passes
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let (packed, da) = encode(mid, ceiling)?;
        if da <= bound(0.5) {
            hi = mid;
            pass = (mid, packed, da);
        } else {
            lo = mid;
        }
    }
    let qc = pass.0;
    // Fewest q_w with that q_c within the whole allowance; (qc, ceiling) already passes.
    let mut best = (pass.1, pass.2);
    let (mut lo, mut hi) = (MIN_BITS - 1, ceiling);
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        let (packed, da) = encode(qc, mid)?;
        if da <= bound(1.0) {
            hi = mid;
            best = (packed, da);
        } else {
            lo = mid;
        }
    }
    Ok(best)
}
