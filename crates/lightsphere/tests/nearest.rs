//! Nearest-direction queries are exactly the linear scan (same arg-max, same tie rule), on
//! random directions, on Voronoi edges and vertices, at the poles and cube seams, and for
//! rotated lightspheres.

mod common;

use common::Rng;
use glam::{DVec3, Quat, Vec3};
use lightsphere::Lightsphere;
use proptest::prelude::*;

/// The best dot product over all directions, computed independently.
fn best_dot(s: &Lightsphere, q: DVec3) -> f64 {
    s.directions_f64()
        .iter()
        .map(|l| l.dot(q))
        .fold(f64::NEG_INFINITY, f64::max)
}

#[track_caller]
fn assert_exact(s: &Lightsphere, q: DVec3) {
    let fast = s.nearest_f64(q);
    let linear = s.nearest_linear_f64(q);
    assert_eq!(fast, linear, "level {} query {q:?}", s.level());
    let qn = q.normalize();
    assert!(s.directions_f64()[fast].dot(qn) >= best_dot(s, qn) - 1e-14);
}

fn unit_vector() -> impl Strategy<Value = DVec3> {
    (-1.0f64..=1.0, 0.0f64..std::f64::consts::TAU).prop_map(|(z, phi)| {
        let r = (1.0 - z * z).sqrt();
        DVec3::new(r * phi.cos(), z, r * phi.sin())
    })
}

fn quaternion() -> impl Strategy<Value = Quat> {
    (unit_vector(), -4.0f64..4.0)
        .prop_map(|(axis, angle)| Quat::from_axis_angle(axis.as_vec3(), angle as f32))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn nearest_equals_linear_scan(level in 0u32..=5, q in unit_vector()) {
        let s = Lightsphere::new(level).unwrap();
        assert_exact(&s, q);
        prop_assert_eq!(s.nearest(q.as_vec3()), s.nearest_linear(q.as_vec3()));
    }

    #[test]
    fn nearest_equals_linear_scan_when_rotated(level in 0u32..=4, rot in quaternion(), q in unit_vector()) {
        let s = Lightsphere::new(level).unwrap().rotated(rot);
        assert_exact(&s, q);
    }

    #[test]
    fn nearest_ignores_the_query_length(level in 0u32..=4, q in unit_vector(), scale in -30i32..30) {
        let s = Lightsphere::new(level).unwrap();
        let f = 10f64.powi(scale);
        prop_assert_eq!(s.nearest_f64(q * f), s.nearest_linear_f64(q * f));
    }

    #[test]
    fn rotation_preserves_weights_and_angles(level in 0u32..=3, rot in quaternion()) {
        let s = Lightsphere::new(level).unwrap();
        let r = s.rotated(rot);
        prop_assert_eq!(r.solid_angles(), s.solid_angles());
        let (a, b) = (s.directions_f64(), r.directions_f64());
        for i in (0..s.len()).step_by(5) {
            prop_assert!((b[i].length() - 1.0).abs() < 1e-14);
            for j in (0..s.len()).step_by(7) {
                prop_assert!((b[i].dot(b[j]) - a[i].dot(a[j])).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn every_direction_is_its_own_nearest() {
    for level in 0..=6 {
        let s = Lightsphere::new(level).unwrap();
        for (j, &l) in s.directions_f64().iter().enumerate() {
            assert_eq!(s.nearest_f64(l), j);
        }
        for (j, &l) in s.directions().iter().enumerate() {
            assert_eq!(s.nearest(l), j, "f32 direction {j} at level {level}");
        }
    }
}

/// Points on Voronoi edges (equidistant from two directions) and at Voronoi vertices
/// (circumcentres of Delaunay triangles, equidistant from three or four).
#[test]
fn cell_borders_and_vertices_match_the_linear_scan() {
    for level in 0..=4 {
        let s = Lightsphere::new(level).unwrap();
        let d = s.directions_f64().to_vec();
        for t in s.delaunay_triangles() {
            let [a, b, c] = t.map(|i| d[i as usize]);
            assert_exact(&s, (b - a).cross(c - a));
            assert_exact(&s, a + b);
            assert_exact(&s, (a + b).normalize());
            assert_exact(&s, a + b + c);
        }
    }
}

#[test]
fn cell_borders_at_level_six_match_the_linear_scan() {
    let s = Lightsphere::new(6).unwrap();
    let d = s.directions_f64().to_vec();
    for t in s.delaunay_triangles().iter().step_by(41) {
        let [a, b, c] = t.map(|i| d[i as usize]);
        assert_exact(&s, (b - a).cross(c - a));
        assert_exact(&s, a + b);
    }
}

#[test]
fn poles_axes_and_cube_seams_match_the_linear_scan() {
    let mut queries = vec![];
    for x in [-1.0, -0.5, 0.0, 0.5, 1.0] {
        for y in [-1.0, -0.5, 0.0, 0.5, 1.0] {
            for z in [-1.0, -0.5, 0.0, 0.5, 1.0] {
                queries.push(DVec3::new(x, y, z));
            }
        }
    }
    queries.push(DVec3::new(1.0, 1e-300, -1e-300));
    queries.push(DVec3::new(-0.0, 1.0, 0.0));
    for level in 0..=6 {
        let s = Lightsphere::new(level).unwrap();
        for &q in &queries {
            if q != DVec3::ZERO {
                assert_exact(&s, q);
            }
        }
        assert_eq!(s.nearest(Vec3::Y), 2);
        assert_eq!(s.nearest(Vec3::NEG_Y), 3);
    }
}

#[test]
fn random_queries_at_level_six_and_seven() {
    let mut rng = Rng::new(11);
    for level in [6, 7] {
        let s = Lightsphere::new(level).unwrap();
        for _ in 0..300 {
            assert_exact(&s, rng.unit());
        }
    }
}

#[test]
fn invalid_queries_give_index_zero() {
    let s = Lightsphere::new(2).unwrap();
    for q in [
        Vec3::ZERO,
        Vec3::NAN,
        Vec3::new(f32::INFINITY, 0.0, 0.0),
        Vec3::new(0.0, f32::NEG_INFINITY, 1.0),
    ] {
        assert_eq!(s.nearest(q), 0);
        assert_eq!(s.nearest_linear(q), 0);
        assert_eq!(s.try_nearest(q), None);
    }
    assert_eq!(s.try_nearest(Vec3::Z), Some(4));
}
