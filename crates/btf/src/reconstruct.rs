//! CPU reconstruction of a compressed BTF (thesis §5.5, eqs. 5.2–5.5).
//!
//! Reconstruction is split in two, as in the thesis's derivation of eq. 5.3:
//!
//! 1. **γ** — the light enters only through the per-slot coefficients
//!    γ_kj = Σ_m τ_m p_{i_m k j} (eq. 5.3), with γ_0j = Σ_m τ_m for the mean B_0j. They depend
//!    on the light, not on the texel, so a renderer computes them once per vertex or frame.
//!    [`BtfPca::accumulate_gamma`] adds one measured light direction with a weight, the
//!    building block of environment illumination (γ*, thesis §5.5.2), which sums many.
//! 2. **Texel sum** — T_j = γ_0j B_0j + Σ_k γ_kj B_kj (eq. 5.4), per texel
//!    ([`BtfPca::texel`]) or for the whole normtexture ([`BtfPca::image_from_gamma`]).
//!
//! The light intensity g of eqs. 5.2–5.4 is left to the caller (multiply the result).
//! [`BtfPca::eval`] adds the view interpolation of eq. 5.5, T = Σ_m ω_m T_{j_m}, and looks up
//! the **nearest texel** of (u, v) with wrap-around (u, v ∈ [0, 1) cover the texture once;
//! u runs along a row, v down the rows from the first row stored). Nearest, not bilinear: the
//! GPU path filters with the sampler, and the CPU reference is kept exact per texel.

use glam::Vec3;

use crate::model::{BtfPca, LIGHTS};
use crate::sampling::{DIRECTIONS, Weights4};

/// The longest γ vector: γ_0 plus at most 80 components.
pub const MAX_GAMMAS: usize = LIGHTS;

impl BtfPca {
    /// Number of γ coefficients of view slot `view_slot`: c_j + 1 (γ_0 for the mean).
    ///
    /// # Panics
    /// If `view_slot ≥ 81`.
    pub fn gamma_len(&self, view_slot: usize) -> usize {
        self.slots[view_slot].components() + 1
    }

    /// γ_0j … γ_cj of view slot `view_slot` for a light direction in the tangent frame
    /// (eq. 5.3 with τ_m from [`crate::Sampling::light_weights`]). All zero for a light at
    /// or below the horizon.
    ///
    /// # Panics
    /// If `view_slot ≥ 81`.
    pub fn gamma(&self, view_slot: usize, light_dir_in_tangent: Vec3) -> Vec<f32> {
        let tau = self.sampling.light_weights(light_dir_in_tangent);
        let mut out = vec![0.0; self.gamma_len(view_slot)];
        self.gamma_from_weights(view_slot, &tau, &mut out);
        out
    }

    /// Writes γ for given light weights τ into `out` (overwritten; length c_j + 1).
    ///
    /// # Panics
    /// If `view_slot ≥ 81` or `out.len() ≠ c_j + 1`.
    pub fn gamma_from_weights(&self, view_slot: usize, tau: &Weights4, out: &mut [f32]) {
        out.iter_mut().for_each(|g| *g = 0.0);
        for (i, w) in tau.iter() {
            self.accumulate_gamma(view_slot, i, w, out);
        }
    }

    /// out += weight · (1, p_i1j, …, p_icj): adds measured light direction `light` with
    /// `weight` to γ (eq. 5.3's inner sum; for an environment, weight = radiance · solid
    /// angle of the direction's cell).
    ///
    /// # Panics
    /// If `view_slot` or `light` ≥ 81, or `out.len() ≠ c_j + 1`.
    pub fn accumulate_gamma(&self, view_slot: usize, light: usize, weight: f32, out: &mut [f32]) {
        let slot = &self.slots[view_slot];
        assert_eq!(
            out.len(),
            slot.components() + 1,
            "γ of view slot {view_slot} has c_j + 1 = {} entries",
            slot.components() + 1
        );
        assert!(light < DIRECTIONS, "light index {light} ≥ {DIRECTIONS}");
        out[0] += weight;
        for (g, &p) in out[1..].iter_mut().zip(slot.light_weights(light)) {
            *g += weight * p;
        }
    }

    /// The texel (x, y) of T_j = Σ_k γ_kj B_kj, k = 0..=c_j (eq. 5.4), linear RGB. Bit for
    /// bit the texel of [`BtfPca::image_from_gamma`].
    ///
    /// # Panics
    /// If `view_slot ≥ 81`, `gammas.len() ≠ c_j + 1`, `x ≥ width` or `y ≥ height`.
    pub fn texel(&self, view_slot: usize, gammas: &[f32], x: usize, y: usize) -> [f32; 3] {
        let slot = &self.slots[view_slot];
        assert_eq!(gammas.len(), slot.textures.len(), "γ length ≠ c_j + 1");
        assert!(
            x < self.width && y < self.height,
            "texel ({x}, {y}) outside"
        );
        let t = 3 * (y * self.width + x);
        let mut rgb = [0.0f32; 3];
        for (tex, &g) in slot.textures.iter().zip(gammas) {
            if g == 0.0 {
                continue;
            }
            tex.add_scaled_texel(g, t, &mut rgb);
        }
        rgb
    }

    /// The whole normtexture T_j for coefficients γ (eq. 5.4): width·height linear RGB
    /// texels, row-major.
    ///
    /// # Panics
    /// If `view_slot ≥ 81` or `gammas.len() ≠ c_j + 1`.
    pub fn image_from_gamma(&self, view_slot: usize, gammas: &[f32]) -> Vec<[f32; 3]> {
        let slot = &self.slots[view_slot];
        assert_eq!(gammas.len(), slot.textures.len(), "γ length ≠ c_j + 1");
        let mut flat = vec![0.0f32; self.texel_values()];
        for (tex, &g) in slot.textures.iter().zip(gammas) {
            if g != 0.0 {
                tex.add_scaled(g, &mut flat);
            }
        }
        flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
    }

    /// Reconstructs the measured normtexture N_ij of light `light` in view slot `view_slot`
    /// (eq. 5.1 with the mean): B_0j + Σ_k p_ikj B_kj.
    ///
    /// # Panics
    /// If `view_slot` or `light` ≥ 81.
    pub fn image(&self, view_slot: usize, light: usize) -> Vec<[f32; 3]> {
        let mut g = vec![0.0; self.gamma_len(view_slot)];
        self.accumulate_gamma(view_slot, light, 1.0, &mut g);
        self.image_from_gamma(view_slot, &g)
    }

    /// The BTF at texture coordinates (u, v) for a view and a light direction in the tangent
    /// frame, with light (eq. 5.3) and view (eq. 5.5) interpolation; nearest texel, (u, v)
    /// wrap (see the [module docs](crate::reconstruct)). Radiance per unit light intensity g;
    /// 0 for a light at or below the horizon.
    ///
    /// # Examples
    /// ```
    /// # use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
    /// # let s = Sampling::H1;
    /// # let load = |j: usize| ViewSlot::new(j, 1, 1, (0..81).flat_map(|i| vec![s.vector(i).z.max(0.0); 3]).collect());
    /// # let (pca, _) = BtfPca::compress_with(s, 1, 1, &BtfPcaParams::default(), load, None).unwrap();
    /// let rgb = pca.eval(glam::Vec3::Z, glam::Vec3::Z, 0.3, 1.7);
    /// assert!((rgb[0] - 1.0).abs() < 1e-3);
    /// assert_eq!(pca.eval(glam::Vec3::Z, -glam::Vec3::Z, 0.0, 0.0), [0.0; 3]);
    /// ```
    pub fn eval(
        &self,
        view_dir_in_tangent: Vec3,
        light_dir_in_tangent: Vec3,
        u: f32,
        v: f32,
    ) -> [f32; 3] {
        let omega = self.sampling.view_weights(view_dir_in_tangent);
        let tau = self.sampling.light_weights(light_dir_in_tangent);
        let (x, y) = self.nearest_texel(u, v);
        let mut gammas = [0.0f32; MAX_GAMMAS];
        let mut rgb = [0.0f32; 3];
        for (j, w) in omega.iter() {
            let g = &mut gammas[..self.gamma_len(j)];
            self.gamma_from_weights(j, &tau, g);
            let t = self.texel(j, g, x, y);
            for (o, t) in rgb.iter_mut().zip(t) {
                *o += w * t;
            }
        }
        rgb
    }

    /// The texel nearest (u, v), wrapping both coordinates; non-finite coordinates give (0, 0).
    pub fn nearest_texel(&self, u: f32, v: f32) -> (usize, usize) {
        (wrap_index(u, self.width), wrap_index(v, self.height))
    }
}

fn wrap_index(u: f32, n: usize) -> usize {
    if !u.is_finite() {
        return 0;
    }
    let f = f64::from(u).rem_euclid(1.0);
    ((f * n as f64).floor() as usize).min(n - 1)
}
