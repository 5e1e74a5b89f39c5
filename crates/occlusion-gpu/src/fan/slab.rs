//! Slabs: the two parallel planes along a subtree's area-weighted normal that hold its
//! triangles, a second bound beside the box for rays that graze a surface.

use glam::Vec3A;
use obvhs::bvh2::node::Bvh2Node;
use rayon::prelude::*;

use super::FanTriangle;
use crate::refit::LeafOrder;

/// Largest subtree (in triangles) that gets a [`Slab`].
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

    /// The slab along the triangles' area-weighted normal, padded by 1e-5 × `diagonal` (the
    /// scene's coordinates are centred, so rounding in n·x stays far below that).
    fn around(triangles: impl Iterator<Item = [Vec3A; 3]> + Clone, diagonal: f32) -> Self {
        let normal = triangles
            .clone()
            .map(|[a, b, c]| (b - a).cross(c - a))
            .sum::<Vec3A>()
            .normalize_or_zero();
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
    // Triangles under each node, bottom-up.
    let mut count = vec![0u32; nodes.len()];
    for &i in &leaves.bottom_up {
        let node = &nodes[i as usize];
        count[i as usize] = if node.prim_count > 0 {
            node.prim_count
        } else {
            let c = node.first_index as usize;
            count[c] + count[c + 1]
        };
    }
    (0..nodes.len())
        .into_par_iter()
        .map_init(Vec::new, |under: &mut Vec<FanTriangle>, i| {
            if count[i] > SLAB_MAX_TRIANGLES {
                return Slab::UNBOUNDED;
            }
            under.clear();
            let mut stack = vec![i];
            while let Some(n) = stack.pop() {
                let node = &nodes[n];
                if node.prim_count > 0 {
                    let first = node.first_index as usize;
                    under.extend(&triangles[first..first + node.prim_count as usize]);
                } else {
                    stack.extend([node.first_index as usize, node.first_index as usize + 1]);
                }
            }
            Slab::around(under.iter().map(|t| t.0), diagonal)
        })
        .collect()
}
