//! Frame layout of one clip or several clips analysed together as *cells* (thesis §3.2.2
//! "Motion Control": "several small sequences … each containing only a specific motion
//! subtype").
//!
//! The frames of all cells are numbered consecutively, cell after cell. Natural play runs
//! from a frame to the next one *of the same cell*; the last frame of a cell has no successor
//! and, like the last frame of a single clip, continues at a frame whose predecessor resembles
//! it (see [`probability`](super::probability)).

use std::ops::Range;

/// Cell ranges over the consecutive frame numbering.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    ranges: Vec<Range<usize>>,
    cell_of: Vec<usize>,
    /// Whether a frame without successor has any candidate under the predecessor rule (there
    /// is a frame other than itself that has a predecessor). False only for one 2-frame cell.
    rule_has_candidates: bool,
}

impl Layout {
    /// Cells of the given lengths (each ≥ 1), numbered in order.
    pub fn new(lengths: &[usize]) -> Self {
        let mut ranges = Vec::with_capacity(lengths.len());
        let mut cell_of = Vec::with_capacity(lengths.iter().sum());
        let mut start = 0;
        for (cell, &n) in lengths.iter().enumerate() {
            ranges.push(start..start + n);
            cell_of.extend(std::iter::repeat_n(cell, n));
            start += n;
        }
        let with_predecessor = start - lengths.iter().filter(|&&n| n > 0).count();
        Self {
            ranges,
            cell_of,
            rule_has_candidates: with_predecessor > 1,
        }
    }

    /// Total frames.
    pub fn n(&self) -> usize {
        self.cell_of.len()
    }

    /// The cells' frame ranges.
    pub fn ranges(&self) -> &[Range<usize>] {
        &self.ranges
    }

    /// Cell of frame i.
    pub fn cell_of(&self, i: usize) -> usize {
        self.cell_of[i]
    }

    /// Frame range of frame i's cell.
    pub fn range_of(&self, i: usize) -> Range<usize> {
        self.ranges[self.cell_of[i]].clone()
    }

    /// The natural successor i + 1, if it is in i's cell.
    pub fn successor(&self, i: usize) -> Option<usize> {
        (i + 1 < self.n() && self.cell_of[i + 1] == self.cell_of[i]).then_some(i + 1)
    }

    /// The natural predecessor j − 1, if it is in j's cell.
    pub fn predecessor(&self, j: usize) -> Option<usize> {
        (j > 0 && self.cell_of[j - 1] == self.cell_of[j]).then(|| j - 1)
    }

    /// Whether the transition i → j exists at all: every j from a frame with a successor;
    /// from a cell's last frame every j ≠ i that has a predecessor, or — when no such j exists
    /// (a single 2-frame clip) — the first frame of i's cell.
    pub fn is_candidate(&self, i: usize, j: usize) -> bool {
        if self.successor(i).is_some() {
            true
        } else if self.rule_has_candidates {
            j != i && self.predecessor(j).is_some()
        } else {
            j == self.range_of(i).start
        }
    }

    /// Whether i → j is a transition rather than natural play.
    pub fn is_jump(&self, i: usize, j: usize) -> bool {
        self.successor(i) != Some(j)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn successors_stop_at_cell_ends() {
        let l = Layout::new(&[3, 2]);
        assert_eq!(l.successor(1), Some(2));
        assert_eq!(l.successor(2), None);
        assert_eq!(l.predecessor(3), None);
        assert_eq!(l.predecessor(4), Some(3));
        assert_eq!(l.successor(4), None);
        // From the end of cell 0: frames with a predecessor, other than itself.
        let from2: Vec<usize> = (0..5).filter(|&j| l.is_candidate(2, j)).collect();
        assert_eq!(from2, vec![1, 4]);
    }

    #[test]
    fn two_frame_clip_restarts() {
        let l = Layout::new(&[2]);
        let from1: Vec<usize> = (0..2).filter(|&j| l.is_candidate(1, j)).collect();
        assert_eq!(from1, vec![0]);
    }
}
