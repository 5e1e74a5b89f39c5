//! Ray marching through the height field: the primary ray from the registration plane down
//! to the first intersection, and the shadow ray from a surface point towards the light.
//!
//! A ray is parametrised by its horizontal travel s (tile units). It advances in segments
//! of [`TOP_SEGMENT_STEPS`] fine steps. A segment whose lowest ray height lies above the
//! maximum of the height field over the segment's bounding rectangle (bounded by a
//! [`MaxPyramid`]) is skipped whole; the others are halved, front half
//! first, down to [`LEAF_STEPS`] fine steps, which are sampled every fine step. So a ray
//! costs a few bound look-ups per level where it passes close to the surface, not one
//! height evaluation per fine step, and the cost barely grows with the resolution. The
//! first fine sample at or below the surface ends the march; the primary ray then refines
//! the crossing by bisection. A crossing of a sliver thinner than a fine step
//! (a yarn's corner grazed by the ray) can be missed; the fine step is at most half a
//! sub-sample and a 32nd of a yarn's half-width.

use super::bound::MaxPyramid;
use super::weave::Weave;
use glam::{Vec2, Vec3};

/// Fine steps per top-level segment of the march. (With [`LEAF_STEPS`]: 64 and 4 were
/// tried against 16 and 256, and leaves of 2 and 8, on the default weave at 32² × 2²; all
/// were within the measurement's noise.)
const TOP_SEGMENT_STEPS: f32 = 64.0;
/// Segments of at most this many fine steps are sampled instead of halved; also the size
/// of the max pyramid's finest cells.
const LEAF_STEPS: f32 = 4.0;
/// Bisection iterations after the primary ray's crossing is bracketed: the hit is located
/// to 2⁻⁸ of a fine step, 2⁻⁹ of a sub-sample.
const BISECTION_STEPS: u32 = 8;
/// Horizontal travel below which a direction counts as vertical (straight down or up).
const VERTICAL_EPSILON: f32 = 1e-7;
/// A shadow ray is occluded only where the surface rises this far above it (tile units;
/// heights are ~0.1 and computed to ~10⁻⁸, so this only absorbs rounding at the start).
pub(crate) const SHADOW_BIAS: f32 = 1e-6;
/// Longest horizontal travel of a shadow ray (tile units). A ray that leaves the surface
/// at an elevation below about 3° can need more before it clears the top of the tile;
/// such a ray is almost always blocked within two yarn pitches, and one that is not
/// blocked within this many tiles is treated as lit.
pub(crate) const MAX_SHADOW_TRAVEL: f32 = 4.0;

/// A straight ray in the tangent frame, parametrised by horizontal travel.
#[derive(Debug, Clone, Copy)]
struct Ray {
    origin: Vec3,
    /// Unit horizontal direction.
    dir_xy: Vec2,
    /// Change of height per unit of horizontal travel.
    dz_ds: f32,
}

impl Ray {
    #[inline]
    fn at(&self, s: f32) -> Vec3 {
        let xy = self.origin.truncate() + s * self.dir_xy;
        xy.extend(self.origin.z + s * self.dz_ds)
    }
}

/// The height field with its acceleration structure and march step.
#[derive(Debug, Clone)]
pub(crate) struct Tracer {
    pub(crate) weave: Weave,
    bounds: MaxPyramid,
    /// Fine march step, tile units.
    pub(crate) step: f32,
}

impl Tracer {
    /// A tracer that samples the surface every `step` (tile units) along a ray.
    pub(crate) fn new(weave: Weave, step: f32) -> Self {
        let bounds = MaxPyramid::new(&weave, LEAF_STEPS * step);
        Self {
            weave,
            bounds,
            step,
        }
    }

    /// The first fine sample along `ray`, for s in (0, s_end], where the surface is at
    /// least `bias` above the ray, bracketed as (previous sample, that sample).
    fn first_crossing(&self, ray: &Ray, s_end: f32, bias: f32) -> Option<(f32, f32)> {
        let top = self.step * TOP_SEGMENT_STEPS;
        let mut start = (0.0, ray.at(0.0));
        while start.0 < s_end {
            let s = (start.0 + top).min(s_end);
            let end = (s, ray.at(s));
            if let Some(found) = self.search(ray, start, end, bias) {
                return Some(found);
            }
            start = end;
        }
        None
    }

    /// [`first_crossing`](Self::first_crossing) within the segment from `start` to `end`
    /// (each a parameter and the ray's point there): skipped whole when the ray stays above
    /// the bound of the height field over the segment's bounding rectangle, halved while
    /// longer than [`LEAF_STEPS`] fine steps, sampled every fine step otherwise.
    fn search(
        &self,
        ray: &Ray,
        start: (f32, Vec3),
        end: (f32, Vec3),
        bias: f32,
    ) -> Option<(f32, f32)> {
        let ((a, pa), (b, pb)) = (start, end);
        let bound = self.bounds.max_in_rect(
            (pa.x.min(pb.x), pa.x.max(pb.x)),
            (pa.y.min(pb.y), pa.y.max(pb.y)),
        );
        if pa.z.min(pb.z) - bias > bound {
            return None;
        }
        if b - a > LEAF_STEPS * self.step {
            let m = 0.5 * (a + b);
            let middle = (m, ray.at(m));
            return self
                .search(ray, start, middle, bias)
                .or_else(|| self.search(ray, middle, end, bias));
        }
        let steps = ((b - a) / self.step).ceil().max(1.0) as u32;
        let mut previous = a;
        for i in 1..=steps {
            let (s, p) = if i == steps {
                (b, pb)
            } else {
                let s = a + self.step * i as f32;
                (s, ray.at(s))
            };
            if p.z + bias <= self.weave.height(p.x, p.y) {
                return Some((previous, s));
            }
            previous = s;
        }
        None
    }

    /// Where the ray from `origin` (on the plane `z = z_top`) along `-view` first meets
    /// the surface, with x and y unwrapped. `view` is a unit vector with `view.z > 0`.
    ///
    /// The point is on the ray: where the ray enters through the vertical face between a
    /// yarn's edge and the floor (the height field jumps there), its z lies below the
    /// height field at its (x, y), which is just inside the yarn.
    pub(crate) fn primary_hit(&self, origin: Vec2, view: Vec3) -> Vec3 {
        let weave = &self.weave;
        let horizontal = view.truncate().length();
        if horizontal < VERTICAL_EPSILON {
            return origin.extend(weave.height(origin.x, origin.y));
        }
        let ray = Ray {
            origin: origin.extend(weave.z_top),
            dir_xy: -view.truncate() / horizontal,
            dz_ds: -view.z / horizontal,
        };
        // The ray reaches the floor, the lowest point of the surface, at s_floor.
        let s_floor = (weave.z_top - weave.z_floor) * horizontal / view.z;
        let Some((mut above, mut below)) = self.first_crossing(&ray, s_floor, 0.0) else {
            // Only f32 rounding at the floor gets here: the ray ends on the floor.
            return ray.at(s_floor).truncate().extend(weave.z_floor);
        };
        for _ in 0..BISECTION_STEPS {
            let mid = 0.5 * (above + below);
            let p = ray.at(mid);
            if p.z <= weave.height(p.x, p.y) {
                below = mid;
            } else {
                above = mid;
            }
        }
        // The sample at or below the surface: its (x, y) lies on the surface piece that was
        // hit.
        let p = ray.at(below);
        p.truncate().extend(p.z.min(weave.height(p.x, p.y)))
    }

    /// Whether the surface point `point` (on the surface) is hidden from the directional
    /// light `light` (unit, `light.z > 0`) by another part of the surface. Does not look at
    /// the normal: a point facing away from the light is typically reported occluded by
    /// itself.
    pub(crate) fn occluded(&self, point: Vec3, light: Vec3) -> bool {
        let horizontal = light.truncate().length();
        if horizontal < VERTICAL_EPSILON {
            // A height field never occludes the zenith.
            return false;
        }
        let ray = Ray {
            origin: point,
            dir_xy: light.truncate() / horizontal,
            dz_ds: light.z / horizontal,
        };
        let s_clear = ((self.weave.z_top - point.z) * horizontal / light.z).min(MAX_SHADOW_TRAVEL);
        self.first_crossing(&ray, s_clear, SHADOW_BIAS).is_some()
    }
}
