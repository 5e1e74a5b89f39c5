//! Fans: up to 64 rays from one common origin walking a binary BVH together — the traversal
//! of callers whose rays share their start (a hemicube's pixels seen from one vertex).
//!
//! Lanes are stored structure of arrays in groups of [`FAN_GROUP`] = 4, one SSE vector
//! (glam's `Vec4`) each, so a slab or triangle test covers four rays in one instruction
//! stream; only groups with a live lane are visited (found by bit tricks on the 64-bit mask,
//! not by a branch per group — that branch alone cost 12–26 %). Per node of the BVH (`obvhs`
//! PLOC with reinsertion, ≤ 8 triangles per leaf):
//!
//! * a box containing the origin is entered by every lane (the origin's own root-to-leaf
//!   path: 8–11 % of the work on the dress, skipped);
//! * a box that the interval bounds of the live lanes' reciprocal directions show no lane can
//!   enter is skipped outright (without this test the hemicube's traversal was 1.7× slower
//!   before slabs, 4 % now) — only for fans whose lanes bound two axes or more: a wide fan
//!   (the lightsphere's hemisphere of one vertex in three runs) bounds at most one, and the
//!   test then costs 8–9 % for nothing;
//! * otherwise each live group is slab-tested and the child's mask narrows; the child whose
//!   centre is nearer the origin is visited first (near occluders end lanes early: 1.1–1.5×
//!   faster than ordering along the fan's mean direction, which the nearest point of the box
//!   or the entry distance of the interval test also lose to);
//! * every subtree of at most 1,024 triangles also carries a [`slab::Slab`], the two planes along
//!   its area-weighted normal that hold its triangles: a lane whose ray enters and leaves the
//!   box on the same side of the slab is dropped. A surface patch is much thinner than its
//!   box, and the rays that graze the surface near their origin cross the boxes of the
//!   patches beside it: on the bunny at k = 258 leaf slabs alone took 5 % off, slabs up to
//!   128 / 512 / 1,024 / 4,096 triangles 12 / 16 / 17 / 17 %. They are thin nearly everywhere:
//!   only 949 of the bunny's 32,363 are as much as half their box's extent along their normal,
//!   and leaving out the slabs of nodes where that ratio exceeds 0.3 / 0.5 / 0.7 / 0.9 (3,295 /
//!   949 / 265 / 39 nodes) left the time unchanged (189–196 ms against 189–192, k = 258);
//! * where a subtree is entered by [`single::ALONE`] = 4 live lanes or fewer, each walks it
//!   alone (the `single` module): lanes diverge with depth, and on the bunny at k = 258
//!   44 % of the internal nodes visited held one live lane (55 % two or fewer, 70 % eight or
//!   fewer), each paying for a whole lane group. A lone ray tests four boxes per step — its
//!   node's grandchildren, one per SSE lane — and gets the same answer as the lane groups
//!   (a unit test compares them bit for bit). On the bunny at k = 258 (k = 1,026): one lane
//!   through the binary tree 3 % faster, four boxes per step a further 10 % (10 %),
//!   thresholds 2 / 4 / 6 / 8 / 12 lanes a further 2 / 4.5 / 3 / 2 / −1 %.
//!
//! Each node's box, slab and children sit in one 64-byte [`FanNode`], siblings in one
//! 128-byte aligned [`NodePair`] (obvhs's `Bvh2Node` is 48 bytes and the slabs were an array
//! beside it: a visit touched four or five cache lines, now two): 2.6 % faster on the bunny —
//! its 31,887 nodes fit the L2 cache either way, so the traversal is bound by arithmetic
//! and branches, not memory.
//!
//! Where the CPU has AVX2 (checked at run time) the groups are eight lanes wide (the `avx2`
//! module): the same formulas in the same operand order, no fused multiply-add, so every
//! lane's answer is bit for bit the four-lane one (a unit test compares them); 5–8 % faster
//! on the bunny at k = 258 (the per-group loops are under half of the time).
//!
//! The triangle test uses the common origin o: with a = v₀ − o, b = v₁ − o, c = v₂ − o, the
//! edge normals n₀ = b × c, n₁ = c × a, n₂ = a × b are computed once per triangle and a
//! direction d meets the triangle where dᵀnᵢ all share the sign of det = aᵀn₀ —
//! dᵀnᵢ / dᵀ(n₀+n₁+n₂) are the barycentric coordinates of the hit and t = det / dᵀ(n₀+n₁+n₂)
//! its distance. Three dot products per ray and triangle, against Möller–Trumbore's two cross
//! products, four dot products and a division.
//!
//! The answer is that of [`crate::RayCaster::occluded`] (any hit, both faces, the same
//! barycentric [`EDGE_TOLERANCE`]): a direction through an edge shared by two triangles is
//! tested against the exact negatives of one edge normal, so none leaks between them. Only
//! rays within rounding of an edge may differ between the two formulas (tests: against f64
//! brute force and single rays on every lane of the sphere over the plane).
//!
//! Tried and dropped (dress, hemicube pixels): 128-lane fans (u128 masks; 1.15–1.7× slower),
//! per-16-lane interval bounds (slower), a cone-against-bounding-sphere cull per node and a
//! gnomonic footprint grid per fan (both cull < 3 % of the groups they cost), a per-lane
//! cache of the last blocking triangle across neighbouring vertices (slower, even in Morton
//! order), skipping triangles whose plane faces away from the fan's cone (slower).
//! Tried and dropped (lightsphere, bunny at k = 258, A/B medians): one traversal for all of
//! a vertex's fans, a node popped once for them all (2 % slower: 37 % of the fans' node
//! visits repeat one of the same vertex's, but the work is in the lane groups, not the
//! visits); sixteen-lane AVX-512 groups (3 % slower: emptier groups); a cone-against-box
//! cull of the whole fan (would skip 8 % of the groups it costs); lone walks eight boxes per
//! step (AVX2, three levels: −2 % at k = 258, +1–3 % at k = 1026); the lane groups stepping
//! through the [`Quad`]s as the lone walks do, four grandchildren per pop (half the pops,
//! same M: 3–5 % slower at bunny k = 258 and 1026 and igea k = 258 — a child's cull narrows
//! the lanes its two children are tested with, worth more than the pops it costs); a call's
//! lone walks (two to four lanes in 67 % of the 926 k calls at bunny k = 258) advanced a
//! step each in turn, to overlap one's quad loads with another's arithmetic (5 % slower,
//! A/B median of 5); each child's box tested when it is popped rather than when pushed, so
//! that lanes its nearer sibling's subtree occluded meanwhile are not tested (same M, 4.5 %
//! slower, A/B median of 5 — every child now goes on the stack with its parent's lanes,
//! where the push-time test left no lane in many); per axis, the lanes heading away from a
//! box that lies wholly on one side of the origin dropped by a mask before the slab test
//! (exact, same M; 1.01× the time, A/B median of 7); the tangent plane as a cull — every
//! lane of a vertex's fans has n·d > 0, so a box or triangle lying below the plane through the
//! origin across n (by 10⁻⁴ of its distance from the origin, for rounding) cannot be hit. On
//! the bunny at k = 258 that holds for 9 % of the lane groups' box calls, 57 % of their
//! triangle calls (58 % of the triangle-group tests: the leaves around the origin), 10 % of the
//! lone walks' boxes and 13 % of their triangles; exact (M's hash unchanged), and no faster:
//! one thread, six alternated rounds, the mean of each round's best was 1.05× the time with the
//! lane groups' boxes and triangles culled and 1.01× with the lone walks' too, within a day's
//! noise (the same binary's rounds spread from 0.52 to 0.80 s) — the triangle tests it spares
//! are about a tenth of the work, and the box cull's test runs on every call. Not tried, for
//! its ceiling: on the bunny
//! at k = 258 the eight-lane box tests find 6.1 live lanes per live group (3.1 M calls,
//! 5.4 groups each) and the triangle tests 7.1, so repacking sparse groups could take at
//! most a quarter off the box tests' 26 % of the time.

use glam::{BVec3A, BVec4A, Mat3, Vec3, Vec3A, Vec4};
use obvhs::BvhBuildParams;
use obvhs::bvh2::node::Bvh2Node;

use crate::cpu::EDGE_TOLERANCE;
use crate::refit::LeafOrder;
use crate::refit::padded_bvh2;
use crate::scene::{Prepared, scaled_max_t};

#[cfg(target_arch = "x86_64")]
mod avx2;
mod directions;
mod single;
mod slab;

pub use directions::fan_groups;
pub(crate) use directions::{Packed, PreparedDirections};
use single::{ALONE, Quad, lanes_alone, quads};
use slab::subtree_slabs;

/// Rays per fan: one bit each of a `u64` mask.
pub const FAN_SIZE: usize = 64;

/// Lanes tested together as one SSE vector (glam's `Vec4`).
pub const FAN_GROUP: usize = 4;

/// Groups of four lanes (one SSE `Vec4` each) per fan.
const GROUPS: usize = FAN_SIZE / FAN_GROUP;

/// Axes a fan's lanes must bound (all lanes of one sign) for the whole-fan interval test to
/// run: with fewer it culls next to nothing and costs 8–9 % (the bunny's per-vertex fans at
/// k = 258); a hemicube's narrow fans bound all three, and lose 4 % without it at HC 32².
const INTERVAL_AXES: usize = 2;

/// Largest triangle count per leaf of the fan BVH.
const FAN_LEAF_SIZE: u32 = 8;

/// Up to [`FAN_SIZE`] ray directions (need not be unit) sharing one origin, stored as
/// structure of arrays. Lanes past [`RayFan::len`] are unused.
#[derive(Clone, Debug)]
pub struct RayFan {
    x: [Vec4; GROUPS],
    y: [Vec4; GROUPS],
    z: [Vec4; GROUPS],
    /// The reciprocal of each component ([`reciprocal`]), kept with the direction: the slab
    /// test's, computed once per push instead of once per traversal.
    ix: [Vec4; GROUPS],
    iy: [Vec4; GROUPS],
    iz: [Vec4; GROUPS],
    len: usize,
    used: u64,
}

impl Default for RayFan {
    fn default() -> Self {
        Self {
            x: [Vec4::ZERO; GROUPS],
            y: [Vec4::ZERO; GROUPS],
            z: [Vec4::ZERO; GROUPS],
            ix: [Vec4::ZERO; GROUPS],
            iy: [Vec4::ZERO; GROUPS],
            iz: [Vec4::ZERO; GROUPS],
            len: 0,
            used: 0,
        }
    }
}

/// One coordinate of every lane, as a flat array.
#[inline(always)]
fn lanes_of(groups: &mut [Vec4; GROUPS]) -> &mut [f32; FAN_SIZE] {
    bytemuck::cast_mut(groups)
}

/// The slab test's reciprocal of each component, a zero becoming a huge finite value of its
/// sign (so a slab product is never 0 · ∞).
#[inline(always)]
fn reciprocal(v: Vec4) -> Vec4 {
    Vec4::select(
        v.abs().cmplt(Vec4::splat(1e-30)),
        Vec4::splat(1e30).copysign(v),
        v.recip(),
    )
}

impl RayFan {
    /// An empty fan.
    pub fn new() -> Self {
        Self::default()
    }

    /// Removes every direction.
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Appends a direction; returns its lane. A zero or non-finite direction takes its lane
    /// but is left out of [`RayFan::full_mask`] and never traced (it points nowhere).
    ///
    /// # Panics
    /// When the fan already holds [`FAN_SIZE`] directions.
    pub fn push(&mut self, direction: Vec3) -> usize {
        assert!(self.len < FAN_SIZE, "a fan holds at most {FAN_SIZE} rays");
        let lane = self.len;
        let inv = reciprocal(direction.extend(0.0));
        lanes_of(&mut self.x)[lane] = direction.x;
        lanes_of(&mut self.y)[lane] = direction.y;
        lanes_of(&mut self.z)[lane] = direction.z;
        lanes_of(&mut self.ix)[lane] = inv.x;
        lanes_of(&mut self.iy)[lane] = inv.y;
        lanes_of(&mut self.iz)[lane] = inv.z;
        self.len += 1;
        if direction.is_finite() && direction != Vec3::ZERO {
            self.used |= 1 << lane;
        }
        lane
    }

    /// Sets this fan to the packed directions `range` (at most [`FAN_SIZE`], finite and
    /// non-zero, as a lightsphere's are): lane i holds `packed`'s direction `range.start + i`.
    pub(crate) fn fill(&mut self, packed: &Packed, range: std::ops::Range<usize>) {
        let count = range.len();
        assert!(count <= FAN_SIZE, "a fan holds at most {FAN_SIZE} rays");
        let [x, y, z, ix, iy, iz] = &packed.lanes;
        for (lanes, source) in [
            (&mut self.x, x),
            (&mut self.y, y),
            (&mut self.z, z),
            (&mut self.ix, ix),
            (&mut self.iy, iy),
            (&mut self.iz, iz),
        ] {
            lanes_of(lanes)[..count].copy_from_slice(&source[range.clone()]);
        }
        self.len = count;
        self.used = if count == FAN_SIZE {
            u64::MAX
        } else {
            (1 << count) - 1
        };
    }

    /// Leaves the rest of the current group of [`FAN_GROUP`] lanes unused, so the next push
    /// starts a new group. Groups are tested as one SIMD vector and skipped as one: filling
    /// each with close directions makes the traversal faster (the answer does not depend on
    /// it).
    pub fn finish_group(&mut self) {
        self.len = self.len.next_multiple_of(FAN_GROUP);
    }

    /// Number of lanes pushed or skipped so far (the next push's lane).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the fan holds no direction.
    pub fn is_empty(&self) -> bool {
        self.used == 0
    }

    /// The mask of every lane holding a direction.
    pub fn full_mask(&self) -> u64 {
        self.used
    }

    /// Sets `out` to this fan with every direction multiplied by `rotation` (the same lanes,
    /// four at a time): a template fan in a local frame, placed at each origin.
    pub fn rotate_into(&self, rotation: Mat3, out: &mut RayFan) {
        let [c0, c1, c2] = [rotation.x_axis, rotation.y_axis, rotation.z_axis];
        for g in 0..GROUPS {
            let (x, y, z) = (self.x[g], self.y[g], self.z[g]);
            out.x[g] = x * c0.x + y * c1.x + z * c2.x;
            out.y[g] = x * c0.y + y * c1.y + z * c2.y;
            out.z[g] = x * c0.z + y * c1.z + z * c2.z;
            out.ix[g] = reciprocal(out.x[g]);
            out.iy[g] = reciprocal(out.y[g]);
            out.iz[g] = reciprocal(out.z[g]);
        }
        out.len = self.len;
        out.used = self.used;
    }

    /// The lanes in use whose direction d has d·`normal` > 0 (the n·l culling of shadow rays).
    pub fn facing(&self, normal: Vec3) -> u64 {
        let mut mask = 0u64;
        for g in 0..GROUPS {
            let dot = self.x[g] * normal.x + self.y[g] * normal.y + self.z[g] * normal.z;
            mask |= u64::from(dot.cmpgt(Vec4::ZERO).bitmask()) << (4 * g);
        }
        mask & self.used
    }

    /// A fan of the directions `lanes` indexes (one entry of [`fan_groups`]'s result).
    pub fn from_group(directions: &[Vec3], lanes: &[u32]) -> Self {
        let mut fan = Self::new();
        for quad in lanes.chunks(FAN_GROUP) {
            for &i in quad.iter().filter(|&&i| i != u32::MAX) {
                fan.push(directions[i as usize]);
            }
            fan.finish_group();
        }
        fan
    }

    /// The direction and reciprocal of `lane`.
    #[inline(always)]
    fn lane_ray(&self, lane: usize) -> [Vec3A; 2] {
        let flat =
            |v: &[Vec4; GROUPS]| bytemuck::cast_ref::<[Vec4; GROUPS], [f32; FAN_SIZE]>(v)[lane];
        [
            Vec3A::new(flat(&self.x), flat(&self.y), flat(&self.z)),
            Vec3A::new(flat(&self.ix), flat(&self.iy), flat(&self.iz)),
        ]
    }

    /// The direction of `lane`.
    pub fn direction(&self, lane: usize) -> Vec3 {
        let flat =
            |v: &[Vec4; GROUPS]| bytemuck::cast_ref::<[Vec4; GROUPS], [f32; FAN_SIZE]>(v)[lane];
        Vec3::new(flat(&self.x), flat(&self.y), flat(&self.z))
    }
}

/// The interval each axis of a fan's reciprocal directions spans over the live lanes
/// (`bounded` false where the lanes' signs differ: that axis does not bound the fan).
struct FanSetup {
    bound_lo: Vec3A,
    bound_hi: Vec3A,
    bounded: BVec3A,
    /// Whether the whole-fan interval test runs: only where the lanes bound `INTERVAL_AXES`
    /// axes or more.
    interval: bool,
}

impl FanSetup {
    fn new(fan: &RayFan, mask: u64) -> Self {
        let (mut low, mut high) = ([Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]);
        let mut live = live_groups(mask);
        while live != 0 {
            let g = live.trailing_zeros() as usize / 4;
            live &= live - 1;
            let nibble = mask >> (4 * g);
            let on = BVec4A::new(
                nibble & 1 != 0,
                nibble & 2 != 0,
                nibble & 4 != 0,
                nibble & 8 != 0,
            );
            for (k, inv) in [fan.ix[g], fan.iy[g], fan.iz[g]].into_iter().enumerate() {
                low[k] = low[k].min(Vec4::select(on, inv, Vec4::INFINITY));
                high[k] = high[k].max(Vec4::select(on, inv, Vec4::NEG_INFINITY));
            }
        }
        let mut r = Self {
            bound_lo: Vec3A::ZERO,
            bound_hi: Vec3A::ZERO,
            bounded: BVec3A::FALSE,
            interval: false,
        };
        let mut bounded = [false; 3];
        for k in 0..3 {
            let (a, b) = (low[k].min_element(), high[k].max_element());
            // Lanes of one sign bound the axis; mixed signs do not.
            bounded[k] = a > 0.0 || b < 0.0;
            if bounded[k] {
                r.bound_lo[k] = a;
                r.bound_hi[k] = b;
            }
        }
        r.bounded = BVec3A::from_array(bounded);
        r.interval = bounded.iter().filter(|&&b| b).count() >= INTERVAL_AXES;
        r
    }
}

/// Whether this CPU runs AVX2 (the eight-lane fan and packet traversals).
pub(crate) fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::is_x86_feature_detected!("avx2")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Bit 8g set for every group g of eight lanes with a lane in `mask`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn live_wide(mask: u64) -> u64 {
    let m = mask | mask >> 1;
    let m = m | m >> 2;
    (m | m >> 4) & 0x0101_0101_0101_0101
}

/// Bit 4g set for every group g of four lanes with a lane in `mask`.
#[inline(always)]
fn live_groups(mask: u64) -> u64 {
    let m = mask | mask >> 1;
    (m | m >> 2) & 0x1111_1111_1111_1111
}

/// A triangle as its three vertices (the fan test is relative to each fan's origin).
#[derive(Clone, Copy, Debug)]
struct FanTriangle([Vec3A; 3]);

/// A node as the traversal reads it: its box, the [`slab::Slab`] of its subtree's triangles
/// (unbounded for large subtrees) and its children or triangles, in one cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct FanNode {
    min: Vec3A,
    max: Vec3A,
    normal: Vec3A,
    centre: f32,
    half: f32,
    /// The first child (internal nodes, an index into [`FanTracer::packed`]'s nodes) or
    /// the first triangle (leaves).
    first_index: u32,
    prim_count: u32,
}

/// Two siblings, tested together: one aligned 128-byte block (the pair of lines the
/// adjacent-line prefetcher fetches together).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(128))]
struct NodePair([FanNode; 2]);

/// The traversal's stacks: the fan's (node, lanes) and the lone walks' entries.
#[derive(Default)]
struct Stacks {
    fan: Vec<(u32, u64)>,
    single: Vec<u32>,
}

thread_local! {
    /// Each thread's [`Stacks`], allocated once rather than once per fan (the bunny at
    /// k = 258 traces 104,502 fans).
    static STACKS: std::cell::RefCell<Stacks> = std::cell::RefCell::default();
}

/// The scene's binary BVH for fans, triangles in leaf order.
pub(crate) struct FanTracer {
    /// The tree as built and refitted.
    nodes: Vec<Bvh2Node>,
    /// The same tree for the traversal, node `i` (shifted by `root`) at `packed[i / 2].0[i % 2]`.
    packed: Vec<NodePair>,
    /// Per pair of siblings in `packed`, the grandchildren of their parent, for the lone
    /// walks ([`lanes_alone`]).
    quads: Vec<Quad>,
    /// The root's index in `packed`: 1 where obvhs puts siblings at odd-even indices, so
    /// that every pair of siblings shares a [`NodePair`].
    root: u32,
    triangles: Vec<FanTriangle>,
    leaves: LeafOrder,
    /// Whether the CPU runs AVX2: lanes tested eight at a time instead of four (the same
    /// answer, bit for bit).
    wide: bool,
    /// Whether a subtree entered by [`ALONE`] live lanes or fewer is walked by each alone
    /// ([`lanes_alone`]): on wherever the [`Quad`]s could be built (always, with leaves of at
    /// most eight triangles), off in the test that shows it answers as the lane groups do.
    single: bool,
    /// The power of two the tree, its triangles and every ray's origin and `max_t` are
    /// multiplied by ([`Prepared::tracer_scale`]): the common-origin test's triple products
    /// are coordinates cubed, which left f32's range for a mesh 10¹⁵ across and fell into
    /// its subnormals for one 10⁻¹² across (the bunny so scaled lost up to 0.88 of a_i).
    scale: f32,
}

impl FanTracer {
    /// `quality`: obvhs's build settings (a static scene affords the slowest, best tree).
    pub(crate) fn new(prepared: &Prepared, quality: BvhBuildParams) -> Self {
        let scale = prepared.tracer_scale();
        let prepared = &*prepared.scaled(scale);
        let (nodes, tris, leaves) = padded_bvh2(prepared, quality, FAN_LEAF_SIZE);
        let triangles = tris
            .iter()
            .map(|t| FanTriangle([t.v0, t.v1, t.v2]))
            .collect();
        let mut tracer = Self {
            nodes,
            packed: Vec::new(),
            quads: Vec::new(),
            root: 0,
            triangles,
            leaves,
            wide: has_avx2(),
            single: true,
            scale,
        };
        tracer.pack(prepared.diagonal);
        tracer
    }

    /// Lays `nodes` and their slabs out for the traversal.
    fn pack(&mut self, diagonal: f32) {
        let slabs = subtree_slabs(&self.nodes, &self.leaves, &self.triangles, diagonal);
        let internal = || self.nodes.iter().filter(|n| n.prim_count == 0);
        let shift = u32::from(internal().all(|n| n.first_index % 2 == 1));
        let empty = FanNode {
            min: Vec3A::ZERO,
            max: Vec3A::ZERO,
            normal: Vec3A::ZERO,
            centre: 0.0,
            half: f32::INFINITY,
            first_index: 0,
            prim_count: 0,
        };
        let mut flat = vec![empty; (self.nodes.len() + shift as usize).next_multiple_of(2)];
        for ((node, slab), out) in self
            .nodes
            .iter()
            .zip(&slabs)
            .zip(&mut flat[shift as usize..])
        {
            *out = FanNode {
                min: node.aabb.min,
                max: node.aabb.max,
                normal: slab.normal,
                centre: slab.centre,
                half: slab.half,
                first_index: if node.prim_count > 0 {
                    node.first_index
                } else {
                    node.first_index + shift
                },
                prim_count: node.prim_count,
            };
        }
        let quads = quads(&flat);
        self.single = quads.is_some();
        self.quads = quads.unwrap_or_default();
        self.packed = flat
            .chunks_exact(2)
            .map(|p| NodePair([p[0], p[1]]))
            .collect();
        self.root = shift;
    }

    /// Node `index` of [`Self::packed`].
    #[inline(always)]
    fn node(&self, index: u32) -> &FanNode {
        &self.packed[(index / 2) as usize].0[(index % 2) as usize]
    }

    /// Refits to `prepared`'s positions (same topology); the new SAH cost over the build's.
    pub(crate) fn refit(&mut self, prepared: &Prepared) -> Option<f32> {
        let scale = prepared.tracer_scale();
        let prepared = &*prepared.scaled(scale);
        let cost = crate::refit::refit_tree(
            &mut self.nodes,
            &self.leaves,
            &mut self.triangles,
            prepared,
            FanTriangle,
        )?;
        self.pack(prepared.diagonal);
        self.scale = scale;
        Some(cost)
    }

    /// `origin` and `max_t` in the tree's coordinates ([`FanTracer::scale`]; a finite `max_t`
    /// stays finite).
    #[inline(always)]
    fn local(&self, origin: Vec3A, max_t: f32) -> (Vec3A, f32) {
        (origin * self.scale, scaled_max_t(max_t, self.scale))
    }

    /// The lanes of `mask` whose rays `origin + t·d`, 0 < t < `max_t`, meet no triangle.
    pub(crate) fn unoccluded(&self, origin: Vec3A, fan: &RayFan, mask: u64, max_t: f32) -> u64 {
        let (origin, max_t) = self.local(origin, max_t);
        STACKS.with_borrow_mut(|stacks| {
            #[cfg(target_arch = "x86_64")]
            if self.wide {
                // SAFETY: `wide` is set only where `is_x86_feature_detected!("avx2")` said so.
                #[allow(unsafe_code)]
                return unsafe {
                    if max_t == f32::INFINITY {
                        avx2::traverse::<false>(self, origin, fan, mask, max_t, stacks)
                    } else {
                        avx2::traverse::<true>(self, origin, fan, mask, max_t, stacks)
                    }
                };
            }
            // Two instances: rays to infinity skip the distance comparisons.
            if max_t == f32::INFINITY {
                self.traverse::<false>(origin, fan, mask, max_t, stacks)
            } else {
                self.traverse::<true>(origin, fan, mask, max_t, stacks)
            }
        })
    }

    #[inline(always)]
    fn traverse<const BOUNDED: bool>(
        &self,
        origin: Vec3A,
        fan: &RayFan,
        mask: u64,
        max_t: f32,
        stacks: &mut Stacks,
    ) -> u64 {
        let mask = mask & fan.full_mask();
        if self.nodes.is_empty() || mask == 0 {
            return mask;
        }
        let inv = FanSetup::new(fan, mask);
        let mut visible = mask;
        let Stacks { fan: stack, single } = stacks;
        stack.clear();
        let root = box_lanes::<BOUNDED>(self.node(self.root), origin, &inv, fan, mask, max_t);
        if root != 0 {
            stack.push((self.root, root));
        }
        while let Some((index, m)) = stack.pop() {
            let mut m = m & visible;
            if m == 0 {
                continue;
            }
            if self.single && m.count_ones() <= ALONE {
                visible &= !lanes_alone::<BOUNDED>(self, index, origin, fan, m, max_t, single);
                if visible == 0 {
                    return 0;
                }
                continue;
            }
            let node = self.node(index);
            if node.prim_count > 0 {
                let first = node.first_index as usize;
                for t in &self.triangles[first..first + node.prim_count as usize] {
                    let hit = triangle_lanes::<BOUNDED>(t, origin, fan, m, max_t);
                    visible &= !hit;
                    m &= !hit;
                    if m == 0 {
                        break;
                    }
                }
                if visible == 0 {
                    return 0;
                }
            } else {
                let first = node.first_index;
                let (a, b) = (self.node(first), self.node(first + 1));
                // (Twice) the distance² from the origin to each child's centre: the nearer
                // child is popped (and so tested) first.
                let distance = |n: &FanNode| (n.min + n.max - 2.0 * origin).length_squared();
                let order = if distance(a) <= distance(b) {
                    [(first + 1, b), (first, a)]
                } else {
                    [(first, a), (first + 1, b)]
                };
                // Pushed even when empty (the pop skips it): cheaper than a branch that the
                // predictor misses half the time.
                for (child, node) in order {
                    let lanes = box_lanes::<BOUNDED>(node, origin, &inv, fan, m, max_t);
                    stack.push((child, lanes));
                }
            }
        }
        visible
    }
}

/// The lanes of `mask` whose rays enter `node`'s box before `max_t`.
#[inline(always)]
fn box_lanes<const BOUNDED: bool>(
    node: &FanNode,
    origin: Vec3A,
    inv: &FanSetup,
    fan: &RayFan,
    mask: u64,
    max_t: f32,
) -> u64 {
    let low = node.min - origin;
    let high = node.max - origin;
    // A box around the origin holds every ray's start: all lanes enter it (the nodes on the
    // origin's root-to-leaf path, tested by every lane otherwise).
    if low.cmple(Vec3A::ZERO).all() && high.cmpge(Vec3A::ZERO).all() {
        return mask;
    }
    // Interval test for the whole fan: no lane's slab interval leaves this range.
    if inv.interval {
        let (pa, pc) = (low * inv.bound_lo, low * inv.bound_hi);
        let (qa, qc) = (high * inv.bound_lo, high * inv.bound_hi);
        let enter = Vec3A::select(inv.bounded, pa.min(pc).min(qa.min(qc)), Vec3A::NEG_INFINITY);
        let leave = Vec3A::select(inv.bounded, pa.max(pc).max(qa.max(qc)), Vec3A::INFINITY);
        let near = enter.max_element().max(0.0);
        let far = leave.min_element().min(max_t);
        if near > far {
            return 0;
        }
    }
    let (lx, ly, lz) = (Vec4::splat(low.x), Vec4::splat(low.y), Vec4::splat(low.z));
    let (hx, hy, hz) = (
        Vec4::splat(high.x),
        Vec4::splat(high.y),
        Vec4::splat(high.z),
    );
    let far = Vec4::splat(max_t);
    let sliced = node.half.is_finite();
    let s0 = Vec4::splat(node.normal.dot(origin) - node.centre);
    let mut out = 0u64;
    let mut live = live_groups(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / 4;
        live &= live - 1;
        let (x1, x2) = (lx * fan.ix[g], hx * fan.ix[g]);
        let (y1, y2) = (ly * fan.iy[g], hy * fan.iy[g]);
        let (z1, z2) = (lz * fan.iz[g], hz * fan.iz[g]);
        let enter = x1.min(x2).max(y1.min(y2)).max(z1.min(z2).max(Vec4::ZERO));
        let leave = x1.max(x2).min(y1.max(y2)).min(z1.max(z2));
        let leave = if BOUNDED { leave.min(far) } else { leave };
        let mut inside = enter.cmple(leave);
        if sliced {
            // The signed distance to the slab's mid-plane where the ray enters and leaves
            // the box: a lane is out when both ends lie beyond the same face.
            let n = node.normal;
            let along = fan.x[g] * n.x + fan.y[g] * n.y + fan.z[g] * n.z;
            let (a, b) = (s0 + enter * along, s0 + leave * along);
            let half = Vec4::splat(node.half);
            let above = a.cmpgt(half) & b.cmpgt(half);
            let below = a.cmplt(-half) & b.cmplt(-half);
            inside &= !(above | below);
        }
        out |= u64::from(inside.bitmask()) << (4 * g);
    }
    out & mask
}

/// The lanes of `mask` whose rays meet triangle `t` at 0 < t < `max_t`.
#[inline(always)]
fn triangle_lanes<const BOUNDED: bool>(
    t: &FanTriangle,
    origin: Vec3A,
    fan: &RayFan,
    mask: u64,
    max_t: f32,
) -> u64 {
    let [a, b, c] = t.0.map(|v| v - origin);
    let (mut n0, mut n1, mut n2) = (b.cross(c), c.cross(a), a.cross(b));
    let mut det = a.dot(n0);
    if det == 0.0 || !det.is_finite() {
        // The origin lies in the triangle's plane (or the triangle is degenerate): no ray
        // from it crosses the triangle.
        return 0;
    }
    // Orient so that det > 0 (multiplying by its sign: the branch would be a coin toss).
    let sign = 1.0f32.copysign(det);
    (n0, n1, n2, det) = (n0 * sign, n1 * sign, n2 * sign, det * sign);
    let mut out = 0u64;
    let mut live = live_groups(mask);
    while live != 0 {
        let g = live.trailing_zeros() as usize / 4;
        live &= live - 1;
        let (x, y, z) = (fan.x[g], fan.y[g], fan.z[g]);
        let e0 = x * n0.x + y * n0.y + z * n0.z;
        let e1 = x * n1.x + y * n1.y + z * n1.z;
        let e2 = x * n2.x + y * n2.y + z * n2.z;
        let sum = e0 + e1 + e2;
        let tol = sum * -EDGE_TOLERANCE;
        // eᵢ ≥ −ε·Σe for all i implies Σe > 0 (for d ≠ 0, which `push` guarantees): the hit
        // is in front of the origin, no separate test needed.
        let hit = e0.min(e1).min(e2).cmpge(tol);
        let hit = if BOUNDED {
            hit & Vec4::splat(det).cmplt(sum * max_t)
        } else {
            hit
        };
        out |= u64::from(hit.bitmask()) << (4 * g);
    }
    out & mask
}

#[cfg(all(test, target_arch = "x86_64"))]
pub(crate) mod tests;
