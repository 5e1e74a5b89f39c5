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
            render::usable_radius(radius),
        ),
    }
}

/// A `width × height` camera looking at the sphere (`centre`, `radius`) from `direction`
/// (towards the camera) with `up`, the default field of view, the sphere framed and enclosed
/// by the near and far planes — the framing of the CLI's pictures and the repro figures.
pub fn frame_sphere(
    direction: Vec3,
    up: Vec3,
    centre: Vec3,
    radius: f32,
    width: u32,
    height: u32,
) -> Camera {
    let desc = CameraDesc {
        width,
        height,
        direction: direction.to_array(),
        up: up.to_array(),
        ..CameraDesc::default()
    };
    resolve(&desc, centre, radius)
}

/// The `[camera]` values no framing can fix, refused before any work as `(TOML key, problem)`:
/// non-finite or zero vectors, an eye on its target, an up vector along the view direction
/// (which the renderer would only find after every stage ran).
pub(crate) fn check_desc(desc: &CameraDesc) -> Result<(), (&'static str, String)> {
    let vectors = [
        ("camera.eye", desc.eye),
        ("camera.target", desc.target),
        ("camera.direction", Some(desc.direction)),
        ("camera.up", Some(desc.up)),
    ];
    for (key, v) in vectors {
        let Some(v) = v.map(Vec3::from) else { continue };
        if !v.is_finite() {
            return Err((key, format!("{v} is not finite")));
        }
        if v == Vec3::ZERO && matches!(key, "camera.direction" | "camera.up") {
            return Err((key, "[0, 0, 0] has no direction".to_owned()));
        }
    }
    let view = match (desc.eye, desc.target) {
        (Some(eye), Some(target)) if eye == target => {
            return Err((
                "camera.target",
                format!(
                    "{} is the eye's position; look somewhere else",
                    Vec3::from(target)
                ),
            ));
        }
        (Some(eye), Some(target)) => Vec3::from(target) - Vec3::from(eye),
        // The target (the objects' centre) is known only once they load.
        (Some(_), None) => return Ok(()),
        (None, _) => Vec3::from(desc.direction),
    };
    let up = Vec3::from(desc.up);
    if view.normalize().cross(up.normalize()).length() < 1e-3 {
        return Err((
            "camera.up",
            format!("{up} is parallel to the view direction {view}; pick an up vector across it"),
        ));
    }
    Ok(())
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

    #[test]
    fn degenerate_camera_values_name_their_key() {
        let check = |edit: fn(&mut CameraDesc)| {
            let mut desc = CameraDesc::default();
            edit(&mut desc);
            check_desc(&desc).err().map(|(key, _)| key)
        };
        assert_eq!(check(|_| {}), None);
        assert_eq!(check(|d| d.direction = [0.0; 3]), Some("camera.direction"));
        assert_eq!(check(|d| d.up = [0.0; 3]), Some("camera.up"));
        assert_eq!(
            check(|d| d.eye = Some([f32::NAN, 0.0, 0.0])),
            Some("camera.eye")
        );
        assert_eq!(
            check(|d| {
                d.eye = Some([1.0, 2.0, 3.0]);
                d.target = Some([1.0, 2.0, 3.0]);
            }),
            Some("camera.target")
        );
        assert_eq!(
            check(|d| {
                d.direction = [0.0, 2.0, 0.0];
                d.up = [0.0, 1.0, 0.0];
            }),
            Some("camera.up")
        );
        assert_eq!(
            check(|d| {
                d.eye = Some([0.0, 5.0, 0.0]);
                d.target = Some([0.0, 0.0, 0.0]);
            }),
            Some("camera.up")
        );
        // With an eye and no target, the view direction is known only after loading.
        assert_eq!(check(|d| d.eye = Some([0.0, 5.0, 0.0])), None);
    }
}
