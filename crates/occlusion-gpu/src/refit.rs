//! Refitting the `cpu` backend's binary BVH to a deforming mesh: the topology is fixed, so the
//! tree built for one frame is kept and only its boxes are recomputed from the new positions,
//! bottom-up — O(N) instead of the O(N log N) build. A refitted tree answers every ray exactly
//! as a fresh one does (its boxes still contain their triangles; the triangle tests are the
//! same), only its traversal cost can grow as triangles drift apart. That cost is measured by
//! the surface-area heuristic (SAH) relative to the tree's cost when it was built, and by the
//! clock. The engine keeps a refitted tree while the extra traversal it costs — the larger of
//! (ratio − 1) × the fresh tree's traversal time and the extra time measured on the last
//! refitted frame — stays below the last build's time (measured, so the rule adapts to k and
//! to the mesh), and never beyond [`REBUILD_SAH_RATIO`]. On the drape at k = 258 a traversal
//! of ~24 ms against a 4 ms build tolerates ~15 % of degradation; a fixed 1.5 cap alone
//! made refitting 7.5 % slower than rebuilding every frame there, and the SAH ratio alone
//! (which underestimates the slowdown of the slab-culled fan traversal) 10 % slower. Per frame
//! (`benches/deforming.rs`, one run, medians): drape k = 258 23.7 ms refitting against
//! 27.3 ms rebuilding, k = 66 10.1 vs 12.6; the chicken at k = 258 19.8 vs 22.1, k = 66 7.1
//! vs 9.6.
//!
//! Tried and dropped (2026-12-06, the drape at k = 258 with its ball, 9,730 triangles):
//!
//! * obvhs's reinsertion after each refit (`ReinsertionOptimizer` on 2 % and 10 % of the
//!   nodes, then the depth-first renumbering of [`padded_bvh2`]). Over 120 frames, refitting
//!   always (a rebuild only past SAH 1.5: 4 builds), four alternated rounds: 33.6 / 38.9 /
//!   33.2 / 35.1 ms of trace per frame against 34.6 / 38.8 / 32.8 / 36.4 without, and
//!   0.3–0.6 ms more per refit. Fresh trees traced in 27.7–32.8 ms in the same rounds. The
//!   reinsertion moved the SAH ratio by under 0.3 % (1.1246 before, 1.1246 after, on a late
//!   frame): a refitted tree loses its speed in its leaves (triangles grouped for another
//!   frame's shape), not in where its subtrees hang.
//! * `very_fast_build` (no search radius, 1 % reinsertion) for the fans' tree, which a
//!   deforming mesh rebuilds often. Its build is 0.6–0.8 ms cheaper (drape 2.7–2.8 against
//!   3.4–3.5 ms), but its trees trace slower. With the engine's refit rule (`benches/
//!   deforming.rs`, two alternated rounds) the drape took 31.3 / 30.4 ms per frame against
//!   29.8 / 29.3 with `fast_build`, the chicken at k = 258 27.2 / 27.2 against 25.4 / 24.6.
//!   Running obvhs's build on one thread instead of two (rayon's overhead on 8,450 triangles:
//!   2.0 ms alone against 2.7–2.8) gained nothing inside the engine (4.3–4.5 ms per build
//!   against 3.7–4.5).

use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb;
use obvhs::bvh2::node::Bvh2Node;
use obvhs::triangle::Triangle;

use crate::scene::Prepared;

/// Never keep a refitted tree whose SAH cost exceeds its build-time cost by this factor.
pub const REBUILD_SAH_RATIO: f32 = 1.5;

/// A binary BVH whose leaves index triangles in `order` (leaf order → scene triangle).
pub(crate) struct LeafOrder {
    /// Scene triangle of each leaf slot.
    pub order: Vec<u32>,
    /// Node indices with every node after its children (a reversed depth-first pre-order):
    /// the order of a bottom-up refit.
    pub bottom_up: Vec<u32>,
    /// SAH cost when built (relative to the root's area).
    pub build_cost: f32,
}

impl LeafOrder {
    /// Records the leaf order of freshly built, padded `nodes`.
    pub(crate) fn new(nodes: &[Bvh2Node], order: Vec<u32>) -> Self {
        // Recorded once, at build, from the tree itself (it does not rely on `padded_bvh2`'s
        // depth-first numbering).
        let mut bottom_up = Vec::with_capacity(nodes.len());
        let mut stack = if nodes.is_empty() { vec![] } else { vec![0u32] };
        while let Some(i) = stack.pop() {
            bottom_up.push(i);
            let n = &nodes[i as usize];
            if n.prim_count == 0 {
                stack.extend([n.first_index, n.first_index + 1]);
            }
        }
        bottom_up.reverse();
        Self {
            order,
            bottom_up,
            build_cost: sah_cost(nodes),
        }
    }
}

/// The padding every box gets (as at build): absolute 1e-6 × the scene's diagonal plus 1e-5 ×
/// the box's largest side, so rays grazing a box's face are never lost to rounding.
pub(crate) fn pad(aabb: &mut Aabb, diagonal: f32) {
    let pad = Vec3A::splat(1e-6 * diagonal + 1e-5 * (aabb.max - aabb.min).max_element());
    aabb.min -= pad;
    aabb.max += pad;
}

/// SAH cost of a tree: Σ inner areas + Σ leaf areas × primitives, over the root's area
/// (traversal and triangle test weighted alike).
pub(crate) fn sah_cost(nodes: &[Bvh2Node]) -> f32 {
    let Some(root) = nodes.first() else {
        return 0.0;
    };
    let root_area = root.aabb.half_area().max(f32::MIN_POSITIVE);
    let total: f32 = nodes
        .iter()
        .map(|n| n.aabb.half_area() * (n.prim_count.max(1) as f32))
        .sum();
    total / root_area
}

/// Refits `nodes` to `positions`: each leaf's box becomes the padded bounds of its triangles
/// (`triangles[order[slot]]`), each inner box the union of its children. Returns the new SAH
/// cost, or `None` when `nodes` is not the tree `leaves` was recorded for.
pub(crate) fn refit(
    nodes: &mut [Bvh2Node],
    leaves: &LeafOrder,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    diagonal: f32,
) -> Option<f32> {
    if leaves.bottom_up.len() != nodes.len() {
        return None;
    }
    for &i in &leaves.bottom_up {
        let i = i as usize;
        let node = nodes[i];
        let mut aabb = Aabb::empty();
        if node.prim_count > 0 {
            let first = node.first_index as usize;
            for &t in &leaves.order[first..first + node.prim_count as usize] {
                for v in triangles[t as usize] {
                    aabb.extend(Vec3A::from(positions[v as usize]));
                }
            }
            pad(&mut aabb, diagonal);
        } else {
            let c = node.first_index as usize;
            aabb = nodes[c].aabb.union(&nodes[c + 1].aabb);
        }
        nodes[i].aabb = aabb;
    }
    Some(sah_cost(nodes))
}

/// Refits a tree built by [`padded_bvh2`] and its leaf-ordered triangle data to
/// `prepared`'s positions (same topology): the boxes through [`refit`], each triangle remade
/// by `make`. The new SAH cost over the build's.
pub(crate) fn refit_tree<T>(
    nodes: &mut [Bvh2Node],
    leaves: &LeafOrder,
    triangles: &mut [T],
    prepared: &crate::scene::Prepared,
    make: impl Fn([Vec3A; 3]) -> T,
) -> Option<f32> {
    let cost = refit(
        nodes,
        leaves,
        &prepared.positions,
        &prepared.triangles,
        prepared.diagonal,
    )?;
    for (slot, t) in triangles.iter_mut().zip(leaf_triangles(prepared, leaves)) {
        *slot = make(t);
    }
    Some(cost / leaves.build_cost.max(f32::MIN_POSITIVE))
}

/// A binary BVH (`obvhs`'s PLOC build with `quality`'s settings, at most `leaf_size` triangles
/// per leaf) over the scene's triangles, with every box padded a little so that the slab test
/// never drops a ray that the triangle test (with its [`crate::cpu::EDGE_TOLERANCE`]) counts
/// as a hit on the box's boundary; the triangles come back in leaf order. Empty for a scene
/// without triangles.
pub(crate) fn padded_bvh2(
    prepared: &Prepared,
    quality: BvhBuildParams,
    leaf_size: u32,
) -> (Vec<obvhs::bvh2::node::Bvh2Node>, Vec<Triangle>, LeafOrder) {
    let tris = scene_triangles(prepared);
    if tris.is_empty() {
        return (Vec::new(), Vec::new(), LeafOrder::new(&[], Vec::new()));
    }
    let mut params = quality;
    params.max_prims_per_leaf = leaf_size;
    let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&tris, params, &mut Duration::default());
    // One depth-first walk renumbers the nodes — each pair of siblings placed when its parent
    // is reached: the root at 0, every pair from an odd index, a subtree's nodes near each
    // other — and the leaves' triangles, so that every subtree's triangles are one range of
    // the leaf order (the fan slabs' bounds). obvhs leaves both in PLOC's merge order.
    let mut nodes = Vec::with_capacity(bvh.nodes.len());
    nodes.push(bvh.nodes[0]);
    let mut order = Vec::with_capacity(bvh.primitive_indices.len());
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        let at = nodes.len();
        let node: &mut obvhs::bvh2::node::Bvh2Node = &mut nodes[i];
        let first = node.first_index as usize;
        if node.prim_count > 0 {
            node.first_index = order.len() as u32;
            order
                .extend_from_slice(&bvh.primitive_indices[first..first + node.prim_count as usize]);
        } else {
            node.first_index = at as u32;
            nodes.extend([bvh.nodes[first], bvh.nodes[first + 1]]);
            stack.extend([at + 1, at]);
        }
    }
    let ordered = order.iter().map(|&i| tris[i as usize]).collect();
    for node in &mut nodes {
        pad(&mut node.aabb, prepared.diagonal);
    }
    let leaves = LeafOrder::new(&nodes, order);
    (nodes, ordered, leaves)
}

/// The triangles of `prepared` in `leaves`' order (what a refitted tree's leaves index).
pub(crate) fn leaf_triangles(prepared: &Prepared, leaves: &LeafOrder) -> Vec<[Vec3A; 3]> {
    leaves
        .order
        .iter()
        .map(|&t| {
            prepared.triangles[t as usize].map(|v| Vec3A::from(prepared.positions[v as usize]))
        })
        .collect()
}

/// The scene's triangles as `obvhs` takes them (degenerate ones included: they never hit).
pub(crate) fn scene_triangles(prepared: &Prepared) -> Vec<Triangle> {
    prepared
        .triangles
        .iter()
        .map(|t| Triangle {
            v0: prepared.positions[t[0] as usize].into(),
            v1: prepared.positions[t[1] as usize].into(),
            v2: prepared.positions[t[2] as usize].into(),
        })
        .collect()
}
