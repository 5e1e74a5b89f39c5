//! The lightsphere's defining properties: counts, nesting, unit norms, triangle tiling,
//! Voronoi solid angles (against an independent clip-based construction), symmetry, rotation.

mod common;

use common::{Rng, assert_close, clipped_voronoi_cell, girard_area, octahedral_symmetries};
use glam::{DVec3, Quat};
use lightsphere::{Lightsphere, LightsphereError, MAX_LEVEL, direction_count};
use std::collections::HashMap;
use std::f64::consts::PI;

const FOUR_PI: f64 = 4.0 * PI;

#[test]
fn direction_counts_follow_k_equals_2_plus_4_to_the_s_plus_1() {
    let expected = [6, 18, 66, 258, 1026, 4098, 16386, 65538, 262_146];
    for (level, &k) in expected.iter().enumerate() {
        assert_eq!(direction_count(level as u32), k, "level {level}");
    }
    for level in 0..=6 {
        let s = Lightsphere::new(level).unwrap();
        assert_eq!(s.len(), direction_count(level));
        assert_eq!(s.level(), level);
        assert!(!s.is_empty());
        assert_eq!(
            s.triangles().len(),
            2 * 4usize.pow(level + 1),
            "faces at level {level}"
        );
        assert_eq!(s.solid_angles().len(), s.len());
    }
    assert_eq!(direction_count(40), usize::MAX);
}

#[test]
fn level_above_maximum_is_an_error_naming_it() {
    let err = Lightsphere::new(MAX_LEVEL + 1).unwrap_err();
    assert!(
        matches!(err, LightsphereError::LevelTooHigh { requested, maximum } if requested == MAX_LEVEL + 1 && maximum == MAX_LEVEL)
    );
    let msg = err.to_string();
    assert!(
        msg.contains(&(MAX_LEVEL + 1).to_string()) && msg.contains(&MAX_LEVEL.to_string()),
        "{msg}"
    );
}

#[test]
fn level_zero_is_the_octahedron() {
    let s = Lightsphere::new(0).unwrap();
    let expected = [
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    assert_eq!(s.directions_f64(), &expected);
    for &w in s.solid_angles() {
        assert_close(w, FOUR_PI / 6.0, 1e-14, "octahedron cell");
    }
}

#[test]
fn finer_levels_start_with_the_coarser_directions_in_order() {
    for level in 0..6 {
        let coarse = Lightsphere::new(level).unwrap();
        let fine = Lightsphere::new(level + 1).unwrap();
        assert_eq!(
            &fine.directions_f64()[..coarse.len()],
            coarse.directions_f64(),
            "level {level}"
        );
        assert_eq!(
            &fine.directions()[..coarse.len()],
            coarse.directions(),
            "level {level}"
        );
    }
}

#[test]
fn new_directions_are_projected_edge_midpoints_of_the_coarser_level() {
    for level in 0..4 {
        let coarse = Lightsphere::new(level).unwrap();
        let fine = Lightsphere::new(level + 1).unwrap();
        let mut edges = std::collections::HashSet::new();
        for t in coarse.triangles() {
            for i in 0..3 {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        assert_eq!(edges.len(), fine.len() - coarse.len());
        let d = coarse.directions_f64();
        for &(a, b) in &edges {
            let m = (d[a as usize] + d[b as usize]).normalize();
            let j = fine.nearest_linear_f64(m);
            assert!(j >= coarse.len(), "midpoint of {a}-{b} is an old direction");
            assert!((fine.directions_f64()[j] - m).length() < 1e-15);
        }
    }
}

#[test]
fn directions_are_unit_vectors() {
    let s = Lightsphere::new(6).unwrap();
    for (d64, d32) in s.directions_f64().iter().zip(s.directions()) {
        assert_close(d64.length(), 1.0, 4.0 * f64::EPSILON, "f64 norm");
        assert_close(
            f64::from(d32.length()),
            1.0,
            4.0 * f64::from(f32::EPSILON),
            "f32 norm",
        );
    }
}

#[test]
fn triangles_tile_the_sphere_counter_clockwise() {
    for level in 0..=5 {
        let s = Lightsphere::new(level).unwrap();
        let d = s.directions_f64();
        let mut edge_use: HashMap<(u32, u32), usize> = HashMap::new();
        let mut area = 0.0;
        for t in s.triangles() {
            let [a, b, c] = t.map(|i| d[i as usize]);
            assert!(
                (b - a).cross(c - a).dot(a + b + c) > 0.0,
                "clockwise face {t:?}"
            );
            area += girard_area(&[a, b, c]);
            for i in 0..3 {
                *edge_use.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
            }
        }
        assert!(
            edge_use.values().all(|&n| n == 1),
            "repeated half-edge at level {level}"
        );
        assert!(
            edge_use
                .keys()
                .all(|&(a, b)| edge_use.contains_key(&(b, a))),
            "open edge"
        );
        assert_close(area, FOUR_PI, 1e-10 * s.len() as f64, "triangle areas");
    }
}

#[test]
fn solid_angles_are_positive_and_sum_to_four_pi() {
    for level in 0..=6 {
        let s = Lightsphere::new(level).unwrap();
        assert!(s.solid_angles().iter().all(|&w| w > 0.0));
        let sum: f64 = s.solid_angles().iter().sum();
        assert_close(sum, FOUR_PI, 1e-9, &format!("Σω at level {level}"));
    }
}

#[test]
fn solid_angles_equal_independently_clipped_voronoi_cells() {
    for level in 0..=3 {
        let s = Lightsphere::new(level).unwrap();
        let d = s.directions_f64();
        for (i, &w) in s.solid_angles().iter().enumerate() {
            let cell = clipped_voronoi_cell(d, i);
            let reference = girard_area(&cell);
            assert_close(w, reference, 1e-11, &format!("cell {i} at level {level}"));
        }
    }
}

/// The weights are Voronoi areas, not a third of the adjacent subdivision triangles (which
/// differ by up to ~2 % at level 1).
#[test]
fn solid_angles_are_not_the_triangle_thirds() {
    let s = Lightsphere::new(1).unwrap();
    let d = s.directions_f64();
    let mut thirds = vec![0.0; s.len()];
    for t in s.triangles() {
        let a = girard_area(&t.map(|i| d[i as usize])) / 3.0;
        for &v in t {
            thirds[v as usize] += a;
        }
    }
    let max_rel = s
        .solid_angles()
        .iter()
        .zip(&thirds)
        .map(|(w, t)| (w - t).abs() / w)
        .fold(0.0, f64::max);
    assert!(
        max_rel > 0.005,
        "Voronoi and triangle-third weights agree to {max_rel}"
    );
}

#[test]
fn delaunay_triangles_have_empty_circumcircles() {
    for level in 0..=3 {
        let s = Lightsphere::new(level).unwrap();
        let d = s.directions_f64();
        assert_eq!(s.delaunay_triangles().len(), s.triangles().len());
        for t in s.delaunay_triangles() {
            let [a, b, c] = t.map(|i| d[i as usize]);
            let n = (b - a).cross(c - a).normalize();
            let plane = n.dot(a);
            for (j, p) in d.iter().enumerate() {
                if t.contains(&(j as u32)) {
                    continue;
                }
                assert!(
                    n.dot(*p) <= plane + 1e-12,
                    "direction {j} inside circumcircle of {t:?}"
                );
            }
        }
    }
}

#[test]
fn solid_angles_are_invariant_under_the_octahedral_group() {
    for level in 1..=5 {
        let s = Lightsphere::new(level).unwrap();
        let d = s.directions_f64();
        for m in octahedral_symmetries() {
            for (i, &p) in d.iter().enumerate() {
                let image = m * p;
                let j = s.nearest_linear_f64(image);
                assert!(
                    (d[j] - image).length() < 1e-12,
                    "symmetry image of {i} is not a direction"
                );
                let (wi, wj) = (s.solid_angles()[i], s.solid_angles()[j]);
                assert_close(wj, wi, 1e-12 * wi, &format!("ω of {i} vs its image {j}"));
            }
        }
    }
}

#[test]
fn rotation_keeps_order_weights_and_angles() {
    let s = Lightsphere::new(3).unwrap();
    let q = Quat::from_euler(glam::EulerRot::YXZ, 0.7, -1.1, 2.3);
    let r = s.rotated(q);
    assert_eq!(r.solid_angles(), s.solid_angles());
    assert_eq!(r.triangles(), s.triangles());
    assert_eq!(r.len(), s.len());
    let (a, b) = (s.directions_f64(), r.directions_f64());
    let q64 = q.as_dquat().normalize();
    for i in 0..s.len() {
        assert!((b[i] - q64 * a[i]).length() < 1e-12);
        for j in (0..s.len()).step_by(17) {
            assert_close(
                b[i].dot(b[j]),
                a[i].dot(a[j]),
                1e-12,
                "angle between directions",
            );
        }
    }
    // Rotations compose (up to the f32 rounding of the product q2 * q).
    let q2 = Quat::from_rotation_x(0.4);
    let twice = s.rotated(q).rotated(q2);
    let once = s.rotated(q2 * q);
    for (u, v) in twice.directions_f64().iter().zip(once.directions_f64()) {
        assert!((*u - *v).length() < 4.0 * f64::from(f32::EPSILON));
    }
}

#[test]
fn invalid_rotation_is_an_error() {
    let s = Lightsphere::new(1).unwrap();
    assert!(matches!(
        s.try_rotated(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)),
        Err(LightsphereError::InvalidRotation { .. })
    ));
    assert!(
        s.try_rotated(Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0))
            .is_err()
    );
    // A non-unit quaternion is normalised.
    let scaled = s.rotated(Quat::from_xyzw(0.0, 0.0, 0.0, 3.0));
    assert_eq!(scaled.directions_f64(), s.directions_f64());
}

#[test]
fn cached_levels_are_shared_and_cheap_to_clone() {
    let mut rng = Rng::new(7);
    let a = Lightsphere::new(4).unwrap();
    let b = a.clone();
    let q = rng.unit().as_vec3();
    assert_eq!(a.nearest(q), b.nearest(q));
    assert!(
        a.mean_candidates_per_query() < 8.0,
        "{}",
        a.mean_candidates_per_query()
    );
}
