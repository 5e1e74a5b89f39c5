//! Triangle-strip decoding (PLY `tristrips`, e.g. igea.ply).
//!
//! A strip `v0 v1 v2 v3 …` yields triangles `(v0 v1 v2)`, `(v2 v1 v3)`, `(v2 v3 v4)`, … : the
//! winding alternates so that every triangle faces the same way as the first. `-1` ends a strip
//! and starts a new one (restart marker); the alternation restarts with it. Leading, trailing
//! and consecutive markers are allowed and produce nothing. Triangles with repeated indices
//! (stitching) are kept; the loader reports them as degenerate.

/// Why a strip entry was rejected.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct BadEntry {
    /// Position of the entry in the strip list.
    pub position: usize,
    /// Its value.
    pub value: i64,
}

/// Appends the triangles of `entries` to `out`. Entries must be `-1` or in `0..vertex_count`.
pub(crate) fn decode_strip(
    entries: &[i64],
    vertex_count: u64,
    out: &mut Vec<[u32; 3]>,
) -> Result<(), BadEntry> {
    let mut run = 0usize; // vertices in the current strip so far
    let (mut older, mut newer) = (0u32, 0u32);
    for (position, &value) in entries.iter().enumerate() {
        if value == -1 {
            run = 0;
            continue;
        }
        if value < 0 || value as u64 >= vertex_count {
            return Err(BadEntry { position, value });
        }
        let v = value as u32;
        if run >= 2 {
            // Triangle k = run - 2 of the strip: even k keeps the order, odd k swaps.
            out.push(if (run - 2).is_multiple_of(2) {
                [older, newer, v]
            } else {
                [newer, older, v]
            });
        }
        older = newer;
        newer = v;
        run += 1;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(entries: &[i64]) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        decode_strip(entries, 100, &mut out).unwrap();
        out
    }

    #[test]
    fn alternating_winding_keeps_orientation() {
        // A quad strip 0-1-2-3 over the unit square: 0=(0,0) 1=(0,1) 2=(1,0) 3=(1,1)... both
        // triangles must have the same orientation.
        assert_eq!(decode(&[0, 1, 2, 3]), vec![[0, 1, 2], [2, 1, 3]]);
    }

    #[test]
    fn restarts_reset_parity_and_window() {
        assert_eq!(
            decode(&[-1, 0, 1, 2, -1, -1, 3, 4, 5, 6, -1]),
            vec![[0, 1, 2], [3, 4, 5], [5, 4, 6]]
        );
        assert!(decode(&[0, 1, -1, 2]).is_empty());
    }

    #[test]
    fn rejects_other_negative_and_out_of_range() {
        let mut out = Vec::new();
        assert_eq!(
            decode_strip(&[0, 1, -2], 10, &mut out),
            Err(BadEntry {
                position: 2,
                value: -2
            })
        );
        assert_eq!(
            decode_strip(&[0, 10], 10, &mut out),
            Err(BadEntry {
                position: 1,
                value: 10
            })
        );
    }
}
