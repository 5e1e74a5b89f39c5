//! The `cpu` backend: exact visibility by ray casting (the accuracy reference of the issue,
//! and the fallback when no adapter exists).
//!
//! One shadow ray per (vertex, direction) with n·l > 0 (n·l culling: directions below the
//! tangent plane are 0 in M anyway), from the vertex pushed [`CpuParams::offset_relative`] ×
//! the scene's bounding-box diagonal along its normal, to infinity, with a Möller–Trumbore
//! triangle test in f32 on coordinates centred on the scene (so a 1e5 offset costs no
//! precision) and scaled by the power of two that brings its diagonal into (8, 16] (so a
//! scene 10⁻²⁰ or 10¹⁵ across keeps f32's range, with the answers of scale 1 bit for bit).
//! Receiver rows are visited in Morton (Z) order of their positions, in chunks of 64 spatial
//! neighbours per rayon task. Three traversals, all exact ([`CpuMethod`]):
//!
//! * [`CpuMethod::Packets`]: the rays of one chunk towards one direction l_j are parallel and
//!   start close together, so they walk a binary BVH together: a node is skipped outright when
//!   no ray of the family o + t·l_j (o in the chunk's origin box) can meet it, otherwise each
//!   live ray of a 64-bit mask is slab-tested (eight per instruction where the CPU has AVX2,
//!   the `packets` module); a ray leaves the mask at its first hit. This is
//!   the CPU counterpart of the seed's per-direction pass (paper 000 §3.2), without its
//!   resolution limit.
//! * [`CpuMethod::Fans`]: the rays of one vertex share its origin, so its directions walk
//!   the BVH together in fans of up to 64, with a common-origin triangle test (the `fan`
//!   module). The directions are ordered once along the recursive median split of
//!   [`fan_groups`] (neighbours in that order are neighbours on the sphere); each vertex
//!   keeps those above its tangent plane and cuts them into runs of 64, one fan each, the
//!   last holding the rest — on the bunny at k = 258 (125 directions per vertex on average)
//!   4 % faster than ⌈n / 64⌉ equal runs of 43 (igea 3–6 %, bunny k = 1026 1.4 %), which
//!   were 7 % faster than fixed fans masked by the tangent plane (29 live lanes of 64).
//! * [`CpuMethod::SingleRays`]: one any-hit traversal per ray of `obvhs`'s compressed 8-wide
//!   BVH (CWBVH), with a per-direction shadow cache (the last blocking triangle of the chunk
//!   is tested first). Kept as the independent cross-check: a test asserts all three give the
//!   same M.
//!
//! [`CpuMethod::Auto`] (the default) takes fans when a call computes at least
//! [`FAN_MIN_COLUMNS`] columns and packets below. Measured on the full bunny (35,947
//! vertices, BVH build included — each method's own `obvhs` preset, [`packets::packet_build`] and
//! [`fan_build`] — on 2 threads, one session, best of 9 runs; of 5 at k = 258, of 5 / 3 at
//! k = 1026): packets 34.5 / 63.3 / 163 / 604 / 2,305 ms at k = 6 / 18 / 66 / 258 / 1026,
//! fans 43.6 / 52.8 / 91.6 / 226 / 681 ms. (An earlier session, its day: packets 43.3 / 67.9
//! / 173 / 571 / 2,062, fans 49.4 / 56.0 / 92.4 / 221 / 614; at the start: fans 427
//! / 1,171 ms at k = 258 / 1026.) With few directions a vertex's fan is nearly empty and the
//! per-fan set-up dominates; with many, the shared origin pays. Since the packets test eight
//! rays per instruction (2026-12-06, a slower day; the same measure, medians of 9 in each of
//! three alternated rounds): packets 48.2–56.5 / 72.4–87.5 / 222–226 ms at k = 6 / 18 / 66
//! against 57.5–60.3 / 97.9–120 / 304–329 for the scalar packets of the round before and
//! 71.5–77.4 / 94.8–102 / 146–163 for the fans: the packets now win at k = 18 as well, and
//! [`FAN_MIN_COLUMNS`] moved from 12 to 32. Same M: at k = 258 no entry
//! of the 9.3 M differs between packets and fans, at k = 1026 4 of 36.9 M (edge-grazing
//! rays); neither changes with the build preset (M's hash checked).
//!
//! A per-direction uniform grid of the projected triangles (the rays of one direction are
//! parallel: project every vertex onto the plane across l_j, bin each triangle's 2D box into
//! cells, test each origin against its cell's list in 2D) was tried twice and dropped. First
//! against single rays (1.7× slower). Then against fans, with a correct prototype (1 bit of M
//! in 9.3 M apart from the fans', an edge-grazing ray): bunny k = 258 on 2 threads, best of
//! 3, 0.84–1.12 s (the best at 0.25 cells per triangle) against the fans' 0.20 s, over cell
//! sizes of 0.1–2 cells per triangle. At 1 cell per triangle, 8.5 list entries per triangle
//! and direction and 18 triangle tests per ray: the fill alone took 1.0–1.1 s of CPU time,
//! 2.7× the fans' whole call on one thread (0.38 s), and it grows with triangles × k
//! whatever the rays. Bigger cells trade entries for tests (0.1 cells per triangle: 2.6
//! entries, 48 tests per ray, 1.08 s).
//!
//! Proofs that rays' far parts are free, in bulk, were tried as well. Rays cut at 0.02 /
//! 0.05 / 0.1 / 0.2 × the diagonal trace in 0.54–0.59 / 0.67–0.72 / 0.79–0.87 / 0.97–1.04×
//! the time of whole rays (bunny k = 258, BVH reused, two rounds): the ceiling of any such
//! scheme, reached only if the proofs cost nothing. Two exact ones (M's hash unchanged) cost
//! more than they saved:
//!
//! * a fat beam per chunk of 64 origins — the ray from the chunk's centre, every box grown by
//!   the chunk's radius r — free of every leaf box beyond a start of r / 2r / 4r for 0 / 18
//!   / 62 % of the chunk's directions: 108 k beams and 35 ms of CPU time per call, and the
//!   free ones only past 5r, too far out to save anything (trace 244 ms against 212);
//! * an orthographic max-depth map per direction (64² or 128² cells, each triangle's 2D box
//!   at its highest depth): 54–83 % of the rays proved free beyond 0.01–0.05 × the diagonal,
//!   but the maps took 270–285 ms per call to fill (triangles × k again), and the rest of
//!   the call (a projection and a map look-up per ray, each vertex's fans split into proved
//!   and unproved directions) about 268 ms against the whole call's 205.
//!
//! Nor does splitting each ray at a radius R pay (measured with M's hash unchanged: every fan
//! traced to R, its survivors from R on, boxes and triangles before R skipped). Bunny at
//! k = 258, CPU time of one call summed over both threads, two rounds: whole rays 327–331 ms;
//! at R = 0.004 / 0.01 / 0.02 / 0.04 × the diagonal the part before R took 122–128 / 151–163 /
//! 179–203 / 209–228 ms and the part after it 290–306 / 260–281 / 224–258 / 181–193 ms. A
//! free near part would still leave 0.55–0.58 of the call at R = 0.04 × the diagonal, where
//! the ball around an origin holds about 380 triangles (π R² of the bunny's 0.057 m² of
//! surface, 69,451 triangles) — listing and testing those per vertex costs more than the
//! BVH's near part — and more than 0.68 at any smaller R: no split reaches the 1.46× faster
//! trace that half of Mitsuba's time needs. The scene's convex hull (3,124 faces) proves
//! 5.6 % of the facing rays free before any traversal (numpy prototype, 3,000 of the bunny's
//! vertices, 258 directions); the rest leave the hull within 0.004 / 0.01 / 0.02 × the
//! diagonal in 15 / 25 / 34 % of cases, but rays cut at 0.004 × the diagonal already cost,
//! on average, 0.37–0.39 of whole ones (above): worth at most about 6 % before the hull's
//! own test.
//!
//! Where the time goes by ray, measured with oracles taken from M itself (bunny at k = 258,
//! BVH reused, medians of 7, each against a baseline of 194–200 ms in the same run): the rays
//! of each vertex's largest cone around its normal that holds only visible directions (53 %
//! of the 4.49 M facing rays, an upper bound on what an exact free-cone proof could skip)
//! take 5.5 % of the time — open sky near the normal is the cheap part; the rays with
//! n·l < 0.1 / 0.2 / 0.3 / 0.5 (10 / 20 / 30 / 50 % of them) 12 / 24 / 36 / 55 %; the
//! occluded rays (716 k, 16 %) 38 %. A free guess of each occluded ray's blocker would thus
//! leave 0.62× the trace, the one ceiling found beyond the 1.46× needed; but the previous
//! Morton neighbour's blocker in the same direction (the single rays' shadow cache) blocks
//! only 43 k of the 716 k (6 %: 623 k are blocked by another triangle, 50 k find no
//! neighbour's), too few to pay for the test on every lane. Its blocker's *subtree* catches
//! more and still does not pay (exact, M's hash unchanged; bunny at k = 258, medians of 9,
//! against 190–193 ms in the same session): each lane whose ray the previous Morton
//! neighbour's ray in the same direction found blocked (686 k) first walked alone from the
//! blocking triangle's leaf, or its ancestor 1 / 2 / 3 / 4 / 6 / 8 levels up, then the fan
//! traced the rest. The walks caught 150 / 219 / 287 / 352 / 411 / 509 / 570 k of them (22
//! to 83 %) and the call took 217 / 207 / 206 / 209 / 207 / 220 / 238 ms. A lane taken out
//! of a fan saves work only where that empties its group of eight or spares a lone walk (the
//! oracle above removed every occluded lane at once), and the caught ones are, presumably,
//! those the near-first order reaches early; the 686 k extra walks cost more. The lanes that
//! share a subtree traced from it together as one fan instead took 208–229 ms (545 k such
//! traversals for the 686 k lanes at two levels up: a fan's neighbouring directions have
//! different blockers).
//!
//! Nor are the blockers near enough to find without the tree. The first hits of the
//! bunny's occluded rays at k = 258 (Open3D's `cast_rays` on the bench's own rays, 20,000
//! of the 716 k sampled): 10 / 18 / 30 / 54 % lie within 0.005 / 0.01 / 0.02 / 0.05 × the
//! diagonal, and the hit triangle belongs to the vertex's 1- / 2- / 3- / 4- / 6-ring (6 /
//! 24 / 55 / 100 / 230 triangles) for 9 / 17 / 24 / 29 / 39 % of them. Testing a vertex's
//! 2-ring against all its lanes before the traversal would thus end 17 % of the occluded
//! lanes — at most about 6 % of the trace by the oracle above, for 24 triangle tests per
//! fan — so it was not built.
//!
//! Nor does the build: fat link-time optimisation with one codegen unit (the release profile
//! leaves both at Cargo's defaults) traced the bunny at k = 66 / 258 in 0.99–1.01× the time
//! (`cargo xtask bench visibility --quick`, three alternated rounds): the traversal's hot
//! loops are `#[inline(always)]` within this crate already.
//!
//! BVH crate: `obvhs` 0.4 over `bvh` 0.13. `bvh` is a binary BVH on nalgebra whose
//! traversal collects candidate shapes per ray; `obvhs` builds BVHs by PLOC with reinsertion
//! (better trees) and exposes its binary nodes, which the packet traversal walks, as well as
//! an early-exit single-ray traversal of its 8-wide compressed form. Its `parallel` feature
//! builds on rayon: 7.5 % off the bunny's build + trace at k = 258 on 2 threads, and the same
//! tree whatever the thread count (the drape's 120-frame refit/rebuild sequence checked
//! identical on 1, 2, 3, 4 and 8 threads).

use std::ops::Range;
use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::Ray;
use rayon::prelude::*;

use crate::fan::{FanTracer, Packed, PreparedDirections, RayFan, fan_groups};
use crate::matrix::WORD_BITS;
use crate::progress::Ticker;
use crate::refit::scene_triangles;
use crate::scene::{Prepared, power_of_two, scaled_max_t};

mod packets;

use packets::{PacketTracer, packet_columns};

/// Ray origin offset along the normal, relative to the scene's bounding-box diagonal: the
/// issue's exact reference (without an offset rays hit the vertex's own triangles; the offset
/// itself moves results by ~1e-4).
pub const DEFAULT_OFFSET_RELATIVE: f32 = 1e-4;

/// Barycentric tolerance of the triangle test: a ray through a shared edge must hit one of
/// the two triangles even when f32 rounding puts it a hair outside both (rays along the
/// octahedron's axis-aligned directions over axis-aligned geometry do exactly that). Tuned on
/// the sphere-over-plane test against f64 brute force; it only ever adds occlusion within
/// 1e-6 of an edge.
pub(crate) const EDGE_TOLERANCE: f32 = 1e-6;

/// `obvhs`'s build settings for the fans' tree: `fast_build` (PLOC over a short search
/// distance, 2 % reinsertion). Against `medium_build`, same day, BVH build included (A/B
/// medians of 5 alternated runs, best of 3 each): bunny k = 18 / 66 / 258 / 1026 0.95 /
/// 0.97 / 0.97 / 0.98× the time, igea and dragon at k = 258 0.96 / 0.97× — the build's
/// saving (bunny 28 → 24 ms, igea 143 → 120, dragon 112 → 89) outweighs the slightly worse
/// tree. `very_fast_build` against `fast_build`: igea 0.94×, but the dragon 1.07× (its build
/// 89 → 80 ms, its trace slower) and the bunny at k = 1026 1.01–1.02×; `slow_build` (spatial
/// splits) was 1.06–1.15× `medium_build`'s time. Within `fast_build` (bunny k = 258, best of 5,
/// one session, M's hash unchanged throughout): the collapse's traversal cost at 1 / 2 / 3 /
/// 4 / 6 (the leaves' size) gave 222 / 205 / 207 / 203 / 206 ms, a post-collapse reinsertion
/// (× 1 / × 3) 200 / 209 ms and a reinsertion ratio of 0.05 / 0.1 215 / 214 ms, against
/// 207–219 ms for the preset itself: flat within the machine's noise, except fewer triangles
/// per leaf (cost 1), which is slower.
pub(crate) fn fan_build() -> BvhBuildParams {
    BvhBuildParams::fast_build()
}

/// How the `cpu` backend traverses its BVH. All are exact and give the same M (up to rays
/// within rounding of a triangle edge).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CpuMethod {
    /// Fans when a call computes at least [`FAN_MIN_COLUMNS`] columns, packets below (the
    /// default: the faster of the two on either side).
    #[default]
    Auto,
    /// Packets of up to 64 parallel rays through a binary BVH (faster for k ≤ 18).
    Packets,
    /// One traversal per ray of an 8-wide compressed BVH, with a shadow cache.
    SingleRays,
    /// Fans: each vertex's directions in fans of up to 64 from its origin (faster for
    /// k ≥ 66).
    Fans,
}

/// Columns from which [`CpuMethod::Auto`] takes fans: between the bunny's k = 18 (packets
/// 1.17× faster, BVH build included, the median of three rounds) and k = 66 (fans 1.39×
/// faster); the ratios, interpolated in log k, cross at about 27.
pub const FAN_MIN_COLUMNS: usize = 32;

impl CpuMethod {
    /// The traversal this method runs for a call computing `columns` columns.
    pub fn resolve(self, columns: usize) -> Self {
        match self {
            Self::Auto if columns >= FAN_MIN_COLUMNS => Self::Fans,
            Self::Auto => Self::Packets,
            other => other,
        }
    }
}

/// Tuning knobs of the `cpu` backend.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct CpuParams {
    /// Ray origin offset along the normal × bounding-box diagonal.
    pub offset_relative: f32,
    /// How candidate triangles are found.
    pub method: CpuMethod,
    /// Refit the BVH of the last scene when only its positions changed (a deforming mesh;
    /// the `rays` backend's too), rebuilding once its SAH cost exceeds
    /// [`crate::REBUILD_SAH_RATIO`] × the build's; false rebuilds every time the geometry
    /// changes.
    pub refit: bool,
    /// Keep a refitted tree only while its measured extra traversal time stays below the last
    /// build's time (the default: adapts to k and the mesh, but depends on the machine's
    /// timings); false keeps it up to [`crate::REBUILD_SAH_RATIO`] whatever the clock says —
    /// the same refit/rebuild sequence on every run, for tests and reproducible reports.
    pub refit_timed: bool,
    /// Occluders farther than this along a ray (world units, measured from the offset ray
    /// origin) are ignored: the "distance" of Blender's and QtMeshEditor's AO bakers, which
    /// keeps a room's far walls from darkening an object inside it. `f32::INFINITY` (the
    /// default) is paper 000's unbounded visibility. Must be > 0 (not NaN).
    pub max_distance: f32,
}

impl Default for CpuParams {
    fn default() -> Self {
        Self {
            offset_relative: DEFAULT_OFFSET_RELATIVE,
            method: CpuMethod::default(),
            refit: true,
            refit_timed: true,
            max_distance: f32::INFINITY,
        }
    }
}

impl CpuParams {
    /// The same parameters with another candidate search.
    pub fn with_method(mut self, method: CpuMethod) -> Self {
        self.method = method;
        self
    }

    /// The same parameters with refitting on or off.
    pub fn with_refit(mut self, refit: bool) -> Self {
        self.refit = refit;
        self
    }

    /// The same parameters with refits kept by measured time (`true`, the default) or by the
    /// SAH cap alone (`false`, deterministic); see [`CpuParams::refit_timed`].
    pub fn with_refit_timed(mut self, timed: bool) -> Self {
        self.refit_timed = timed;
        self
    }

    /// The same parameters with occluders beyond `distance` ignored ([`CpuParams::max_distance`]).
    pub fn with_max_distance(mut self, distance: f32) -> Self {
        self.max_distance = distance;
        self
    }

    /// Checks [`CpuParams::max_distance`].
    ///
    /// # Errors
    /// [`crate::OcclusionError::InvalidParameter`] when it is NaN or not > 0.
    pub(crate) fn validate(&self) -> Result<(), crate::OcclusionError> {
        if self.max_distance > 0.0 {
            Ok(())
        } else {
            Err(crate::OcclusionError::InvalidParameter {
                what: "max_distance",
                value: f64::from(self.max_distance),
                expected: "> 0 (f32::INFINITY: no limit)",
            })
        }
    }
}

/// "No cached triangle" in a shadow cache.
const NO_TRIANGLE: u32 = u32::MAX;

/// A triangle prepared for Möller–Trumbore: one vertex and the two edges from it.
#[derive(Clone, Copy, Debug)]
struct EdgeTriangle {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

impl EdgeTriangle {
    fn new([v0, v1, v2]: [Vec3; 3]) -> Self {
        let v0 = Vec3A::from(v0);
        Self {
            v0,
            e1: Vec3A::from(v1) - v0,
            e2: Vec3A::from(v2) - v0,
        }
    }

    /// Distance along the ray to the hit, or +∞. Edges and vertices count as hits, with
    /// [`EDGE_TOLERANCE`] (shadow rays must not leak between two triangles sharing an edge);
    /// back faces hit too (two-sided
    /// sheets occlude from both sides). No absolute epsilon, so any scale works.
    #[inline(always)]
    fn intersect(&self, origin: Vec3A, direction: Vec3A) -> f32 {
        let p = direction.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 || !det.is_finite() {
            return f32::INFINITY;
        }
        let inv_det = 1.0 / det;
        let s = origin - self.v0;
        let u = s.dot(p) * inv_det;
        if !(-EDGE_TOLERANCE..=1.0 + EDGE_TOLERANCE).contains(&u) {
            return f32::INFINITY;
        }
        let q = s.cross(self.e1);
        let v = direction.dot(q) * inv_det;
        if v < -EDGE_TOLERANCE || u + v > 1.0 + EDGE_TOLERANCE {
            return f32::INFINITY;
        }
        let t = self.e2.dot(q) * inv_det;
        if t > 0.0 { t } else { f32::INFINITY }
    }
}

/// The scene's BVH with triangles stored in BVH leaf order.
///
/// `obvhs`'s CWBVH node test clamps a box's entry to t ≥ 10⁻⁴ in the ray's own units (its
/// `EPSILON`), whatever the ray's `tmin`, so hits closer than 10⁻⁴ · |d| were lost:
/// * with unit directions, every occluder within 10⁻⁴ scene units — 3.8 × 10⁻⁴ of the bunny's
///   diagonal in metres, everything in a scene 10⁻³ across;
/// * with a point light's l − p (length 10⁵), every occluder within 10 units.
///
/// Its debug builds also check the quantised boxes against an absolute 10⁻⁵, which f32
/// rounding exceeds once coordinates reach the hundreds.
///
/// So the tracer works in its own coordinates:
/// * the scene is scaled by the power of two that brings its diagonal into (8, 16];
/// * each ray's direction is scaled by the power of two that brings its largest component into
///   (0.5, 1] — a unit direction is left as it is;
/// * `t` and `max_t` follow.
///
/// Scaling by a power of two commutes with f32 rounding (far from overflow and subnormals), so
/// every Möller–Trumbore decision is bit for bit the one in the caller's coordinates. So is
/// every box test of a unit direction: each slab's t scales with the scene's power of two, even
/// a zero component's, whose inverse `obvhs` clamps to ±1/ε (a direction scaled to [1, 2)
/// instead halved the margin such a ray needs inside a slab, and 6 more of the 73 k entries of
/// `matches_brute_force_on_sphere_over_plane` flipped, all on a grid edge).
///
/// What changes:
/// * the clamp now falls at 6–12 × 10⁻⁶ of the diagonal at any scale, about a tenth of the
///   rays' offset from the surface ([`DEFAULT_OFFSET_RELATIVE`]);
/// * the debug check holds at any scale.
///
/// The fans' and packets' traversals have no such clamp, but scale their scenes alike, for
/// f32's range ([`Prepared::tracer_scale`]).
pub(crate) struct CpuTracer {
    bvh: CwBvh,
    triangles: Vec<EdgeTriangle>,
    /// The power of two the scene's centred coordinates are multiplied by.
    scale: f32,
}

impl CpuTracer {
    /// Builds the BVH over all scene triangles (degenerate ones included: they never hit).
    pub(crate) fn new(prepared: &Prepared) -> Self {
        let scale = prepared.tracer_scale();
        let tris = scene_triangles(&prepared.scaled(scale));
        if tris.is_empty() {
            return Self {
                bvh: CwBvh::default(),
                triangles: Vec::new(),
                scale,
            };
        }
        let bvh = build_cwbvh_from_tris(
            &tris,
            BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        let triangles = bvh
            .primitive_indices
            .iter()
            .map(|&i| {
                let t = &tris[i as usize];
                EdgeTriangle {
                    v0: t.v0,
                    e1: t.v1 - t.v0,
                    e2: t.v2 - t.v0,
                }
            })
            .collect();
        Self {
            bvh,
            triangles,
            scale,
        }
    }

    /// A ray in the tracer's coordinates: the origin scaled as the scene, the direction by
    /// the power of two that brings its largest component into (0.5, 1], `max_t` to match (a
    /// product past f32's range stays finite for a finite `max_t`).
    #[inline(always)]
    fn scaled(&self, origin: Vec3A, direction: Vec3A, max_t: f32) -> (Vec3A, Vec3A, f32) {
        let largest = direction.abs().max_element();
        if !(largest > 0.0 && largest.is_finite()) {
            // A zero or non-finite direction meets nothing (Möller–Trumbore's det is 0 or NaN).
            return (origin * self.scale, direction, max_t);
        }
        let e = largest.log2().ceil() as i32;
        let t_scale = self.scale * power_of_two(e);
        let max_t = scaled_max_t(max_t, t_scale);
        (origin * self.scale, direction * power_of_two(-e), max_t)
    }

    /// Whether a ray from `origin` towards `direction` meets no triangle before `max_t`
    /// (`f32::INFINITY`: escapes to infinity). `cache` is the last blocking triangle seen for
    /// this direction (or [`NO_TRIANGLE`]): it is tested first, and updated to the triangle
    /// that blocks this ray.
    #[inline]
    pub(crate) fn unoccluded_cached(
        &self,
        origin: Vec3A,
        direction: Vec3A,
        max_t: f32,
        cache: &mut u32,
    ) -> bool {
        let (origin, direction, max_t) = self.scaled(origin, direction, max_t);
        if let Some(t) = self.triangles.get(*cache as usize)
            && t.intersect(origin, direction) < max_t
        {
            return false;
        }
        if self.triangles.is_empty() {
            return true;
        }
        let ray = Ray::new(origin, direction, 0.0, max_t);
        let mut blocker = NO_TRIANGLE;
        let miss = self.bvh.ray_traverse_miss(ray, |r, id| {
            let t = self.triangles[id].intersect(r.origin, r.direction);
            if t < r.tmax {
                blocker = id as u32;
            }
            t
        });
        if !miss {
            *cache = blocker;
        }
        miss
    }
}

/// Fills the bits of columns `columns` of every row (`target.bits` is row-major with
/// `target.words_per_row` words); the other columns are left as they are; each finished chunk
/// of rows is counted on `target.ticker`. Returns the rays cast.
pub(crate) fn compute_columns(
    prepared: &Prepared,
    tracer: &Tracer,
    directions: &[Vec3],
    columns: Range<usize>,
    params: &CpuParams,
    target: ColumnsTarget<'_>,
) -> u64 {
    if columns.is_empty() {
        return 0;
    }
    let span = RaySpan {
        offset: params.offset_relative * prepared.diagonal,
        max_t: params.max_distance,
    };
    let dirs: Vec<Vec3A> = directions.iter().map(|&d| d.into()).collect();
    let call = ColumnsCall {
        prepared,
        columns,
        span,
        target,
    };
    match &tracer.kind {
        TracerKind::Packets(t) => packet_columns(t, &dirs, call),
        TracerKind::Fans(t) => fan_columns(t, directions, call),
        TracerKind::SingleRays(t) => bvh_columns(t, &dirs, call),
    }
}

/// Where [`compute_columns`] writes: the row-major bits of M, and the progress counter.
pub(crate) struct ColumnsTarget<'a> {
    /// M's bits, `words_per_row` words per row.
    pub(crate) bits: &'a mut [u32],
    /// Words per row of `bits`.
    pub(crate) words_per_row: usize,
    /// Counts the cells of finished chunks of rows.
    pub(crate) ticker: &'a Ticker,
}

/// One [`compute_columns`] call as each traversal's chunks see it: the scene, the columns
/// to fill, where the rays start and end, and where the bits go.
struct ColumnsCall<'a> {
    prepared: &'a Prepared,
    columns: Range<usize>,
    span: RaySpan,
    target: ColumnsTarget<'a>,
}

/// Where every ray of a call starts and ends: origins pushed `offset` along the normal, hits
/// counted for 0 < t < `max_t`.
#[derive(Clone, Copy, Debug)]
struct RaySpan {
    offset: f32,
    max_t: f32,
}

/// A BVH over a scene's triangles, with the geometry it was built for so that it is reused
/// only while that geometry is unchanged (refinement, a static mesh across frames).
pub(crate) struct Tracer {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    method: CpuMethod,
    kind: TracerKind,
}

enum TracerKind {
    Packets(PacketTracer),
    SingleRays(CpuTracer),
    Fans(FanTracer),
}

impl Tracer {
    pub(crate) fn new(prepared: &Prepared, method: CpuMethod) -> Self {
        let kind = match method {
            // `Auto` is resolved by the engine per call ([`CpuMethod::resolve`]).
            CpuMethod::Packets | CpuMethod::Auto => {
                TracerKind::Packets(PacketTracer::new(prepared))
            }
            CpuMethod::SingleRays => TracerKind::SingleRays(CpuTracer::new(prepared)),
            CpuMethod::Fans => TracerKind::Fans(FanTracer::new(prepared, fan_build())),
        };
        Self {
            positions: prepared.positions.clone(),
            triangles: prepared.triangles.clone(),
            method,
            kind,
        }
    }

    /// Whether this BVH was built for exactly this geometry and method (an O(N) comparison
    /// against an O(N log N) build).
    pub(crate) fn fits(&self, prepared: &Prepared, method: CpuMethod) -> bool {
        self.method == method
            && self.positions == prepared.positions
            && self.triangles == prepared.triangles
    }

    /// Refits this BVH to `prepared` when only positions changed (same method, topology): the
    /// new SAH cost relative to the build's, or `None` when it cannot be refitted (another
    /// topology or method, or the single-ray 8-wide tree). The caller rebuilds when the ratio
    /// exceeds [`crate::REBUILD_SAH_RATIO`].
    pub(crate) fn refit(&mut self, prepared: &Prepared, method: CpuMethod) -> Option<f32> {
        if self.method != method
            || self.triangles != prepared.triangles
            || self.positions.len() != prepared.positions.len()
        {
            return None;
        }
        let ratio = match &mut self.kind {
            TracerKind::Packets(t) => t.refit(prepared)?,
            TracerKind::Fans(t) => t.refit(prepared)?,
            TracerKind::SingleRays(_) => return None,
        };
        self.positions.clone_from(&prepared.positions);
        Some(ratio)
    }
}

/// The origin of vertex i's shadow rays (none for a zero normal).
#[inline]
fn ray_origin(prepared: &Prepared, row: usize, offset: f32) -> Option<(Vec3A, Vec3A)> {
    let receiver = &prepared.receivers[row];
    let normal = Vec3A::from(receiver.normal);
    (normal != Vec3A::ZERO).then(|| (Vec3A::from(receiver.position) + normal * offset, normal))
}

/// Rows per work item of the BVH method: neighbours in Morton order share a shadow cache
/// (see [`bvh_columns`]). Tuned on the bunny: 16–128 all do within a few percent.
const ROWS_PER_CHUNK: usize = 64;

/// [`compute_columns`] with the BVH ([`CpuMethod::SingleRays`]).
///
/// Rows are visited in Morton (Z-order) of their positions, in chunks of [`ROWS_PER_CHUNK`]
/// per thread, and every chunk keeps a *shadow cache*: per direction, the last triangle that
/// blocked a ray. Neighbouring vertices are often blocked by the same triangle, so that one
/// triangle is tested before the BVH is traversed. The result is exactly that of a plain
/// traversal: a cached triangle that is hit is a hit the traversal would also report (the
/// any-hit query has no closest-hit order), and a miss falls through to the traversal.
fn bvh_columns(tracer: &CpuTracer, dirs: &[Vec3A], call: ColumnsCall<'_>) -> u64 {
    let (prepared, span, columns) = (call.prepared, call.span, call.columns.clone());
    let words_per_row = call.target.words_per_row;
    in_chunks(call, ROWS_PER_CHUNK, |rows, out| {
        let mut cache = vec![NO_TRIANGLE; dirs.len()];
        let mut rays = 0u64;
        for (&row, out_row) in rows.iter().zip(out.chunks_exact_mut(words_per_row)) {
            let Some((origin, normal)) = ray_origin(prepared, row as usize, span.offset) else {
                continue;
            };
            for j in columns.clone() {
                let direction = dirs[j];
                if normal.dot(direction) <= 0.0 {
                    continue;
                }
                rays += 1;
                if tracer.unoccluded_cached(origin, direction, span.max_t, &mut cache[j]) {
                    out_row[j / WORD_BITS] |= 1 << (j % WORD_BITS);
                }
            }
        }
        rays
    })
}

/// [`compute_columns`] with fans ([`CpuMethod::Fans`]): the columns' directions ordered
/// once along [`fan_groups`]' split; every vertex takes those above its tangent plane in that
/// order and traces them from its origin in runs of 64 (the last shorter), one fan each; rows in
/// Morton order, [`ROWS_PER_CHUNK`] per task.
fn fan_columns(tracer: &FanTracer, directions: &[Vec3], call: ColumnsCall<'_>) -> u64 {
    let (prepared, span, columns) = (call.prepared, call.span, call.columns.clone());
    let words_per_row = call.target.words_per_row;
    let dirs = &directions[columns.clone()];
    // The directions in the order of their recursive median split (`fan_groups`): neighbours
    // in this order are neighbours on the sphere.
    let curve: Vec<u32> = fan_groups(dirs)
        .into_iter()
        .flatten()
        .filter(|&i| i != u32::MAX)
        .collect();
    let curve_dirs: Vec<Vec3> = curve.iter().map(|&i| dirs[i as usize]).collect();
    let prepared_dirs = PreparedDirections::new(&curve_dirs);
    in_chunks(call, ROWS_PER_CHUNK, |rows, out| {
        let mut rays = 0u64;
        let mut facing = Vec::new();
        let mut packed = Packed::default();
        let mut fan = RayFan::new();
        for (&row, out_row) in rows.iter().zip(out.chunks_exact_mut(words_per_row)) {
            let Some((origin, normal)) = ray_origin(prepared, row as usize, span.offset) else {
                continue;
            };
            prepared_dirs.facing(normal.into(), &mut facing);
            let n = facing
                .iter()
                .map(|w| w.count_ones() as usize)
                .sum::<usize>();
            rays += n as u64;
            // The facing directions in curve order, cut into runs of 64 (the last holds the
            // rest): full lane groups in all but one fan.
            prepared_dirs.compact(&facing, &mut packed);
            for start in (0..n).step_by(crate::fan::FAN_SIZE) {
                let run = start..(start + crate::fan::FAN_SIZE).min(n);
                fan.fill(&packed, run);
                let mut open = tracer.unoccluded(origin, &fan, fan.full_mask(), span.max_t);
                while open != 0 {
                    let lane = open.trailing_zeros() as usize;
                    open &= open - 1;
                    let c = packed.index[start + lane] as usize;
                    let j = columns.start + curve[c] as usize;
                    out_row[j / WORD_BITS] |= 1 << (j % WORD_BITS);
                }
            }
        }
        rays
    })
}

/// The rows of `call.prepared` in Morton order, `chunk_rows` per rayon task:
/// `chunk(rows, out)` sets the bits of `call.columns` in `out` (`rows`' rows of M, zeroed,
/// `call.target.words_per_row` words each) and returns the rays it cast; each finished chunk
/// is counted on `call.target.ticker` and copied into `call.target.bits`. Returns the rays
/// cast.
fn in_chunks(
    call: ColumnsCall<'_>,
    chunk_rows: usize,
    chunk: impl Fn(&[u32], &mut [u32]) -> u64 + Sync,
) -> u64 {
    let ColumnsCall {
        prepared,
        columns,
        target:
            ColumnsTarget {
                bits,
                words_per_row,
                ticker,
            },
        ..
    } = call;
    let order = morton_order(prepared);
    let chunks: Vec<(Vec<u32>, u64)> = order
        .par_chunks(chunk_rows)
        .map(|rows| {
            let mut out = vec![0u32; rows.len() * words_per_row];
            let rays = chunk(rows, &mut out);
            ticker.tick((rows.len() * columns.len()) as u64);
            (out, rays)
        })
        .collect();
    scatter_chunks(&order, chunk_rows, chunks, columns, bits, words_per_row)
}

/// Copies the columns `columns` of per-chunk row blocks (rows `order` in chunks of
/// `chunk_rows`, as computed in Morton order) into the row-major `bits`; returns the rays
/// the chunks cast.
fn scatter_chunks(
    order: &[u32],
    chunk_rows: usize,
    chunks: Vec<(Vec<u32>, u64)>,
    columns: Range<usize>,
    bits: &mut [u32],
    words_per_row: usize,
) -> u64 {
    // Per word of the row, the bits of `columns` in it: a row is a handful of word copies
    // (this loop is serial; bit by bit it took 3 % of the bunny's CPU time at k = 258, all on
    // one core while the other waited).
    let words: Vec<(usize, u32)> = if columns.is_empty() {
        Vec::new()
    } else {
        (columns.start / WORD_BITS..=(columns.end - 1) / WORD_BITS)
            .map(|w| {
                let lo = columns.start.max(w * WORD_BITS) - w * WORD_BITS;
                let hi = columns.end.min((w + 1) * WORD_BITS) - w * WORD_BITS;
                (w, (u32::MAX >> (WORD_BITS - (hi - lo))) << lo)
            })
            .collect()
    };
    let mut rays = 0;
    for (rows, (out, chunk_rays)) in order.chunks(chunk_rows).zip(chunks) {
        rays += chunk_rays;
        for (&row, out_row) in rows.iter().zip(out.chunks_exact(words_per_row)) {
            let target = &mut bits[row as usize * words_per_row..][..words_per_row];
            for &(w, mask) in &words {
                target[w] = (target[w] & !mask) | (out_row[w] & mask);
            }
        }
    }
    rays
}

/// The receiver rows sorted by the Morton code of their positions (10 bits per axis over the
/// scene's bounding cube), so consecutive rows are spatial neighbours.
pub(crate) fn morton_order(prepared: &Prepared) -> Vec<u32> {
    let scale = if prepared.radius > 0.0 {
        1023.0 / (2.0 * prepared.radius)
    } else {
        0.0
    };
    let spread = |v: f32| -> u64 {
        let mut x = (v * scale + 511.5).clamp(0.0, 1023.0) as u64;
        x = (x | (x << 16)) & 0x0300_00ff;
        x = (x | (x << 8)) & 0x0300_f00f;
        x = (x | (x << 4)) & 0x030c_30c3;
        (x | (x << 2)) & 0x0924_9249
    };
    let mut keyed: Vec<(u64, u32)> = prepared
        .receivers
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let p = r.position;
            (spread(p.x) | spread(p.y) << 1 | spread(p.z) << 2, i as u32)
        })
        .collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}
