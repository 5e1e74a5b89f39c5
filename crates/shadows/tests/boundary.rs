//! Eq. 5.6 against the worked values of SEED-NOTES §3.3, and its smooth boundary against the
//! analytic terminator on spheres of rising tessellation.

mod common;

use common::sphere;
use glam::{DVec3, Vec3};
use shadows::boundary::{BoundaryMode, BoundaryTexture, boundary_coordinates, contour_points};
use shadows::{Light, boundary_u};

#[test]
fn eq_5_6_gives_the_worked_values_at_alpha_15() {
    let alpha = 15f64.to_radians();
    let n = DVec3::Y;
    for (deg, u) in [
        (0.0, 0.982963),
        (30.0, 0.853553),
        (60.0, 0.629410),
        (75.0, 0.5),
        (90.0, 0.370590),
        (120.0, 0.146447),
        (165.0, 0.0),
        (180.0, 0.017037),
    ] {
        let t = f64::to_radians(deg);
        let l = DVec3::new(t.sin(), t.cos(), 0.0) * 3.0; // length must not matter
        let got = boundary_u(n, l, alpha, BoundaryMode::Cosine);
        assert!((got - u).abs() < 5e-7, "{deg}°: {got} vs {u}");
    }
}

#[test]
fn the_two_readings_place_an_edge_crossing_differently() {
    // θ1 = 60°, θ2 = 100°, α = 0: angle-linear t = 0.75, eq. 5.6 t = 0.742 (SEED-NOTES §3.4).
    let u = |deg: f64, mode| {
        let t = deg.to_radians();
        boundary_u(DVec3::Y, DVec3::new(t.sin(), t.cos(), 0.0), 0.0, mode)
    };
    let crossing = |mode| {
        let (u1, u2) = (u(60.0, mode), u(100.0, mode));
        (u1 - 0.5) / (u1 - u2)
    };
    assert!((crossing(BoundaryMode::AngleLinear) - 0.75).abs() < 1e-12);
    let cosine = crossing(BoundaryMode::Cosine);
    let expected =
        60f64.to_radians().cos() / (60f64.to_radians().cos() - 100f64.to_radians().cos());
    assert!(
        (cosine - expected).abs() < 1e-12 && (cosine - 0.742).abs() < 1e-3,
        "{cosine}"
    );
}

#[test]
fn the_textures_are_a_step_and_a_ramp_without_the_tail() {
    let step = BoundaryTexture::step(1024);
    assert_eq!(step.texels().len(), 1024);
    assert_eq!(step.texels().iter().sum::<f32>(), 512.0);
    assert_eq!((step.sample(0.499), step.sample(0.501)), (0.0, 1.0));
    let ramp = BoundaryTexture::blurred(1024, 0.2, 15.0).unwrap();
    assert!(ramp.texels().windows(2).all(|w| w[1] >= w[0]), "monotone");
    assert_eq!(ramp.sample(0.39), 0.0);
    assert!((ramp.sample(0.5) - 0.5).abs() < 0.01);
    assert_eq!(ramp.sample(0.61), 1.0);
    // A blur as wide as the whole texture would lift eq. 5.6's tail (u ≤ 0.017 at α = 15°).
    let wide = BoundaryTexture::blurred(1024, 1.0, 15.0).unwrap();
    assert_eq!(wide.sample(0.01), 0.0);
    assert!(wide.sample(0.02) > 0.0);
    assert!(BoundaryTexture::blurred(1024, 1.5, 15.0).is_err());
    assert!(BoundaryTexture::blurred(1024, 0.1, 90.0).is_err());
}

/// Largest angular error (degrees) of the u = ½ contour against the small circle at 90° − α.
fn contour_error(detail: u32, alpha_deg: f64, mode: BoundaryMode) -> (f64, usize) {
    let (positions, triangles) = sphere(Vec3::ZERO, 1.0, detail);
    let normals: Vec<Vec3> = positions.iter().map(|p| p.normalize()).collect();
    let d = DVec3::new(0.3, 0.8, 0.5).normalize();
    let mut u = Vec::new();
    boundary_coordinates(
        &positions,
        &normals,
        &Light::Directional(d),
        alpha_deg,
        mode,
        &mut u,
    )
    .unwrap();
    let points = contour_points(&positions, &triangles, &u, 0.5);
    let target = 90.0 - alpha_deg;
    let worst = points
        .iter()
        .map(|p| (p.normalize().dot(d).clamp(-1.0, 1.0).acos().to_degrees() - target).abs())
        .fold(0.0, f64::max);
    (worst, points.len())
}

#[test]
fn the_smooth_boundary_converges_to_the_small_circle_at_90_minus_alpha() {
    for mode in [BoundaryMode::Cosine, BoundaryMode::AngleLinear] {
        for alpha in [0.0, 15.0] {
            let errors: Vec<f64> = (1..=5).map(|s| contour_error(s, alpha, mode).0).collect();
            eprintln!("{mode:?} α {alpha}: {errors:?}");
            // Each level halves the edges; the error falls at least 2× per level (2.5–4.4× measured) — unless it
            // is already at f32 noise (eq. 5.6 with α = 0 interpolates n·l, which is linear
            // on the sphere, so its contour lies exactly on the terminator's plane).
            for w in errors.windows(2) {
                assert!(
                    w[1] < w[0] / 2.0 || w[1] < 1e-4,
                    "{mode:?} α {alpha}: {errors:?}"
                );
            }
            assert!(errors[4] < 0.05, "{mode:?} α {alpha}: {errors:?}");
        }
    }
}
