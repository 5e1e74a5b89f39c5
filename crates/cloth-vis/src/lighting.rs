//! Per-vertex image-based diffuse lighting over a lightsphere (paper 000 §3.3, §5).
//!
//! The seed renders c_i = Σ_j M_ij I_j with M_ij = n_i·l_j where vertex i sees direction j.
//! Without visibility (the `lighting` effect; self-shadowing adds M's zeros later) every
//! direction with n_i·l_j > 0 counts. We weight each direction by its solid angle ω_j (the
//! lightsphere's Voronoi cell) so the sum is a quadrature of the irradiance integral
//! E_i = ∫ L(l) max(0, n_i·l) dω, and return outgoing radiance of a Lambertian surface,
//! c_i = (ρ/π) E_i. The seed's unweighted sum equals ours up to the constant ω ≈ 4π/k and ρ/π;
//! the weighting removes the ±3% bias of the octahedral set's unequal cells.
//!
//! Accumulation is in f64: at level 6 a vertex sums 16,386 terms spanning the sun (10⁴× the
//! mean sky) and faint sky directions.
//!
//! This module is the one home of the formula: [`lambertian_radiance`] without visibility,
//! [`shadowed_radiance`] with the visibility matrix M (used by the `self-shadowing` stage and
//! by `cloth-vis visibility`), and the environment rotation both share
//! ([`environment_rotation`], [`rotated_lookup_radiance`]).

use glam::{DQuat, DVec3, Quat, Vec3};
use rayon::prelude::*;

use crate::Error;

/// Vertex radiance of a white Lambertian surface with visibility:
/// c_i = (1/π) Σ_j M_ij I_j ω_j for every row i of `m` (multiply by the albedo ρ for a
/// coloured surface). Rows of vertices used by no face are NaN. The sum runs in the
/// visibility engine's f64 accumulation over `sphere.light_weights(radiance)` = I_j ω_j.
///
/// # Errors
/// [`Error::Light`] when `radiance` does not hold one value per direction of `sphere`, or
/// [`Error::Visibility`] when `m` was computed for another direction count.
pub fn shadowed_radiance(
    m: &occlusion_gpu::VisibilityMatrix,
    sphere: &lightsphere::Lightsphere,
    radiance: &[Vec3],
) -> Result<Vec<Vec3>, Error> {
    let weights = sphere.light_weights(radiance)?;
    Ok(m.radiance(&weights)?
        .into_iter()
        .map(|c| c / std::f32::consts::PI)
        .collect())
}

/// `world_from_rotated_env`: the rotation by `deg` degrees about +Y (right-handed), built in
/// f64 so that quarter turns map the octahedral directions onto each other to f64 rounding.
/// Scenes' `[environment] rotation_deg` and `cloth-vis visibility --env-rotation` use it.
pub fn environment_rotation(deg: f32) -> Quat {
    DQuat::from_rotation_y(f64::from(deg).to_radians()).as_quat()
}

/// Radiance per light direction I_j of `env` turned by `deg` about +Y relative to the object
/// (on top of its own `world_from_env`), by rotated look-ups (thesis §4.4.5: "the light
/// directions are multiplied by the same rotation matrix to obtain the new look-up
/// positions"): I_j is the environment's cell mean around R⁻¹·l_j. M, indexed by the
/// unrotated l_j, is reused as is — this is how a viewer turns the light without recomputing
/// visibility. Equals `env.with_rotation(environment_rotation(deg) * env.world_from_env())`
/// sampled at the l_j, up to rounding (tested).
///
/// # Errors
/// [`Error::Light`] for a non-finite angle.
pub fn rotated_lookup_radiance(
    env: &lightsphere::Environment,
    sphere: &lightsphere::Lightsphere,
    deg: f32,
) -> Result<Vec<Vec3>, Error> {
    let lookup = if deg == 0.0 {
        sphere.clone()
    } else {
        sphere.try_rotated(environment_rotation(deg).inverse())?
    };
    Ok(env.radiance_per_direction(&lookup, lightsphere::RadianceMethod::CellMean)?)
}

/// Outgoing Lambertian radiance per vertex: c_i = (ρ/π) Σ_j max(0, n_i·l_j) I_j ω_j.
///
/// `directions`, `solid_angles` and `radiance` are indexed by light direction j; `normals` by
/// vertex i. Zero normals (unreferenced vertices) get zero radiance.
///
/// # Panics
/// When the per-direction slices differ in length (an internal bug).
pub fn lambertian_radiance(
    normals: &[Vec3],
    directions: &[Vec3],
    solid_angles: &[f64],
    radiance: &[Vec3],
    albedo: Vec3,
) -> Vec<Vec3> {
    assert_eq!(
        directions.len(),
        solid_angles.len(),
        "one solid angle per direction"
    );
    assert_eq!(
        directions.len(),
        radiance.len(),
        "one radiance per direction"
    );
    // Pre-multiply I_j ω_j once (f64).
    let weighted: Vec<(DVec3, DVec3)> = directions
        .iter()
        .zip(solid_angles)
        .zip(radiance)
        .map(|((l, &w), i)| (l.as_dvec3(), i.as_dvec3() * w))
        .collect();
    let scale = albedo.as_dvec3() / std::f64::consts::PI;
    normals
        .par_iter()
        .map(|n| {
            let n = n.as_dvec3();
            let mut e = DVec3::ZERO;
            for (l, iw) in &weighted {
                let cos = n.dot(*l);
                if cos > 0.0 {
                    e += *iw * cos;
                }
            }
            (e * scale).as_vec3()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_environment_gives_albedo_times_radiance_for_an_open_plane() {
        // ∫_hemisphere L cosθ dω = π L, so c = ρ L. With a lightsphere the quadrature error
        // shrinks with the level; level 5 (4098 directions) is within 0.5%.
        let sphere = lightsphere::Lightsphere::new(5).unwrap();
        let l = Vec3::new(2.0, 1.0, 0.5);
        let radiance = vec![l; sphere.len()];
        let albedo = Vec3::new(0.5, 0.25, 1.0);
        let normals = [Vec3::Y, Vec3::new(1.0, 2.0, -3.0).normalize(), Vec3::ZERO];
        let c = lambertian_radiance(
            &normals,
            sphere.directions(),
            sphere.solid_angles(),
            &radiance,
            albedo,
        );
        let expected = albedo * l;
        for (n, got) in c.iter().take(2).enumerate() {
            let rel = ((*got - expected) / expected).abs().max_element();
            assert!(rel < 5e-3, "normal {n}: {got:?} vs {expected:?} ({rel})");
        }
        assert_eq!(c[2], Vec3::ZERO);
    }

    #[test]
    fn a_single_direction_lights_only_the_facing_side() {
        let dirs = [Vec3::Y];
        let c = lambertian_radiance(
            &[Vec3::Y, -Vec3::Y],
            &dirs,
            &[0.5],
            &[Vec3::splat(4.0)],
            Vec3::ONE,
        );
        let expected = 4.0 * 0.5 / std::f32::consts::PI;
        assert!((c[0].x - expected).abs() < 1e-6);
        assert_eq!(c[1], Vec3::ZERO);
    }
}
