//! The `cpu` backend: exact visibility by ray casting (the accuracy reference of the issue,
//! and the fallback when no adapter exists).
//!
//! One shadow ray per (vertex, direction) with n·l > 0 (n·l culling: directions below the
//! tangent plane are 0 in M anyway), from the vertex pushed [`CpuParams::offset_relative`] ×
//! the scene's bounding-box diagonal along its normal, to infinity, with any-hit traversal of a
//! compressed wide BVH (`obvhs`'s CWBVH, 8-wide nodes) and a Möller–Trumbore triangle test in
//! f32 on coordinates centred on the scene (so a 1e5 offset costs no precision). Rows are
//! distributed over threads with rayon; each row is written by one thread only.
//!
//! BVH crate: `obvhs` 0.4 over `bvh` 0.13. `bvh` is a binary BVH on nalgebra whose
//! traversal collects candidate shapes per ray; `obvhs` builds an 8-wide compressed BVH
//! (PLOC and reinsertion) with an early-exit shadow-ray traversal (`ray_traverse_miss`),
//! which is the access pattern here: millions of short-lived incoherent any-hit rays. The
//! choice was made on these design grounds, not by a head-to-head benchmark against `bvh`;
//! the measured rays/s of this backend are in the crate's bench (`benches/visibility.rs`).

use std::ops::Range;
use std::time::Duration;

use glam::{Vec3, Vec3A};
use obvhs::BvhBuildParams;
use obvhs::cwbvh::CwBvh;
use obvhs::cwbvh::builder::build_cwbvh_from_tris;
use obvhs::ray::Ray;
use obvhs::triangle::Triangle;
use rayon::prelude::*;

use crate::matrix::WORD_BITS;
use crate::scene::Prepared;

/// Ray origin offset along the normal, relative to the scene's bounding-box diagonal: the
/// issue's exact reference (without an offset rays hit the vertex's own triangles; the offset
/// itself moves results by ~1e-4).
pub const DEFAULT_OFFSET_RELATIVE: f32 = 1e-4;

/// Barycentric tolerance of the triangle test: a ray through a shared edge must hit one of
/// the two triangles even when f32 rounding puts it a hair outside both (rays along the
/// octahedron's axis-aligned directions over axis-aligned geometry do exactly that). Tuned on
/// the sphere-over-plane test against f64 brute force; it only ever adds occlusion within
/// 1e-6 of an edge.
const EDGE_TOLERANCE: f32 = 1e-6;

/// Tuning knobs of the `cpu` backend.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct CpuParams {
    /// Ray origin offset along the normal × bounding-box diagonal.
    pub offset_relative: f32,
}

impl Default for CpuParams {
    fn default() -> Self {
        Self {
            offset_relative: DEFAULT_OFFSET_RELATIVE,
        }
    }
}

/// A triangle prepared for Möller–Trumbore: one vertex and the two edges from it.
#[derive(Clone, Copy, Debug)]
struct EdgeTriangle {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

impl EdgeTriangle {
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
pub(crate) struct CpuTracer {
    bvh: CwBvh,
    triangles: Vec<EdgeTriangle>,
}

impl CpuTracer {
    /// Builds the BVH over all scene triangles (degenerate ones included: they never hit).
    pub(crate) fn new(prepared: &Prepared) -> Self {
        let tris: Vec<Triangle> = prepared
            .triangles
            .iter()
            .map(|t| Triangle {
                v0: prepared.positions[t[0] as usize].into(),
                v1: prepared.positions[t[1] as usize].into(),
                v2: prepared.positions[t[2] as usize].into(),
            })
            .collect();
        if tris.is_empty() {
            return Self {
                bvh: CwBvh::default(),
                triangles: Vec::new(),
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
        Self { bvh, triangles }
    }

    /// Whether a ray from `origin` towards `direction` escapes to infinity.
    #[inline]
    pub(crate) fn unoccluded(&self, origin: Vec3A, direction: Vec3A) -> bool {
        if self.triangles.is_empty() {
            return true;
        }
        let ray = Ray::new(origin, direction, 0.0, f32::INFINITY);
        self.bvh.ray_traverse_miss(ray, |r, id| {
            self.triangles[id].intersect(r.origin, r.direction)
        })
    }
}

/// Fills the bits of columns `columns` of every row (`bits` is row-major with
/// `words_per_row` words); the other columns are left as they are. Returns the rays cast.
pub(crate) fn compute_columns(
    prepared: &Prepared,
    tracer: &CpuTracer,
    directions: &[Vec3],
    columns: Range<usize>,
    params: &CpuParams,
    bits: &mut [u32],
    words_per_row: usize,
) -> u64 {
    let offset = params.offset_relative * prepared.diagonal;
    let dirs: Vec<Vec3A> = directions.iter().map(|&d| d.into()).collect();
    bits.par_chunks_mut(words_per_row)
        .zip(prepared.receivers.par_iter())
        .map(|(row, receiver)| {
            let normal = Vec3A::from(receiver.normal);
            if normal == Vec3A::ZERO {
                for j in columns.clone() {
                    row[j / WORD_BITS] &= !(1 << (j % WORD_BITS));
                }
                return 0u64;
            }
            let origin = Vec3A::from(receiver.position) + normal * offset;
            let mut rays = 0u64;
            for j in columns.clone() {
                let direction = dirs[j];
                let visible = normal.dot(direction) > 0.0 && {
                    rays += 1;
                    tracer.unoccluded(origin, direction)
                };
                let mask = 1u32 << (j % WORD_BITS);
                if visible {
                    row[j / WORD_BITS] |= mask;
                } else {
                    row[j / WORD_BITS] &= !mask;
                }
            }
            rays
        })
        .sum()
}
