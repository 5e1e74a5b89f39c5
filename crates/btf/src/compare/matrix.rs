//! [`AbrdfMatrix`]: the BTF held once as 8-bit sRGB codes, rows = texels' ABRDFs.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use rayon::prelude::*;

use super::{ABRDF_LEN, SLOT_LEN, abrdf_index};
use crate::compress::{for_each_slot_bounded, resolve_workers};
use crate::dataset::ViewSlot;
use crate::error::{BtfError, Result};
use crate::io::{linear_to_srgb8, srgb8_table};
use crate::sampling::{DIRECTIONS, Sampling};

/// A BTF in memory as the 8-bit sRGB codes of its texels' ABRDFs (see the
/// [module docs](super)): row t is texel t (row-major in the image), laid out as
/// [`abrdf_index`].
#[derive(Clone, PartialEq, Eq)]
pub struct AbrdfMatrix {
    sampling: Sampling,
    width: usize,
    height: usize,
    codes: Vec<u8>,
}

impl std::fmt::Debug for AbrdfMatrix {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AbrdfMatrix")
            .field("sampling", &self.sampling)
            .field("width", &self.width)
            .field("height", &self.height)
            .finish_non_exhaustive()
    }
}

impl AbrdfMatrix {
    /// Builds the matrix from view slots `load(j)` (linear RGB, as for
    /// [`BtfPca::compress_with`](crate::BtfPca::compress_with)), encoding every value as an 8-bit sRGB code. At most
    /// `min(rayon threads, 4)` slots are in memory at once; `progress(done, 81)` is called
    /// after each slot.
    ///
    /// # Errors
    /// [`BtfError::InvalidParameter`] for a zero or too large size;
    /// [`BtfError::LengthMismatch`] if a slot has another size or view index than asked for;
    /// whatever `load` returns.
    pub fn from_slots<L>(
        sampling: Sampling,
        width: usize,
        height: usize,
        load: L,
        progress: Option<&(dyn Fn(usize, usize) + Sync)>,
    ) -> Result<Self>
    where
        L: Fn(usize) -> Result<ViewSlot> + Sync,
    {
        let n = width.checked_mul(height).filter(|&n| n > 0);
        let len = n.and_then(|n| n.checked_mul(ABRDF_LEN));
        let (Some(n), Some(len)) = (n, len) else {
            return Err(BtfError::InvalidParameter {
                what: "AbrdfMatrix::from_slots",
                name: "width × height",
                value: format!("{width} × {height}"),
                reason: "a normtexture has at least one texel and 19,683 · texels must fit memory",
            });
        };
        let codes = Mutex::new(vec![0u8; len]);
        let done = AtomicUsize::new(0);
        for_each_slot_bounded(resolve_workers(0), DIRECTIONS, |j| {
            let slot = load(j)?;
            if slot.view() != j || slot.width() != width || slot.height() != height {
                return Err(BtfError::LengthMismatch {
                    what: "AbrdfMatrix::from_slots load(j)",
                    expected: n,
                    found: slot.width() * slot.height(),
                    hint: "return the slot asked for (ViewSlot::view() = j) at the BTF's size",
                });
            }
            // Texel-major within the slot, so the copy below moves 243-byte runs.
            let mut buf = vec![0u8; n * SLOT_LEN];
            for i in 0..DIRECTIONS {
                for (t, rgb) in slot.image(i).chunks_exact(3).enumerate() {
                    for (c, &v) in rgb.iter().enumerate() {
                        buf[t * SLOT_LEN + i * 3 + c] = linear_to_srgb8(v);
                    }
                }
            }
            drop(slot);
            {
                let mut codes = codes.lock().unwrap_or_else(PoisonError::into_inner);
                for (t, run) in buf.chunks_exact(SLOT_LEN).enumerate() {
                    let at = t * ABRDF_LEN + j * SLOT_LEN;
                    codes[at..at + SLOT_LEN].copy_from_slice(run);
                }
            }
            let d = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(p) = progress {
                p(d, DIRECTIONS);
            }
            Ok(())
        })?;
        Ok(Self {
            sampling,
            width,
            height,
            codes: codes.into_inner().unwrap_or_else(PoisonError::into_inner),
        })
    }

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

    /// Number of texels n = width · height (rows of the matrix).
    pub fn texels(&self) -> usize {
        self.width * self.height
    }

    /// The codes of texel `t`'s ABRDF ([`ABRDF_LEN`] values, see [`abrdf_index`]).
    ///
    /// # Panics
    /// If `t ≥ texels()`.
    pub fn abrdf(&self, t: usize) -> &[u8] {
        &self.codes[t * ABRDF_LEN..(t + 1) * ABRDF_LEN]
    }

    /// Bytes held: n · 19,683.
    pub fn bytes(&self) -> usize {
        self.codes.len()
    }

    /// View slot `view` decoded to linear RGB (81 images; 81 · 3 · n f32).
    ///
    /// # Errors
    /// [`BtfError::IndexOutOfRange`] for `view ≥ 81`.
    pub fn view_slot(&self, view: usize) -> Result<ViewSlot> {
        check_index("view slot", view)?;
        let lut = srgb8_table();
        let n = self.texels();
        let mut data = vec![0.0f32; DIRECTIONS * 3 * n];
        for (t, row) in self.codes.chunks_exact(ABRDF_LEN).enumerate() {
            let run = &row[view * SLOT_LEN..(view + 1) * SLOT_LEN];
            for (i, rgb) in run.chunks_exact(3).enumerate() {
                let at = i * 3 * n + 3 * t;
                for (o, &q) in data[at..at + 3].iter_mut().zip(rgb) {
                    *o = lut[usize::from(q)];
                }
            }
        }
        ViewSlot::new(view, self.width, self.height, data)
    }

    /// The normtexture of (view slot, light) decoded to linear RGB, row-major.
    ///
    /// # Errors
    /// [`BtfError::IndexOutOfRange`] for an index ≥ 81.
    pub fn image(&self, view: usize, light: usize) -> Result<Vec<[f32; 3]>> {
        check_index("view slot", view)?;
        check_index("light", light)?;
        let lut = srgb8_table();
        let at = abrdf_index(view, light, 0);
        Ok(self
            .codes
            .chunks_exact(ABRDF_LEN)
            .map(|row| std::array::from_fn(|c| lut[usize::from(row[at + c])]))
            .collect())
    }

    /// Rows `rows` decoded to linear f32, row-major.
    pub(super) fn decode_rows(&self, rows: &[usize]) -> Vec<f32> {
        let lut = srgb8_table();
        let mut out = vec![0.0f32; rows.len() * ABRDF_LEN];
        out.par_chunks_mut(ABRDF_LEN)
            .zip(rows.par_iter())
            .for_each(|(o, &t)| {
                for (v, &q) in o.iter_mut().zip(self.abrdf(t)) {
                    *v = lut[usize::from(q)];
                }
            });
        out
    }
}

fn check_index(what: &'static str, index: usize) -> Result<()> {
    if index >= DIRECTIONS {
        return Err(BtfError::IndexOutOfRange {
            what,
            index,
            len: DIRECTIONS,
        });
    }
    Ok(())
}

pub(super) fn check_size(btf: &AbrdfMatrix, width: usize, height: usize) -> Result<()> {
    if (btf.width, btf.height) != (width, height) {
        return Err(BtfError::LengthMismatch {
            what: "compare: BTF size",
            expected: width * height,
            found: btf.texels(),
            hint: "compare against the BTF the model was fitted to (same size)",
        });
    }
    Ok(())
}
