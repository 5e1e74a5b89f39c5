//! The camera of vertex filtering (paper 000 §4.1): a perspective clip transform of the
//! scene's world space and a target size, and the scene in the camera's centred frame.

use glam::{DMat4, DVec3, Mat4, Vec3};

use crate::scene::Prepared;
use crate::{OcclusionError, Scene};

/// Near plane of [`Camera::look_at`] as a fraction of the eye–target distance.
const LOOK_AT_NEAR_RELATIVE: f32 = 1e-3;

/// A perspective camera: the clip space of the render target (wgpu conventions: y up, depth
/// 0..1) from the [`Scene`]'s world space, and the target's size in pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Clip space from the scene's world space.
    pub clip_from_world: Mat4,
    /// Target width in pixels.
    pub width: u32,
    /// Target height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera from a projection-view matrix and a target size.
    ///
    /// # Errors
    /// [`OcclusionError::InvalidParameter`] for a zero size or a non-finite matrix.
    pub fn new(clip_from_world: Mat4, width: u32, height: u32) -> Result<Self, OcclusionError> {
        if let Some(&value) = clip_from_world
            .to_cols_array()
            .iter()
            .find(|c| !c.is_finite())
        {
            return Err(invalid(
                "camera clip_from_world entry",
                value.into(),
                "finite",
            ));
        }
        for (what, value) in [("camera width", width), ("camera height", height)] {
            if value == 0 {
                return Err(invalid(what, value.into(), "at least 1 pixel"));
            }
        }
        Ok(Self {
            clip_from_world,
            width,
            height,
        })
    }

    /// A right-handed perspective camera at `eye` looking at `target` with vertical field of
    /// view `fov_y_radians` and an infinite far plane (the near plane is 10⁻³ × the eye–target
    /// distance).
    ///
    /// # Errors
    /// As [`Camera::new`], and [`OcclusionError::InvalidParameter`] when `eye == target` or the
    /// field of view is outside (0, π).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_radians: f32,
        width: u32,
        height: u32,
    ) -> Result<Self, OcclusionError> {
        let distance = eye.distance(target);
        if !(distance > 0.0 && distance.is_finite()) {
            return Err(invalid("eye–target distance", distance.into(), "positive"));
        }
        if !(fov_y_radians > 0.0 && fov_y_radians < std::f32::consts::PI) {
            return Err(invalid("fov_y_radians", fov_y_radians.into(), "in (0, π)"));
        }
        let aspect = width.max(1) as f32 / height.max(1) as f32;
        // wgpu clip space: y up, depth 0..1, the DirectX convention.
        let clip_from_view = glam::camera::rh::proj::directx::perspective_infinite(
            fov_y_radians,
            aspect,
            LOOK_AT_NEAR_RELATIVE * distance,
        );
        let view_from_world = glam::camera::rh::view::look_at_mat4(eye, target, up);
        Self::new(clip_from_view * view_from_world, width, height)
    }

    /// Clip space from the prepared (centred) frame: world = centred + centre.
    pub(crate) fn clip_from_centred(&self, center: DVec3) -> Mat4 {
        (self.clip_from_world.as_dmat4() * DMat4::from_translation(center)).as_mat4()
    }
}

pub(crate) fn invalid(what: &'static str, value: f64, expected: &'static str) -> OcclusionError {
    OcclusionError::InvalidParameter {
        what,
        value,
        expected,
    }
}

/// The scene in the centred frame and the camera's clip matrix for it; `None` when the scene
/// has no triangles (nothing can be visible).
pub(crate) fn prepare(
    scene: &Scene,
    camera: &Camera,
) -> Result<Option<(Prepared, Mat4)>, OcclusionError> {
    Camera::new(camera.clip_from_world, camera.width, camera.height)?;
    if scene.triangle_count() == 0 {
        return Ok(None);
    }
    let prepared = Prepared::new(scene)?;
    let clip = camera.clip_from_centred(prepared.center);
    Ok(Some((prepared, clip)))
}
