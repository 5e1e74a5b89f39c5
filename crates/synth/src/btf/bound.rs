//! A max pyramid of the height field: the acceleration structure of the ray marcher.
//!
//! Level 0 holds, for each cell of a `side₀ × side₀` grid over the tile, the exact maximum
//! of the height field over the cell ([`Weave::max_height_in_rect`]); level l + 1 holds the
//! maximum of 2 × 2 cells of level l, up to a single cell. Bounding a small rectangle then
//! costs at most four reads at the level whose cells are at least as large as the
//! rectangle, instead of the analytic bound's per-yarn sines and square roots (which were
//! half of a BTF's time). The surface itself is still evaluated analytically; the pyramid
//! only decides where the marcher may skip.

use super::weave::{Weave, floor_i32};
use rayon::prelude::*;

/// Largest level-0 side (1024² cells, 4 MiB): finer cells than a fine march step bring
/// nothing.
const MAX_SIDE: usize = 1024;

/// Maxima of the height field over a hierarchy of grids over the (periodic) tile.
#[derive(Debug, Clone)]
pub(crate) struct MaxPyramid {
    /// `levels[l]` is row-major `(side₀ >> l)²`; the last level is 1 × 1.
    levels: Vec<Vec<f32>>,
    side0: usize,
}

impl MaxPyramid {
    /// A pyramid whose finest cells are at most `finest_cell` wide (tile units, > 0).
    pub(crate) fn new(weave: &Weave, finest_cell: f32) -> Self {
        let side0 = ((1.0 / finest_cell).ceil() as usize)
            .clamp(1, MAX_SIDE)
            .next_power_of_two();
        let cell = 1.0 / side0 as f32;
        let finest: Vec<f32> = (0..side0 * side0)
            .into_par_iter()
            .map(|index| {
                let (i, j) = ((index % side0) as f32, (index / side0) as f32);
                weave.max_height_in_rect((i * cell, (i + 1.0) * cell), (j * cell, (j + 1.0) * cell))
            })
            .collect();
        let mut levels = vec![finest];
        let mut side = side0;
        while side > 1 {
            let below = levels.last().map_or(&[][..], Vec::as_slice);
            let half = side / 2;
            let above: Vec<f32> = (0..half * half)
                .map(|index| {
                    let (i, j) = (2 * (index % half), 2 * (index / half));
                    let at = |i: usize, j: usize| below[j * side + i];
                    at(i, j)
                        .max(at(i + 1, j))
                        .max(at(i, j + 1))
                        .max(at(i + 1, j + 1))
                })
                .collect();
            levels.push(above);
            side = half;
        }
        Self { levels, side0 }
    }

    /// An upper bound of the height over `[x0, x1] × [y0, y1]` (any real coordinates,
    /// x0 ≤ x1, y0 ≤ y1).
    #[inline]
    pub(crate) fn max_in_rect(&self, (x0, x1): (f32, f32), (y0, y1): (f32, f32)) -> f32 {
        // The finest level whose cells are at least as wide as the rectangle, so that it
        // overlaps at most 2 × 2 of them.
        let mut extent = (x1 - x0).max(y1 - y0) * self.side0 as f32;
        let mut level = 0;
        while extent > 1.0 && level + 1 < self.levels.len() {
            extent *= 0.5;
            level += 1;
        }
        let cells = &self.levels[level];
        let side = self.side0 >> level;
        if side == 1 {
            return cells[0];
        }
        let scale = side as f32;
        let mask = side as i32 - 1;
        let (i0, i1) = (floor_i32(x0 * scale), floor_i32(x1 * scale));
        let (j0, j1) = (floor_i32(y0 * scale), floor_i32(y1 * scale));
        let mut best = f32::NEG_INFINITY;
        for j in j0..=j1 {
            let row = (j & mask) as usize * side;
            for i in i0..=i1 {
                best = best.max(cells[row + (i & mask) as usize]);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SplitMix64;

    #[test]
    fn pyramid_bounds_the_height_and_is_not_loose() {
        let weave = Weave::new(4, 6, 0.8, 0.3, 0.6);
        let pyramid = MaxPyramid::new(&weave, 1.0 / 100.0);
        assert_eq!(pyramid.side0, 128);
        let mut rng = SplitMix64::new(9);
        for _ in 0..500 {
            let (x0, y0) = (4.0 * rng.next_signed(), 4.0 * rng.next_signed());
            let size = 0.1 * rng.next_f32() * rng.next_f32();
            let (w, h) = (size * rng.next_f32(), size);
            let bound = pyramid.max_in_rect((x0, x0 + w), (y0, y0 + h));
            let exact = weave.max_height_in_rect((x0, x0 + w), (y0, y0 + h));
            assert!(
                bound >= exact,
                "pyramid {bound} below the exact bound {exact}"
            );
            for k in 0..50 {
                let (x, y) = (x0 + w * (k % 7) as f32 / 6.0, y0 + h * (k / 7) as f32 / 7.0);
                assert!(bound >= weave.height(x, y));
            }
        }
        // The top level is the tile's maximum.
        let top = pyramid.max_in_rect((-3.0, 3.0), (0.0, 1.0));
        assert!((top - weave.z_top).abs() < 1e-5, "{top} vs {}", weave.z_top);
    }
}
