//! One ray through a subtree: a fan's last live lane, walked alone.
//!
//! Lanes diverge with depth: on the bunny at k = 258, 44 % of the internal nodes the fans
//! visited held a single live lane (55 % two or fewer, 70 % eight or fewer), each paying for
//! a whole lane group. Such a lane leaves the fan and walks the rest of the subtree on its
//! own, four boxes at a time: every internal node carries a [`Quad`], its grandchildren's
//! boxes and slabs lane by lane (a child that is a leaf stands in for its two), so one SIMD
//! pass tests two levels of the binary tree.
//!
//! Where their time goes (bunny, k = 258, the time-stamp counter read around each call and
//! around each fan's whole traversal): the walks take 45 % of the traversal (38 % at
//! k = 1026). 926 k calls walk 2.09 M lanes, each through 2.1 quads, 0.43 leaves and 2.0
//! triangles on average, about 210 counter ticks a walk: most end at their first or second
//! quad, every box and slab missed. Prefetching a subtree's first quad (three lines) when the
//! lane groups push it with [`ALONE`] lanes or fewer made the call 6 % slower (A/B median of
//! 5), so these short walks are not bound by that load alone, whatever the profile's hottest
//! instruction (the first quad's load) suggests. Nor by arithmetic: a walk whose subtree's box
//! does not hold the origin can skip the containment test of every box below it (a parent's
//! box is the union of its children's; exact, M's hash unchanged), which takes about a fifth of
//! [`quad_hits`]'s vector operations — and changed nothing (bunny at k = 258, A/B medians of
//! 7, two rounds: 1.04× and 1.00×; k = 1026: 1.00×). What is left is, presumably, the chain
//! from a quad's load through its tests to the branch on their mask. Nor is it the quads'
//! size (three lines each, 3.1 MB on the bunny against a 2 MB L2 per core): on
//! `bun_zipper_res2` (16 k triangles, quads 0.7 MB, well within L2) a ray costs 37.7 ns
//! against the full bunny's 42.9 (k = 258, 2 threads, medians of 9), 1.14× for two more
//! levels of tree, and the profile's split barely moves. With each walk function kept
//! out of line, the quad tests take 14.4 % against 19.0 %, the leaf tests 13.4 % / 12.9 %,
//! the walk's own loop 12.7 % / 13.2 %, the lane groups' box tests 29 % / 28 %. So quads
//! compressed to one line (quantised boxes) could take about 5 % off at most, before paying
//! for their decoding.
//!
//! Nor by the walk's steps. The two to four lanes of one call walked their subtree together
//! (one walk over the union of their paths, each stack entry carrying the rays that entered
//! its box; what depends on the common origin alone — box corners relative to it, whether a
//! box holds it, the slabs' offsets, a triangle's edge normals — computed once for all; same
//! M). On the bunny at k = 258 the 620 k calls of two or more lanes (2.9 on average) then
//! made 2.08 M quad visits instead of 3.54 M, and 3.55 M ray-quad tests against 3.54 M (the
//! union costs nearly nothing: rays of one fan diverge little below the fan), yet the call
//! was slower in each of three variants (build + trace, bunny at k = 258, mean of two
//! alternated rounds against a baseline that itself measured 0.97–1.03×): the live rays
//! looped over and their boxes scattered bit by bit 1.10×, all of a call's rays tested with
//! a branch-free 4 × 4 bit transpose of the box masks 1.07×, the live rays with the
//! transpose 1.04×. Each ray's tests stay its own, so the steps saved are the cheap part;
//! the branches added are not.
//!
//! Nor by when they run. The walks put off until the fan's lane groups had finished (each
//! walk's lanes then narrowed to those still open, a walk whose lanes had all been blocked
//! meanwhile skipped; same M) took 1.07× the time (bunny at k = 258, 2 threads, the median of
//! six alternated pairs of best-of-3 runs): a walk's hit, found early, spares the lane in
//! every group test still on the stack, which is worth more than the walks it would skip.

use glam::{BVec4A, Vec3A, Vec4};

use super::{FanNode, FanTracer, FanTriangle, RayFan};
use crate::cpu::EDGE_TOLERANCE;

/// A [`Quad`] entry that is a leaf: its first triangle in the low 28 bits, its count less one
/// in the next three.
const LEAF: u32 = 1 << 31;
/// Bits of a leaf entry's first triangle.
const FIRST_BITS: u32 = 28;
/// An unused [`Quad`] entry.
const EMPTY: u32 = u32::MAX;

/// Up to four boxes and slabs, one per SIMD lane, and what each leads to: a leaf's triangles
/// or the next [`Quad`]. Three cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(super) struct Quad {
    min: [Vec4; 3],
    max: [Vec4; 3],
    normal: [Vec4; 3],
    centre: Vec4,
    half: Vec4,
    /// `LEAF | (count − 1) << FIRST_BITS | first` for a leaf, the [`Quad`] of its
    /// grandchildren for an internal node, [`EMPTY`] for none.
    entry: [u32; 4],
}

impl Quad {
    const EMPTY: Self = Self {
        min: [Vec4::ZERO; 3],
        max: [Vec4::ZERO; 3],
        normal: [Vec4::ZERO; 3],
        centre: Vec4::ZERO,
        half: Vec4::INFINITY,
        entry: [EMPTY; 4],
    };

    /// Lanes holding an entry.
    #[inline(always)]
    fn valid(&self) -> u32 {
        BVec4A::new(
            self.entry[0] != EMPTY,
            self.entry[1] != EMPTY,
            self.entry[2] != EMPTY,
            self.entry[3] != EMPTY,
        )
        .bitmask()
    }
}

/// The [`Quad`] of every pair of siblings in `flat` (the traversal's nodes, siblings at
/// indices 2p and 2p + 1): quad p holds the grandchildren of the pair's parent. `None` where a
/// leaf does not fit an entry (more than eight triangles, or a first triangle past 2²⁸) or
/// siblings straddle two pairs.
pub(super) fn quads(flat: &[FanNode]) -> Option<Vec<Quad>> {
    let leaf = |n: &FanNode| {
        (n.prim_count <= 8 && n.first_index < 1 << FIRST_BITS)
            .then(|| LEAF | (n.prim_count - 1) << FIRST_BITS | n.first_index)
    };
    let mut out = vec![Quad::EMPTY; flat.len() / 2];
    for (p, quad) in out.iter_mut().enumerate() {
        let mut lane = 0;
        for child in &flat[2 * p..2 * p + 2] {
            let under: &[FanNode] = if child.prim_count > 0 {
                std::slice::from_ref(child)
            } else if child.first_index == 0 {
                // The padding before the root (no children) or an empty tree.
                &[]
            } else if child.first_index % 2 == 1 {
                // Siblings that straddle two pairs.
                return None;
            } else {
                let first = child.first_index as usize;
                &flat[first..first + 2]
            };
            for n in under {
                quad.entry[lane] = if n.prim_count > 0 {
                    leaf(n)?
                } else {
                    n.first_index / 2
                };
                for axis in 0..3 {
                    quad.min[axis][lane] = n.min[axis];
                    quad.max[axis][lane] = n.max[axis];
                    quad.normal[axis][lane] = n.normal[axis];
                }
                quad.centre[lane] = n.centre;
                quad.half[lane] = n.half;
                lane += 1;
            }
        }
    }
    Some(out)
}

/// Live lanes at or below which a fan's lanes leave it and walk a subtree alone.
pub(super) const ALONE: u32 = 4;

/// The lanes of `mask` (at most [`ALONE`]) whose rays, walked alone through the subtree at
/// `index`, meet a triangle at 0 < t < `max_t`.
#[inline(always)]
pub(super) fn lanes_alone<const BOUNDED: bool>(
    tracer: &FanTracer,
    index: u32,
    origin: Vec3A,
    fan: &RayFan,
    mask: u64,
    max_t: f32,
    stack: &mut Vec<u32>,
) -> u64 {
    let mut hit = 0;
    let mut rest = mask;
    while rest != 0 {
        let lane = rest.trailing_zeros() as usize;
        rest &= rest - 1;
        if single_lane::<BOUNDED>(tracer, index, origin, fan.lane_ray(lane), max_t, stack) {
            hit |= 1 << lane;
        }
    }
    hit
}

/// A ray splatted across lanes.
struct Ray4 {
    origin: [Vec4; 3],
    d: [Vec4; 3],
    inv: [Vec4; 3],
    /// n·o is taken from `origin3` as the lane groups take it (a `Vec3A` dot product).
    origin3: Vec3A,
}

/// One lane's ray, `origin + t·d` with its reciprocal `inv`, through the subtree at `index`
/// (whose box it enters): whether it meets a triangle at 0 < t < `max_t`. The lane groups'
/// box, slab and triangle formulas in their operand order (SSE's min/max, no fused
/// multiply-add); the interval cull of the whole fan and the tests of every second level's
/// boxes are skipped, which in exact arithmetic never changes an answer — a ray meets a
/// triangle only inside every box and slab above it (`single_lane_answers_as_lane_groups`
/// compares them on a sheet whose origins lie on box faces).
#[inline(always)]
fn single_lane<const BOUNDED: bool>(
    tracer: &FanTracer,
    index: u32,
    origin: Vec3A,
    [d, inv]: [Vec3A; 2],
    max_t: f32,
    stack: &mut Vec<u32>,
) -> bool {
    let node = tracer.node(index);
    let first = node.first_index;
    if node.prim_count > 0 {
        return leaf_hit::<BOUNDED>(tracer, first, node.prim_count, origin, d, max_t);
    }
    let ray = Ray4 {
        origin: [0, 1, 2].map(|k| Vec4::splat(origin[k])),
        d: [0, 1, 2].map(|k| Vec4::splat(d[k])),
        inv: [0, 1, 2].map(|k| Vec4::splat(inv[k])),
        origin3: origin,
    };
    stack.clear();
    let mut entry = first / 2;
    loop {
        if entry & LEAF != 0 {
            let count = (entry >> FIRST_BITS & 7) + 1;
            let first = entry & ((1 << FIRST_BITS) - 1);
            if leaf_hit::<BOUNDED>(tracer, first, count, origin, d, max_t) {
                return true;
            }
        } else {
            let quad = &tracer.quads[entry as usize];
            let (hits, enter) = quad_hits::<BOUNDED>(quad, &ray, max_t);
            let mut hits = hits & quad.valid();
            if hits != 0 {
                // Nearest entry first; the others go on the stack in lane order.
                let enter = enter.to_array();
                let mut near = hits.trailing_zeros() as usize;
                hits &= hits - 1;
                while hits != 0 {
                    let lane = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    let far = if enter[lane] < enter[near] {
                        std::mem::replace(&mut near, lane)
                    } else {
                        lane
                    };
                    stack.push(quad.entry[far]);
                }
                entry = quad.entry[near];
                continue;
            }
        }
        match stack.pop() {
            Some(e) => entry = e,
            None => return false,
        }
    }
}

/// The lanes of `quad` whose box (and slab) the ray enters before `max_t`, and where it
/// enters each: the lane groups' `box_lanes` with boxes across the lanes.
#[inline(always)]
fn quad_hits<const BOUNDED: bool>(quad: &Quad, ray: &Ray4, max_t: f32) -> (u32, Vec4) {
    let low = [0, 1, 2].map(|k| quad.min[k] - ray.origin[k]);
    let high = [0, 1, 2].map(|k| quad.max[k] - ray.origin[k]);
    // A box around the origin: entered, whatever its slab says.
    let contains = low[0].cmple(Vec4::ZERO)
        & low[1].cmple(Vec4::ZERO)
        & low[2].cmple(Vec4::ZERO)
        & high[0].cmpge(Vec4::ZERO)
        & high[1].cmpge(Vec4::ZERO)
        & high[2].cmpge(Vec4::ZERO);
    let (x1, x2) = (low[0] * ray.inv[0], high[0] * ray.inv[0]);
    let (y1, y2) = (low[1] * ray.inv[1], high[1] * ray.inv[1]);
    let (z1, z2) = (low[2] * ray.inv[2], high[2] * ray.inv[2]);
    let enter = x1.min(x2).max(y1.min(y2)).max(z1.min(z2).max(Vec4::ZERO));
    let leave = x1.max(x2).min(y1.max(y2)).min(z1.max(z2));
    let leave = if BOUNDED {
        leave.min(Vec4::splat(max_t))
    } else {
        leave
    };
    let mut inside = enter.cmple(leave);
    // The slab: both ends beyond the same face (never for an unbounded one, half = ∞).
    let [nx, ny, nz] = quad.normal;
    let o = ray.origin3;
    let s0 = nx * o.x + ny * o.y + nz * o.z - quad.centre;
    let along = ray.d[0] * nx + ray.d[1] * ny + ray.d[2] * nz;
    let (a, b) = (s0 + enter * along, s0 + leave * along);
    let above = a.cmpgt(quad.half) & b.cmpgt(quad.half);
    let below = a.cmplt(-quad.half) & b.cmplt(-quad.half);
    inside &= !(above | below);
    ((inside | contains).bitmask(), enter)
}

/// Whether the ray meets one of the `count` triangles from `first`. (Four triangles across
/// the lanes of one test were no faster, gathered from the leaf or laid out four across at
/// build — 3 % slower at k = 1026: a leaf holds 4.4 on average, and the first hit ends the
/// scalar loop.)
#[inline(always)]
fn leaf_hit<const BOUNDED: bool>(
    tracer: &FanTracer,
    first: u32,
    count: u32,
    origin: Vec3A,
    d: Vec3A,
    max_t: f32,
) -> bool {
    let first = first as usize;
    tracer.triangles[first..first + count as usize]
        .iter()
        .any(|t| triangle_hit::<BOUNDED>(t, origin, d, max_t))
}

/// `_mm_min_ps` on one lane: `b` where either is NaN.
#[inline(always)]
fn sse_min(a: f32, b: f32) -> f32 {
    if a < b { a } else { b }
}

/// The lane groups' `triangle_lanes` for one ray.
#[inline(always)]
fn triangle_hit<const BOUNDED: bool>(t: &FanTriangle, origin: Vec3A, d: Vec3A, max_t: f32) -> bool {
    let [a, b, c] = t.0.map(|v| v - origin);
    let (mut n0, mut n1, mut n2) = (b.cross(c), c.cross(a), a.cross(b));
    let mut det = a.dot(n0);
    if det == 0.0 || !det.is_finite() {
        return false;
    }
    let sign = 1.0f32.copysign(det);
    (n0, n1, n2, det) = (n0 * sign, n1 * sign, n2 * sign, det * sign);
    let e = |n: Vec3A| d.x * n.x + d.y * n.y + d.z * n.z;
    let (e0, e1, e2) = (e(n0), e(n1), e(n2));
    let sum = e0 + e1 + e2;
    let tol = sum * -EDGE_TOLERANCE;
    let hit = sse_min(sse_min(e0, e1), e2) >= tol;
    if BOUNDED {
        hit && det < sum * max_t
    } else {
        hit
    }
}
