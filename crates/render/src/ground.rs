//! The optional ground plane: a square grid under the scene.
//!
//! It is a real object, not a painted floor: the facade gives it to the visibility engine as a
//! receiver and occluder like any mesh, so per-vertex visibility darkens it under the cloth
//! (its resolution is the resolution of that shadow), and it is drawn by the Gouraud pass.

use glam::{Vec2, Vec3};

/// A horizontal (y = `height`) square grid centred under `centre`, `size` wide, with `cells`
/// × `cells` quads, normals +Y (counter-clockwise seen from above), UVs over [0, 1]².
///
/// Returns positions, triangles and UVs. `cells` is clamped to at least 1.
pub fn ground_grid(
    centre: Vec3,
    height: f32,
    size: f32,
    cells: u32,
) -> (Vec<Vec3>, Vec<[u32; 3]>, Vec<Vec2>) {
    let n = cells.max(1);
    let side = n + 1;
    let mut positions = Vec::with_capacity((side * side) as usize);
    let mut uvs = Vec::with_capacity(positions.capacity());
    for r in 0..side {
        for c in 0..side {
            let u = c as f32 / n as f32;
            let v = r as f32 / n as f32;
            positions.push(Vec3::new(
                centre.x + (u - 0.5) * size,
                height,
                centre.z + (v - 0.5) * size,
            ));
            uvs.push(Vec2::new(u, v));
        }
    }
    let mut triangles = Vec::with_capacity((2 * n * n) as usize);
    for r in 0..n {
        for c in 0..n {
            let a = r * side + c;
            let b = a + 1;
            let d = a + side;
            let e = d + 1;
            // Seen from +Y, x right and z down the screen: (a, d, b) turns counter-clockwise.
            triangles.push([a, d, b]);
            triangles.push([b, d, e]);
        }
    }
    (positions, triangles, uvs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_faces_up_and_covers_its_square() {
        let (p, t, uv) = ground_grid(Vec3::new(1.0, 5.0, -2.0), -0.5, 4.0, 8);
        assert_eq!(p.len(), 81);
        assert_eq!(uv.len(), 81);
        assert_eq!(t.len(), 128);
        let mut area = 0.0;
        for tri in &t {
            let [a, b, c] = tri.map(|i| p[i as usize]);
            let n = (b - a).cross(c - a);
            assert!(n.y > 0.0, "triangle {tri:?} faces down");
            area += 0.5 * n.length();
        }
        assert!((area - 16.0).abs() < 1e-4, "{area}");
        assert!(p.iter().all(|q| q.y == -0.5));
        let (lo, hi) = p
            .iter()
            .fold((Vec3::MAX, Vec3::MIN), |(l, h), q| (l.min(*q), h.max(*q)));
        assert_eq!((lo.x, hi.x, lo.z, hi.z), (-1.0, 3.0, -4.0, 0.0));
    }
}
