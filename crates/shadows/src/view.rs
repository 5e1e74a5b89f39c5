//! The exact shadow mask of any view: for each pixel the visible surface point (the first hit
//! of the pixel's ray, found with occlusion-gpu's any-hit queries by bisection) and its segment
//! to the light through the same BVH — the CPU twin of what the stencil decides per pixel.

use glam::{Vec3, Vec4};
use rayon::prelude::*;
use render::Camera;

use crate::{Light, ShadowError};

/// Bisection steps for the first hit: the hit is found within far / 2⁴⁰.
const BISECTIONS: u32 = 40;

/// Per pixel of `camera`'s image (row-major, top row first): 1 where the surface the pixel
/// sees is in shadow (its segment to the light meets a triangle, its own surface included when
/// it faces away from the light), 0 where it is lit, NaN where the pixel sees nothing before
/// the camera's far plane. Every triangle both occludes and receives.
///
/// The surface point is taken a hair (occlusion-gpu's relative offset times the scene's
/// diagonal) towards the eye, so a surface facing away from the light shadows itself and one
/// facing it does not.
///
/// # Errors
/// [`ShadowError::Rays`] for a scene the BVH cannot take; [`ShadowError::Light`] for an
/// invalid light; [`ShadowError::Parameter`] for a camera that makes no image.
pub fn exact_view_mask(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    camera: &Camera,
) -> Result<Vec<f32>, ShadowError> {
    let light = light.validated()?;
    let clip_from_world = camera.clip_from_world().map_err(|e| {
        crate::error::bad_parameter("camera", e.value.clone(), "must make an image")
    })?;
    let world_from_clip = clip_from_world.inverse();
    let (caster, offset) = crate::ground::ray_caster(positions, triangles)?;
    let (w, h) = (camera.width as usize, camera.height as usize);
    let eye = camera.eye.as_dvec3();
    let mut mask = vec![f32::NAN; w * h];
    mask.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let mut cache = Default::default();
        for (x, cell) in row.iter_mut().enumerate() {
            let ndc = |z: f32| {
                let p = world_from_clip
                    * Vec4::new(
                        (x as f32 + 0.5) / w as f32 * 2.0 - 1.0,
                        1.0 - (y as f32 + 0.5) / h as f32 * 2.0,
                        z,
                        1.0,
                    );
                (p.truncate() / p.w).as_dvec3()
            };
            let far_point = ndc(1.0);
            let reach = (far_point - eye).length();
            let dir = (far_point - eye) / reach;
            let blocked_within = |t: f64, cache: &mut _| {
                caster.occluded(caster.centred(eye), (dir * t).as_vec3(), 1.0, cache)
            };
            if !blocked_within(reach, &mut cache) {
                continue;
            }
            let (mut lo, mut hi) = (0.0, reach);
            for _ in 0..BISECTIONS {
                let mid = 0.5 * (lo + hi);
                if blocked_within(mid, &mut cache) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            let p = eye + dir * (lo - offset).max(0.0);
            let blocked = match light {
                Light::Point(l) => {
                    caster.occluded(caster.centred(p), (l - p).as_vec3(), 1.0, &mut cache)
                }
                Light::Directional(d) => {
                    caster.occluded(caster.centred(p), d.as_vec3(), f32::INFINITY, &mut cache)
                }
            };
            *cell = f32::from(u8::from(blocked));
        }
    });
    Ok(mask)
}
