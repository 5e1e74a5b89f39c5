//! The one camera of the workspace: a perspective pinhole looking from `eye` at `target`,
//! used by every pass, the CPU references, the CLI, scene files and frame strips.
//!
//! Conventions: glam's right-handed view (`look_at`), wgpu's clip space (x, y ∈ [−w, w] left
//! to right and bottom to top), pixel centres at (x + ½, y + ½), top row first. Two depth
//! mappings ([`DepthConvention`]):
//!
//! * [`DepthConvention::Standard`]: near → 0, far → 1, compare `Less`, clear 1 — finite
//!   `near` and `far`, what the CPU references rasterise;
//! * [`DepthConvention::ReversedInfinite`]: near → 1, infinity → 0, compare `Greater`,
//!   clear 0 — no far plane, which z-fail shadow volumes need (their caps are projected to
//!   infinity), and float depth spends its precision evenly over distance.

use glam::{Mat4, Vec3};

/// A camera parameter that cannot make an image.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("camera {name} = {value}: {reason}")]
pub struct CameraError {
    /// The field.
    pub name: &'static str,
    /// Its value, formatted.
    pub value: String,
    /// What it must be.
    pub reason: &'static str,
}

/// How depth is mapped and compared in a frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DepthConvention {
    /// near → 0, far → 1, `Less`, cleared to 1.
    #[default]
    Standard,
    /// near → 1, ∞ → 0, `Greater`, cleared to 0; the camera's `far` is ignored.
    ReversedInfinite,
}

impl DepthConvention {
    /// The depth the frame is cleared to (nothing drawn).
    pub fn clear_depth(self) -> f32 {
        match self {
            Self::Standard => 1.0,
            Self::ReversedInfinite => 0.0,
        }
    }

    /// Whether depth `a` is nearer the camera than depth `b`.
    pub fn nearer(self, a: f32, b: f32) -> bool {
        match self {
            Self::Standard => a < b,
            Self::ReversedInfinite => a > b,
        }
    }
}

/// A perspective pinhole camera and the image size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// World-space eye position.
    pub eye: Vec3,
    /// World-space point looked at (the image centre).
    pub target: Vec3,
    /// World-space up direction (the image's up, after orthogonalisation).
    pub up: Vec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f32,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Distance of the near clipping plane (> 0).
    pub near: f32,
    /// Distance of the far clipping plane (> near; unused by
    /// [`DepthConvention::ReversedInfinite`]).
    pub far: f32,
}

/// [`Camera::look_at`]'s near plane as a fraction of the eye–target distance.
const NEAR_FRACTION: f32 = 1e-2;
/// [`Camera::look_at`]'s far plane as a multiple of the eye–target distance.
const FAR_MULTIPLE: f32 = 1e2;
/// Margin of [`Camera::framing`]: the bounding sphere fills 1/FRAMING_MARGIN of the narrower
/// field of view (tuned by eye on the demo: the cloth and ball with a little air around).
pub const FRAMING_MARGIN: f32 = 1.08;

/// The default direction from the subject towards the eye for [`Camera::framing`]: in front,
/// a little above and to the right, so that a cloth draped over a ball shows its folds and the
/// floor (scene files' `[camera] direction`, strips, `cloth-vis visibility --render`).
pub const DEFAULT_VIEW_DIRECTION: Vec3 = Vec3::new(0.55, 0.45, 1.0);
/// The default vertical field of view in degrees (a normal lens on a 35 mm frame).
pub const DEFAULT_FOV_Y_DEG: f32 = 35.0;

impl Camera {
    /// A camera at `eye` looking at `target`, with clipping planes at 1/100 and 100 times the
    /// eye–target distance (set `near`/`far` to change them).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> Self {
        let distance = eye.distance(target);
        Self {
            eye,
            target,
            up,
            fov_y_deg,
            width,
            height,
            near: NEAR_FRACTION * distance,
            far: FAR_MULTIPLE * distance,
        }
    }

    /// A camera looking at `target` from along `direction` (from the target towards the
    /// eye), far enough that the sphere (`centre`, `radius`) fills the narrower field of view
    /// up to [`FRAMING_MARGIN`], with near and far planes hugging the sphere.
    #[allow(clippy::too_many_arguments)]
    pub fn framing(
        centre: Vec3,
        radius: f32,
        target: Vec3,
        direction: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
    ) -> Self {
        let radius = usable_radius(radius);
        let fov = fov_y_deg.to_radians();
        let aspect = width as f32 / height.max(1) as f32;
        let half = (fov * 0.5).min((aspect * (fov * 0.5).tan()).atan());
        let distance = FRAMING_MARGIN * radius / half.sin();
        let eye = target + direction.try_normalize().unwrap_or(Vec3::Z) * distance;
        Self::looking_at_sphere(eye, target, up, fov_y_deg, width, height, centre, radius)
    }

    /// A camera at `eye` looking at `target` whose near and far planes enclose the sphere
    /// (`centre`, `radius`) with half a radius to spare.
    #[allow(clippy::too_many_arguments)]
    pub fn looking_at_sphere(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        fov_y_deg: f32,
        width: u32,
        height: u32,
        centre: Vec3,
        radius: f32,
    ) -> Self {
        let distance = (eye - centre).length();
        // Relative to the scene alone (an eye inside the sphere still gets a near plane).
        let near = (distance - 1.5 * radius).max(distance.max(radius) * 1e-3);
        let far = (distance + 1.5 * radius).max(near * 2.0);
        Self {
            eye,
            target,
            up: up.try_normalize().unwrap_or(Vec3::Y),
            fov_y_deg,
            width,
            height,
            near,
            far,
        }
    }

    /// Checks that the camera makes an image.
    ///
    /// # Errors
    /// [`CameraError`] for an empty image, a field of view outside (0°, 180°), non-finite
    /// vectors, eye = target, `up` parallel to the view direction, or clipping planes not
    /// 0 < near < far < ∞.
    pub fn validate(&self) -> Result<(), CameraError> {
        let bad = |name, value: String, reason| {
            Err(CameraError {
                name,
                value,
                reason,
            })
        };
        if self.width == 0 || self.height == 0 {
            let size = format!("{} × {}", self.width, self.height);
            return bad("width × height", size, "the image must not be empty");
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            let fov = self.fov_y_deg.to_string();
            return bad("fov_y_deg", fov, "the field of view must be in (0°, 180°)");
        }
        for (name, v) in [("eye", self.eye), ("target", self.target), ("up", self.up)] {
            if !v.is_finite() {
                return bad(name, v.to_string(), "must be finite");
            }
        }
        let forward = self.target - self.eye;
        if forward.length_squared() == 0.0 {
            let t = self.target.to_string();
            return bad("target", t, "must differ from the eye");
        }
        if forward.cross(self.up).length_squared() <= f32::EPSILON * forward.length_squared() {
            return bad(
                "up",
                self.up.to_string(),
                "must be non-zero and not parallel to the view direction",
            );
        }
        if !(self.near > 0.0 && self.far > self.near && self.far.is_finite()) {
            let planes = format!("near {} far {}", self.near, self.far);
            return bad(
                "near, far",
                planes,
                "clipping planes need 0 < near < far < ∞",
            );
        }
        Ok(())
    }

    /// `view_from_world`: glam's right-handed look-at.
    pub fn view_from_world(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// `perspective(fov_y, width/height, near, far) · look_at(eye, target, up)` with the
    /// [`DepthConvention::Standard`] depth (near → 0, far → 1).
    ///
    /// # Errors
    /// As [`Camera::validate`].
    pub fn clip_from_world(&self) -> Result<Mat4, CameraError> {
        self.clip_from_world_with(DepthConvention::Standard)
    }

    /// The clip transform for a depth convention; [`DepthConvention::ReversedInfinite`] maps
    /// near → 1 and infinity → 0 (a point at view depth d gets z/w = near / d).
    ///
    /// # Errors
    /// As [`Camera::validate`].
    pub fn clip_from_world_with(&self, depth: DepthConvention) -> Result<Mat4, CameraError> {
        self.validate()?;
        let aspect = self.width as f32 / self.height as f32;
        let fov = self.fov_y_deg.to_radians();
        let clip_from_view = match depth {
            DepthConvention::Standard => {
                glam::camera::rh::proj::directx::perspective(fov, aspect, self.near, self.far)
            }
            DepthConvention::ReversedInfinite => {
                glam::camera::rh::proj::directx::perspective_infinite_reverse(
                    fov, aspect, self.near,
                )
            }
        };
        Ok(clip_from_view * self.view_from_world())
    }
}

/// `radius` where it is positive and finite, else 1 (a single point, or an empty scene): the
/// radius to frame, zoom and size things by. Any positive radius is kept as it is — an
/// absolute floor (10⁻⁶ here, 10⁻⁴ on the near plane) once clipped away every mesh under
/// 10⁻⁴ across.
pub fn usable_radius(radius: f32) -> f32 {
    if radius > 0.0 && radius.is_finite() {
        radius
    } else {
        1.0
    }
}

/// Bounding sphere (centre of the box, half its diagonal) of a set of points; `None` when empty.
pub fn bounding_sphere<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Option<(Vec3, f32)> {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut any = false;
    for p in points {
        lo = lo.min(*p);
        hi = hi.max(*p);
        any = true;
    }
    any.then(|| ((lo + hi) * 0.5, (hi - lo).length() * 0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framed_sphere_projects_inside_the_image_for_both_depth_conventions() {
        let centre = Vec3::new(5.0, 1.0, -2.0);
        let cam = Camera::framing(centre, 2.0, centre, Vec3::Z, Vec3::Y, 35.0, 300, 200);
        for depth in [DepthConvention::Standard, DepthConvention::ReversedInfinite] {
            let m = cam.clip_from_world_with(depth).unwrap();
            for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
                let p = m.project_point3(centre + d * 2.0);
                assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
                assert!(p.z > 0.0 && p.z < 1.0, "{p}");
            }
            // Nearer points win under the convention's own comparison.
            let near = m.project_point3(centre + Vec3::Z * 2.0).z;
            let far = m.project_point3(centre - Vec3::Z * 2.0).z;
            assert!(depth.nearer(near, far), "{depth:?}: {near} vs {far}");
        }
    }

    #[test]
    fn reversed_infinite_depth_is_near_over_distance() {
        let cam = Camera::look_at(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0, 64, 64);
        let m = cam
            .clip_from_world_with(DepthConvention::ReversedInfinite)
            .unwrap();
        for d in [cam.near, 1.0, 10.0, 1e6] {
            let z = m.project_point3(Vec3::new(0.0, 0.0, -d)).z;
            assert!(
                (z - cam.near / d).abs() <= 1e-6 * (cam.near / d).max(1e-3),
                "{d}: {z}"
            );
        }
        // A point at infinity (w = 0) lands on depth 0.
        let clip = m * glam::Vec4::new(0.0, 0.0, -1.0, 0.0);
        assert_eq!(clip.z, 0.0);
    }

    #[test]
    fn bad_cameras_name_the_field() {
        let ok = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 8, 8);
        let cases = [
            (Camera { width: 0, ..ok }, "width × height"),
            (
                Camera {
                    fov_y_deg: 180.0,
                    ..ok
                },
                "fov_y_deg",
            ),
            (
                Camera {
                    eye: Vec3::NAN,
                    ..ok
                },
                "eye",
            ),
            (
                Camera {
                    target: ok.eye,
                    ..ok
                },
                "target",
            ),
            (Camera { up: Vec3::Z, ..ok }, "up"),
            (Camera { far: ok.near, ..ok }, "near, far"),
        ];
        for (cam, name) in cases {
            assert_eq!(cam.clip_from_world().unwrap_err().name, name);
        }
    }
}
