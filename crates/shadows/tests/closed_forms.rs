//! The closed forms of SEED-NOTES §2.4: a sphere under a point light straight above casts a
//! disc of radius H·R/√((H − h)² − R²); under a directional light at zenith angle θ an
//! ellipse with semi-axes R and R/cos θ, centred h·tan θ away. A tessellated sphere lies between
//! its inscribed ball and the ball through its vertices, so its shadow lies between the two
//! balls' shadows: every cell is checked against that bracket (± half a cell diagonal), for the
//! exact ray mask, the volume's own winding number and the stencil mask.

mod common;

use common::*;
use glam::{DVec3, Vec3};
use shadows::volume::Sides;
use shadows::{GroundGrid, Light, exact_ground_mask};

/// Checks `mask` against the bracket: `inside(p, R)` ≤ 1 means p is in the shadow of the ball
/// of radius R (in units of the shadow's own scale).
fn check_bracket(
    name: &str,
    mask: &[f32],
    grid: &GroundGrid,
    r_in: f64,
    r_out: f64,
    rho: impl Fn(DVec3, f64) -> f64,
) {
    let half_diag =
        (grid.extent[2] - grid.extent[0]) / grid.n as f64 * std::f64::consts::FRAC_1_SQRT_2;
    let (mut sure_in, mut sure_out) = (0, 0);
    for j in 0..grid.n {
        for i in 0..grid.n {
            let p = grid.cell_centre(i, j);
            let v = mask[j * grid.n + i];
            if rho(p, r_in) < 1.0 - half_diag / r_in {
                sure_in += 1;
                assert_eq!(v, 1.0, "{name}: cell ({i}, {j}) at {p} must be in shadow");
            }
            if rho(p, r_out) > 1.0 + half_diag / r_out {
                sure_out += 1;
                assert_eq!(v, 0.0, "{name}: cell ({i}, {j}) at {p} must be lit");
            }
        }
    }
    // The bracket decides most cells, so the test cannot pass vacuously.
    assert!(
        sure_in > 1000 && sure_out > 1000,
        "{name}: {sure_in} in, {sure_out} out"
    );
}

fn check_all(
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    light: &Light,
    grid: &GroundGrid,
    r_in: f64,
    r_out: f64,
    rho: impl Fn(DVec3, f64) -> f64 + Copy,
) {
    let exact = exact_ground_mask(positions, triangles, light, grid).unwrap();
    check_bracket("exact rays", &exact, grid, r_in, r_out, rho);
    let winding = winding_mask(positions, triangles, light, Sides::One, grid);
    check_bracket("volume winding", &winding, grid, r_in, r_out, rho);
    let (far, near, boundary) = compare(&exact, &winding, grid.n);
    assert_eq!(far, 0, "volume winding vs rays away from the boundary");
    assert!(
        near * 20 <= boundary,
        "{near} of {boundary} boundary cells differ"
    );
    if let Some(stencil) = stencil_mask(positions, triangles, light, Sides::One, grid) {
        check_bracket("stencil", &stencil, grid, r_in, r_out, rho);
        let (far, near, boundary) = compare(&exact, &stencil, grid.n);
        assert_eq!(far, 0, "stencil vs rays away from the boundary");
        assert!(
            near * 20 <= boundary,
            "{near} of {boundary} boundary cells differ"
        );
    }
}

#[test]
fn sphere_under_a_point_light_casts_the_disc_of_radius_h_r_over_root() {
    let (radius, h, height) = (1.0f64, 2.0f64, 6.0f64);
    let centre = Vec3::new(0.0, h as f32, 0.0);
    let (positions, triangles) = sphere(centre, radius as f32, 4);
    let r_in = inscribed_radius(&positions, &triangles, centre);
    let light = Light::Point(DVec3::new(0.0, height, 0.0));
    let grid = GroundGrid::new(0.0, [-3.0, -3.0, 3.0, 3.0], 160).unwrap();
    let disc = |r: f64| height * r / ((height - h).powi(2) - r * r).sqrt();
    // ρ = distance / disc radius of a ball of radius r; the bracket's scale is the disc's.
    check_all(
        &positions,
        &triangles,
        &light,
        &grid,
        disc(r_in),
        disc(radius),
        |p, r| (p.x * p.x + p.z * p.z).sqrt() / r,
    );
    // The disc of the formula itself (R = 1: 6/√15 = 1.549) within the bracket.
    assert!((disc(radius) - 6.0 / 15f64.sqrt()).abs() < 1e-12);
}

#[test]
fn sphere_under_a_directional_light_casts_the_ellipse_r_by_r_over_cos_theta() {
    let (radius, h, theta) = (1.0f64, 2.0f64, 40f64.to_radians());
    let centre = Vec3::new(0.0, h as f32, 0.0);
    let (positions, triangles) = sphere(centre, radius as f32, 4);
    let r_in = inscribed_radius(&positions, &triangles, centre);
    let light = Light::Directional(DVec3::new(theta.sin(), theta.cos(), 0.0));
    let grid = GroundGrid::new(0.0, [-4.5, -3.0, 1.5, 3.0], 160).unwrap();
    let cx = -h * theta.tan();
    check_all(
        &positions,
        &triangles,
        &light,
        &grid,
        r_in,
        radius,
        |p, r| {
            // Semi-axes r/cos θ along x and r along z.
            (((p.x - cx) * theta.cos()).powi(2) + p.z * p.z).sqrt() / r
        },
    );
}
