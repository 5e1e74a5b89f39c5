//! The sine deformer of seed 004's Fig. 12 ("a sine deformer on the Happy Buddha as a function
//! of time and z"): a static translucent object becomes an N-frame loop, so the translucency
//! pipeline — which precomputes nothing but its Y_lm table — is shown on a deforming mesh.
//!
//! Vertex p moves along x by A·H·h·sin(2π(k·h − f/N)) at frame f, with h = (p.y − y_min)/H
//! its height fraction (H the object's height, y up): the base stays, the top sways, and the
//! wave travels up the object once per period.

use std::sync::Arc;

use glam::{Mat4, Vec3};

use crate::Error;
use crate::object::{Animation, WorldObject};
use crate::scene::{Scene, SineDeformDesc};

/// Largest frames × vertices the deformer may allocate (the frames are kept, 12 bytes each).
pub const MAX_DEFORMED_VERTEX_FRAMES: usize = 50_000_000;

/// The deformed positions of `positions` at frame `f` of `d.frames`.
pub fn sine_frame(positions: &[Vec3], d: &SineDeformDesc, f: usize) -> Vec<Vec3> {
    let (lo, hi) = positions
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.y), hi.max(p.y))
        });
    let height = f64::from(hi - lo);
    let phase = f as f64 / d.frames as f64;
    positions
        .iter()
        .map(|p| {
            let h = if height > 0.0 {
                f64::from(p.y - lo) / height
            } else {
                0.0
            };
            let s = (std::f64::consts::TAU * (d.waves * h - phase)).sin();
            *p + Vec3::X * (d.amplitude * height * h * s) as f32
        })
        .collect()
}

/// Turn every translucent static object into the deformer's loop (when `[translucency]
/// deform` is set and the effect runs), posed at frame 0.
///
/// # Errors
/// [`Error::Scene`] for an object that is already animated, flat in y, or whose frames would
/// exceed [`MAX_DEFORMED_VERTEX_FRAMES`].
pub fn apply(scene: &Scene, objects: &mut [WorldObject]) -> Result<(), Error> {
    let Some(d) = scene.translucency.deform else {
        return Ok(());
    };
    for o in objects
        .iter_mut()
        .filter(|o| scene.translucency.covers(&o.name))
    {
        if o.animation.is_some() {
            return Err(scene.invalid(
                "translucency.deform",
                format!(
                    "object {:?} is already animated; the deformer takes static objects",
                    o.name
                ),
            ));
        }
        if o.positions.len().saturating_mul(d.frames) > MAX_DEFORMED_VERTEX_FRAMES {
            return Err(scene.invalid(
                "translucency.deform.frames",
                format!(
                    "{} frames × {} vertices of {:?} exceed {MAX_DEFORMED_VERTEX_FRAMES}",
                    d.frames,
                    o.positions.len(),
                    o.name
                ),
            ));
        }
        let frames: Vec<Vec<Vec3>> = (0..d.frames)
            .map(|f| sine_frame(&o.positions, &d, f))
            .collect();
        o.animation = Some(Animation {
            frames: Arc::new(frames),
            world_from_object: Mat4::IDENTITY,
        });
        o.pose(0);
    }
    Ok(())
}
