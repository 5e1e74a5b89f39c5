//! The exact builder: one ray per (vertex, pixel) through `occlusion-gpu`'s BVH.
//!
//! A pixel is open when the ray from the vertex, pushed [`BuildParams::offset_relative`] × the
//! scene's bounding-box diagonal along its normal (the counterpart of `glPolygonOffset`, §4.4),
//! towards the pixel's centre direction meets no triangle. Both faces of every triangle occlude
//! (cloth is open and two-sided). Works for all three models (§4.3.4: "ray tracing works for
//! all"), and is the accuracy reference of the GPU builder, which samples the same directions.
//!
//! The rays of one vertex share their origin, so they are cast as *fans*
//! ([`occlusion_gpu::RayFan`]): the layout's pixels are split once into compact groups of
//! four neighbouring directions (recursive median splits) and 64 per fan, and each fan walks
//! the BVH together, one SIMD test per group and node, with a common-origin triangle test.
//! Every pixel is the answer of [`RayCaster::occluded`] (a test asserts it); on the dress this
//! is 3.4–4.1× faster than one traversal per ray (`benches/build.rs`: HC 16² of the dress in
//! 89 ms against 340 ms; 2 of its 3.5 M pixels differ, both within rounding of an edge).
//!
//! [`BuildParams::max_distance`] is the seed's *triangle preselection* (Table 4.1, "distance
//! 1/6 ums"): occluders farther than that many units of the mesh's largest bounding-box side
//! are ignored. With a BVH the preselection is only a shorter ray: it saves the far part of
//! each traversal and changes the answer wherever a distant fold occludes. What it buys today,
//! on the dress at 1/6 (`rays-preselect-1_6` in `benches/build.rs`): nothing measurable
//! (±2 %) — near occluders end most rays, and escaping rays leave the BVH's boxes soon anyway —
//! for a biased answer (mean open fraction at HC 16² 0.4892 → 0.4911, at SP 8² 0.4676 →
//! 0.4689).
//! The seed needed it because its rasteriser drew every triangle for every vertex.

use std::sync::Arc;

use glam::{Mat3, Vec3};
use occlusion_gpu::{RayCaster, RayFan, Scene, fan_groups};
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
    build_with_frames(caster, layout, params, frames_of(caster), progress)
}

/// [`build_with_progress`] with each receiver's map frame given (`None`: no map), e.g.
/// [`VertexFrame::from_normal_tangent`] so that a map pixel's direction is the same in every
/// vertex's texture tangent frame (BTF rendering, [`crate::BtfLightChannel`]).
///
/// # Panics
/// If `frames` has not one entry per receiver vertex.
pub fn build_with_frames(
    caster: &RayCaster,
    layout: Arc<PixelLayout>,
    params: &BuildParams,
    frames: Vec<Option<VertexFrame>>,
    progress: &(dyn Fn(u64) + Sync),
) -> (VisibilityMaps, BuildStats) {
    assert_eq!(
        frames.len(),
        caster.receiver_count(),
        "one map frame per receiver vertex"
    );
    let offset = params.offset_relative * caster.diagonal();
    let max_t = params
        .max_distance
        .map_or(f32::INFINITY, |d| d * largest_side(caster));
    let receivers: Vec<(Vec3, Vec3)> = caster.receivers().collect();
    let groups = fan_groups(layout.directions());
    // Each fan in the vertex frame, built once; per vertex it is only rotated.
    let templates: Vec<RayFan> = groups
        .iter()
        .map(|group| RayFan::from_group(layout.directions(), group))
        .collect();
    let pixels = layout.len() as u64;
    let mut maps = VisibilityMaps::new(layout, frames.clone());
    let (bits, words) = maps.words_mut();
    let samples: u64 = bits
        .par_chunks_mut(words)
        .zip(frames.par_iter())
        .zip(receivers.par_iter())
        .map_init(RayFan::new, |fan, ((out, frame), &(position, normal))| {
            let Some(frame) = frame else { return 0 };
            let m = Mat3::from_quat(frame.rotation);
            let origin = position + normal * offset;
            for (group, template) in groups.iter().zip(&templates) {
                template.rotate_into(m, fan);
                let mut open = caster.unoccluded_fan(origin, fan, fan.full_mask(), max_t);
                while open != 0 {
                    let p = group[open.trailing_zeros() as usize] as usize;
                    open &= open - 1;
                    out[p / 64] |= 1 << (p % 64);
                }
            }
            progress(1);
            pixels
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
