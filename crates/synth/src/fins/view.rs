//! The fixed grazing view: for every sub-sample, the nearest fibre point along −x, found
//! once by rasterising the segments as tapered capsules in the yz-plane (see "Rendering"
//! in the [module documentation](super)).

use super::strands::Segment;
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// What a sub-sample's ray meets first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hit {
    /// The point on the fibre's front surface (material units, y wrapped into [0, 1)).
    pub position: Vec3,
    /// Unit tangent of the fibre there.
    pub tangent: Vec3,
    /// Index of the strand, or [`Hit::MISS`].
    pub strand: u32,
}

impl Hit {
    /// The strand index of a sub-sample that sees only the black background.
    pub const MISS: u32 = u32::MAX;

    const BACKGROUND: Self = Self {
        position: Vec3::ZERO,
        tangent: Vec3::Z,
        strand: Self::MISS,
    };

    /// Whether the sub-sample sees a fibre.
    pub fn is_fibre(&self) -> bool {
        self.strand != Self::MISS
    }
}

/// The nearest hit of every sub-sample of a `width × height` image with `n × n`
/// sub-samples per pixel, pixel-major (row-major pixels, top row first), then sub-sample
/// `b·n + a` (a the sub-column, b the sub-row from the top).
///
/// Sub-sample column c (0 ≤ c < width·n) sits at y = (c + ½)/(width·n), sub-sample row q
/// (0 from the top) at z = (height·n − q − ½)/(width·n). Rayon over pixel rows; each row
/// visits its segments in a fixed order, so the result does not depend on the threads.
pub(super) fn trace(segments: &[Segment], width: usize, height: usize, n: usize) -> Vec<Hit> {
    let columns = width * n;
    let rows = height * n;
    let scale = columns as f32;
    let buckets = bucket_rows(segments, height, n, scale);
    let mut hits = vec![Hit::BACKGROUND; rows * columns];
    hits.par_chunks_mut(columns * n)
        .zip(buckets.par_iter())
        .enumerate()
        .for_each(|(row, (chunk, bucket))| {
            for &index in bucket {
                let segment = &segments[index as usize];
                for b in 0..n {
                    let q = row * n + b;
                    let z = ((rows - q) as f32 - 0.5) / scale;
                    raster_line(segment, z, scale, columns, |column, hit| {
                        let slot = &mut chunk[(column / n) * n * n + b * n + column % n];
                        if !slot.is_fibre() || hit.position.x > slot.position.x {
                            *slot = hit;
                        }
                    });
                }
            }
        });
    hits
}

/// For every pixel row, the indices of the segments that may cover one of its sub-sample
/// rows (a superset: [`raster_line`] tests exactly).
fn bucket_rows(segments: &[Segment], height: usize, n: usize, scale: f32) -> Vec<Vec<u32>> {
    let rows = (height * n) as f64;
    let mut buckets = vec![Vec::new(); height];
    for (index, segment) in segments.iter().enumerate() {
        let radius = segment.max_radius();
        if radius <= 0.0 {
            continue;
        }
        let b = segment.a + segment.d;
        let z_low = f64::from(segment.a.z.min(b.z) - radius);
        let z_high = f64::from(segment.a.z.max(b.z) + radius);
        // Sub-sample row q sits at z = (rows − q − ½)/scale; one row of margin each side.
        let first = (rows - 0.5 - z_high * f64::from(scale)).floor() - 1.0;
        let last = (rows - 0.5 - z_low * f64::from(scale)).ceil() + 1.0;
        if last < 0.0 || first > rows - 1.0 {
            continue;
        }
        let first = first.max(0.0) as usize / n;
        let last = last.min(rows - 1.0) as usize / n;
        for bucket in &mut buckets[first..=last] {
            // Fits: the segment count is bounded by MAX_FIN_SEGMENTS < 2³².
            bucket.push(index as u32);
        }
    }
    buckets
}

/// Calls `emit(column, hit)` for every sub-sample on the line at height `z` that the
/// segment's capsule covers; `column` is wrapped into `0..columns` (the image is periodic
/// in y with period 1 = `columns` sub-samples).
///
/// A sub-sample at P = (y, z) is covered when its distance to the closest point
/// C = A + t·D of the projected axis is below the radius interpolated at t; its depth is
/// the axis's x at t plus the height √(r² − dist²) of the fibre's front surface there.
fn raster_line(
    segment: &Segment,
    z: f32,
    scale: f32,
    columns: usize,
    mut emit: impl FnMut(usize, Hit),
) {
    let radius = segment.max_radius();
    let (a, d) = (segment.a, segment.d);
    // The part of the axis within `radius` of the line, as a range of t.
    let (t_low, t_high) = if d.z != 0.0 {
        let t1 = (z - radius - a.z) / d.z;
        let t2 = (z + radius - a.z) / d.z;
        (t1.min(t2).max(0.0), t1.max(t2).min(1.0))
    } else if (a.z - z).abs() <= radius {
        (0.0, 1.0)
    } else {
        return;
    };
    if t_low > t_high {
        return;
    }
    let (y1, y2) = (a.y + t_low * d.y, a.y + t_high * d.y);
    let y_low = y1.min(y2) - radius;
    let y_high = y1.max(y2) + radius;
    // Sub-sample column c sits at y = (c + ½)/scale.
    let first = (f64::from(y_low) * f64::from(scale) - 0.5).ceil() as i64;
    let last = (f64::from(y_high) * f64::from(scale) - 0.5).floor() as i64;
    let axis_start = Vec2::new(a.y, a.z);
    let axis = Vec2::new(d.y, d.z);
    let length2 = axis.length_squared();
    for c in first..=last {
        let p = Vec2::new((c as f32 + 0.5) / scale, z);
        let relative = p - axis_start;
        let t = if length2 > 0.0 {
            (relative.dot(axis) / length2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let distance2 = (relative - t * axis).length_squared();
        let r = segment.radius_a + t * (segment.radius_b - segment.radius_a);
        if distance2 < r * r {
            let column = c.rem_euclid(columns as i64) as usize;
            let x = a.x + t * d.x + (r * r - distance2).sqrt();
            emit(
                column,
                Hit {
                    position: Vec3::new(x, (column as f32 + 0.5) / scale, z),
                    tangent: segment.tangent,
                    strand: segment.strand,
                },
            );
        }
    }
}
