//! The `cpu` backend's packet traversal ([`CpuMethod::Packets`](super::CpuMethod::Packets)):
//! the rays of one chunk of spatial neighbours towards one direction are parallel and start
//! close together, so they walk a binary BVH together, up to 64 at a time (see the parent
//! module). Where the CPU has AVX2 (checked at run time) each node's box and each triangle
//! is tested against eight rays at once (the `avx2` module), with the scalar answers bit for
//! bit: on the bunny (2 threads, BVH build included, medians of 9 in each of three alternated
//! rounds) 0.89 / 0.72 / 0.70× the scalar packets' time at k = 6 / 18 / 66 (the median
//! round's ratio; with larger leaves, `PACKET_LEAF_SIZE`), the same M.

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;

use super::{ColumnsCall, EdgeTriangle, in_chunks, ray_origin};
use crate::matrix::WORD_BITS;
use crate::refit::{LeafOrder, padded_bvh2};
use crate::scene::{Prepared, scaled_max_t};

#[cfg(target_arch = "x86_64")]
mod avx2;

/// The packet's origins, structure of arrays (`[axis][ray]`), for the eight-ray tests.
type Soa = [[f32; PACKET]; 3];

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
    /// Whether the CPU runs AVX2: eight rays per test (the same answers, bit for bit).
    wide: bool,
}

/// What every ray of a packet shares: the slab test's reciprocal direction and the box of
/// the live rays' origins.
pub(super) struct PacketSetup {
    inv: Vec3A,
    lo: Vec3A,
    hi: Vec3A,
}

impl PacketSetup {
    fn new(origins: &[Vec3A; PACKET], direction: Vec3A, mask: u64) -> Self {
        // A zero component becomes a huge finite one, so 0 · ∞ never makes a NaN.
        let inv = Vec3A::select(
            direction.abs().cmplt(Vec3A::splat(1e-30)),
            Vec3A::splat(1e30).copysign(direction),
            direction.recip(),
        );
        let (mut lo, mut hi) = (Vec3A::INFINITY, Vec3A::NEG_INFINITY);
        let mut m = mask;
        while m != 0 {
            let r = m.trailing_zeros() as usize;
            m &= m - 1;
            lo = lo.min(origins[r]);
            hi = hi.max(origins[r]);
        }
        Self { inv, lo, hi }
    }

    /// Whether no ray of the family o + t·l (o in the origins' box, t ≥ 0) meets `node`'s
    /// box: the node is skipped without testing rays one by one.
    #[inline(always)]
    fn misses(&self, node: &obvhs::bvh2::node::Bvh2Node) -> bool {
        let a = (node.aabb.min - self.hi) * self.inv;
        let b = (node.aabb.max - self.lo) * self.inv;
        a.min(b).max_element().max(0.0) > a.max(b).min_element()
    }
}

impl PacketTracer {
    pub(super) fn new(prepared: &Prepared) -> Self {
        let scale = prepared.tracer_scale();
        let prepared = &*prepared.scaled(scale);
        let wide = crate::fan::has_avx2();
        let leaf_size = if wide {
            PACKET_LEAF_SIZE
        } else {
            SCALAR_LEAF_SIZE
        };
        let (nodes, tris, leaves) = padded_bvh2(prepared, packet_build(), leaf_size);
        let triangles = tris
            .iter()
            .map(|t| EdgeTriangle::new([t.v0.into(), t.v1.into(), t.v2.into()]))
            .collect();
        Self {
            nodes,
            triangles,
            leaves,
            scale,
            wide,
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

    /// The rays of `mask` (bit r: ray from `origins[r]`, also `soa[..][r]`, towards
    /// `direction`) that meet no triangle before `max_t`.
    fn unoccluded(
        &self,
        origins: &[Vec3A; PACKET],
        soa: &Soa,
        direction: Vec3A,
        mask: u64,
        max_t: f32,
    ) -> u64 {
        if self.nodes.is_empty() || mask == 0 {
            return mask;
        }
        let setup = PacketSetup::new(origins, direction, mask);
        #[cfg(target_arch = "x86_64")]
        if self.wide {
            // SAFETY: `wide` is set only where `is_x86_feature_detected!("avx2")` said so.
            #[allow(unsafe_code)]
            return unsafe { avx2::unoccluded(self, soa, &setup, direction, mask, max_t) };
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = soa;
        self.unoccluded_scalar(origins, &setup, direction, mask, max_t)
    }

    /// [`PacketTracer::unoccluded`] one ray at a time.
    fn unoccluded_scalar(
        &self,
        origins: &[Vec3A; PACKET],
        setup: &PacketSetup,
        direction: Vec3A,
        mask: u64,
        max_t: f32,
    ) -> u64 {
        let inv = setup.inv;
        let hits = |node: &obvhs::bvh2::node::Bvh2Node, mut m: u64| {
            if setup.misses(node) {
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
/// Largest triangle count per BVH leaf of the packet tracer where it tests eight rays at a
/// time (AVX2): a triangle's shared set-up (p = d × e₂, det) then serves a whole group, and
/// larger leaves make a shallower tree that builds faster. Bunny, 2 threads, BVH build
/// included, medians of 9 in each of three alternated rounds: leaves of 8 took 0.86–1.21×
/// the time of leaves of 2 at k = 6, 0.93–0.95× at k = 18 and 0.97–1.05× at k = 66; 16 did no
/// better than 8 (the trace alone, two rounds). Same M.
const PACKET_LEAF_SIZE: u32 = 8;
/// The same for the scalar test (one ray and triangle at a time; tuned before the AVX2 path).
const SCALAR_LEAF_SIZE: u32 = 2;

/// [`compute_columns`](super::compute_columns) with packets
/// ([`CpuMethod::Packets`](super::CpuMethod::Packets)): rows in Morton order, one
/// packet per chunk of [`PACKET`] rows and direction.
pub(super) fn packet_columns(tracer: &PacketTracer, dirs: &[Vec3A], call: ColumnsCall<'_>) -> u64 {
    let (prepared, span, columns) = (call.prepared, call.span, call.columns.clone());
    let words_per_row = call.target.words_per_row;
    in_chunks(call, PACKET, |rows, out| {
        let mut origins = [Vec3A::ZERO; PACKET];
        let mut soa = [[0.0; PACKET]; 3];
        let mut normals = [Vec3A::ZERO; PACKET];
        for (r, &row) in rows.iter().enumerate() {
            if let Some((o, n)) = ray_origin(prepared, row as usize, span.offset) {
                origins[r] = o * tracer.scale;
                for (axis, lanes) in soa.iter_mut().enumerate() {
                    lanes[r] = origins[r][axis];
                }
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
            let mut visible = tracer.unoccluded(&origins, &soa, direction, mask, max_t);
            while visible != 0 {
                let r = visible.trailing_zeros() as usize;
                visible &= visible - 1;
                out[r * words_per_row + j / WORD_BITS] |= 1 << (j % WORD_BITS);
            }
        }
        rays
    })
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use glam::Vec3A;

    use super::{PACKET, PacketSetup, PacketTracer, Soa, avx2};
    use crate::scene::Prepared;

    /// The AVX2 packets answer every ray exactly as the scalar ones: chunks of 64 vertices of
    /// a crumpled sheet towards every direction of the level-3 lightsphere (upward rays that
    /// graze, hit or escape, downward ones that start just above the surface), to infinity
    /// and within a finite distance.
    #[test]
    fn eight_rays_answer_as_one() {
        if !std::is_x86_feature_detected!("avx2") {
            eprintln!("skipping: this CPU has no AVX2");
            return;
        }
        let prepared = Prepared::new(&crate::fan::tests::crumpled()).unwrap();
        let tracer = PacketTracer::new(&prepared);
        let sphere = lightsphere::Lightsphere::new(3).unwrap();
        let (mut rays, mut open, mut differ) = (0u32, 0u32, 0u32);
        for chunk in prepared.receivers.chunks(PACKET) {
            let mut origins = [Vec3A::ZERO; PACKET];
            let mut soa: Soa = [[0.0; PACKET]; 3];
            for (r, receiver) in chunk.iter().enumerate() {
                origins[r] = (Vec3A::from(receiver.position) + Vec3A::Y * 1e-3) * tracer.scale;
                for (axis, lanes) in soa.iter_mut().enumerate() {
                    lanes[r] = origins[r][axis];
                }
            }
            let mask = if chunk.len() == PACKET {
                u64::MAX
            } else {
                (1 << chunk.len()) - 1
            };
            for &d in sphere.directions() {
                let d = Vec3A::from(d);
                let setup = PacketSetup::new(&origins, d, mask);
                for max_t in [f32::INFINITY, 5.0 * tracer.scale] {
                    let one = tracer.unoccluded_scalar(&origins, &setup, d, mask, max_t);
                    // SAFETY: AVX2 was detected above.
                    #[allow(unsafe_code)]
                    let eight = unsafe { avx2::unoccluded(&tracer, &soa, &setup, d, mask, max_t) };
                    rays += mask.count_ones();
                    open += one.count_ones();
                    differ += (one ^ eight).count_ones();
                }
            }
        }
        assert_eq!(differ, 0, "{differ} of {rays} rays answered differently");
        // Both answers occur in bulk, so the comparison covers hits and misses.
        assert!(
            open > rays / 5 && open < rays * 4 / 5,
            "{open} of {rays} open"
        );
    }
}
