//! A scene's `[camera]` table resolved into the workspace's one camera, [`render::Camera`].

use glam::Vec3;
use render::Camera;

use crate::scene::CameraDesc;

/// Resolve a camera description against the scene's bounding sphere (`centre`, `radius`): an
/// omitted eye is framed from `direction` ([`Camera::framing`]), an omitted target is the
/// sphere's centre; near and far planes enclose the sphere.
pub fn resolve(desc: &CameraDesc, centre: Vec3, radius: f32) -> Camera {
    let target = desc.target.map_or(centre, Vec3::from);
    let up = Vec3::from(desc.up);
    match desc.eye {
        None => Camera::framing(
            centre,
            radius,
            target,
            Vec3::from(desc.direction),
            up,
            desc.fov_deg,
            desc.width,
            desc.height,
        ),
        Some(eye) => Camera::looking_at_sphere(
            Vec3::from(eye),
            target,
            up,
            desc.fov_deg,
            desc.width,
            desc.height,
            centre,
            radius.max(1e-6),
        ),
    }
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
        let centre = Vec3::new(5.0, 1.0, -2.0);
        let cam = resolve(&desc, centre, 2.0);
        let m = cam.clip_from_world().unwrap();
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z] {
            let p = m.project_point3(centre + d * 2.0);
            assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0, "{p}");
            assert!(p.z > 0.0 && p.z < 1.0, "{p}");
        }
    }
}
