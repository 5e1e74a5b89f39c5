//! The error of a reconstruction against the 8-bit codes, as [`ErrorStats`].

use std::sync::OnceLock;

use crate::io::{linear_to_srgb, srgb8_table};
use crate::stats::ErrorStats;

/// Steps of the sRGB encoding table over linear [0, 1].
const ENCODE_STEPS: usize = 1 << 16;

/// linear_to_srgb at ENCODE_STEPS + 1 points.
fn encode_table() -> &'static [f32] {
    static TABLE: OnceLock<Vec<f32>> = OnceLock::new();
    TABLE.get_or_init(|| {
        (0..=ENCODE_STEPS)
            .map(|i| linear_to_srgb(i as f32 / ENCODE_STEPS as f32))
            .collect()
    })
}

/// sRGB encoding of a linear value clamped to [0, 1] (NaN → 0), from the table.
#[inline]
fn encode(table: &[f32], l: f32) -> f32 {
    if l.is_nan() || l <= 0.0 {
        return table[0];
    }
    if l >= 1.0 {
        return table[ENCODE_STEPS];
    }
    let x = l * ENCODE_STEPS as f32;
    let i = (x as usize).min(ENCODE_STEPS - 1);
    let f = x - i as f32;
    table[i] + f * (table[i + 1] - table[i])
}

/// Running sums of [`ErrorStats`] against 8-bit originals.
#[derive(Clone, Copy, Default)]
pub(super) struct Acc {
    values: u64,
    sq_srgb: f64,
    sq_linear: f64,
    max_abs: f64,
}

impl Acc {
    pub(super) fn add(&mut self, original: &[u8], reconstructed: &[f32]) {
        let (lut, enc) = (srgb8_table(), encode_table());
        let (mut sq_s, mut sq_l, mut max) = (0.0f64, 0.0f64, 0.0f32);
        for (&q, &r) in original.iter().zip(reconstructed) {
            let ds = (encode(enc, r) * 255.0 - f32::from(q)).abs();
            let dl = (lut[usize::from(q)] - r) * 255.0;
            sq_s += f64::from(ds * ds);
            sq_l += f64::from(dl * dl);
            max = max.max(ds);
        }
        self.sq_srgb += sq_s;
        self.sq_linear += sq_l;
        self.max_abs = self.max_abs.max(f64::from(max));
        self.values += original.len() as u64;
    }

    pub(super) fn merge(mut self, o: Self) -> Self {
        self.values += o.values;
        self.sq_srgb += o.sq_srgb;
        self.sq_linear += o.sq_linear;
        self.max_abs = self.max_abs.max(o.max_abs);
        self
    }

    pub(super) fn finish(self, images: usize) -> ErrorStats {
        let n = self.values.max(1) as f64;
        let rms = (self.sq_srgb / n).sqrt();
        ErrorStats {
            images,
            values: self.values,
            rms_srgb8: rms,
            psnr_db: if rms > 0.0 {
                20.0 * (255.0 / rms).log10()
            } else {
                f64::INFINITY
            },
            max_abs_srgb8: self.max_abs,
            rms_linear8: (self.sq_linear / n).sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_table_matches_the_transfer_function() {
        let enc = encode_table();
        let mut worst = 0.0f32;
        for i in 0..200_000 {
            let l = i as f32 / 200_000.0;
            worst = worst.max((encode(enc, l) - linear_to_srgb(l)).abs() * 255.0);
        }
        // Measured 9.6e-5 codes: the table's interpolation error (≤ 2e-5) plus f32 rounding of
        // both sides.
        assert!(worst < 2e-4, "{worst} codes");
        assert_eq!(encode(enc, -1.0), 0.0);
        assert_eq!(encode(enc, f32::NAN), 0.0);
        assert_eq!(encode(enc, 2.0), linear_to_srgb(1.0));
    }
}
