//! The `.cpca` container: a compressed animation as bytes, and back with every field checked.
//!
//! Layout (all little-endian):
//!
//! | offset | size | field |
//! |---|---|---|
//! | 0 | 8 | magic `\x89CPCA\r\n\x1a` |
//! | 8 | 2 | version (2; version 1 had one range per cluster mean and delta-varint connectivity) |
//! | 10 | 2 | flags: bit 0 = time compression present; other bits 0 |
//! | 12 | 4 × 5 | V, F, k, c, c* (0 without time compression) |
//! | 32 | 1 + 1 + 2 | q_c, q_w, reserved (0) |
//! | 36 | 4 | triangle count T |
//! | 40 | 4 | frame rate (f32) |
//! | 44 | 8 | total file length in bytes |
//! | 52 | … | sections: tag (4 bytes), payload length (u32), payload |
//! | end − 4 | 4 | CRC-32 (IEEE) of every byte before it |
//!
//! Sections, in this order: `RNGE` the (lo, hi) `f32` range of every quantized array (3k
//! mean axes, eigentrajectories, time mean and basis, weights); `LABL` the cluster index,
//! ⌈log₂ k⌉ bits per vertex (at least 1); `MEAN` 3k arrays of F codes of q_c bits (axis a of
//! cluster j's mean at 3j + a, each axis over its own range); `EIGN` k·c·3F (or k·c·c*) codes of
//! q_c bits; `TBAS` (only with time compression) (1 + c*)·3F codes of q_w bits; `WGHT` c·V
//! codes of q_w bits; `CONN` the triangles. Codes are bit-packed least significant bit first,
//! each section padded to a byte.
//!
//! Connectivity is coded with meshoptimizer's index codec (version 1, the codec of glTF's
//! `EXT_meshopt_compression`, through the `meshopt` crate): an edge and vertex FIFO predicts
//! each triangle from its predecessors, one code byte per triangle plus varint extras. The
//! encoder first orders the triangles for the vertex cache (`meshopt::optimize_vertex_cache`;
//! the vertex order is the animation's and stays), and the codec may rotate a triangle's
//! corners (winding kept), so a decoded file lists the same triangles in another order. It
//! costs 25.4 bits per vertex on the chicken and 30.1 on the horse (the previous delta/varint
//! code: 57); the seed's Edgebreaker budget is 6 (eq. 3.16). [`super::bpvf_from_file`] counts
//! it.
//!
//! Reading validates before it allocates: magic, version, flags, every count (V, F ≥ 1;
//! 1 ≤ k ≤ V; 1 ≤ c ≤ 3F; 1 ≤ c* ≤ min(k·c, 3F); bits in 1..=32), the declared length
//! against the actual one, the checksum, and every section's tag and length against the
//! length the header implies (checked arithmetic, so no overflow). Every array allocated is
//! then bounded by bytes present in the file. Ranges must be finite with lo ≤ hi, labels
//! below k, triangle indices below V, and the sections must end exactly at the checksum.

use super::connectivity::{decode_triangles, encode_triangles, min_conn_len};
use super::container::{Compressed, TimeBasis};
use super::quantize::{BitReader, BitWriter, MAX_BITS, MIN_BITS, Quantized, packed_len};
use crate::error::{AnimPcaError, Result, bad_file as bad};

/// The file signature (PNG-style: a high byte, the name, CR LF, ^Z).
pub const MAGIC: [u8; 8] = *b"\x89CPCA\r\n\x1a";
/// The format version written and read.
pub const VERSION: u16 = 2;
const HEADER_LEN: usize = 52;
const SECTION_HEAD: usize = 8;
const CRC_LEN: usize = 4;
const FLAG_TIME: u16 = 1;

/// Bits per cluster index: ⌈log₂ k⌉, at least 1 so that every vertex costs a bit.
fn label_bits(k: usize) -> u8 {
    (usize::BITS - (k.max(2) - 1).leading_zeros()) as u8
}

impl Compressed {
    /// Serialises to the `.cpca` layout of [`crate::compress::format`].
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        out.extend_from_slice(&MAGIC);
        out.extend_from_slice(&VERSION.to_le_bytes());
        let flags = if self.time.is_some() { FLAG_TIME } else { 0 };
        out.extend_from_slice(&flags.to_le_bytes());
        let cs = self.time_components().unwrap_or(0);
        for n in [
            self.vertices,
            self.frames,
            self.clusters,
            self.components,
            cs,
        ] {
            out.extend_from_slice(&(n as u32).to_le_bytes());
        }
        out.extend_from_slice(&[self.bits_components, self.bits_weights, 0, 0]);
        out.extend_from_slice(&(self.triangles.len() as u32).to_le_bytes());
        out.extend_from_slice(&self.frame_rate.to_le_bytes());
        out.extend_from_slice(&[0; 8]); // total length, patched below
        let mut ranges = Vec::new();
        for q in self.arrays() {
            ranges.extend_from_slice(&q.lo().to_le_bytes());
            ranges.extend_from_slice(&q.hi().to_le_bytes());
        }
        section(&mut out, b"RNGE", &ranges);
        let lb = label_bits(self.clusters);
        let mut w = BitWriter::default();
        self.labels.iter().for_each(|&l| w.push(l, lb));
        section(&mut out, b"LABL", &w.finish());
        section(&mut out, b"MEAN", &pack(&self.means));
        section(&mut out, b"EIGN", &pack(&self.eigen));
        if let Some(t) = &self.time {
            let mut all = vec![t.mean.clone()];
            all.extend(t.basis.iter().cloned());
            section(&mut out, b"TBAS", &pack(&all));
        }
        section(&mut out, b"WGHT", &pack(&self.weights));
        section(
            &mut out,
            b"CONN",
            &encode_triangles(&self.triangles, self.vertices),
        );
        let total = (out.len() + CRC_LEN) as u64;
        out[44..52].copy_from_slice(&total.to_le_bytes());
        let crc = crc32(&out);
        out.extend_from_slice(&crc.to_le_bytes());
        out
    }

    /// Every quantized array in file order.
    fn arrays(&self) -> impl Iterator<Item = &Quantized> {
        let time = self
            .time
            .iter()
            .flat_map(|t| std::iter::once(&t.mean).chain(&t.basis));
        self.means
            .iter()
            .chain(&self.eigen)
            .chain(time)
            .chain(&self.weights)
    }

    /// Reads a `.cpca` file, validating every field and size before allocating.
    ///
    /// # Errors
    /// [`AnimPcaError::Truncated`] when the bytes end early, [`AnimPcaError::ChecksumMismatch`]
    /// when the CRC-32 does not match, [`AnimPcaError::InvalidFile`] for any impossible or
    /// unsupported field (naming it). Never panics and never allocates more than a small
    /// multiple of `bytes.len()`.
    pub fn from_bytes(bytes: &[u8]) -> Result<Self> {
        let h = Header::read(bytes)?;
        let mut r = Cursor {
            bytes: &bytes[..bytes.len() - CRC_LEN],
            pos: HEADER_LEN,
        };
        let (v, f, k, c, cs) = (h.v as u64, h.f as u64, h.k as u64, h.c as u64, h.cs as u64);
        let len = if cs > 0 { cs } else { 3 * f };
        let time_arrays = if cs > 0 { 1 + cs } else { 0 };
        let n_arrays = sized(
            k.checked_mul(c)
                .and_then(|kc| kc.checked_add(3 * k + c + time_arrays))
                .and_then(|n| n.checked_mul(8)),
        )?;
        let ranges = r.section(b"RNGE", "section RNGE", Some(n_arrays))?;
        let labl = r.section(
            b"LABL",
            "section LABL",
            Some(sized(packed_len(v, label_bits(h.k as usize)))?),
        )?;
        let mean = r.section(
            b"MEAN",
            "section MEAN",
            Some(sized(packed_len(sized(k.checked_mul(3 * f))?, h.qc))?),
        )?;
        let eign = r.section(
            b"EIGN",
            "section EIGN",
            Some(sized(packed_len(
                sized(k.checked_mul(c).and_then(|x| x.checked_mul(len)))?,
                h.qc,
            ))?),
        )?;
        let tbas = if cs > 0 {
            Some(r.section(
                b"TBAS",
                "section TBAS",
                Some(sized(packed_len(
                    sized((1 + cs).checked_mul(3 * f))?,
                    h.qw,
                ))?),
            )?)
        } else {
            None
        };
        let wght = r.section(
            b"WGHT",
            "section WGHT",
            Some(sized(packed_len(sized(c.checked_mul(v))?, h.qw))?),
        )?;
        let conn = r.section(b"CONN", "section CONN", None)?;
        if r.pos != r.bytes.len() {
            return Err(bad(
                "sections",
                r.bytes.len() - r.pos,
                "bytes left after CONN",
            ));
        }
        if h.t > 0 && (conn.len() as u64) < min_conn_len(u64::from(h.t)) {
            return Err(bad(
                "triangles",
                h.t,
                "the CONN section is too short for this many triangles",
            ));
        }
        // Every size is now bounded by bytes present in the file.
        let (v, f, k, c, cs, len) = (
            v as usize,
            f as usize,
            k as usize,
            c as usize,
            cs as usize,
            len as usize,
        );
        let mut rng = ranges.chunks_exact(8).map(|b| {
            let lo = f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            let hi = f32::from_le_bytes([b[4], b[5], b[6], b[7]]);
            (lo, hi)
        });
        let mut labels = Vec::with_capacity(v);
        let mut lr = BitReader::new(labl);
        for _ in 0..v {
            let l = lr
                .read(label_bits(k))
                .ok_or_else(|| bad("labels", v, "too few"))?;
            if l as usize >= k {
                return Err(bad("labels", l, "a cluster index is not below k"));
            }
            labels.push(l);
        }
        let mut mr = BitReader::new(mean);
        let means = read_arrays(&mut mr, &mut rng, 3 * k, f, h.qc)?;
        let mut er = BitReader::new(eign);
        let eigen = read_arrays(&mut er, &mut rng, k * c, len, h.qc)?;
        let time = match tbas {
            Some(t) => {
                let mut tr = BitReader::new(t);
                let mut all = read_arrays(&mut tr, &mut rng, 1 + cs, 3 * f, h.qw)?;
                let basis = all.split_off(1);
                Some(TimeBasis {
                    mean: all.remove(0),
                    basis,
                })
            }
            None => None,
        };
        let mut wr = BitReader::new(wght);
        let weights = read_arrays(&mut wr, &mut rng, c, v, h.qw)?;
        let triangles = decode_triangles(conn, h.t as usize, v)?;
        Ok(Self {
            vertices: v,
            frames: f,
            clusters: k,
            components: c,
            bits_components: h.qc,
            bits_weights: h.qw,
            frame_rate: h.frame_rate,
            labels,
            means,
            eigen,
            time,
            weights,
            triangles,
        })
    }
}

/// The fixed header, validated.
struct Header {
    v: u32,
    f: u32,
    k: u32,
    c: u32,
    cs: u32,
    qc: u8,
    qw: u8,
    t: u32,
    frame_rate: f32,
}

impl Header {
    fn read(b: &[u8]) -> Result<Self> {
        let need = |n: usize| {
            if b.len() < n {
                Err(AnimPcaError::Truncated {
                    section: "header",
                    needed: n as u64,
                    available: b.len() as u64,
                })
            } else {
                Ok(())
            }
        };
        need(MAGIC.len())?;
        if b[..8] != MAGIC {
            return Err(bad(
                "magic",
                format!("{:02x?}", &b[..8]),
                "not a .cpca file",
            ));
        }
        need(12)?;
        let u16_at = |o: usize| u16::from_le_bytes([b[o], b[o + 1]]);
        let version = u16_at(8);
        if version != VERSION {
            return Err(bad(
                "version",
                version,
                "only version 2 is supported (version 1 files: re-encode from the original)",
            ));
        }
        need(HEADER_LEN + CRC_LEN)?;
        let u32_at = |o: usize| u32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        let mut total = [0u8; 8];
        total.copy_from_slice(&b[44..52]);
        let total = u64::from_le_bytes(total);
        if (b.len() as u64) < total {
            return Err(AnimPcaError::Truncated {
                section: "file",
                needed: total,
                available: b.len() as u64,
            });
        }
        if b.len() as u64 > total {
            return Err(bad(
                "file length",
                b.len(),
                "the file is longer than its header says",
            ));
        }
        let stored = u32_at(b.len() - CRC_LEN);
        let computed = crc32(&b[..b.len() - CRC_LEN]);
        if stored != computed {
            return Err(AnimPcaError::ChecksumMismatch { stored, computed });
        }
        let flags = u16_at(10);
        if flags & !FLAG_TIME != 0 {
            return Err(bad("flags", flags, "unknown flag bits are set"));
        }
        let h = Self {
            v: u32_at(12),
            f: u32_at(16),
            k: u32_at(20),
            c: u32_at(24),
            cs: u32_at(28),
            qc: b[32],
            qw: b[33],
            t: u32_at(36),
            frame_rate: f32::from_le_bytes([b[40], b[41], b[42], b[43]]),
        };
        if u16_at(34) != 0 {
            return Err(bad("reserved", u16_at(34), "must be 0"));
        }
        if h.v == 0 {
            return Err(bad("vertices", h.v, "must be at least 1"));
        }
        if h.f == 0 || u64::from(h.f) * 3 > u64::from(u32::MAX) {
            return Err(bad("frames", h.f, "must be in 1..=(2³² − 1)/3"));
        }
        if h.k == 0 || h.k > h.v {
            return Err(bad("clusters", h.k, "must be in 1..=V"));
        }
        if h.c == 0 || h.c > 3 * h.f {
            return Err(bad("components", h.c, "must be in 1..=3F"));
        }
        let cs_max = (u64::from(h.k) * u64::from(h.c)).min(3 * u64::from(h.f));
        match (flags & FLAG_TIME != 0, h.cs) {
            (false, 0) => {}
            (true, cs) if cs >= 1 && u64::from(cs) <= cs_max => {}
            (_, cs) => {
                return Err(bad(
                    "time_components",
                    cs,
                    "must be 0 without the time flag and in 1..=min(k·c, 3F) with it",
                ));
            }
        }
        for (name, q) in [("bits_components", h.qc), ("bits_weights", h.qw)] {
            if !(MIN_BITS..=MAX_BITS).contains(&q) {
                return Err(bad(name, q, "must be in 1..=32"));
            }
        }
        if !h.frame_rate.is_finite() {
            return Err(bad("frame_rate", h.frame_rate, "must be finite"));
        }
        Ok(h)
    }
}

/// A read position in the checksummed part of the file.
struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
}

impl<'a> Cursor<'a> {
    /// The next section's payload, after checking its tag and (when given) its length.
    fn section(
        &mut self,
        tag: &[u8; 4],
        name: &'static str,
        expected: Option<u64>,
    ) -> Result<&'a [u8]> {
        let avail = (self.bytes.len() - self.pos) as u64;
        if avail < SECTION_HEAD as u64 {
            return Err(AnimPcaError::Truncated {
                section: name,
                needed: SECTION_HEAD as u64,
                available: avail,
            });
        }
        let head = &self.bytes[self.pos..self.pos + SECTION_HEAD];
        if &head[..4] != tag {
            return Err(bad(
                "section tag",
                String::from_utf8_lossy(&head[..4]),
                "sections must be RNGE, LABL, MEAN, EIGN, [TBAS,] WGHT, CONN in order",
            ));
        }
        let len = u64::from(u32::from_le_bytes([head[4], head[5], head[6], head[7]]));
        if let Some(e) = expected {
            if len != e {
                return Err(bad(
                    name,
                    len,
                    "the payload length does not match the header",
                ));
            }
        }
        if len > avail - SECTION_HEAD as u64 {
            return Err(AnimPcaError::Truncated {
                section: name,
                needed: len,
                available: avail - SECTION_HEAD as u64,
            });
        }
        let start = self.pos + SECTION_HEAD;
        self.pos = start + len as usize;
        Ok(&self.bytes[start..self.pos])
    }
}

/// A size from checked arithmetic, or an error if it overflowed.
fn sized(x: Option<u64>) -> Result<u64> {
    x.ok_or_else(|| {
        bad(
            "sizes",
            "overflow",
            "the header's counts are impossibly large",
        )
    })
}

fn section(out: &mut Vec<u8>, tag: &[u8; 4], payload: &[u8]) {
    out.extend_from_slice(tag);
    out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    out.extend_from_slice(payload);
}

fn pack(arrays: &[Quantized]) -> Vec<u8> {
    let mut w = BitWriter::default();
    for q in arrays {
        q.codes().iter().for_each(|&u| w.push(u, q.bits()));
    }
    w.finish()
}

fn read_arrays(
    r: &mut BitReader<'_>,
    ranges: &mut impl Iterator<Item = (f32, f32)>,
    count: usize,
    len: usize,
    bits: u8,
) -> Result<Vec<Quantized>> {
    let mut out = Vec::with_capacity(count);
    for _ in 0..count {
        let (lo, hi) = ranges
            .next()
            .ok_or_else(|| bad("ranges", count, "too few ranges"))?;
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(bad(
                "range",
                format!("[{lo}, {hi}]"),
                "must be finite with lo ≤ hi",
            ));
        }
        let mut codes = Vec::with_capacity(len);
        for _ in 0..len {
            codes.push(r.read(bits).ok_or_else(|| bad("codes", len, "too few"))?);
        }
        out.push(Quantized::from_parts(lo, hi, bits, codes));
    }
    Ok(out)
}

/// CRC-32 (IEEE 802.3, the zlib/PNG checksum) of `bytes`, by `crc32fast` (SIMD where the
/// CPU has it). The container's last 4 bytes hold it, little-endian, over everything before.
pub fn crc32(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crc32_check_value() {
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
        assert_eq!(crc32(b""), 0);
    }

    #[test]
    fn label_bits_cover_k() {
        assert_eq!(label_bits(1), 1);
        assert_eq!(label_bits(2), 1);
        assert_eq!(label_bits(3), 2);
        assert_eq!(label_bits(32), 5);
        assert_eq!(label_bits(33), 6);
    }
}
