//! Pinhole camera: framing from the scene's bounding sphere and the clip-space matrices.

use glam::{Mat4, Vec3};

use crate::scene::CameraDesc;

/// Margin of automatic framing: the bounding sphere fills 1/FRAMING_MARGIN of the view height.
const FRAMING_MARGIN: f32 = 1.08;

/// A resolved camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (world).
    pub eye: Vec3,
    /// Look-at point (world).
    pub target: Vec3,
    /// `clip_from_world` (wgpu depth range 0..1).
    pub clip_from_world: Mat4,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// Resolve a camera description against the scene's bounding sphere (`centre`, `radius`).
    pub fn frame(desc: &CameraDesc, centre: Vec3, radius: f32) -> Self {
        let radius = radius.max(1e-6);
        let fov = desc.fov_deg.to_radians();
        let aspect = desc.width as f32 / desc.height as f32;
        let target = desc.target.map_or(centre, Vec3::from);
        let eye = match desc.eye {
            Some(eye) => Vec3::from(eye),
            None => {
                // Fit the sphere in the narrower of the two fields of view.
                let half = (fov * 0.5).min((aspect * (fov * 0.5).tan()).atan());
                let distance = FRAMING_MARGIN * radius / half.sin();
                let dir = Vec3::from(desc.direction)
                    .try_normalize()
                    .unwrap_or(Vec3::Z);
                target + dir * distance
            }
        };
        let distance = (eye - centre).length();
        let near = (distance - 1.5 * radius).max(distance * 1e-3).max(1e-4);
        let far = distance + 1.5 * radius;
        let up = Vec3::from(desc.up).try_normalize().unwrap_or(Vec3::Y);
        let view = glam::camera::rh::view::look_at_mat4(eye, target, up);
        // wgpu clip space: y up, depth 0..1 — the DirectX convention.
        let proj = glam::camera::rh::proj::directx::perspective(fov, aspect, near, far);
        Self {
            eye,
            target,
            clip_from_world: proj * view,
            width: desc.width,
            height: desc.height,
        }
    }
}

/// Bounding sphere (centre of the box, half its diagonal) of a set of points.
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
    fn framed_sphere_projects_inside_the_image() {
        let desc = CameraDesc {
            width: 300,
            height: 200,
            ..CameraDesc::default()
        };
        let cam = Camera::frame(&desc, Vec3::new(5.0, 1.0, -2.0), 2.0);
        // Points on the bounding sphere land inside NDC [-1, 1]² with depth in (0, 1).
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let p = cam
                .clip_from_world
                .project_point3(Vec3::new(5.0, 1.0, -2.0) + d * 2.0);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
            assert!(p.z > 0.0 && p.z < 1.0, "{p}");
        }
    }
}
