//! The per-vertex stage of thesis §5.5, shared by both renderers: view and light directions
//! in the vertex's tangent frame, the four nearest view slots with weights ω_m (eq. 5.5) and
//! per slot the light's γ_kj (eq. 5.3).

use glam::Vec3;
use rayon::prelude::*;

use super::mesh::{BtfMesh, Frame, Light};
use crate::env::EnvLightWeights;
use crate::model::BtfPca;

/// ω, slots and γ of every vertex, in the layout uploaded to the GPU.
#[derive(Clone, Debug)]
pub(crate) struct VertexShading {
    /// Length of one γ vector: max_j c_j + 1 (entries past c_j + 1 are 0); three times that
    /// with `rgb`.
    pub(crate) gamma_stride: usize,
    /// RGB γ* (environment light, three floats per coefficient) instead of one γ per
    /// coefficient times the light's colour.
    pub(crate) rgb: bool,
    /// The four nearest view slots j_m of each vertex (padding repeats the first).
    pub(crate) slots: Vec<[u32; 4]>,
    /// Their weights ω_m (0 for padding).
    pub(crate) omega: Vec<[f32; 4]>,
    /// vertices × 4 × `gamma_stride`: γ_{0 j_m} … γ_{c j_m} of the light, per vertex and slot.
    pub(crate) gammas: Vec<f32>,
}

impl VertexShading {
    /// Computes the per-vertex data of `mesh` (already validated into `frames`) seen from
    /// `eye_world` under `light`.
    pub(crate) fn compute(
        pca: &BtfPca,
        mesh: &BtfMesh<'_>,
        frames: &[Frame],
        light: &Light,
        eye_world: Vec3,
    ) -> Self {
        let n = mesh.positions.len();
        let gamma_stride = pca.max_components() + 1;
        let mut out = Self {
            gamma_stride,
            rgb: false,
            slots: vec![[0; 4]; n],
            omega: vec![[0.0; 4]; n],
            gammas: vec![0.0; n * 4 * gamma_stride],
        };
        let sampling = pca.sampling();
        let per_vertex = out.gammas.chunks_exact_mut(4 * gamma_stride);
        for (v, gammas) in per_vertex.enumerate() {
            let p = mesh.positions[v];
            let frame = &frames[v];
            let view_in_tangent = frame.in_frame(eye_world - p);
            let light_in_tangent = frame.in_frame(light.dir_to_light_world(p));
            let omega = sampling.view_weights(view_in_tangent);
            let tau = sampling.light_weights(light_in_tangent);
            for (m, g) in gammas.chunks_exact_mut(gamma_stride).enumerate() {
                let j = omega.indices[m];
                // Slot indices are < 81.
                out.slots[v][m] = j as u32;
                out.omega[v][m] = omega.weights[m];
                if omega.weights[m] != 0.0 {
                    pca.gamma_from_weights(j, &tau, &mut g[..pca.gamma_len(j)]);
                }
            }
        }
        out
    }

    /// The per-vertex data under an environment: `w[v]` the environment binned for vertex v
    /// ([`EnvLightWeights`]), γ* RGB per slot (eq. 5.11).
    pub(crate) fn compute_env(
        pca: &BtfPca,
        mesh: &BtfMesh<'_>,
        frames: &[Frame],
        w: &[EnvLightWeights],
        eye_world: Vec3,
    ) -> Self {
        let n = mesh.positions.len();
        let coefficients = pca.max_components() + 1;
        let gamma_stride = 3 * coefficients;
        let mut out = Self {
            gamma_stride,
            rgb: true,
            slots: vec![[0; 4]; n],
            omega: vec![[0.0; 4]; n],
            gammas: vec![0.0; n * 4 * gamma_stride],
        };
        let sampling = pca.sampling();
        // Parallel over vertices: γ* is an 81 × (c + 1) product per slot, the bulk of an
        // environment update.
        out.gammas
            .par_chunks_exact_mut(4 * gamma_stride)
            .zip(out.slots.par_iter_mut())
            .zip(out.omega.par_iter_mut())
            .enumerate()
            .for_each(|(v, ((gammas, slots), omegas))| {
                let mut scratch = [Vec3::ZERO; crate::MAX_GAMMAS];
                let view_in_tangent = frames[v].in_frame(eye_world - mesh.positions[v]);
                let omega = sampling.view_weights(view_in_tangent);
                for (m, g) in gammas.chunks_exact_mut(gamma_stride).enumerate() {
                    let j = omega.indices[m];
                    slots[m] = j as u32;
                    omegas[m] = omega.weights[m];
                    if omega.weights[m] != 0.0 {
                        let len = pca.gamma_len(j);
                        pca.env_gamma(j, &w[v], &mut scratch[..len]);
                        for (k, c) in scratch[..len].iter().enumerate() {
                            g[3 * k..3 * k + 3].copy_from_slice(&c.to_array());
                        }
                    }
                }
            });
        debug_assert!(coefficients <= crate::MAX_GAMMAS);
        out
    }

    /// γ of vertex `v`'s slot entry `m` (0..4), `gamma_stride` long.
    pub(crate) fn gamma(&self, v: usize, m: usize) -> &[f32] {
        let start = (v * 4 + m) * self.gamma_stride;
        &self.gammas[start..start + self.gamma_stride]
    }
}
