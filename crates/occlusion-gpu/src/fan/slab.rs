//! Slabs: the two parallel planes along a subtree's area-weighted normal that hold its
//! triangles, a second bound beside the box for rays that graze a surface.

use glam::Vec3A;
use obvhs::bvh2::node::Bvh2Node;
use rayon::prelude::*;

use super::FanTriangle;
use crate::refit::LeafOrder;

/// Largest subtree (in triangles) that gets a [`Slab`]. The larger ones — about 130 nodes on
/// the bunny, yet 32 % of its eight-lane group tests at k = 258, the siblings along every
/// origin's path to the root — are not flat along any normal. A slab across one of their
/// box's corners instead (the best of the ten body and face diagonals, where it is under
/// 0.9 or 0.7 of the box's width) left the bunny's trace at k = 258 where it was (208–213
/// ms against 206–209, same M) and cost 20 ms of build, computed naively.
const SLAB_MAX_TRIANGLES: u32 = 1024;

/// The region |n·x − c| ≤ h between two parallel planes that holds a subtree's triangles: for
/// a nearly flat patch much thinner than its box, so the rays that graze a surface (which
/// cross the boxes of the patches beside their origin) are culled before the triangle
/// tests.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slab {
    pub(super) normal: Vec3A,
    pub(super) centre: f32,
    pub(super) half: f32,
}

impl Slab {
    /// A slab that culls nothing.
    pub(super) const UNBOUNDED: Self = Self {
        normal: Vec3A::ZERO,
        centre: 0.0,
        half: f32::INFINITY,
    };

    /// The slab of `triangles` along `area` (the sum of their area-weighted normals), padded
    /// by 1e-5 × `diagonal` (the scene's coordinates are centred, so rounding in n·x stays
    /// far below that).
    fn around(area: Vec3A, triangles: impl Iterator<Item = [Vec3A; 3]>, diagonal: f32) -> Self {
        let normal = area.normalize_or_zero();
        if normal == Vec3A::ZERO {
            return Self::UNBOUNDED;
        }
        let (lo, hi) = triangles
            .flatten()
            .map(|v| normal.dot(v))
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), d| {
                (lo.min(d), hi.max(d))
            });
        Self {
            normal,
            centre: 0.5 * (lo + hi),
            half: 0.5 * (hi - lo) + 1e-5 * diagonal,
        }
    }
}

/// Each node's [`Slab`] over its subtree's triangles, for subtrees of at most
/// [`SLAB_MAX_TRIANGLES`] triangles (larger ones: unbounded); `triangles` in leaf order.
pub(super) fn subtree_slabs(
    nodes: &[Bvh2Node],
    leaves: &LeafOrder,
    triangles: &[FanTriangle],
    diagonal: f32,
) -> Vec<Slab> {
    // Bottom-up: each subtree's triangles as a range of the leaf order (contiguous: see
    // `padded_bvh2`) and its area-weighted normal, the sum of its children's. (Gathering each
    // subtree's triangles by walking it took 5.6 ms on the bunny, the ranges 2.0.)
    let area = |t: &FanTriangle| {
        let [a, b, c] = t.0;
        (b - a).cross(c - a)
    };
    let mut under = vec![(0u32, 0u32, Vec3A::ZERO); nodes.len()];
    let mut contiguous = true;
    for &i in &leaves.bottom_up {
        let node = &nodes[i as usize];
        under[i as usize] = if node.prim_count > 0 {
            let (first, end) = (node.first_index, node.first_index + node.prim_count);
            let sum = triangles[first as usize..end as usize]
                .iter()
                .map(area)
                .sum();
            (first, end, sum)
        } else {
            let c = node.first_index as usize;
            let ((a0, a1, an), (b0, b1, bn)) = (under[c], under[c + 1]);
            contiguous &= a1 == b0 || b1 == a0;
            (a0.min(b0), a1.max(b1), an + bn)
        };
    }
    if !contiguous {
        // Not a tree from `padded_bvh2` (which numbers leaves depth-first): no slabs, still
        // the right answer.
        return vec![Slab::UNBOUNDED; nodes.len()];
    }
    under
        .par_iter()
        .map(|&(first, end, area)| {
            if end - first > SLAB_MAX_TRIANGLES {
                return Slab::UNBOUNDED;
            }
            let range = &triangles[first as usize..end as usize];
            Slab::around(area, range.iter().map(|t| t.0), diagonal)
        })
        .collect()
}
