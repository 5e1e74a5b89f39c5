//! Lighting the fins of one frame (thesis §5.7.3, eq. 5.15, Listing 5.1) on the CPU: γ at
//! both ends of every fin, and the fragment colour the GPU pass computes from them.

use glam::Vec3;

use super::mesh::Light;
use crate::error::{BtfError, Result};
use crate::fin_pca::{ALPHA_CUT, FinPca, fin_alpha, fin_frame};
use crate::fins::FinMesh;

/// How fins are shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FinShading {
    /// Listing 5.1's `alpha_adjust`: alpha below it is 0 (default [`ALPHA_CUT`]).
    pub alpha_cut: f32,
}

impl Default for FinShading {
    fn default() -> Self {
        Self {
            alpha_cut: ALPHA_CUT,
        }
    }
}

impl FinShading {
    pub(crate) fn validate(&self) -> Result<()> {
        if !(self.alpha_cut.is_finite() && (0.0..=3.0).contains(&self.alpha_cut)) {
            return Err(BtfError::InvalidParameter {
                what: "FinShading",
                name: "alpha_cut",
                value: self.alpha_cut.to_string(),
                reason: "must be in [0, 3] (alpha is r + g + b)",
            });
        }
        Ok(())
    }
}

/// γ of both ends of every fin, 2 · (c + 1) per fin (end V1 first), for `light` seen from
/// `eye`: at each end's mesh vertex, the light direction in the fin frame ([`fin_frame`]: the
/// vertex normal and the direction to the eye) gives γ by eq. 5.3's interpolation over
/// Table 5.3's lights. `out` is cleared and refilled (no allocation once it is large enough).
///
/// # Errors
/// [`BtfError::InvalidParameter`] for a light that is not finite;
/// [`BtfError::IndexOutOfRange`] when a fin names a vertex beyond `positions` or `normals`.
pub fn fin_gammas(
    fins: &FinPca,
    mesh: &FinMesh,
    positions: &[Vec3],
    normals: &[Vec3],
    light: &Light,
    eye: Vec3,
    out: &mut Vec<f32>,
) -> Result<()> {
    light.validate()?;
    let n = fins.gamma_len();
    out.clear();
    out.resize(2 * n * mesh.len(), 0.0);
    let vertices = positions.len().min(normals.len());
    for (ends, gammas) in mesh.ends.iter().zip(out.chunks_exact_mut(2 * n)) {
        for (&v, g) in ends.iter().zip(gammas.chunks_exact_mut(n)) {
            let v = v as usize;
            if v >= vertices {
                return Err(BtfError::IndexOutOfRange {
                    what: "fin end vertex",
                    index: v,
                    len: vertices,
                });
            }
            let p = positions[v];
            let Some([x, y, z]) = fin_frame(normals[v], eye - p) else {
                continue; // no normal: this end stays dark.
            };
            let Some(l) = light.dir_to_light_world(p).try_normalize() else {
                continue;
            };
            let local = Vec3::new(l.dot(x), l.dot(y), l.dot(z));
            g.copy_from_slice(&fins.gamma(local));
        }
    }
    Ok(())
}

/// The premultiplied colour and alpha of a fin fragment (Listing 5.1): with `w` the V2 end's
/// weight (blend02) at texture coordinates (s, t), each end's colour is its weight times
/// g ⊙ (γ_0 B_0 + Σ_k γ_k B_k) at the texel of (s, t), its alpha r + g + b cut below
/// `shading.alpha_cut`, and the fragment is their sum (alpha clamped to 1). A cut end adds
/// nothing — neither colour nor alpha — so camera noise below the cut disappears entirely.
pub fn fin_fragment(
    fins: &FinPca,
    gammas: [&[f32]; 2],
    radiance: Vec3,
    st: [f32; 2],
    w: f32,
    shading: &FinShading,
) -> [f32; 4] {
    let (x, y) = fins.texel_of(st[0], st[1]);
    let mut out = [0.0f32; 4];
    for (g, weight) in gammas.into_iter().zip([1.0 - w, w]) {
        let t = fins.texel(g, x, y);
        let rgb = [
            weight * radiance.x * t[0],
            weight * radiance.y * t[1],
            weight * radiance.z * t[2],
        ];
        let a = fin_alpha(rgb, shading.alpha_cut);
        if a > 0.0 {
            for c in 0..3 {
                out[c] += rgb[c];
            }
            out[3] += a;
        }
    }
    out[3] = out[3].min(1.0);
    out
}
