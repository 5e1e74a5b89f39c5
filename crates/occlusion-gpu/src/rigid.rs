//! Rigid motion of a single object (paper 000 §6): "in an environment with a single object, a
//! rigid transformation can be handled quite efficiently: a translation can be ignored, while
//! a rotation just amounts to an additional matrix multiplication before the look-up". M is
//! computed once in the object's own frame; when the object turns by R, its vertex radiance is
//! c_i = Σ_j M_ij I(R·l_j) ω_j: the light directions are carried into the world by R and the
//! environment is looked up there (§5 does the same for a rotated environment). No ray is
//! cast again.
//!
//! This holds only while nothing else occludes the object: with several objects moving
//! relative to each other, or a deforming mesh, M must be recomputed (§6).

use glam::{Quat, Vec3};
use lightsphere::{Environment, Lightsphere, RadianceMethod};

use crate::{OcclusionError, VisibilityMatrix};

/// A visibility matrix computed once in an object's frame, lit under any rotation of the
/// object by rotated look-ups.
///
/// # Examples
/// ```
/// use glam::{Quat, Vec3};
/// use lightsphere::{Environment, Lightsphere, RadianceMethod};
/// use occlusion_gpu::{RigidLighting, Scene, VisibilityEngine, VisibilityParams};
///
/// // A square facing +y, under a sky that is bright above and dark below.
/// let positions = vec![
///     Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0),
///     Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 1.0),
/// ];
/// let scene = Scene::single(positions, vec![Vec3::Y; 4], vec![[0, 2, 1], [0, 3, 2]])?;
/// let sphere = Lightsphere::new(2)?;
/// let matrix = VisibilityEngine::cpu(VisibilityParams::default()).compute(&scene, &sphere)?;
/// let (w, h) = (64, 32);
/// let texels = (0..w * h).map(|t| if t / w < h / 2 { [1.0; 3] } else { [0.0; 3] }).collect();
/// let sky = Environment::from_latlong(w, h, texels)?;
/// let rigid = RigidLighting::new(matrix, sphere)?;
/// let upright = rigid.radiance(&sky, Quat::IDENTITY, RadianceMethod::CellMean)?;
/// let flipped = rigid.radiance(&sky, Quat::from_rotation_x(std::f32::consts::PI), RadianceMethod::CellMean)?;
/// assert!(upright[0].x > 10.0 * flipped[0].x); // turned face down: dark
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Debug)]
pub struct RigidLighting {
    matrix: VisibilityMatrix,
    sphere: Lightsphere,
}

impl RigidLighting {
    /// Wraps a matrix computed in the object's frame with the lightsphere it was computed for.
    ///
    /// # Errors
    /// [`OcclusionError::RadianceCountMismatch`] when the matrix was computed for another
    /// direction set (different k, or other directions).
    pub fn new(matrix: VisibilityMatrix, sphere: Lightsphere) -> Result<Self, OcclusionError> {
        if matrix.directions() != sphere.directions() {
            return Err(OcclusionError::RadianceCountMismatch {
                given: sphere.len(),
                expected: matrix.directions_len(),
            });
        }
        Ok(Self { matrix, sphere })
    }

    /// The matrix, in the object's frame.
    pub fn matrix(&self) -> &VisibilityMatrix {
        &self.matrix
    }

    /// The light term I(R·l_j)·ω_j of every object-frame direction l_j when the object is
    /// turned by `world_from_object` (a translation would change nothing, §6).
    ///
    /// # Errors
    /// [`OcclusionError::Lighting`] for a rotation that cannot be normalised or a bad σ.
    pub fn light_weights(
        &self,
        environment: &Environment,
        world_from_object: Quat,
        method: RadianceMethod,
    ) -> Result<Vec<Vec3>, OcclusionError> {
        let world = self.sphere.try_rotated(world_from_object)?;
        let radiance = environment.radiance_per_direction(&world, method)?;
        Ok(world.light_weights(&radiance)?)
    }

    /// Vertex irradiance c_i = Σ_j M_ij I(R·l_j) ω_j (divide by π for a white Lambertian
    /// surface's radiance), in the matrix's row order; NaN for vertices with a zero normal.
    ///
    /// # Errors
    /// As [`RigidLighting::light_weights`].
    pub fn radiance(
        &self,
        environment: &Environment,
        world_from_object: Quat,
        method: RadianceMethod,
    ) -> Result<Vec<Vec3>, OcclusionError> {
        let weights = self.light_weights(environment, world_from_object, method)?;
        self.matrix.radiance(&weights)
    }
}
