//! The quantization bits `cloth-vis anim compress` chooses itself when `--qc`/`--qw` are not
//! given ([`choose_bits`]: the fewest bits within 1 % of the unquantized d_a).

use anim_pca::compress::{Compressed, CpcaModel, CpcaParams, DEFAULT_BITS_TOLERANCE, choose_bits};

/// Which quantization bit counts `compress` chooses itself (those not given on the command
/// line).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AutoBits {
    /// Choose q_c.
    pub components: bool,
    /// Choose q_w.
    pub weights: bool,
}

/// [`choose_bits`], keeping a bit count the user fixed: when only one of q_c, q_w is chosen,
/// it takes the value `choose_bits` picks with both free, the other stays as given, and the
/// summary reports the d_a that pair measures.
pub(super) fn choose_bits_for(
    model: &CpcaModel,
    clip: &meshio::Animation,
    params: &CpcaParams,
    auto: AutoBits,
) -> anim_pca::Result<anim_pca::compress::BitsChoice> {
    let mut chosen = choose_bits(
        model,
        &clip.frames,
        &clip.triangles,
        clip.frame_rate,
        params,
        DEFAULT_BITS_TOLERANCE,
    )?;
    if auto.components && auto.weights {
        return Ok(chosen);
    }
    // One fixed: re-encode with the fixed count and the chosen other.
    let p = CpcaParams {
        bits_components: if auto.components {
            chosen.bits_components()
        } else {
            params.bits_components
        },
        bits_weights: if auto.weights {
            chosen.bits_weights()
        } else {
            params.bits_weights
        },
        ..*params
    };
    chosen.compressed = Compressed::from_model(model, &clip.triangles, clip.frame_rate, &p)?;
    chosen.tried += 1;
    Ok(chosen)
}
