//! Triangle connectivity of a `.cpca` file (its `CONN` section): meshoptimizer's index codec
//! (version 1, the codec of glTF's `EXT_meshopt_compression`, through the `meshopt` crate).
//! Its own module so that both the container (which stores the triangles as a decoder will
//! return them) and the file format (which writes and reads the section) depend on it, and not
//! on each other.

use crate::error::{Result, bad_file as bad};

/// Smallest meshopt index-codec stream for `count` triangles: a header byte, one code byte
/// per triangle and the 16-byte auxiliary table (meshoptimizer's own decoder check).
pub(crate) fn min_conn_len(count: u64) -> u64 {
    1 + count + 16
}

/// The triangles as a meshoptimizer index-codec stream (empty for no triangles).
pub(crate) fn encode_triangles(tris: &[[u32; 3]], v: usize) -> Vec<u8> {
    if tris.is_empty() {
        return Vec::new();
    }
    let flat: Vec<u32> = tris.iter().flatten().copied().collect();
    // The only failure meshopt reports is a too-small output buffer, which its own bound
    // rules out.
    meshopt::encode_index_buffer(&flat, v).expect("meshopt sizes its own output buffer")
}

/// Decodes `count` triangles and checks every index against the vertex count.
pub(crate) fn decode_triangles(bytes: &[u8], count: usize, v: usize) -> Result<Vec<[u32; 3]>> {
    if count == 0 {
        return if bytes.is_empty() {
            Ok(Vec::new())
        } else {
            Err(bad(
                "triangles",
                bytes.len(),
                "bytes in CONN for 0 triangles",
            ))
        };
    }
    let flat: Vec<u32> = meshopt::decode_index_buffer(bytes, 3 * count).map_err(|e| {
        bad(
            "triangles",
            e,
            "the CONN section is not a valid index stream",
        )
    })?;
    if let Some(&i) = flat.iter().find(|&&i| i as usize >= v) {
        return Err(bad("triangle index", i, "must be below the vertex count"));
    }
    Ok(flat.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangles_round_trip() {
        let tris = vec![[0, 1, 2], [2, 1, 3], [1000, 0, 70_000], [69_999, 70_000, 1]];
        let bytes = encode_triangles(&tris, 70_001);
        let back = decode_triangles(&bytes, 4, 70_001).unwrap();
        // Same triangles in the same order, each possibly rotated (winding kept).
        let canonical = |t: [u32; 3]| {
            let r = t.iter().position(|x| x == t.iter().min().unwrap()).unwrap();
            [t[r], t[(r + 1) % 3], t[(r + 2) % 3]]
        };
        assert_eq!(
            back.iter().map(|t| canonical(*t)).collect::<Vec<_>>(),
            tris.iter().map(|t| canonical(*t)).collect::<Vec<_>>()
        );
        // Decoding is a fixed point: re-encoding the decoded triangles gives them back.
        assert_eq!(
            decode_triangles(&encode_triangles(&back, 70_001), 4, 70_001).unwrap(),
            back
        );
        assert!(decode_triangles(&bytes, 4, 70_000).is_err());
        assert!(decode_triangles(&bytes[..bytes.len() - 1], 4, 70_001).is_err());
        assert!(decode_triangles(&[], 0, 10).unwrap().is_empty());
        assert!(decode_triangles(&[0], 0, 10).is_err());
    }
}
