//! The `.btfpca` file: a per-view PCA compressed BTF as bytes, and back with every field
//! checked.
//!
//! Layout (all little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `\x89BTFPCA\n` |
//! | 8 | 2 | version (1) |
//! | 10 | 1 | sampling: 1 = H1, 2 = H2 |
//! | 11 | 1 | storage of the eigen-normtextures: bytes per value, 1 (u8), 2 (u16) or 4 (f32) |
//! | 12 | 1 | storage of the mean normtextures, as above |
//! | 13 | 3 | reserved (0) |
//! | 16 | 4 × 4 | width w, height h, requested components c, slot count (81) |
//! | 32 | 8 | total file length in bytes |
//! | 40 | 81 × 8 | slot table: components c_j (u32), rank r_j (u32) |
//! | 688 | … | 81 slot sections, j = 0…80 (below) |
//! | end − 4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! Slot section j: (c_j + 1) ranges (lo, hi) as f32 pairs, the mean's then each
//! eigen-normtexture's; the mean's 3wh codes; c_j × 3wh eigen-normtexture codes (texture-major,
//! texels row-major, RGB interleaved); the 81 × c_j weights p_ikj (f32, light-major); the r_j
//! eigenvalues (f32, descending). A u8/u16 code q stands for lo + q·(hi − lo)/(2^bits − 1).
//!
//! Reading validates before it allocates: magic, version, codes, reserved bytes, sizes
//! (w, h ≥ 1, slot count 81, c_j ≤ r_j ≤ 80, c_j ≤ c), the declared length against the actual
//! one and the length the header implies (checked arithmetic, so no overflow), and the
//! checksum. Every array allocated is then bounded by bytes present in the file. Ranges must be
//! finite with lo ≤ hi, weights and f32 texture values finite, eigenvalues finite, ≥ 0 and
//! descending.

use std::path::{Path, PathBuf};

use crate::compress::MAX_COMPONENTS;
use crate::error::{BtfError, Result};
use crate::model::{BtfPca, Codes, LIGHTS, SlotPca, Storage, Texture};
use crate::sampling::{DIRECTIONS, Sampling};

/// The file signature (PNG-style: a high byte, the name, a line feed).
pub const MAGIC: [u8; 8] = *b"\x89BTFPCA\n";
/// The format version written and read.
pub const VERSION: u16 = 1;
const HEADER_LEN: usize = 40;
const CRC_LEN: usize = 4;

impl BtfPca {
    /// Serialises to the `.btfpca` layout of [`crate::format`](mod@crate::format).
    pub fn to_bytes(&self) -> Vec<u8> {
        self.to_bytes_with(&MAGIC)
    }

    /// The layout with another signature (the fin file, [`crate::fin_pca`], shares it with
    /// one slot).
    pub(crate) fn to_bytes_with(&self, magic: &[u8; 8]) -> Vec<u8> {
        let table_len = self.slots.len() * 8;
        let mut out = Vec::with_capacity(HEADER_LEN + table_len + self.payload_bytes() + CRC_LEN);
        out.extend_from_slice(magic);
        out.extend_from_slice(&VERSION.to_le_bytes());
        out.push(match self.sampling {
            Sampling::H1 => 1,
            Sampling::H2 => 2,
        });
        out.push(self.storage.code());
        out.push(self.mean_storage.code());
        out.extend_from_slice(&[0; 3]);
        for v in [
            self.width,
            self.height,
            self.requested_components,
            self.slots.len(),
        ] {
            out.extend_from_slice(&(v as u32).to_le_bytes());
        }
        let total = HEADER_LEN + table_len + self.payload_bytes() + CRC_LEN;
        out.extend_from_slice(&(total as u64).to_le_bytes());
        for s in &self.slots {
            out.extend_from_slice(&(s.components() as u32).to_le_bytes());
            out.extend_from_slice(&(s.rank() as u32).to_le_bytes());
        }
        for s in &self.slots {
            for t in &s.textures {
                out.extend_from_slice(&t.lo.to_le_bytes());
                out.extend_from_slice(&t.hi.to_le_bytes());
            }
            for t in &s.textures {
                match &t.codes {
                    Codes::U8(c) => out.extend_from_slice(c),
                    Codes::U16(c) => c
                        .iter()
                        .for_each(|q| out.extend_from_slice(&q.to_le_bytes())),
                    Codes::F32(c) => c
                        .iter()
                        .for_each(|q| out.extend_from_slice(&q.to_le_bytes())),
                }
            }
            s.weights
                .iter()
                .chain(&s.eigenvalues)
                .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
        }
        debug_assert_eq!(out.len() + CRC_LEN, total);
        let crc = crc32fast::hash(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Parses and validates `.btfpca` bytes (see [`crate::format`](mod@crate::format)).
    ///
    /// # Errors
    /// [`BtfError::Format`] naming the first invalid field; never panics on any input.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        parse(bytes, Path::new("<bytes>"), &BTFPCA)
    }

    /// Writes a `.btfpca` file atomically (temporary file + rename).
    ///
    /// # Errors
    /// [`BtfError::Io`] if the file cannot be written (then `path` is untouched).
    pub fn write(&self, path: &Path) -> Result<()> {
        atomic_out::write_bytes(path, &self.to_bytes())?;
        Ok(())
    }

    /// Reads and validates a `.btfpca` file.
    ///
    /// # Errors
    /// [`BtfError::Io`] if it cannot be read, [`BtfError::Format`] naming the file and the
    /// first invalid field.
    pub fn read(path: &Path) -> Result<Self> {
        let bytes = input_guard::read_regular(path).map_err(|e| BtfError::io(path, "read", e))?;
        parse(&bytes, path, &BTFPCA)
    }
}

/// What distinguishes the files sharing this layout: signature, name and slot count.
pub(crate) struct Kind {
    pub magic: [u8; 8],
    /// For messages: "a .btfpca file".
    pub name: &'static str,
    pub slots: usize,
    /// For messages: "must be 81".
    pub slots_reason: &'static str,
}

/// The per-view BTF file.
const BTFPCA: Kind = Kind {
    magic: MAGIC,
    name: "not a .btfpca file",
    slots: DIRECTIONS,
    slots_reason: "must be 81",
};

/// A cursor over validated bytes.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    path: &'a Path,
}

impl<'a> Reader<'a> {
    fn bad(
        &self,
        field: &'static str,
        value: impl std::fmt::Display,
        reason: &'static str,
    ) -> BtfError {
        bad(self.path, field, value, reason)
    }

    fn take(&mut self, n: usize, field: &'static str) -> Result<&'a [u8]> {
        let end = self
            .pos
            .checked_add(n)
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| self.bad(field, self.pos, "the data ends inside this field"))?;
        let s = &self.bytes[self.pos..end];
        self.pos = end;
        Ok(s)
    }

    fn u32(&mut self, field: &'static str) -> Result<u32> {
        let b = self.take(4, field)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn f32(&mut self, field: &'static str) -> Result<f32> {
        Ok(f32::from_bits(self.u32(field)?))
    }

    fn f32s(&mut self, n: usize, field: &'static str) -> Result<Vec<f32>> {
        let len = n
            .checked_mul(4)
            .ok_or_else(|| self.bad(field, n, "count overflows"))?;
        let b = self.take(len, field)?;
        let v: Vec<f32> = b
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(self.bad(field, x, "values must be finite"));
        }
        Ok(v)
    }
}

fn bad(
    path: &Path,
    field: &'static str,
    value: impl std::fmt::Display,
    reason: &'static str,
) -> BtfError {
    BtfError::Format {
        path: PathBuf::from(path),
        field,
        value: value.to_string(),
        reason,
    }
}

pub(crate) fn parse(bytes: &[u8], path: &Path, kind: &Kind) -> Result<BtfPca> {
    let fixed = HEADER_LEN + kind.slots * 8 + CRC_LEN;
    if bytes.len() < fixed {
        return Err(bad(
            path,
            "length",
            format!("{} (the fixed header has {fixed})", bytes.len()),
            "shorter than the fixed header",
        ));
    }
    let mut r = Reader {
        bytes,
        pos: 0,
        path,
    };
    let magic = r.take(8, "magic")?;
    if magic != kind.magic {
        let reason = match magic {
            m if m == crate::fin_pca::FIN_MAGIC => {
                "this is a .finpca (a fin BTF, §5.7): read it with FinPca::read / pass it to --fins"
            }
            m if m == MAGIC => {
                "this is a .btfpca (a per-view BTF): read it with BtfPca::read / pass it to --btf"
            }
            _ => kind.name,
        };
        return Err(r.bad("magic", format!("{magic:02x?}"), reason));
    }
    let vb = r.take(2, "version")?;
    let version = u16::from_le_bytes([vb[0], vb[1]]);
    if version != VERSION {
        return Err(r.bad("version", version, "only version 1 is known"));
    }
    let codes = r.take(6, "sampling/storage")?;
    let sampling = match codes[0] {
        1 => Sampling::H1,
        2 => Sampling::H2,
        v => return Err(r.bad("sampling", v, "must be 1 (H1) or 2 (H2)")),
    };
    let storage = Storage::from_code(codes[1])
        .ok_or_else(|| r.bad("storage", codes[1], "must be 1, 2 or 4 bytes per value"))?;
    let mean_storage = Storage::from_code(codes[2]).ok_or_else(|| {
        r.bad(
            "mean storage",
            codes[2],
            "must be 1, 2 or 4 bytes per value",
        )
    })?;
    if codes[3..] != [0, 0, 0] {
        return Err(r.bad("reserved", format!("{:02x?}", &codes[3..]), "must be 0"));
    }
    let width = r.u32("width")? as usize;
    let height = r.u32("height")? as usize;
    let requested = r.u32("requested components")? as usize;
    let slot_count = r.u32("slot count")? as usize;
    if width == 0 || height == 0 {
        return Err(r.bad(
            "width × height",
            format!("{width} × {height}"),
            "must be ≥ 1",
        ));
    }
    if slot_count != kind.slots {
        return Err(r.bad("slot count", slot_count, kind.slots_reason));
    }
    let lb = r.take(8, "file length")?;
    let declared = u64::from_le_bytes(lb.try_into().unwrap_or([0; 8]));
    if declared != bytes.len() as u64 {
        return Err(r.bad(
            "file length",
            format!("{declared} (actual {})", bytes.len()),
            "the declared length differs from the actual one (truncated or extended file)",
        ));
    }
    let mut table = Vec::with_capacity(kind.slots);
    for _ in 0..kind.slots {
        let c = r.u32("slot components")? as usize;
        let rank = r.u32("slot rank")? as usize;
        if rank > MAX_COMPONENTS || c > rank || c > requested {
            return Err(r.bad(
                "slot components/rank",
                format!("c = {c}, r = {rank}, requested {requested}"),
                "need c ≤ r ≤ 80 and c ≤ requested",
            ));
        }
        table.push((c, rank));
    }
    // The length the header implies, with checked arithmetic.
    let values = (3u64 * width as u64)
        .checked_mul(height as u64)
        .ok_or_else(|| r.bad("width × height", format!("{width} × {height}"), "too large"))?;
    let slot_len = |c: u64, rank: u64| -> Option<u64> {
        let ranges = (c + 1).checked_mul(8)?;
        let mean = values.checked_mul(mean_storage.bytes() as u64)?;
        let eigen = c.checked_mul(values)?.checked_mul(storage.bytes() as u64)?;
        let floats = (LIGHTS as u64 * c + rank).checked_mul(4)?;
        ranges
            .checked_add(mean)?
            .checked_add(eigen)?
            .checked_add(floats)
    };
    let expected = table.iter().try_fold(fixed as u64, |acc, &(c, rank)| {
        acc.checked_add(slot_len(c as u64, rank as u64)?)
    });
    if expected != Some(bytes.len() as u64) {
        return Err(r.bad(
            "file length",
            format!(
                "{} (the header implies {})",
                bytes.len(),
                expected.map_or("more than 2^64".to_string(), |e| e.to_string())
            ),
            "the sizes in the header do not match the data",
        ));
    }
    let body_end = bytes.len() - CRC_LEN;
    let stored_crc = u32::from_le_bytes([
        bytes[body_end],
        bytes[body_end + 1],
        bytes[body_end + 2],
        bytes[body_end + 3],
    ]);
    let crc = crc32fast::hash(&bytes[..body_end]);
    if crc != stored_crc {
        return Err(r.bad(
            "checksum",
            format!("{stored_crc:08x} (computed {crc:08x})"),
            "the data is corrupt",
        ));
    }
    // From here every size is bounded by the bytes present.
    let values = values as usize;
    let mut slots = Vec::with_capacity(kind.slots);
    for &(c, rank) in &table {
        let mut ranges = Vec::with_capacity(c + 1);
        for _ in 0..=c {
            let lo = r.f32("texture range")?;
            let hi = r.f32("texture range")?;
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(r.bad(
                    "texture range",
                    format!("({lo}, {hi})"),
                    "need finite lo ≤ hi",
                ));
            }
            ranges.push((lo, hi));
        }
        let mut textures = Vec::with_capacity(c + 1);
        for (k, (lo, hi)) in ranges.into_iter().enumerate() {
            let st = if k == 0 { mean_storage } else { storage };
            let codes = read_codes(&mut r, st, values)?;
            textures.push(Texture { lo, hi, codes });
        }
        let weights = r.f32s(LIGHTS * c, "weights")?;
        let eigenvalues = r.f32s(rank, "eigenvalues")?;
        if let Some(e) = eigenvalues.iter().find(|e| **e < 0.0) {
            return Err(r.bad("eigenvalues", e, "must be ≥ 0"));
        }
        if eigenvalues.windows(2).any(|w| w[1] > w[0]) {
            return Err(r.bad(
                "eigenvalues",
                format!("{eigenvalues:?}"),
                "must be descending",
            ));
        }
        slots.push(SlotPca {
            textures,
            weights,
            eigenvalues,
        });
    }
    if r.pos != body_end {
        return Err(r.bad(
            "slot sections",
            r.pos,
            "the sections do not end at the checksum",
        ));
    }
    Ok(BtfPca {
        sampling,
        width,
        height,
        requested_components: requested,
        storage,
        mean_storage,
        slots,
    })
}

fn read_codes(r: &mut Reader<'_>, storage: Storage, values: usize) -> Result<Codes> {
    const FIELD: &str = "texture codes";
    let len = values
        .checked_mul(storage.bytes())
        .ok_or_else(|| r.bad(FIELD, values, "count overflows"))?;
    let b = r.take(len, FIELD)?;
    Ok(match storage {
        Storage::U8 => Codes::U8(b.to_vec()),
        Storage::U16 => Codes::U16(
            b.chunks_exact(2)
                .map(|c| u16::from_le_bytes([c[0], c[1]]))
                .collect(),
        ),
        Storage::F32 => {
            let v: Vec<f32> = b
                .chunks_exact(4)
                .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                .collect();
            if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                return Err(r.bad(FIELD, x, "f32 texture values must be finite"));
            }
            Codes::F32(v)
        }
    })
}
