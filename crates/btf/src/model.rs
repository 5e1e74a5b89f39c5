//! The compressed BTF: per view slot a mean normtexture, c eigen-normtextures, the weights
//! p_ikj and the eigenvalues (thesis §5.4, eq. 5.1, with the mean as B_0j of eq. 5.4).
//!
//! Textures are stored quantized with a per-texture range (lo, hi): an 8-bit code q stands for
//! lo + q·(hi − lo)/255 (16-bit: /65535; f32 stores the value itself). That is the thesis's
//! storage: 81 slots × 16 eigen-normtextures × 256² × 3 bytes ≈ 255 MB, its "1230 MB → 260 MB"
//! (§5.4) in MiB with the mean included.

use crate::sampling::{DIRECTIONS, Sampling};

/// How texture values are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Storage {
    /// 8 bits per value with a per-texture (lo, hi) range: the thesis's storage.
    #[default]
    U8,
    /// 16 bits per value with a per-texture (lo, hi) range.
    U16,
    /// 32-bit floats, unquantized.
    F32,
}

impl Storage {
    /// Bytes per stored value.
    pub fn bytes(self) -> usize {
        match self {
            Self::U8 => 1,
            Self::U16 => 2,
            Self::F32 => 4,
        }
    }

    /// The largest code (255, 65535), 0 for f32.
    pub fn levels(self) -> u32 {
        match self {
            Self::U8 => 255,
            Self::U16 => 65535,
            Self::F32 => 0,
        }
    }

    /// The file code of the storage (its byte count).
    pub(crate) fn code(self) -> u8 {
        self.bytes() as u8
    }

    pub(crate) fn from_code(code: u8) -> Option<Self> {
        match code {
            1 => Some(Self::U8),
            2 => Some(Self::U16),
            4 => Some(Self::F32),
            _ => None,
        }
    }
}

/// Stored values of a texture.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Codes {
    U8(Vec<u8>),
    U16(Vec<u16>),
    F32(Vec<f32>),
}

/// One stored texture (a mean or an eigen-normtexture) of 3·w·h values.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub(crate) lo: f32,
    pub(crate) hi: f32,
    pub(crate) codes: Codes,
}

impl Texture {
    /// Quantizes `values` with `storage` over their own (min, max) range. A constant texture
    /// (zero range) stores code 0 everywhere and is reproduced exactly.
    pub(crate) fn quantize(values: &[f64], storage: Storage) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &v in values {
            lo = lo.min(v);
            hi = hi.max(v);
        }
        if values.is_empty() {
            (lo, hi) = (0.0, 0.0);
        }
        let (lo, hi) = (lo as f32, hi as f32);
        let codes = match storage {
            Storage::F32 => Codes::F32(values.iter().map(|&v| v as f32).collect()),
            Storage::U8 | Storage::U16 => {
                let levels = f64::from(storage.levels());
                let range = f64::from(hi) - f64::from(lo);
                let scale = if range > 0.0 { levels / range } else { 0.0 };
                let code = |v: f64| ((v - f64::from(lo)) * scale).round().clamp(0.0, levels) as u32;
                if storage == Storage::U8 {
                    Codes::U8(values.iter().map(|&v| code(v) as u8).collect())
                } else {
                    Codes::U16(values.iter().map(|&v| code(v) as u16).collect())
                }
            }
        };
        Self { lo, hi, codes }
    }

    /// The storage of the texture.
    pub fn storage(&self) -> Storage {
        match self.codes {
            Codes::U8(_) => Storage::U8,
            Codes::U16(_) => Storage::U16,
            Codes::F32(_) => Storage::F32,
        }
    }

    /// The (lo, hi) range of the stored values.
    pub fn range(&self) -> (f32, f32) {
        (self.lo, self.hi)
    }

    /// The step between codes, (hi − lo)/levels (0 for f32): the quantization error of one
    /// value is at most half of it.
    pub fn step(&self) -> f32 {
        match self.storage() {
            Storage::F32 => 0.0,
            s => (self.hi - self.lo) / s.levels() as f32,
        }
    }

    /// Number of values (3·w·h).
    pub fn len(&self) -> usize {
        match &self.codes {
            Codes::U8(c) => c.len(),
            Codes::U16(c) => c.len(),
            Codes::F32(c) => c.len(),
        }
    }

    /// True for a texture without values.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The dequantized value `i`.
    ///
    /// # Panics
    /// If `i ≥ len()`.
    #[inline]
    pub fn get(&self, i: usize) -> f32 {
        match &self.codes {
            Codes::U8(c) => self.lo + f32::from(c[i]) * self.step(),
            Codes::U16(c) => self.lo + f32::from(c[i]) * self.step(),
            Codes::F32(c) => c[i],
        }
    }

    /// All dequantized values.
    pub fn dequantize(&self) -> Vec<f32> {
        let mut out = vec![0.0; self.len()];
        self.add_scaled(1.0, &mut out);
        out
    }

    /// out += a · texture, over the whole texture (out.len() = len()).
    pub(crate) fn add_scaled(&self, a: f32, out: &mut [f32]) {
        let step = self.step();
        match &self.codes {
            Codes::U8(c) => {
                let (a0, a1) = (a * self.lo, a * step);
                out.iter_mut()
                    .zip(c)
                    .for_each(|(o, &q)| *o += a0 + a1 * f32::from(q));
            }
            Codes::U16(c) => {
                let (a0, a1) = (a * self.lo, a * step);
                out.iter_mut()
                    .zip(c)
                    .for_each(|(o, &q)| *o += a0 + a1 * f32::from(q));
            }
            Codes::F32(c) => out.iter_mut().zip(c).for_each(|(o, &v)| *o += a * v),
        }
    }

    /// rgb += a · values t..t+3, with exactly the arithmetic of `add_scaled`, so a texel and
    /// the whole image agree bit for bit.
    #[inline]
    pub(crate) fn add_scaled_texel(&self, a: f32, t: usize, rgb: &mut [f32; 3]) {
        match &self.codes {
            Codes::U8(c) => {
                let (a0, a1) = (a * self.lo, a * self.step());
                for (o, &q) in rgb.iter_mut().zip(&c[t..t + 3]) {
                    *o += a0 + a1 * f32::from(q);
                }
            }
            Codes::U16(c) => {
                let (a0, a1) = (a * self.lo, a * self.step());
                for (o, &q) in rgb.iter_mut().zip(&c[t..t + 3]) {
                    *o += a0 + a1 * f32::from(q);
                }
            }
            Codes::F32(c) => {
                for (o, &v) in rgb.iter_mut().zip(&c[t..t + 3]) {
                    *o += a * v;
                }
            }
        }
    }

    /// Bytes the codes take in a file.
    pub(crate) fn stored_bytes(&self) -> usize {
        self.len() * self.storage().bytes()
    }
}

/// The PCA of one view slot S_j: B_0j (the mean), B_1j … B_cj, p_ikj and the eigenvalues.
#[derive(Clone, Debug, PartialEq)]
pub struct SlotPca {
    /// `textures[0]` is the mean, `textures[k]` the eigen-normtexture B_kj.
    pub(crate) textures: Vec<Texture>,
    /// 81 × c, row-major: weights[i * c + (k − 1)] = p_ikj.
    pub(crate) weights: Vec<f32>,
    /// Every non-zero eigenvalue λ_1j ≥ … ≥ λ_rj (r = numerical rank), of the covariance
    /// (divided by n − 1 = 80).
    pub(crate) eigenvalues: Vec<f32>,
}

impl SlotPca {
    /// Number of eigen-normtextures c_j (the mean not counted).
    pub fn components(&self) -> usize {
        self.textures.len() - 1
    }

    /// Numerical rank r_j of the slot's centred data (number of eigenvalues stored).
    pub fn rank(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Texture `k`: 0 is the mean normtexture (B_0j of eq. 5.4), 1..=c the eigen-normtextures.
    ///
    /// # Panics
    /// If `k > components()`.
    pub fn texture(&self, k: usize) -> &Texture {
        &self.textures[k]
    }

    /// The 81 × c weights p_ikj, row-major (light i, component k = 1..=c at column k − 1).
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// The weights of light `i`: p_i1j … p_icj.
    ///
    /// # Panics
    /// If `i ≥ 81`.
    pub fn light_weights(&self, i: usize) -> &[f32] {
        let c = self.components();
        &self.weights[i * c..(i + 1) * c]
    }

    /// Every non-zero eigenvalue, descending (Fig. 5.8).
    pub fn eigenvalues(&self) -> &[f32] {
        &self.eigenvalues
    }
}

/// A BTF compressed by per-view PCA (thesis §5.4): 81 [`SlotPca`]s over one sampling.
#[derive(Clone, Debug, PartialEq)]
pub struct BtfPca {
    pub(crate) sampling: Sampling,
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) requested_components: usize,
    pub(crate) storage: Storage,
    pub(crate) mean_storage: Storage,
    pub(crate) slots: Vec<SlotPca>,
}

impl BtfPca {
    /// The sampling of view and light directions.
    pub fn sampling(&self) -> Sampling {
        self.sampling
    }

    /// Normtexture width.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Normtexture height.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The component count c that was asked for (slots may hold fewer, see
    /// [`SlotPca::components`]).
    pub fn requested_components(&self) -> usize {
        self.requested_components
    }

    /// Storage of the eigen-normtextures.
    pub fn storage(&self) -> Storage {
        self.storage
    }

    /// Storage of the mean normtextures.
    pub fn mean_storage(&self) -> Storage {
        self.mean_storage
    }

    /// The PCA of view slot `j`.
    ///
    /// # Panics
    /// If `j ≥ 81`.
    pub fn slot(&self, j: usize) -> &SlotPca {
        &self.slots[j]
    }

    /// All 81 slots.
    pub fn slots(&self) -> &[SlotPca] {
        &self.slots
    }

    /// The largest c_j over the slots (the length of a γ vector is this + 1 at most).
    pub fn max_components(&self) -> usize {
        self.slots
            .iter()
            .map(SlotPca::components)
            .max()
            .unwrap_or(0)
    }

    /// Bytes of texture data (means and eigen-normtextures) plus weights and eigenvalues, as
    /// stored in a `.btfpca` file without its headers.
    pub fn payload_bytes(&self) -> usize {
        self.slots
            .iter()
            .map(|s| {
                s.textures.iter().map(Texture::stored_bytes).sum::<usize>()
                    + 8 * s.textures.len()
                    + 4 * (s.weights.len() + s.eigenvalues.len())
            })
            .sum()
    }

    pub(crate) fn texel_values(&self) -> usize {
        3 * self.width * self.height
    }
}

/// Number of samples per slot PCA (the 81 light directions).
pub(crate) const LIGHTS: usize = DIRECTIONS;
