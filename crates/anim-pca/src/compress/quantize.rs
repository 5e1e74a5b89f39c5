//! Uniform scalar quantization of one array to q bits over its own range (thesis §3.3.2
//! "Quantization"), and the little-endian bit packing of the codes.
//!
//! An array x is normalised to its tight range [lo, hi] and stored as integer codes
//! uᵢ = round((xᵢ − lo)/s) with the step s = (hi − lo)/(2^q − 1); it is read back as
//! lo + uᵢ·s, so every value is off by at most s/2 ([`Quantized::max_error`]). The range is
//! stored as two `f32`, rounded outwards so that the stored range still contains every value
//! and the codes are computed against exactly the range the decoder reads. A zero-range array
//! (hi = lo, e.g. a constant or an all-zero component) gets step 0 and is reproduced exactly.

/// Smallest and largest bit count of a quantized scalar.
pub const MIN_BITS: u8 = 1;
/// Largest bit count: codes are `u32`.
pub const MAX_BITS: u8 = 32;

/// One quantized array: its range, bit count and codes.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantized {
    lo: f32,
    hi: f32,
    bits: u8,
    codes: Vec<u32>,
}

impl Quantized {
    /// Quantizes `values` (finite) with `bits` ∈ 1..=32 bits over their own [min, max].
    pub(crate) fn new(values: &[f64], bits: u8) -> Self {
        assert!(
            (MIN_BITS..=MAX_BITS).contains(&bits),
            "bits checked by caller"
        );
        let (mut lo, mut hi) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        if values.is_empty() {
            (lo, hi) = (0.0, 0.0);
        }
        let (lo, hi) = (round_down(lo), round_up(hi));
        let mut q = Self {
            lo,
            hi,
            bits,
            codes: Vec::with_capacity(values.len()),
        };
        let (lo64, step) = (f64::from(lo), q.step());
        let top = levels(bits) as f64;
        q.codes.extend(values.iter().map(|&x| {
            if step == 0.0 {
                0
            } else {
                ((x - lo64) / step).round().clamp(0.0, top) as u32
            }
        }));
        q
    }

    /// Rebuilds an array read from a file; the caller has checked the range and the codes.
    pub(crate) fn from_parts(lo: f32, hi: f32, bits: u8, codes: Vec<u32>) -> Self {
        Self {
            lo,
            hi,
            bits,
            codes,
        }
    }

    /// Lower end of the range.
    pub fn lo(&self) -> f32 {
        self.lo
    }

    /// Upper end of the range.
    pub fn hi(&self) -> f32 {
        self.hi
    }

    /// Bits per code q.
    pub fn bits(&self) -> u8 {
        self.bits
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.codes.len()
    }

    /// Whether the array is empty.
    pub fn is_empty(&self) -> bool {
        self.codes.is_empty()
    }

    /// The integer codes uᵢ.
    pub fn codes(&self) -> &[u32] {
        &self.codes
    }

    /// Step s = (hi − lo)/(2^q − 1); 0 for a zero-range array.
    pub fn step(&self) -> f64 {
        (f64::from(self.hi) - f64::from(self.lo)) / levels(self.bits) as f64
    }

    /// Largest error of a dequantized value, s/2.
    pub fn max_error(&self) -> f64 {
        0.5 * self.step()
    }

    /// Value i read back: lo + uᵢ·s.
    ///
    /// # Panics
    /// If `i ≥ len()`.
    pub fn value(&self, i: usize) -> f64 {
        f64::from(self.lo) + f64::from(self.codes[i]) * self.step()
    }

    /// All values read back.
    pub fn values(&self) -> impl ExactSizeIterator<Item = f64> + '_ {
        let (lo, step) = (f64::from(self.lo), self.step());
        self.codes.iter().map(move |&u| lo + f64::from(u) * step)
    }
}

/// 2^q − 1, the largest code.
pub(crate) fn levels(bits: u8) -> u64 {
    (1u64 << bits) - 1
}

/// The largest `f32` ≤ x.
fn round_down(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) > x { y.next_down() } else { y }
}

/// The smallest `f32` ≥ x.
fn round_up(x: f64) -> f32 {
    let y = x as f32;
    if f64::from(y) < x { y.next_up() } else { y }
}

/// Packs codes of `bits` bits each, least significant bit first.
#[derive(Default)]
pub(crate) struct BitWriter {
    bytes: Vec<u8>,
    acc: u64,
    filled: u32,
}

impl BitWriter {
    pub fn push(&mut self, code: u32, bits: u8) {
        let bits = u32::from(bits);
        let masked = if bits == 32 {
            u64::from(code)
        } else {
            u64::from(code) & ((1u64 << bits) - 1)
        };
        self.acc |= masked << self.filled;
        self.filled += bits;
        while self.filled >= 8 {
            self.bytes.push(self.acc as u8);
            self.acc >>= 8;
            self.filled -= 8;
        }
    }

    /// The packed bytes, the last one padded with zero bits.
    pub fn finish(mut self) -> Vec<u8> {
        if self.filled > 0 {
            self.bytes.push(self.acc as u8);
        }
        self.bytes
    }
}

/// Reads codes packed by [`BitWriter`]; the caller has checked that enough bytes are present.
pub(crate) struct BitReader<'a> {
    bytes: &'a [u8],
    pos: usize,
    acc: u64,
    filled: u32,
}

impl<'a> BitReader<'a> {
    pub fn new(bytes: &'a [u8]) -> Self {
        Self {
            bytes,
            pos: 0,
            acc: 0,
            filled: 0,
        }
    }

    /// The next code, or `None` past the end of the bytes.
    pub fn read(&mut self, bits: u8) -> Option<u32> {
        let bits = u32::from(bits);
        while self.filled < bits {
            let b = *self.bytes.get(self.pos)?;
            self.pos += 1;
            self.acc |= u64::from(b) << self.filled;
            self.filled += 8;
        }
        let v = if bits == 32 {
            self.acc as u32
        } else {
            (self.acc & ((1u64 << bits) - 1)) as u32
        };
        self.acc >>= bits;
        self.filled -= bits;
        Some(v)
    }
}

/// Bytes that `count` codes of `bits` bits occupy, or `None` on overflow.
pub(crate) fn packed_len(count: u64, bits: u8) -> Option<u64> {
    count
        .checked_mul(u64::from(bits))?
        .checked_add(7)
        .map(|b| b / 8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bits_round_trip_at_every_width() {
        for bits in MIN_BITS..=MAX_BITS {
            let top = levels(bits) as u32;
            let codes = [0, top, top / 3, 1 & top, top.saturating_sub(1)];
            let mut w = BitWriter::default();
            codes.iter().for_each(|&c| w.push(c, bits));
            let bytes = w.finish();
            assert_eq!(bytes.len() as u64, packed_len(5, bits).unwrap());
            let mut r = BitReader::new(&bytes);
            for &c in &codes {
                assert_eq!(r.read(bits), Some(c), "bits {bits}");
            }
        }
    }

    #[test]
    fn error_is_within_half_a_step() {
        let values: Vec<f64> = (0..1000)
            .map(|i| (i as f64 * 0.37).sin() * 3.0 + 1e3)
            .collect();
        for bits in [4, 12, 18, 32] {
            let q = Quantized::new(&values, bits);
            for (i, v) in q.values().enumerate() {
                let bound = q.max_error() + 1e-12 * 1e3;
                assert!(
                    (v - values[i]).abs() <= bound,
                    "bits {bits}: {v} vs {}",
                    values[i]
                );
            }
        }
        let zero = Quantized::new(&[2.5; 7], 4);
        assert_eq!(zero.step(), 0.0);
        assert!(zero.values().all(|v| v == 2.5));
    }
}
