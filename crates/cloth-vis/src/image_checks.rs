//! Results a run refuses instead of writing (issue #12): a camera that sees none of the objects
//! (checked on their bounding sphere before any stage runs, and on the rendered coverage), a
//! rendered image with non-finite pixels, and one whose every object pixel is black. Each was
//! a blank or black picture with exit status 0.

use glam::{Vec3, Vec4};
use gpu_context::HdrImage;
use render::Camera;

use crate::Error;
use crate::scene::Scene;

/// Whether the sphere (`centre`, `radius`) meets the camera's view frustum: its distance to
/// each side plane (from the clip matrix's rows, Gribb–Hartmann) is above −radius. An invalid
/// camera counts as seeing it (the renderer names the invalid value).
pub(crate) fn sphere_in_view(camera: &Camera, centre: Vec3, radius: f32) -> bool {
    let Ok(m) = camera.clip_from_world() else {
        return true;
    };
    let rows = [m.row(0), m.row(1), m.row(2), m.row(3)];
    // Left, right, bottom, top; near and far are placed around the sphere by the framing.
    let planes: [Vec4; 4] = [
        rows[3] + rows[0],
        rows[3] - rows[0],
        rows[3] + rows[1],
        rows[3] - rows[1],
    ];
    // Behind the eye: the whole sphere on the far side of the plane through the eye.
    let forward = (camera.target - camera.eye).normalize_or_zero();
    if (centre - camera.eye).dot(forward) < -radius {
        return false;
    }
    planes.iter().all(|p| {
        let n = p.truncate();
        let len = n.length();
        len == 0.0 || (n.dot(centre) + p.w) / len >= -radius
    })
}

/// Refuses a camera that sees none of the objects, before any work: the scene file and its
/// `[camera]` keys named, with the framing that would see them.
pub(crate) fn check_in_view(
    scene: &Scene,
    camera: &Camera,
    centre: Vec3,
    radius: f32,
) -> Result<(), Error> {
    // The resolved camera (e.g. an eye straight above the objects' centre with the default up)
    // refused by the scene's keys rather than later by the renderer.
    if let Err(e) = camera.validate() {
        let key = match e.name {
            "fov_y_deg" => "fov_deg",
            other => other,
        };
        return Err(Error::Scene {
            origin: scene.origin.clone(),
            message: format!(
                "camera.{key} = {} once framed on the objects (eye {}, target {}): {}",
                e.value, camera.eye, camera.target, e.reason
            ),
        });
    }
    if sphere_in_view(camera, centre, radius) {
        return Ok(());
    }
    Err(Error::Scene {
        origin: scene.origin.clone(),
        message: format!(
            "camera: no object is in view — camera.eye {} looking at camera.target {} misses \
             the objects' bounding sphere (centre {centre}, radius {radius}); aim \
             camera.target at them, or omit camera.eye to frame them",
            camera.eye, camera.target
        ),
    })
}

/// Alpha from which a pixel counts as covered by objects alone.
const FULLY_COVERED: f32 = 0.999;

/// Refuses a rendered image (of `frame` in a sequence) with a non-finite pixel, no object
/// pixel (coverage alpha 0 everywhere), or object pixels that are all black.
pub(crate) fn check_rendered(
    scene: &Scene,
    image: &HdrImage,
    frame: Option<usize>,
) -> Result<(), Error> {
    let which = frame.map_or_else(|| "the rendered image".to_owned(), |f| format!("frame {f}"));
    let refuse = |message: String| Error::Scene {
        origin: scene.origin.clone(),
        message: format!("{which}: {message}"),
    };
    let width = image.width() as usize;
    let pixels = image.pixels();
    let bad: Vec<usize> = (0..pixels.len())
        .filter(|&i| !pixels[i].iter().all(|v| v.is_finite()))
        .collect();
    if let Some(&first) = bad.first() {
        return Err(refuse(format!(
            "{} pixel(s) are NaN or infinite, the first at (x {}, y {}) = {:?}: a value \
             overflowed f32; check the scale of the environment and the objects",
            bad.len(),
            first % width,
            first / width,
            pixels[first]
        )));
    }
    // Coverage is the alpha channel; edge pixels (MSAA) mix in the background, so blackness is
    // judged on the fully covered ones.
    let (mut objects, mut inside, mut lit) = (0usize, 0usize, 0usize);
    for p in pixels.iter().filter(|p| p[3] > 0.0) {
        objects += 1;
        if p[3] >= FULLY_COVERED {
            inside += 1;
            lit += usize::from(p[0] > 0.0 || p[1] > 0.0 || p[2] > 0.0);
        }
    }
    if objects == 0 {
        return Err(refuse(
            "no object covers a pixel: the camera sees none of them (check camera.eye, \
             camera.target and camera.fov_deg, or omit camera.eye to frame them)"
                .to_owned(),
        ));
    }
    if inside > 0 && lit == 0 {
        return Err(refuse(format!(
            "all {inside} object pixels are black: the objects receive no light (a black \
             environment?) or have albedo 0"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(eye: Vec3, target: Vec3) -> Camera {
        Camera::looking_at_sphere(eye, target, Vec3::Y, 40.0, 64, 48, Vec3::ZERO, 1.0)
    }

    #[test]
    fn a_sphere_ahead_is_in_view_and_one_behind_or_beside_is_not() {
        let c = camera(Vec3::new(0.0, 0.0, 10.0), Vec3::ZERO);
        assert!(sphere_in_view(&c, Vec3::ZERO, 1.0));
        // Just past the left edge of a 40° (vertical) view, but touching it: in view.
        assert!(sphere_in_view(&c, Vec3::new(-5.0, 0.0, 0.0), 1.0));
        // Far beside, and behind the eye: out.
        assert!(!sphere_in_view(&c, Vec3::new(-50.0, 0.0, 0.0), 1.0));
        assert!(!sphere_in_view(&c, Vec3::new(0.0, 0.0, 30.0), 1.0));
        // Looking away from it.
        let away = camera(Vec3::new(0.0, 0.0, 50.0), Vec3::new(0.0, 0.0, 100.0));
        assert!(!sphere_in_view(&away, Vec3::ZERO, 1.0));
        // An eye inside the sphere sees it.
        assert!(sphere_in_view(&away, Vec3::new(0.0, 0.0, 50.5), 1.0));
    }
}
