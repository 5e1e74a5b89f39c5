//! BTFs under environment light (thesis §5.5.2, eqs. 5.10–5.11; SEED-NOTES §4.1–4.7): the
//! coefficients γ* of a vertex lit by many directions at once, each with its radiance, solid
//! angle and visibility — from a per-vertex visibility matrix M (crate `occlusion-gpu`), so
//! a deforming garment self-shadows under an HDR map frame by frame.
//!
//! # The sum, in two steps
//! A BTF image under a directional light of irradiance E₀ at normal incidence is the
//! material's radiance times E₀ cos θ; the images here follow the convention of `synth`
//! (E₀ = π, so a white Lambertian sample under a frontal light has radiance 1). An
//! environment of radiance L(d) seen through visibility V(d) then gives
//!
//! ```text
//! T = Σ_d V(d) · L(d) · ω_d / π · F(d)          (F(d): the BTF under light d, interpolated)
//! ```
//!
//! — eq. 5.10's g_i with the solid angle ω_d that the printed equation omits (without it the
//! sum grows with the number of directions) and the 1/π of the E₀ = π convention. With F(d)
//! interpolated over the four measured directions around d (τ_m, eq. 5.3), the sum splits:
//!
//! 1. **[`EnvLightWeights`]** W(m) = Σ_d V(d) τ_m(d) L(d) ω_d / π, RGB, for the 81 measured
//!    light directions m of the vertex's tangent frame: the environment binned onto the
//!    BTF's directions. It depends on the vertex (frame, visibility) and the environment, not
//!    on the view: one pass over the k directions, 4 weights each.
//! 2. **γ\*** (eq. 5.11): γ*_0j = Σ_m W(m), γ*_kj = Σ_m W(m) p_mkj for each view slot j the
//!    vertex needs (the four nearest, eq. 5.5): a dense 81 × (c_j + 1) product per slot,
//!    RGB ([`BtfPca::env_gamma`]). Then T_j = Σ_k γ*_kj ⊙ B_kj ([`BtfPca::texel_rgb`]).
//!
//! γ* is RGB because the environment is coloured; the point-light path's γ is one number
//! per coefficient times the light's colour g.
//!
//! Turning the environment (eq. 5.13): [`decompose`] keeps W of every vertex for A turns as a
//! mean and e PCA components, so any turn costs an e-term sum per vertex. W can also come from
//! static visibility maps (crate `hemicube`, `BtfLightChannel`) instead of M.
//!
//! ```
//! use btf::env::EnvLightWeights;
//! use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
//! use glam::Vec3;
//!
//! // A grey Lambertian BTF: every image 0.5 · cos θ_l.
//! let s = Sampling::H1;
//! let load = |j| ViewSlot::new(j, 1, 1, (0..81).flat_map(|i| [0.5 * s.vector(i).z.max(0.0); 3]).collect());
//! let (pca, _) = BtfPca::compress_with(s, 1, 1, &BtfPcaParams::default(), load, None)?;
//! // One visible direction straight above with L · ω = 2π (RGB): W = 2 at the pole.
//! let mut w = EnvLightWeights::default();
//! let l_omega = Vec3::splat(2.0 * std::f32::consts::PI);
//! w.add_samples(s, [Vec3::X, Vec3::Y, Vec3::Z], &[Vec3::Z], &[l_omega], |_| true);
//! let mut gamma = vec![Vec3::ZERO; pca.gamma_len(0)];
//! pca.env_gamma(0, &w, &mut gamma);
//! let rgb = pca.texel_rgb(0, &gamma, 0, 0);
//! assert!((rgb[0] - 1.0).abs() < 1e-2); // 0.5 · cos 0 · 2
//! # Ok::<(), btf::BtfError>(())
//! ```

use glam::Vec3;
use rayon::prelude::*;

pub mod decompose;
pub use decompose::{EnvDecomposition, relative_error};

use crate::model::BtfPca;
use crate::sampling::{DIRECTIONS, Sampling};

/// The environment as seen by one vertex, binned onto the 81 measured light directions of its
/// tangent frame: W(m) = Σ_d V(d) τ_m(d) L(d) ω_d / π, RGB (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvLightWeights {
    /// W(m), m = 0..81.
    pub weights: [Vec3; DIRECTIONS],
}

impl Default for EnvLightWeights {
    fn default() -> Self {
        Self {
            weights: [Vec3::ZERO; DIRECTIONS],
        }
    }
}

impl EnvLightWeights {
    /// Clears every W(m) to 0.
    pub fn clear(&mut self) {
        self.weights = [Vec3::ZERO; DIRECTIONS];
    }

    /// Adds the environment's directions: `directions[d]` (world, unit), `radiance_omega[d]`
    /// = L(d) · ω_d (RGB; the 1/π is applied here), counted where `visible(d)`. `frame` is
    /// the vertex's (tangent, bitangent, normal), orthonormal; directions at or below its
    /// horizon add nothing (τ = 0 there).
    ///
    /// # Panics
    /// If `radiance_omega` is shorter than `directions`.
    pub fn add_samples(
        &mut self,
        sampling: Sampling,
        frame: [Vec3; 3],
        directions: &[Vec3],
        radiance_omega: &[Vec3],
        visible: impl Fn(usize) -> bool,
    ) {
        assert!(
            radiance_omega.len() >= directions.len(),
            "one L·ω per direction"
        );
        let [t, b, n] = frame;
        let inv_pi = std::f32::consts::FRAC_1_PI;
        for (d, (&dir, &l)) in directions.iter().zip(radiance_omega).enumerate() {
            let z = dir.dot(n);
            if z <= 0.0 || !visible(d) {
                continue;
            }
            let local = Vec3::new(dir.dot(t), dir.dot(b), z);
            for (m, tau) in sampling.light_weights(local).iter() {
                self.weights[m] += (tau * inv_pi) * l;
            }
        }
    }

    /// Σ_m W(m) = Σ_d V(d) L(d) ω_d / π over the visible directions above the horizon (the
    /// τ of each sum to 1): γ*_0, the weight of the mean image in every view slot.
    pub fn total(&self) -> Vec3 {
        self.weights.iter().sum()
    }
}

/// The environment-independent part of W for a fixed geometry and visibility (one frame of a
/// deforming garment): T_i(m, d) = V(i, d) τ_m(d) ω_d / π for every vertex i, stored sparse
/// (at most 4 measured directions per visible environment direction). A new environment —
/// another map, or a sampled map turned — is then one sparse product per vertex,
/// W_i(m) = Σ_d T_i(m, d) L(d) ([`EnvTransfer::update`]), with no trigonometry.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EnvTransfer {
    /// Entries of vertex i: `offsets[i]..offsets[i + 1]`.
    offsets: Vec<usize>,
    /// The environment direction d of each entry.
    direction: Vec<u32>,
    /// The measured light direction m of each entry.
    light: Vec<u8>,
    /// τ_m(d) ω_d / π.
    weight: Vec<f32>,
}

impl EnvTransfer {
    /// Builds the transfer of every vertex: `frames[i]` its (tangent, bitangent, normal),
    /// `directions`/`solid_angles` the environment's sampling (world, unit; steradians), and
    /// `visible(i, d)` the visibility (e.g. a row of `occlusion_gpu::VisibilityMatrix`).
    /// Directions at or below a vertex's horizon are skipped. Parallel over vertices.
    ///
    /// # Panics
    /// If `solid_angles` is shorter than `directions`, or there are 2³² directions or more.
    pub fn build(
        sampling: Sampling,
        frames: &[[Vec3; 3]],
        directions: &[Vec3],
        solid_angles: &[f32],
        visible: impl Fn(usize, usize) -> bool + Sync,
    ) -> Self {
        assert!(
            solid_angles.len() >= directions.len(),
            "one ω per direction"
        );
        assert!(
            u32::try_from(directions.len()).is_ok(),
            "fewer than 2³² directions"
        );
        let inv_pi = std::f32::consts::FRAC_1_PI;
        let rows: Vec<Vec<(u32, u8, f32)>> = frames
            .par_iter()
            .enumerate()
            .map(|(i, &[t, b, n])| {
                let mut row = Vec::new();
                for (d, (&dir, &omega)) in directions.iter().zip(solid_angles).enumerate() {
                    let z = dir.dot(n);
                    if z <= 0.0 || !visible(i, d) {
                        continue;
                    }
                    let local = Vec3::new(dir.dot(t), dir.dot(b), z);
                    for (m, tau) in sampling.light_weights(local).iter() {
                        // m < 81 and d < 2³² (asserted above).
                        row.push((d as u32, m as u8, tau * omega * inv_pi));
                    }
                }
                row
            })
            .collect();
        let total = rows.iter().map(Vec::len).sum();
        let mut out = Self {
            offsets: Vec::with_capacity(frames.len() + 1),
            direction: Vec::with_capacity(total),
            light: Vec::with_capacity(total),
            weight: Vec::with_capacity(total),
        };
        out.offsets.push(0);
        for row in rows {
            for (d, m, w) in row {
                out.direction.push(d);
                out.light.push(m);
                out.weight.push(w);
            }
            out.offsets.push(out.direction.len());
        }
        out
    }

    /// Vertices.
    pub fn vertices(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Stored entries (memory: 9 bytes each).
    pub fn entries(&self) -> usize {
        self.weight.len()
    }

    /// W_i for every vertex under the environment radiance `radiance[d]` (RGB, one per
    /// direction of [`EnvTransfer::build`]); `out` is resized to the vertex count and
    /// overwritten. Parallel over vertices.
    ///
    /// # Panics
    /// If `radiance` is shorter than the directions the transfer was built with.
    pub fn update(&self, radiance: &[Vec3], out: &mut Vec<EnvLightWeights>) {
        out.resize(self.vertices(), EnvLightWeights::default());
        out.par_iter_mut().enumerate().for_each(|(i, w)| {
            w.clear();
            for e in self.offsets[i]..self.offsets[i + 1] {
                let l = radiance[self.direction[e] as usize];
                w.weights[self.light[e] as usize] += self.weight[e] * l;
            }
        });
    }
}

impl BtfPca {
    /// γ*_0j … γ*_cj of view slot `view_slot` (eq. 5.11, RGB) for an environment binned as
    /// `w`: γ*_0 = Σ_m W(m), γ*_k = Σ_m W(m) p_mkj. `out` has c_j + 1 entries.
    ///
    /// # Panics
    /// If `view_slot ≥ 81` or `out.len() ≠ c_j + 1`.
    pub fn env_gamma(&self, view_slot: usize, w: &EnvLightWeights, out: &mut [Vec3]) {
        let slot = &self.slots[view_slot];
        let c = slot.components();
        assert_eq!(
            out.len(),
            c + 1,
            "γ* of view slot {view_slot} has c_j + 1 entries"
        );
        out.iter_mut().for_each(|g| *g = Vec3::ZERO);
        for (m, &wm) in w.weights.iter().enumerate() {
            if wm == Vec3::ZERO {
                continue;
            }
            out[0] += wm;
            for (g, &p) in out[1..].iter_mut().zip(slot.light_weights(m)) {
                *g += p * wm;
            }
        }
    }

    /// The texel (x, y) of T_j = Σ_k γ*_kj ⊙ B_kj with RGB coefficients (environment light).
    ///
    /// # Panics
    /// If `view_slot ≥ 81`, `gammas.len() ≠ c_j + 1`, `x ≥ width` or `y ≥ height`.
    pub fn texel_rgb(&self, view_slot: usize, gammas: &[Vec3], x: usize, y: usize) -> [f32; 3] {
        let slot = &self.slots[view_slot];
        assert_eq!(gammas.len(), slot.textures.len(), "γ* length ≠ c_j + 1");
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside"
        );
        let t = 3 * (y * self.width + x);
        let mut rgb = [0.0f32; 3];
        for (tex, g) in slot.textures.iter().zip(gammas) {
            for (c, gc) in g.to_array().into_iter().enumerate() {
                if gc != 0.0 {
                    let mut one = [0.0f32; 3];
                    tex.add_scaled_texel(gc, t, &mut one);
                    rgb[c] += one[c];
                }
            }
        }
        rgb
    }

    /// The BTF under the environment `w` at texture coordinates (u, v) seen from a view
    /// direction in the tangent frame: γ* for each of the four nearest view slots, blended with
    /// their weights (eq. 5.5); nearest texel, wrapping, as [`BtfPca::eval`].
    pub fn eval_env(
        &self,
        view_dir_in_tangent: Vec3,
        w: &EnvLightWeights,
        u: f32,
        v: f32,
    ) -> [f32; 3] {
        let omega = self.sampling.view_weights(view_dir_in_tangent);
        let (x, y) = self.nearest_texel(u, v);
        let mut gammas = [Vec3::ZERO; crate::MAX_GAMMAS];
        let mut rgb = [0.0f32; 3];
        for (j, wj) in omega.iter() {
            let g = &mut gammas[..self.gamma_len(j)];
            self.env_gamma(j, w, g);
            let t = self.texel_rgb(j, g, x, y);
            for (o, t) in rgb.iter_mut().zip(t) {
                *o += wj * t;
            }
        }
        rgb
    }
}
