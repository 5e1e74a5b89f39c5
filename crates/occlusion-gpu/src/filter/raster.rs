//! The CPU reference of the triangle-id pass: the triangles that cover at least one pixel
//! centre after the depth test, rasterised with an inclusive edge rule (see `visible.rs`).

use glam::{DVec3, Vec4};

use super::camera::{Camera, prepare};
use super::triangle_set::TriangleSet;
use crate::{OcclusionError, Scene};

/// The triangles that cover at least one pixel centre of `camera`'s target after the depth
/// test, rasterised on the CPU (the reference of [`crate::TriangleIdRenderer`]; see its module docs).
///
/// # Errors
/// An invalid camera ([`OcclusionError::InvalidParameter`]) or scene (as
/// [`crate::VisibilityEngine::compute`]).
pub fn visible_triangles_cpu(
    scene: &Scene,
    camera: &Camera,
) -> Result<TriangleSet, OcclusionError> {
    let total = scene.triangle_count();
    let Some((prepared, clip_from_centred)) = prepare(scene, camera)? else {
        return Ok(TriangleSet::empty(total));
    };
    let clip: Vec<Vec4> = prepared
        .positions
        .iter()
        .map(|p| clip_from_centred * p.extend(1.0))
        .collect();
    let (w, h) = (camera.width as usize, camera.height as usize);
    let mut depth = vec![1.0f32; w * h];
    let mut ids = vec![0u32; w * h];
    for (t, tri) in prepared.triangles.iter().enumerate() {
        let polygon = clip_polygon(tri.map(|i| clip[i as usize]));
        // Screen space: pixel (x, y) has its centre at (x + 0.5, y + 0.5), y down.
        let screen: Vec<DVec3> = polygon
            .iter()
            .map(|c| {
                let ndc = c.truncate().as_dvec3() / f64::from(c.w);
                DVec3::new(
                    (ndc.x + 1.0) * 0.5 * w as f64,
                    (1.0 - ndc.y) * 0.5 * h as f64,
                    ndc.z,
                )
            })
            .collect();
        for k in 1..screen.len().saturating_sub(1) {
            raster_triangle(
                [screen[0], screen[k], screen[k + 1]],
                (w, h),
                t as u32 + 1,
                &mut depth,
                &mut ids,
            );
        }
    }
    let mut set = TriangleSet::empty(total);
    for &id in ids.iter().filter(|&&id| id != 0) {
        set.insert(id as usize - 1);
    }
    Ok(set)
}

/// Clips a clip-space triangle to 0 ≤ z ≤ w (near and far planes; x and y are clipped by the
/// pixel loop), returning a convex polygon (empty when fully outside).
fn clip_polygon(triangle: [Vec4; 3]) -> Vec<Vec4> {
    let mut polygon = triangle.to_vec();
    let planes: [fn(Vec4) -> f32; 2] = [|c| c.z, |c| c.w - c.z];
    for plane in planes {
        let mut out = Vec::with_capacity(polygon.len() + 1);
        for (i, &a) in polygon.iter().enumerate() {
            let b = polygon[(i + 1) % polygon.len()];
            let (da, db) = (plane(a), plane(b));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
        polygon = out;
        if polygon.is_empty() {
            break;
        }
    }
    polygon
}

/// Rasterises one screen-space triangle (x, y pixels; z NDC depth) at pixel centres with an
/// inclusive edge rule and a `Less` depth test.
fn raster_triangle(
    v: [DVec3; 3],
    (w, h): (usize, usize),
    id: u32,
    depth: &mut [f32],
    ids: &mut [u32],
) {
    let edge =
        |a: DVec3, b: DVec3, x: f64, y: f64| (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
    let area = edge(v[0], v[1], v[2].x, v[2].y);
    if area == 0.0 || !area.is_finite() {
        return;
    }
    let lo = v[0].min(v[1]).min(v[2]);
    let hi = v[0].max(v[1]).max(v[2]);
    let x0 = (lo.x - 0.5).ceil().max(0.0) as usize;
    let y0 = (lo.y - 0.5).ceil().max(0.0) as usize;
    let x1 = ((hi.x - 0.5).floor()).min(w as f64 - 1.0);
    let y1 = ((hi.y - 0.5).floor()).min(h as f64 - 1.0);
    if x1 < 0.0 || y1 < 0.0 {
        return;
    }
    for y in y0..=y1 as usize {
        let py = y as f64 + 0.5;
        for x in x0..=x1 as usize {
            let px = x as f64 + 0.5;
            let b0 = edge(v[1], v[2], px, py) / area;
            let b1 = edge(v[2], v[0], px, py) / area;
            let b2 = edge(v[0], v[1], px, py) / area;
            if b0 < 0.0 || b1 < 0.0 || b2 < 0.0 {
                continue;
            }
            let z = (b0 * v[0].z + b1 * v[1].z + b2 * v[2].z) as f32;
            let pixel = y * w + x;
            if z < depth[pixel] {
                depth[pixel] = z;
                ids[pixel] = id;
            }
        }
    }
}
