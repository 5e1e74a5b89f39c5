//! A single rigidly rotated object is lit by rotated look-ups into its object-frame M
//! (paper 000 §6), which must equal recomputing M on the rotated mesh.

mod common;

use common::*;
use glam::{Mat4, Quat, Vec3};
use lightsphere::{Environment, Lightsphere, RadianceMethod};
use occlusion_gpu::{RigidLighting, Scene, VisibilityEngine, VisibilityParams};

/// A lat-long map with structure in every direction (so a wrong rotation shows).
fn striped_environment() -> Environment {
    let (w, h) = (128, 64);
    let texels = (0..w * h)
        .map(|t| {
            let (x, y) = ((t % w) as f32 / w as f32, (t / w) as f32 / h as f32);
            [
                1.0 + (6.0 * x).sin().abs() * 4.0,
                0.5 + y * 3.0,
                0.2 + ((3.0 * x + 5.0 * y).cos() + 1.0),
            ]
        })
        .collect();
    Environment::from_latlong(w, h, texels).unwrap()
}

fn rotated_scene(mesh: &TestMesh, rotation: Quat) -> Scene {
    let mut scene = Scene::new();
    scene
        .push(mesh.object().with_transform(Mat4::from_quat(rotation)))
        .unwrap();
    scene
}

/// A half-open box (a bowl): strong self-occlusion that depends on orientation.
fn bowl() -> TestMesh {
    let s = uv_sphere(Vec3::ZERO, 1.0, 12, 24);
    // Keep the lower hemisphere and a ring: triangles whose vertices all have y < 0.3.
    let keep: Vec<[u32; 3]> = s
        .triangles
        .iter()
        .copied()
        .filter(|t| t.iter().all(|&v| s.positions[v as usize].y < 0.3))
        .collect();
    TestMesh {
        normals: s.normals.clone(),
        positions: s.positions.clone(),
        triangles: keep,
    }
}

/// The bowl's M computed once in its own frame and lit turned by `rotation` (rotated
/// look-ups), beside M recomputed on the turned mesh and lit plainly: (rigid lighting, the
/// environment, looked-up c_i, recomputed c_i).
fn look_up_and_recompute(
    level: u32,
    rotation: Quat,
) -> (RigidLighting, Environment, Vec<Vec3>, Vec<Vec3>) {
    let mesh = bowl();
    let sphere = Lightsphere::new(level).unwrap();
    let env = striped_environment();
    let mut engine = VisibilityEngine::cpu(VisibilityParams::default());
    let object = engine
        .compute(&rotated_scene(&mesh, Quat::IDENTITY), &sphere)
        .unwrap();
    let rigid = RigidLighting::new(object, sphere.clone()).unwrap();
    let looked_up = rigid
        .radiance(&env, rotation, RadianceMethod::CellMean)
        .unwrap();
    let world = engine
        .compute(&rotated_scene(&mesh, rotation), &sphere)
        .unwrap();
    let radiance = env
        .radiance_per_direction(&sphere, RadianceMethod::CellMean)
        .unwrap();
    let recomputed = world
        .radiance(&sphere.light_weights(&radiance).unwrap())
        .unwrap();
    (rigid, env, looked_up, recomputed)
}

/// A rotation that maps the octahedral directions onto themselves (90° about y): the
/// rotated look-up must equal a recompute on the rotated mesh up to the cell means of the
/// rotated cells.
#[test]
fn symmetric_rotation_equals_recompute() {
    let rotation = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    let (_, _, looked_up, recomputed) = look_up_and_recompute(3, rotation);
    let mut worst = 0.0f32;
    for (a, b) in looked_up.iter().zip(&recomputed) {
        if a.is_finite() {
            worst = worst.max((*a - *b).abs().max_element() / b.abs().max_element().max(1e-3));
        }
    }
    // The cell means of rotated cells are computed on other texels: a percent, not rounding.
    assert!(worst < 0.02, "worst relative difference {worst}");
}

/// A generic rotation: rotated look-up and recompute sample the same integral with
/// differently placed directions, so they agree to quadrature accuracy on average; and the
/// look-up really depends on the rotation.
#[test]
fn generic_rotation_matches_recompute_to_quadrature() {
    let rotation = Quat::from_euler(glam::EulerRot::YXZ, 0.7, 0.4, -0.3);
    let (rigid, env, looked_up, recomputed) = look_up_and_recompute(4, rotation);
    let (mut diff, mut norm) = (0.0f64, 0.0f64);
    for (a, b) in looked_up.iter().zip(&recomputed) {
        if a.is_finite() {
            diff += f64::from((*a - *b).abs().element_sum());
            norm += f64::from(b.abs().element_sum());
        }
    }
    assert!(
        diff / norm < 0.03,
        "mean relative difference {}",
        diff / norm
    );
    // And the look-up really depends on the rotation.
    let upright = rigid
        .radiance(&env, Quat::IDENTITY, RadianceMethod::CellMean)
        .unwrap();
    let moved: f32 = upright
        .iter()
        .zip(&looked_up)
        .filter(|(a, _)| a.is_finite())
        .map(|(a, b)| (*a - *b).abs().element_sum())
        .sum();
    assert!(moved > 0.05 * norm as f32, "rotation changed nothing");
}

/// A matrix and a lightsphere of another level do not pair.
#[test]
fn mismatched_lightsphere_is_refused() {
    let mesh = bowl();
    let sphere = Lightsphere::new(2).unwrap();
    let matrix = VisibilityEngine::cpu(VisibilityParams::default())
        .compute(&rotated_scene(&mesh, Quat::IDENTITY), &sphere)
        .unwrap();
    assert!(RigidLighting::new(matrix, Lightsphere::new(3).unwrap()).is_err());
}
