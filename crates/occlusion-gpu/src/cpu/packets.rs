//! The `cpu` backend's packet traversal ([`CpuMethod::Packets`](super::CpuMethod::Packets)):
//! the rays of one chunk of spatial neighbours towards one direction are parallel and start
//! close together, so they walk a binary BVH together, up to 64 at a time (see the parent
//! module).

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;

use super::{ColumnsCall, EdgeTriangle, in_chunks, ray_origin};
use crate::matrix::WORD_BITS;
use crate::refit::{LeafOrder, padded_bvh2};
use crate::scene::{Prepared, scaled_max_t};

/// `obvhs`'s build settings for the packets' tree (calls of under
/// [`FAN_MIN_COLUMNS`](super::FAN_MIN_COLUMNS) columns, where the build is most of the time):
/// `very_fast_build`. Bunny, same day, A/B medians of 7: 0.85× `medium_build`'s time at k = 6
/// and 0.89× at k = 18; 0.94× `fast_build`'s at k = 6.
pub(super) fn packet_build() -> BvhBuildParams {
    BvhBuildParams::very_fast_build()
}

/// A binary BVH (`obvhs`'s PLOC build) with its triangles in leaf order, traversed by packets
/// of up to 64 parallel rays.
pub(super) struct PacketTracer {
    nodes: Vec<obvhs::bvh2::node::Bvh2Node>,
    triangles: Vec<EdgeTriangle>,
    leaves: LeafOrder,
    /// The power of two the tree, its triangles and every ray's origin and `max_t` are
    /// multiplied by ([`Prepared::tracer_scale`]: box areas and Möller–Trumbore's products
    /// stay in f32's normal range at any scene scale).
    scale: f32,
}

impl PacketTracer {
    pub(super) fn new(prepared: &Prepared) -> Self {
        let scale = prepared.tracer_scale();
        let prepared = &*prepared.scaled(scale);
        let (nodes, tris, leaves) = padded_bvh2(prepared, packet_build(), PACKET_LEAF_SIZE);
        let triangles = tris
            .iter()
            .map(|t| EdgeTriangle::new([t.v0.into(), t.v1.into(), t.v2.into()]))
            .collect();
        Self {
            nodes,
            triangles,
            leaves,
            scale,
        }
    }

    /// Refits to `prepared`'s positions (same topology); the new SAH cost over the build's.
    pub(super) fn refit(&mut self, prepared: &Prepared) -> Option<f32> {
        let scale = prepared.tracer_scale();
        let ratio = crate::refit::refit_tree(
            &mut self.nodes,
            &self.leaves,
            &mut self.triangles,
            &prepared.scaled(scale),
            |t| EdgeTriangle::new(t.map(Vec3::from)),
        )?;
        self.scale = scale;
        Some(ratio)
    }

    /// The rays of `mask` (bit r: ray from `origins[r]` towards `direction`) that meet no
    /// triangle before `max_t`.
    fn unoccluded(
        &self,
        origins: &[Vec3A; PACKET],
        direction: Vec3A,
        mask: u64,
        max_t: f32,
    ) -> u64 {
        if self.nodes.is_empty() || mask == 0 {
            return mask;
        }
        // Shared by every ray of the packet: the slab test's reciprocal direction (a zero
        // component becomes a huge finite one, so 0 · ∞ never makes a NaN).
        let inv = Vec3A::select(
            direction.abs().cmplt(Vec3A::splat(1e-30)),
            Vec3A::splat(1e30).copysign(direction),
            direction.recip(),
        );
        // The packet's origins' box: a node no ray of the family o + t·l (o in the box, t ≥ 0)
        // meets is skipped without testing rays one by one.
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let mut m = mask;
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            lo = lo.min(origins[r]);
            hi = hi.max(origins[r]);
        }
        let hits = |node: &obvhs::bvh2::node::Bvh2Node, mut m: u64| {
            let a = (node.aabb.min - hi) * inv;
            let b = (node.aabb.max - lo) * inv;
            if a.min(b).max_element().max(0.0) > a.max(b).min_element() {
                return 0;
            }
            let mut out = 0u64;
            while m != 0 {
                let r = m.trailing_zeros() as usize;
                m &= m - 1;
                let t1 = (node.aabb.min - origins[r]) * inv;
                let t2 = (node.aabb.max - origins[r]) * inv;
                let near = t1.min(t2).max_element().max(0.0);
                let far = t1.max(t2).min_element();
                if near <= far {
                    out |= 1 << r;
                }
            }
            out
        };
        let mut visible = mask;
        let mut stack: Vec<(u32, u64)> = Vec::with_capacity(64);
        let root = hits(&self.nodes[0], mask);
        if root != 0 {
            stack.push((0, root));
        }
        while let Some((index, m)) = stack.pop() {
            let m = m & visible;
            if m == 0 {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.prim_count > 0 {
                let tris = &self.triangles
                    [node.first_index as usize..(node.first_index + node.prim_count) as usize];
                let mut left = m;
                while left != 0 {
                    let r = left.trailing_zeros() as usize;
                    left &= left - 1;
                    if tris
                        .iter()
                        .any(|t| t.intersect(origins[r], direction) < max_t)
                    {
                        visible &= !(1 << r);
                    }
                }
                if visible == 0 {
                    break;
                }
            } else {
                let first = node.first_index;
                for child in [first + 1, first] {
                    let cm = hits(&self.nodes[child as usize], m);
                    if cm != 0 {
                        stack.push((child, cm));
                    }
                }
            }
        }
        visible
    }
}

/// Rays per packet (one bit each in a u64 mask).
const PACKET: usize = 64;
/// Largest triangle count per BVH leaf of the packet tracer.
const PACKET_LEAF_SIZE: u32 = 2;

/// [`compute_columns`](super::compute_columns) with packets
/// ([`CpuMethod::Packets`](super::CpuMethod::Packets)): rows in Morton order, one
/// packet per chunk of [`PACKET`] rows and direction.
pub(super) fn packet_columns(tracer: &PacketTracer, dirs: &[Vec3A], call: ColumnsCall<'_>) -> u64 {
    let (prepared, span, columns) = (call.prepared, call.span, call.columns.clone());
    let words_per_row = call.target.words_per_row;
    in_chunks(call, PACKET, |rows, out| {
        let mut origins = [Vec3A::ZERO; PACKET];
        let mut normals = [Vec3A::ZERO; PACKET];
        for (r, &row) in rows.iter().enumerate() {
            if let Some((o, n)) = ray_origin(prepared, row as usize, span.offset) {
                origins[r] = o * tracer.scale;
                normals[r] = n;
            }
        }
        let max_t = scaled_max_t(span.max_t, tracer.scale);
        let mut rays = 0u64;
        for j in columns.clone() {
            let direction = dirs[j];
            let mut mask = 0u64;
            for (r, normal) in normals[..rows.len()].iter().enumerate() {
                if normal.dot(direction) > 0.0 {
                    mask |= 1 << r;
                }
            }
            rays += u64::from(mask.count_ones());
            let mut visible = tracer.unoccluded(&origins, direction, mask, max_t);
            while visible != 0 {
                let r = visible.trailing_zeros() as usize;
                visible &= visible - 1;
                out[r * words_per_row + j / WORD_BITS] |= 1 << (j % WORD_BITS);
            }
        }
        rays
    })
}
