//! `EXT_meshopt_compression` (gltfpack `-c`/`-cc`) and its ratified form
//! `KHR_meshopt_compression` (gltfpack `-ce khr`): buffer views stored compressed by
//! meshoptimizer's codecs, decoded into their fallback buffer before any accessor is read
//! (Khronos `extensions/2.0/Vendor/EXT_meshopt_compression` and
//! `extensions/2.0/Khronos/KHR_meshopt_compression`).
//!
//! A compressed view names its source (`buffer`, `byteOffset`, `byteLength` in the
//! extension), its `count` of elements of `byteStride` bytes, a `mode` (`ATTRIBUTES`: the vertex
//! codec, versions 0 and 1 — the KHR form allows 1; `TRIANGLES`: the index codec; `INDICES`:
//! index sequences, not decoded here — gltfpack writes them only for point and line primitives,
//! which this reader refuses with their own message) and an optional `filter` applied after
//! decoding: `OCTAHEDRAL` (unit vectors as 8/16-bit octahedral x, y), `QUATERNION` (16-bit, the
//! largest component rebuilt), `EXPONENTIAL` (24-bit mantissa, 8-bit exponent per 32-bit
//! float), and in the KHR form `COLOR` (YCoCg with the alpha's top bit marking the bit depth).
//! The decoded bytes go to the view's own `buffer`/`byteOffset`, the "fallback" buffer, which a
//! compressed file leaves without data (allocated here, zero-filled, within the file's decode
//! budget). The codecs are meshoptimizer's (`meshopt::decode_vertex_buffer`,
//! `decode_index_buffer`, meshoptimizer 0.25; safe for untrusted input); the filters are written
//! here after the extensions' filter appendix and meshoptimizer's scalar reference
//! (`vertexfilter.cpp`).

use serde_json::Value;

use super::source::gltf_error;
use crate::MeshIoError;

/// The two names of the extension; a file uses one of them.
pub(super) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// The meshopt extension object of `value`'s `extensions` (either name) and its name.
fn extension(value: &Value) -> Option<(&'static str, &Value)> {
    EXTENSIONS
        .iter()
        .find_map(|name| Some((*name, value.get("extensions")?.get(name)?)))
}

/// Element bytes the vertex codec decodes, as a type of that size.
#[derive(Clone, Copy)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

/// The vertex codec for `stride`-byte elements (a multiple of 4, ≤ 256, as the spec requires).
fn decode_attributes(src: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    fn run<const N: usize>(src: &[u8], count: usize) -> Result<Vec<u8>, String> {
        meshopt::decode_vertex_buffer::<Element<N>>(src, count)
            .map(|v| v.iter().flat_map(|e| e.0).collect())
            .map_err(|e| format!("the vertex codec failed: {e:?}"))
    }
    macro_rules! strides {
        ($($n:literal)*) => {
            match stride {
                $($n => run::<$n>(src, count),)*
                _ => Err(format!("byteStride {stride} is not a multiple of 4 in 4..=256")),
            }
        };
    }
    strides!(4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108
        112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192 196
        200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)
}

/// The index codec (`TRIANGLES`) for 2- or 4-byte indices.
fn decode_triangles(src: &[u8], count: usize, stride: usize) -> Result<Vec<u8>, String> {
    let failed = |e| format!("the index codec failed: {e:?}");
    match stride {
        2 => meshopt::decode_index_buffer::<u16>(src, count)
            .map(|v| v.iter().flat_map(|i| i.to_le_bytes()).collect())
            .map_err(failed),
        4 => meshopt::decode_index_buffer::<u32>(src, count)
            .map(|v| v.iter().flat_map(|i| i.to_le_bytes()).collect())
            .map_err(failed),
        _ => Err(format!("byteStride {stride} of TRIANGLES must be 2 or 4")),
    }
}

/// Octahedral unit vectors: x, y and a z holding "one" at the same bit depth; z rebuilt as
/// one − |x| − |y|, folded for the lower half, normalised and rounded back; w kept.
fn filter_octahedral(data: &mut [u8], stride: usize) -> Result<(), String> {
    let fix = |x: f32, y: f32, one: f32, max: f32| {
        let z = one - x.abs() - y.abs();
        let (mut x, mut y) = (x, y);
        let t = z.min(0.0);
        x += if x >= 0.0 { t } else { -t };
        y += if y >= 0.0 { t } else { -t };
        let s = max / (x * x + y * y + z * z).sqrt();
        let round = |v: f32| (v * s + if v >= 0.0 { 0.5 } else { -0.5 }) as i32;
        [round(x), round(y), round(z)]
    };
    match stride {
        4 => {
            for e in data.chunks_exact_mut(4) {
                let c = |k: usize| f32::from(e[k] as i8);
                let v = fix(c(0), c(1), c(2), 127.0);
                for k in 0..3 {
                    e[k] = (v[k] as i8) as u8;
                }
            }
            Ok(())
        }
        8 => {
            for e in data.chunks_exact_mut(8) {
                let c = |k: usize| f32::from(i16::from_le_bytes([e[2 * k], e[2 * k + 1]]));
                let v = fix(c(0), c(1), c(2), 32767.0);
                for k in 0..3 {
                    e[2 * k..2 * k + 2].copy_from_slice(&(v[k] as i16).to_le_bytes());
                }
            }
            Ok(())
        }
        _ => Err(format!(
            "the OCTAHEDRAL filter needs byteStride 4 or 8, not {stride}"
        )),
    }
}

/// Quaternions as three 16-bit components scaled by 1/√2 and the index of the fourth (largest),
/// rebuilt as √(1 − x² − y² − z²); the output order follows that index.
fn filter_quaternion(data: &mut [u8], stride: usize) -> Result<(), String> {
    if stride != 8 {
        return Err(format!(
            "the QUATERNION filter needs byteStride 8, not {stride}"
        ));
    }
    let scale = std::f32::consts::FRAC_1_SQRT_2;
    for e in data.chunks_exact_mut(8) {
        let c = |k: usize| i16::from_le_bytes([e[2 * k], e[2 * k + 1]]);
        let last = c(3);
        let ss = scale / f32::from(last | 3);
        let (x, y, z) = (
            f32::from(c(0)) * ss,
            f32::from(c(1)) * ss,
            f32::from(c(2)) * ss,
        );
        let w = (1.0 - x * x - y * y - z * z).max(0.0).sqrt();
        let round = |v: f32| (v * 32767.0 + if v >= 0.0 { 0.5 } else { -0.5 }) as i32 as i16;
        let qc = (last & 3) as usize;
        let out = [
            ((qc + 1) & 3, round(x)),
            ((qc + 2) & 3, round(y)),
            ((qc + 3) & 3, round(z)),
            (qc, (w * 32767.0 + 0.5) as i32 as i16),
        ];
        for (slot, value) in out {
            e[2 * slot..2 * slot + 2].copy_from_slice(&value.to_le_bytes());
        }
    }
    Ok(())
}

/// Floats as a signed 24-bit mantissa m and a signed 8-bit exponent e: m · 2^e.
fn filter_exponential(data: &mut [u8], stride: usize) -> Result<(), String> {
    if !stride.is_multiple_of(4) {
        return Err(format!(
            "the EXPONENTIAL filter needs a byteStride divisible by 4, not {stride}"
        ));
    }
    for word in data.chunks_exact_mut(4) {
        let v = u32::from_le_bytes([word[0], word[1], word[2], word[3]]);
        let m = ((v << 8) as i32) >> 8;
        let e = (v as i32) >> 24;
        let scale = f32::from_bits(((e + 127) as u32 & 0x1ff) << 23);
        word.copy_from_slice(&(scale * m as f32).to_bits().to_le_bytes());
    }
    Ok(())
}

/// Colours as Y, Co, Cg (Co and Cg signed) and alpha whose highest set bit marks the bit depth
/// K of the encoding: R = Y + Co − Cg, G = Y + Cg, B = Y − Co − Cg, alpha widened by one bit,
/// all scaled by (2^bits − 1)/(2^K − 1) in f32 and rounded to nearest, ties to even (as
/// meshoptimizer's SIMD `decodeFilterColorSimd8/16` do); stored modulo 2^bits.
fn filter_color(data: &mut [u8], stride: usize) -> Result<(), String> {
    fn decode(y: i32, co: i32, cg: i32, alpha: i32, max: f32) -> [i32; 4] {
        let mut scale_bits = alpha;
        for shift in [1, 2, 4, 8] {
            scale_bits |= scale_bits >> shift;
        }
        let (r, g, b) = (y + co - cg, y + cg, y - co - cg);
        let a = ((alpha << 1) & scale_bits) | (alpha & 1);
        let ss = max / scale_bits as f32;
        // Nearest, ties to even: meshoptimizer's SIMD decoders (its WebAssembly build snaps
        // x + 1.5·2^23); its scalar fallback's int(x + 0.5f) differs by one in rare ties.
        [r, g, b, a].map(|v| (v as f32 * ss).round_ties_even() as i32)
    }
    match stride {
        4 => {
            for e in data.chunks_exact_mut(4) {
                let v = decode(
                    i32::from(e[0]),
                    i32::from(e[1] as i8),
                    i32::from(e[2] as i8),
                    i32::from(e[3]),
                    255.0,
                );
                for k in 0..4 {
                    e[k] = v[k] as u8;
                }
            }
            Ok(())
        }
        8 => {
            for e in data.chunks_exact_mut(8) {
                let c = |k: usize| u16::from_le_bytes([e[2 * k], e[2 * k + 1]]);
                let v = decode(
                    i32::from(c(0)),
                    i32::from(c(1) as i16),
                    i32::from(c(2) as i16),
                    i32::from(c(3)),
                    65535.0,
                );
                for k in 0..4 {
                    e[2 * k..2 * k + 2].copy_from_slice(&(v[k] as u16).to_le_bytes());
                }
            }
            Ok(())
        }
        _ => Err(format!(
            "the COLOR filter needs byteStride 4 or 8, not {stride}"
        )),
    }
}

/// The fallback buffers of `root` (extension `fallback: true`): their index and byte length.
pub(super) fn fallback_buffers(root: &Value) -> Vec<(usize, usize)> {
    root["buffers"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
        .filter(|(_, b)| extension(b).is_some_and(|(_, e)| e["fallback"] == true))
        .map(|(i, b)| (i, b["byteLength"].as_u64().unwrap_or(0) as usize))
        .collect()
}

/// Decodes every compressed buffer view of `root` (either extension) into its target buffer in
/// `buffers`.
///
/// # Errors
/// [`MeshIoError::Gltf`] naming the buffer view: a field missing or out of range, a source or
/// target outside its buffer, a codec failure, an unknown mode or filter.
pub(super) fn decode_views(
    path: &std::path::Path,
    root: &Value,
    buffers: &mut [Vec<u8>],
) -> Result<(), MeshIoError> {
    for (i, view) in root["bufferViews"]
        .as_array()
        .into_iter()
        .flatten()
        .enumerate()
    {
        let Some((name, ext)) = extension(view) else {
            continue;
        };
        let element = format!("bufferViews[{i}].extensions.{name}");
        let err = |m: String| gltf_error(path, &element, m);
        let field = |v: &Value, name: &str| {
            v[name]
                .as_u64()
                .map(|x| x as usize)
                .ok_or_else(|| err(format!("{name} is missing or not a non-negative integer")))
        };
        let (buffer, offset, length) = (
            field(ext, "buffer")?,
            field(ext, "byteOffset").unwrap_or(0),
            field(ext, "byteLength")?,
        );
        let (count, stride) = (field(ext, "count")?, field(ext, "byteStride")?);
        let source = buffers
            .get(buffer)
            .and_then(|b| b.get(offset..offset.checked_add(length)?))
            .ok_or_else(|| {
                err(format!(
                    "bytes {offset}+{length} of buffer {buffer} do not exist"
                ))
            })?;
        let decoded_len = count
            .checked_mul(stride)
            .ok_or_else(|| err(format!("count {count} x byteStride {stride} overflows")))?;
        let target_len = field(view, "byteLength")?;
        if decoded_len > target_len {
            return Err(err(format!(
                "count {count} x byteStride {stride} = {decoded_len} bytes exceed the view's \
                 byteLength {target_len}"
            )));
        }
        let mode = ext["mode"].as_str().unwrap_or("");
        let mut decoded = match mode {
            "ATTRIBUTES" => decode_attributes(source, count, stride),
            "TRIANGLES" => decode_triangles(source, count, stride),
            "INDICES" => Err(
                "mode INDICES (index sequences, for points and lines) is not \
                              decoded here; triangle meshes use TRIANGLES"
                    .to_owned(),
            ),
            other => Err(format!(
                "mode {other:?} is not ATTRIBUTES, TRIANGLES or INDICES"
            )),
        }
        .map_err(&err)?;
        match ext["filter"].as_str().unwrap_or("NONE") {
            "NONE" => Ok(()),
            "OCTAHEDRAL" => filter_octahedral(&mut decoded, stride),
            "QUATERNION" => filter_quaternion(&mut decoded, stride),
            "EXPONENTIAL" => filter_exponential(&mut decoded, stride),
            "COLOR" if name.starts_with("KHR") => filter_color(&mut decoded, stride),
            other => Err(format!(
                "filter {other:?} is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL{}",
                if name.starts_with("KHR") {
                    " or COLOR"
                } else {
                    ""
                }
            )),
        }
        .map_err(&err)?;
        let (target, target_offset) = (
            field(view, "buffer")?,
            field(view, "byteOffset").unwrap_or(0),
        );
        let slot = buffers
            .get_mut(target)
            .and_then(|b| b.get_mut(target_offset..target_offset.checked_add(decoded_len)?))
            .ok_or_else(|| {
                err(format!(
                    "bytes {target_offset}+{decoded_len} of buffer {target} do not exist"
                ))
            })?;
        slot.copy_from_slice(&decoded);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_filter_gives_mantissa_times_two_to_the_exponent() {
        // m = 3, e = −1 → 1.5; m = −5, e = 2 → −20.
        let mut data = Vec::new();
        for (m, e) in [(3i32, -1i32), (-5, 2)] {
            let v = ((e as u32) << 24) | (m as u32 & 0x00ff_ffff);
            data.extend(v.to_le_bytes());
        }
        filter_exponential(&mut data, 8).unwrap();
        let f = |k: usize| f32::from_le_bytes(data[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!((f(0), f(1)), (1.5, -20.0));
    }

    #[test]
    fn octahedral_filter_restores_axes() {
        // +Z: x = y = 0, z = one = 127 → (0, 0, 127); −Z folds: x = 127, y = 0, one = 127 means
        // z = 0 → (127, 0, 0) = +X.
        let mut data = vec![0u8, 0, 127, 9, 127, 0, 127, 9];
        filter_octahedral(&mut data, 4).unwrap();
        assert_eq!(data, [0, 0, 127, 9, 127, 0, 0, 9]);
    }

    #[test]
    fn quaternion_filter_rebuilds_the_largest_component() {
        // Identity: x = y = z = 0 and the largest (w) at index 3: stored index qc = 3 → w goes
        // to slot (3 + 0) & 3 = 3.
        let mut data = Vec::new();
        for v in [0i16, 0, 0, (0x7ff8u16 as i16) | 3] {
            data.extend(v.to_le_bytes());
        }
        filter_quaternion(&mut data, 8).unwrap();
        let c = |k: usize| i16::from_le_bytes([data[2 * k], data[2 * k + 1]]);
        assert_eq!([c(0), c(1), c(2), c(3)], [0, 0, 0, 32767]);
    }
}
