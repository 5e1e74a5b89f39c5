//! Initial placement of the cloth above the obstacle, with a seeded symmetry-breaking
//! perturbation: a perfectly centred, level cloth over a sphere would fold in a 4-fold
//! symmetric (and low-rank) pattern, real drapes do not.

use super::grid::GridMesh;
use super::params::ClothParams;
use crate::rng::SplitMix64;
use glam::{Quat, Vec3};

/// Largest tilt of the cloth from horizontal, in degrees (enough to make one side land
/// first; tuned by eye on the default drape).
const MAX_TILT_DEG: f32 = 3.0;
/// Largest horizontal offset of the cloth centre from the obstacle's top, as a fraction of
/// the cloth size.
const MAX_OFFSET_FRACTION: f32 = 0.03;
/// Largest vertical jitter per vertex, as a fraction of the grid spacing.
const JITTER_FRACTION: f32 = 0.05;

/// Vertex positions at t = 0 in the obstacle-centred frame, already pushed out of the
/// obstacle and ground (so a cloth that starts intersecting is valid from frame 0).
pub(crate) fn initial_positions(params: &ClothParams, mesh: &GridMesh) -> Vec<Vec3> {
    let mut rng = SplitMix64::new(params.seed);
    // A square is symmetric under 90° turns, so a yaw in [0, 90°) covers every orientation.
    let yaw = rng.next_f32() * std::f32::consts::FRAC_PI_2;
    let tilt_axis_angle = rng.next_f32() * std::f32::consts::TAU;
    let tilt = rng.next_f32() * MAX_TILT_DEG.to_radians();
    let offset =
        Vec3::new(rng.next_signed(), 0.0, rng.next_signed()) * (MAX_OFFSET_FRACTION * params.size);

    let tilt_axis = Vec3::new(tilt_axis_angle.cos(), 0.0, tilt_axis_angle.sin());
    let rotation = Quat::from_axis_angle(tilt_axis, tilt) * Quat::from_rotation_y(yaw);
    let centre = Vec3::new(
        0.0,
        params.obstacle.top_above_anchor() + params.drop_height,
        0.0,
    ) + offset;
    let jitter = JITTER_FRACTION * params.spacing();

    let colliders = super::collision::Colliders::new(params);
    mesh.rest
        .iter()
        .map(|r| {
            let p = rotation * *r + centre + Vec3::Y * (jitter * rng.next_signed());
            colliders.push_out_vec3(p)
        })
        .collect()
}
