//! A triangle mesh of the obstacle, to render beside the cloth.

use super::params::Obstacle;
use glam::Vec3;
use std::collections::HashMap;

/// Largest subdivision level of [`obstacle_mesh`] (20 · 4⁷ ≈ 330k triangles).
pub const MAX_OBSTACLE_DETAIL: u32 = 7;

/// Triangulates `obstacle`: for a sphere, an icosphere with `detail` subdivision levels
/// (0 → the icosahedron, 20 triangles; each level × 4; values above
/// [`MAX_OBSTACLE_DETAIL`] are clamped). Triangles are counter-clockwise seen from
/// outside. Returns `(positions, triangles)` in world space.
///
/// # Examples
/// ```
/// let (positions, triangles) = synth::obstacle_mesh(&synth::ClothParams::default().obstacle, 2);
/// assert_eq!(triangles.len(), 20 * 16);
/// assert_eq!(positions.len(), 10 * 16 + 2);
/// ```
pub fn obstacle_mesh(obstacle: &Obstacle, detail: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    match *obstacle {
        Obstacle::Sphere { centre, radius } => {
            let (unit, triangles) = icosphere(detail.min(MAX_OBSTACLE_DETAIL));
            let positions = unit.iter().map(|d| centre + *d * radius).collect();
            (positions, triangles)
        }
    }
}

/// Unit icosphere: vertices on the unit sphere and outward-facing triangles.
fn icosphere(detail: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let t = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut vertices: Vec<Vec3> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .into_iter()
    .map(|v| Vec3::from_array(v).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..detail {
        let mut midpoints: HashMap<(u32, u32), u32> = HashMap::new();
        let mut midpoint = |a: u32, b: u32, vertices: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                vertices.push((vertices[a as usize] + vertices[b as usize]).normalize());
                (vertices.len() - 1) as u32
            })
        };
        let mut finer = Vec::with_capacity(triangles.len() * 4);
        for &[a, b, c] in &triangles {
            let ab = midpoint(a, b, &mut vertices);
            let bc = midpoint(b, c, &mut vertices);
            let ca = midpoint(c, a, &mut vertices);
            finer.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = finer;
    }
    (vertices, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed_outward_and_encloses_the_right_volume() {
        let (centre, radius) = (Vec3::new(1.0, 2.0, 3.0), 0.5);
        let (p, t) = obstacle_mesh(&Obstacle::Sphere { centre, radius }, 4);
        assert_eq!(t.len(), 20 * 4usize.pow(4));
        // Euler characteristic of a closed sphere: V − E + F = 2 with E = 3F/2.
        assert_eq!(p.len() as i64 - 3 * t.len() as i64 / 2 + t.len() as i64, 2);
        // Signed volume (divergence theorem, f64) approaches 4/3 π r³ from below.
        let volume: f64 = t
            .iter()
            .map(|&[a, b, c]| {
                let [a, b, c] = [a, b, c].map(|i| (p[i as usize] - centre).as_dvec3());
                a.dot(b.cross(c)) / 6.0
            })
            .sum();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * 0.125;
        assert!(
            volume > 0.99 * exact && volume < exact,
            "volume {volume} vs {exact}"
        );
        for q in &p {
            assert!(((*q - centre).length() - radius).abs() < 1e-6);
        }
    }
}
