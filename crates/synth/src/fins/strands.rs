//! The fibre geometry: strands generated from the parameters (see "Fibre layer" in the
//! [module documentation](super)), the checks on caller-supplied strands, and the tapered
//! segments both the view raster and the shadow grid are built from.

use super::{
    MAX_FIN_SEGMENTS, MAX_STRAND_COORD, MAX_STRAND_ROOT_RADIUS, WoolFinParams, WoolStrand,
};
use crate::error::{Result, SynthError, check_range};
use crate::rng::SplitMix64;
use glam::Vec3;
use std::f32::consts::TAU;

/// Range of the number of turns of a strand's curl over its whole length.
const CURL_TURNS: (f32, f32) = (0.5, 1.5);

/// The strands of `params` (already validated), in the order the generator drew them.
///
/// Per strand, in this order, from one SplitMix64 stream seeded with `params.seed`: root x,
/// root y, length, tilt, tilt azimuth, curl amplitude, curl turns, curl phase, colour
/// factor.
pub(super) fn generate(params: &WoolFinParams) -> Vec<WoolStrand> {
    let mut rng = SplitMix64::new(params.seed);
    let unit = 1.0 / params.width as f32;
    let image_height = params.height as f32 * unit;
    let root_radius = params.root_radius_px * unit;
    let max_tilt = params.max_tilt_deg.to_radians();
    let segments = params.segments;
    (0..params.strands)
        .map(|_| {
            let root_x = -params.depth * rng.next_f32();
            let root_y = rng.next_f32();
            let length_fraction =
                params.length_min + (params.length_max - params.length_min) * rng.next_f32();
            let tilt = max_tilt * rng.next_f32();
            let azimuth = TAU * rng.next_f32();
            let curl = params.curl * rng.next_f32();
            let turns = CURL_TURNS.0 + (CURL_TURNS.1 - CURL_TURNS.0) * rng.next_f32();
            let phase = TAU * rng.next_f32();
            let factor = 1.0 + params.colour_variation * rng.next_signed();

            let axis = Vec3::new(
                tilt.sin() * azimuth.cos(),
                tilt.sin() * azimuth.sin(),
                tilt.cos(),
            );
            let step = length_fraction * image_height / segments as f32;
            let mut points = Vec::with_capacity(segments + 1);
            let mut p = Vec3::new(root_x, root_y, 0.0);
            points.push(p);
            for k in 0..segments {
                let u = (k as f32 + 0.5) / segments as f32;
                let angle = TAU * turns * u + phase;
                // The curl only adds a horizontal component: the strand always rises.
                let direction = (axis + curl * Vec3::new(angle.cos(), angle.sin(), 0.0))
                    .try_normalize()
                    .unwrap_or(Vec3::Z);
                p += step * direction;
                points.push(p);
            }
            WoolStrand {
                points,
                root_radius,
                colour: (params.colour * factor).clamp(Vec3::ZERO, Vec3::ONE),
            }
        })
        .collect()
}

/// Checks caller-supplied strands (see [`WoolFins::from_strands`](super::WoolFins::from_strands)).
pub(super) fn validate(strands: &[WoolStrand]) -> Result<()> {
    let mut segments: u128 = 0;
    for strand in strands {
        if strand.points.len() < 2 {
            return Err(SynthError::InvalidParameter {
                field: "WoolStrand::points.len()",
                value: strand.points.len() as f64,
                expected: "at least 2 points (root and tip)",
            });
        }
        segments += strand.points.len() as u128 - 1;
        if segments > MAX_FIN_SEGMENTS {
            // Counting on would only make the number larger; report what was seen so far.
            break;
        }
        for p in &strand.points {
            for c in p.to_array() {
                check_range(
                    "WoolStrand::points",
                    c,
                    -MAX_STRAND_COORD,
                    MAX_STRAND_COORD,
                    "finite coordinates within ±10⁴ material units",
                )?;
            }
        }
        check_range(
            "WoolStrand::root_radius",
            strand.root_radius,
            0.0,
            MAX_STRAND_ROOT_RADIUS,
            "0 ..= 0.25 material units",
        )?;
        let fields = [
            "WoolStrand::colour.x",
            "WoolStrand::colour.y",
            "WoolStrand::colour.z",
        ];
        for (value, field) in strand.colour.to_array().into_iter().zip(fields) {
            check_range(field, value, 0.0, 1.0, "0 ..= 1")?;
        }
    }
    if segments > MAX_FIN_SEGMENTS {
        let total: u128 = strands
            .iter()
            .map(|s| s.points.len().saturating_sub(1) as u128)
            .sum();
        return Err(SynthError::TooLarge {
            field: "WoolFins::from_strands segments (Σ points.len() − 1)",
            requested: total,
            maximum: MAX_FIN_SEGMENTS,
            unit: "strand segments",
        });
    }
    Ok(())
}

/// One piece of a strand between two consecutive points: a capsule whose radius tapers
/// linearly from `radius_a` at `a` to `radius_b` at `a + d`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Segment {
    /// Start point (towards the root).
    pub a: Vec3,
    /// End point minus start point.
    pub d: Vec3,
    /// Radius at `a`.
    pub radius_a: f32,
    /// Radius at `a + d`.
    pub radius_b: f32,
    /// Unit direction of `d` (+z for a segment of zero length).
    pub tangent: Vec3,
    /// Index of the strand the segment belongs to.
    pub strand: u32,
}

impl Segment {
    /// The larger of the two end radii.
    pub fn max_radius(&self) -> f32 {
        self.radius_a.max(self.radius_b)
    }
}

/// The segments of all strands, strand by strand from root to tip. The radius falls
/// linearly with arc length from the root radius to 0 at the tip.
pub(super) fn segments(strands: &[WoolStrand]) -> Vec<Segment> {
    let mut out = Vec::new();
    for (index, strand) in strands.iter().enumerate() {
        let total: f32 = strand.points.windows(2).map(|w| w[0].distance(w[1])).sum();
        let radius_at = |arc: f32| {
            if total > 0.0 {
                strand.root_radius * (1.0 - arc / total).max(0.0)
            } else {
                strand.root_radius
            }
        };
        let mut arc = 0.0;
        for w in strand.points.windows(2) {
            let d = w[1] - w[0];
            let length = d.length();
            out.push(Segment {
                a: w[0],
                d,
                radius_a: radius_at(arc),
                radius_b: radius_at(arc + length),
                tangent: d.try_normalize().unwrap_or(Vec3::Z),
                // Fits: the strand count is bounded by MAX_FIN_SEGMENTS < 2³².
                strand: index as u32,
            });
            arc += length;
        }
    }
    out
}
