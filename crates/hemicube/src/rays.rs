//! The exact builder: one ray per (vertex, pixel) through `occlusion-gpu`'s BVH.
//!
//! A pixel is open when the ray from the vertex, pushed [`BuildParams::offset_relative`] × the
//! scene's bounding-box diagonal along its normal (the counterpart of `glPolygonOffset`, §4.4),
//! towards the pixel's centre direction meets no triangle. Both faces of every triangle occlude
//! (cloth is open and two-sided). Works for all three models (§4.3.4: "ray tracing works for
//! all"), and is the accuracy reference of the GPU builder, which samples the same directions.
//!
//! [`BuildParams::max_distance`] is the seed's *triangle preselection* (Table 4.1, "distance
//! 1/6 ums"): occluders farther than that many units of the mesh's largest bounding-box side
//! are ignored. With a BVH the preselection is only a shorter ray: it saves the far part of
//! each traversal and changes the answer wherever a distant fold occludes.

use std::sync::Arc;

use glam::{Mat3, Vec3};
use occlusion_gpu::{RayCache, RayCaster, Scene};
use rayon::prelude::*;

use crate::HemicubeError;
use crate::layout::PixelLayout;
use crate::maps::{VertexFrame, VisibilityMaps};

/// How maps are built (both builders).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct BuildParams {
    /// Eye offset along the normal × the scene's bounding-box diagonal (default
    /// [`occlusion_gpu::DEFAULT_OFFSET_RELATIVE`], the visibility engine's).
    pub offset_relative: f32,
    /// Preselection distance in units of the scene's largest bounding-box side (`None`: every
    /// occluder; rays only).
    pub max_distance: Option<f32>,
}

impl Default for BuildParams {
    fn default() -> Self {
        Self {
            offset_relative: occlusion_gpu::DEFAULT_OFFSET_RELATIVE,
            max_distance: None,
        }
    }
}

impl BuildParams {
    /// Checks the values.
    ///
    /// # Errors
    /// [`HemicubeError::Params`] naming the value.
    pub fn validate(&self) -> Result<(), HemicubeError> {
        if !(self.offset_relative.is_finite() && self.offset_relative >= 0.0) {
            return Err(HemicubeError::Params(format!(
                "eye offset {} must be finite and >= 0",
                self.offset_relative
            )));
        }
        if let Some(d) = self.max_distance
            && (d.is_nan() || d <= 0.0)
        {
            return Err(HemicubeError::Params(format!(
                "preselection distance {d} must be > 0 (units of the mesh's largest side)"
            )));
        }
        Ok(())
    }
}

/// What a build cost.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BuildStats {
    /// Rays cast (CPU) or pixels rasterised (GPU).
    pub samples: u64,
    /// GPU passes (atlases drawn); 0 for rays.
    pub passes: u32,
}

/// The frame of every receiver vertex: from its normal, or `None` for a zero normal.
pub(crate) fn frames_of(caster: &RayCaster) -> Vec<Option<VertexFrame>> {
    caster
        .receivers()
        .map(|(_, n)| (n != Vec3::ZERO).then(|| VertexFrame::from_normal(n)))
        .collect()
}

/// Builds the maps of every receiver vertex of `scene` by exact rays.
///
/// # Errors
/// Scene errors from `occlusion-gpu` (non-finite positions, bad indices, no receivers) and
/// parameter errors.
pub fn build_with_rays(
    scene: &Scene,
    layout: Arc<PixelLayout>,
    params: &BuildParams,
) -> Result<(VisibilityMaps, BuildStats), HemicubeError> {
    params.validate()?;
    let caster = RayCaster::new(scene)?;
    Ok(build_with_caster(&caster, layout, params))
}

/// [`build_with_rays`] on a BVH already built.
pub fn build_with_caster(
    caster: &RayCaster,
    layout: Arc<PixelLayout>,
    params: &BuildParams,
) -> (VisibilityMaps, BuildStats) {
    build_with_progress(caster, layout, params, &|_| {})
}

/// [`build_with_caster`] calling `progress(n)` as every n further vertices are done (from the
/// worker threads: a progress bar's `inc`).
pub fn build_with_progress(
    caster: &RayCaster,
    layout: Arc<PixelLayout>,
    params: &BuildParams,
    progress: &(dyn Fn(u64) + Sync),
) -> (VisibilityMaps, BuildStats) {
    let frames = frames_of(caster);
    let offset = params.offset_relative * caster.diagonal();
    let max_t = params
        .max_distance
        .map_or(f32::INFINITY, |d| d * largest_side(caster));
    let receivers: Vec<(Vec3, Vec3)> = caster.receivers().collect();
    let directions = layout.directions().to_vec();
    let mut maps = VisibilityMaps::new(layout, frames.clone());
    let (bits, words) = maps.words_mut();
    let samples: u64 = bits
        .par_chunks_mut(words)
        .zip(frames.par_iter())
        .zip(receivers.par_iter())
        .map(|((out, frame), &(position, normal))| {
            let Some(frame) = frame else { return 0 };
            let m = Mat3::from_quat(frame.rotation);
            let origin = position + normal * offset;
            let mut cache = RayCache::default();
            for (p, d) in directions.iter().enumerate() {
                if !caster.occluded(origin, m * *d, max_t, &mut cache) {
                    out[p / 64] |= 1 << (p % 64);
                }
            }
            progress(1);
            directions.len() as u64
        })
        .sum();
    (maps, BuildStats { samples, passes: 0 })
}

/// The largest side of the scene's bounding box (the seed's "unit of mesh size").
fn largest_side(caster: &RayCaster) -> f32 {
    let (lo, hi) = caster
        .triangles()
        .flatten()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
    (hi - lo).max_element().max(0.0)
}
