//! Sets of triangles (global indices over a scene's objects), as bitsets: the "todo" list T
//! and the unseen list U of paper 000 §4.1.

use crate::OcclusionError;

/// A set of triangles (global indices over the scene's objects in order), as a bitset.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TriangleSet {
    len: usize,
    words: Vec<u64>,
}

impl TriangleSet {
    /// The empty set over `len` triangles.
    pub fn empty(len: usize) -> Self {
        Self {
            len,
            words: vec![0; len.div_ceil(64)],
        }
    }

    /// The set of all `len` triangles.
    pub fn full(len: usize) -> Self {
        let mut set = Self::empty(len);
        set.words.fill(u64::MAX);
        set.trim();
        set
    }

    /// The set of the given triangles.
    ///
    /// # Errors
    /// [`OcclusionError::SizeMismatch`] when an index is ≥ `len`.
    pub fn from_indices(len: usize, indices: &[u32]) -> Result<Self, OcclusionError> {
        let mut set = Self::empty(len);
        for &i in indices {
            if i as usize >= len {
                return Err(OcclusionError::SizeMismatch {
                    what: "triangle index",
                    given: i as usize,
                    expected: len,
                });
            }
            set.insert(i as usize);
        }
        Ok(set)
    }

    /// Number of triangles the set ranges over (not the number in the set: see
    /// [`TriangleSet::count`]).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the set ranges over no triangles at all.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Number of triangles in the set.
    pub fn count(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Whether triangle `i` is in the set (false out of range).
    pub fn contains(&self, i: usize) -> bool {
        i < self.len && self.words[i / 64] >> (i % 64) & 1 == 1
    }

    /// Adds triangle `i`.
    ///
    /// # Panics
    /// When `i >= len()`.
    pub fn insert(&mut self, i: usize) {
        assert!(i < self.len, "triangle {i} out of range {}", self.len);
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// The triangles in the set, ascending.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        self.words.iter().enumerate().flat_map(|(w, &word)| {
            let mut word = word;
            std::iter::from_fn(move || {
                if word == 0 {
                    return None;
                }
                let bit = word.trailing_zeros() as usize;
                word &= word - 1;
                Some(w * 64 + bit)
            })
        })
    }

    /// Keeps only the triangles also in `other` (same `len`).
    pub(crate) fn intersect_with(&mut self, other: &Self) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a &= b;
        }
    }

    /// Removes the triangles of `other` (same `len`).
    pub(crate) fn subtract(&mut self, other: &Self) {
        for (a, b) in self.words.iter_mut().zip(&other.words) {
            *a &= !b;
        }
    }

    /// Removes every triangle.
    pub(crate) fn clear(&mut self) {
        self.words.fill(0);
    }

    fn trim(&mut self) {
        let rem = self.len % 64;
        if rem != 0
            && let Some(last) = self.words.last_mut()
        {
            *last &= (1u64 << rem) - 1;
        }
    }
}
