//! Real spherical harmonics to l = 2 (9 coefficients per RGB channel) and the irradiance
//! matrix of Ramamoorthi & Hanrahan 2001 (seed 004 eqs. 6–11).
//!
//! # Convention
//!
//! The basis is R&H's real polynomials in **world** (x, y, z) — no Condon–Shortley phase
//! (SEED-NOTES §5.7.2; building eq. 9 from the standard P_l^m with (−1)^m flips the odd-m
//! signs). Coefficient k = l(l + 1) + m:
//!
//! | k | (l, m) | Y |
//! |---|---|---|
//! | 0 | (0, 0) | 0.282095 |
//! | 1 | (1, −1) | 0.488603 y |
//! | 2 | (1, 0) | 0.488603 z |
//! | 3 | (1, 1) | 0.488603 x |
//! | 4 | (2, −2) | 1.092548 xy |
//! | 5 | (2, −1) | 1.092548 yz |
//! | 6 | (2, 0) | 0.315392 (3z² − 1) |
//! | 7 | (2, 1) | 1.092548 xz |
//! | 8 | (2, 2) | 0.546274 (x² − y²) |
//!
//! The world is +Y up (the lat-long convention of `lightsphere::latlong`) but the polynomials
//! do not care which axis is up: R&H's formula is the same in any frame as long as the basis
//! and the matrix use the same one. Every sum is f64.
//!
//! # The irradiance matrix (eq. 10, corrected)
//!
//! B(r) = r̃ᵀ M r̃ with r̃ = (x, y, z, 1) homogeneous and, per channel,
//!
//! ```text
//! M = [ c1 E22   c1 E2−2   c1 E21   c2 E11 ]
//!     [ c1 E2−2  −c1 E22   c1 E2−1  c2 E1−1 ]
//!     [ c1 E21   c1 E2−1   c3 E20   c2 E10 ]
//!     [ c2 E11   c2 E1−1   c2 E10   c4 E00 − c5 E20 ]
//! ```
//!
//! — symmetric, as R&H 2001 print it: the seed's row 4 (TR 116) reads (c1 E11, c2 E2−1, …),
//! two typos (SEED-NOTES §5.7.1). B(r) = ∫ E(ω) max(0, r·ω) dω truncated to l ≤ 2, so it rings:
//! a delta light gives B(−0.5) = −0.039. [`Sh9::irradiance_clamped`] clamps at 0 (the
//! documented clamp); [`Window`] removes the negative lobe at its source.

use glam::{DMat4, DQuat, DVec3, DVec4};
use lightsphere::Environment;
use lightsphere::latlong;
use std::f64::consts::PI;

use crate::cube::CubeMap;

/// Number of coefficients to l = 2.
pub const SH_COUNT: usize = 9;

/// Y00 = 1 / (2√π).
pub const K0: f64 = 0.282_094_791_773_878_14;
/// The band-1 constant √(3 / 4π).
pub const K1: f64 = 0.488_602_511_902_919_9;
/// The xy, yz, xz constant √(15 / 4π).
pub const K2: f64 = 1.092_548_430_592_079_2;
/// The (3z² − 1) constant √(5 / 16π).
pub const K3: f64 = 0.315_391_565_252_520_05;
/// The (x² − y²) constant √(15 / 16π).
pub const K4: f64 = 0.546_274_215_296_039_6;

/// Eq. 11's constants, exact: c1 = (π/4)·K4, c2 = (π/3)·K1, c3 = (3π/4)·K3, c4 = π·K0,
/// c5 = (π/4)·K3 — printed to six digits as 0.429043, 0.511664, 0.743125, 0.886227, 0.247708.
pub const C: [f64; 5] = [
    PI / 4.0 * K4,
    PI / 3.0 * K1,
    3.0 * PI / 4.0 * K3,
    PI * K0,
    PI / 4.0 * K3,
];

/// The band (l) of coefficient k.
pub const BAND: [usize; SH_COUNT] = [0, 1, 1, 1, 2, 2, 2, 2, 2];

/// The nine basis functions at a unit direction `d` (world x, y, z), in the order of the
/// module table.
#[must_use]
pub fn basis(d: DVec3) -> [f64; SH_COUNT] {
    let (x, y, z) = (d.x, d.y, d.z);
    [
        K0,
        K1 * y,
        K1 * z,
        K1 * x,
        K2 * x * y,
        K2 * y * z,
        K3 * (3.0 * z * z - 1.0),
        K2 * x * z,
        K4 * (x * x - y * y),
    ]
}

/// A per-band window h_l applied to the coefficients before evaluation, against the ringing
/// of a band-limited clamped cosine (a small bright sun makes B negative on its far side).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub enum Window {
    /// No window (h_l = 1).
    #[default]
    None,
    /// Sloan's σ factors ("Stupid SH tricks", 2008): h_l = sinc(l / w) = sin(πl/w)/(πl/w);
    /// w = 3 is the classic width for l ≤ 2. It halves the negative lobe of a delta light
    /// (−0.039 → −0.034 at w = 3, −0.019 at w = 4) but no width removes it.
    Lanczos {
        /// The width w > 0.
        width: f64,
    },
    /// A Gaussian h_l = exp(−l(l + 1) / (2w)). For w ≤ 5 the windowed clamped-cosine kernel
    /// is non-negative on the whole sphere (tested), so B ≥ 0 for every non-negative
    /// environment: the negative lobe is gone, at the price of a softer B (w = 5 keeps
    /// 82 % of band 1 and 55 % of band 2).
    Gaussian {
        /// The width w > 0 (larger = sharper; ≤ 5 guarantees B ≥ 0).
        width: f64,
    },
}

/// The largest Gaussian width for which a delta light's windowed response is non-negative
/// everywhere (rounded down; tested).
pub const GAUSSIAN_NON_NEGATIVE_WIDTH: f64 = 5.0;

/// For reports: "no window", "Lanczos σ window, w = 3" or "Gaussian window, w = 5", with the
/// band factors h_1, h_2 when there is a window.
impl std::fmt::Display for Window {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (name, width) = match *self {
            Window::None => return write!(f, "no window"),
            Window::Lanczos { width } => ("Lanczos σ", width),
            Window::Gaussian { width } => ("Gaussian", width),
        };
        let [_, h1, h2] = self.factors();
        write!(
            f,
            "{name} window, w = {width}: h_1 = {h1:.4}, h_2 = {h2:.4}"
        )
    }
}

impl Window {
    /// h_l for bands 0, 1, 2 (h_0 = 1 always).
    #[must_use]
    pub fn factors(self) -> [f64; 3] {
        match self {
            Window::None => [1.0; 3],
            Window::Lanczos { width } => {
                let sinc = |x: f64| {
                    if x == 0.0 {
                        1.0
                    } else {
                        (PI * x).sin() / (PI * x)
                    }
                };
                [1.0, sinc(1.0 / width), sinc(2.0 / width)]
            }
            Window::Gaussian { width } => [
                1.0,
                (-2.0 / (2.0 * width)).exp(),
                (-6.0 / (2.0 * width)).exp(),
            ],
        }
    }

    /// `Ok` when the width is finite and positive.
    ///
    /// # Errors
    /// The window's width, named, when it is not.
    pub fn validate(self) -> Result<Self, crate::TranslucencyError> {
        match self {
            Window::None => Ok(self),
            Window::Lanczos { width } | Window::Gaussian { width } => {
                if width.is_finite() && width > 0.0 {
                    Ok(self)
                } else {
                    Err(crate::error::bad_parameter(
                        "window width",
                        width,
                        "must be finite and > 0",
                    ))
                }
            }
        }
    }
}

/// Nine RGB coefficients E_lm (eq. 6), f64.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Sh9 {
    /// `coeffs[k][channel]`, k in the module table's order.
    pub coeffs: [[f64; 3]; SH_COUNT],
}

impl Sh9 {
    /// The projection of a delta light of RGB power `power` from unit direction `d`:
    /// E_lm = power · Y_lm(d).
    #[must_use]
    pub fn delta(d: DVec3, power: [f64; 3]) -> Self {
        Self {
            coeffs: basis(d.normalize()).map(|y| power.map(|p| y * p)),
        }
    }

    /// Add `value` × `weights` (one texel's Y_lm·Δω) to the coefficients.
    fn accumulate(&mut self, weights: &[f64; SH_COUNT], value: [f32; 3]) {
        for (coeff, w) in self.coeffs.iter_mut().zip(weights) {
            for (c, v) in coeff.iter_mut().zip(value) {
                *c += w * f64::from(v);
            }
        }
    }

    /// Project a lat-long environment exactly as the piecewise-constant function its texels
    /// define: each texel's weight is the closed-form integral of Y_lm over its (θ, φ) cell,
    /// so a constant map is reproduced to rounding whatever its size. The map's rotation
    /// (`world_from_env`) is applied to the coefficients ([`Sh9::rotated`]).
    #[must_use]
    pub fn project_latlong(env: &Environment) -> Self {
        let (w, h) = (env.width(), env.height());
        let mut out = Self::default();
        let columns = column_integrals(w);
        for row in 0..h {
            for (col, weights) in row_weights(row, h, &columns).enumerate() {
                out.accumulate(&weights, env.texel(row, col));
            }
        }
        out.rotated(env.world_from_env().as_dquat())
    }

    /// Project a cube map: Σ texel · Y_lm(texel centre) · Δω with the texel's exact solid
    /// angle ([`crate::cube::texel_solid_angle`]); second-order accurate in the texel size.
    #[must_use]
    pub fn project_cube(cube: &CubeMap) -> Self {
        let mut out = Self::default();
        for (weights, t) in cube.projection_weights().iter().zip(cube.texels()) {
            out.accumulate(weights, *t);
        }
        out
    }

    /// The coefficients with the band factors of `window` applied.
    #[must_use]
    pub fn windowed(&self, window: Window) -> Self {
        let h = window.factors();
        let mut out = *self;
        for (k, c) in out.coeffs.iter_mut().enumerate() {
            for v in c.iter_mut() {
                *v *= h[BAND[k]];
            }
        }
        out
    }

    /// The coefficients of the function rotated by `rotation`: g(ω) = f(R⁻¹ω). Exact for
    /// l ≤ 2 (each band rotates within itself; its (2l+1)² matrix is solved from the basis at
    /// 2l + 1 fixed directions, f64).
    #[must_use]
    pub fn rotated(&self, rotation: DQuat) -> Self {
        let inv = rotation.normalize().inverse();
        let mut out = Self::default();
        out.coeffs[0] = self.coeffs[0];
        for (start, dirs) in [(1usize, &BAND1_DIRS[..]), (4, &BAND2_DIRS[..])] {
            let n = dirs.len();
            // A[k][j] = Y_k(ω_j), B[k][j] = Y_k(R⁻¹ ω_j); Y_i(R⁻¹ω) = Σ_k D_ki Y_k(ω) gives
            // B = Dᵀ A, so Dᵀ = B A⁻¹ and the new coefficient c'_k = Σ_i D_ki c_i.
            let a = nalgebra::DMatrix::from_fn(n, n, |k, j| basis(dirs[j].normalize())[start + k]);
            let b = nalgebra::DMatrix::from_fn(n, n, |k, j| {
                basis(inv * dirs[j].normalize())[start + k]
            });
            let a_inv = a
                .try_inverse()
                .expect("the fixed sample directions make the band's basis matrix invertible");
            let dt = b * a_inv;
            for c in 0..3 {
                for k in 0..n {
                    out.coeffs[start + k][c] =
                        (0..n).map(|i| dt[(i, k)] * self.coeffs[start + i][c]).sum();
                }
            }
        }
        out
    }

    /// The irradiance matrix M of eq. 10 (corrected, symmetric) for `channel` (0, 1, 2).
    #[must_use]
    pub fn irradiance_matrix(&self, channel: usize) -> DMat4 {
        let e = |k: usize| self.coeffs[k][channel];
        let [c1, c2, c3, c4, c5] = C;
        // Columns (glam is column-major); M is symmetric so rows read the same.
        DMat4::from_cols(
            DVec4::new(c1 * e(8), c1 * e(4), c1 * e(7), c2 * e(3)),
            DVec4::new(c1 * e(4), -c1 * e(8), c1 * e(5), c2 * e(1)),
            DVec4::new(c1 * e(7), c1 * e(5), c3 * e(6), c2 * e(2)),
            DVec4::new(c2 * e(3), c2 * e(1), c2 * e(2), c4 * e(0) - c5 * e(6)),
        )
    }

    /// B(r) = r̃ᵀ M r̃ per channel (eq. 10), unclamped: it rings below 0 behind a strong
    /// light. `r` is normalised first.
    #[must_use]
    pub fn irradiance(&self, r: DVec3) -> [f64; 3] {
        let r = r.normalize().extend(1.0);
        std::array::from_fn(|c| r.dot(self.irradiance_matrix(c) * r))
    }

    /// [`Sh9::irradiance`] clamped at 0 — the documented clamp: the exact B is ≥ 0 for a
    /// non-negative environment, so a negative value is ringing, not light.
    #[must_use]
    pub fn irradiance_clamped(&self, r: DVec3) -> [f64; 3] {
        self.irradiance(r).map(|b| b.max(0.0))
    }

    /// The value of the projected function itself at `d` (Σ E_lm Y_lm(d)), per channel.
    #[must_use]
    pub fn evaluate(&self, d: DVec3) -> [f64; 3] {
        let y = basis(d.normalize());
        std::array::from_fn(|c| (0..SH_COUNT).map(|k| self.coeffs[k][c] * y[k]).sum())
    }

    /// The coefficients as f32 `[9][3]`, the layout of `cloth-vis sh --out` (row k = the
    /// module table's order, column = R, G, B).
    #[must_use]
    pub fn to_f32(&self) -> [[f32; 3]; SH_COUNT] {
        self.coeffs.map(|c| c.map(|v| v as f32))
    }
}

/// Generic sample directions for the band rotations (any set whose basis matrix is well
/// conditioned; these are not symmetric under any axis flip).
const BAND1_DIRS: [DVec3; 3] = [
    DVec3::new(1.0, 0.2, 0.1),
    DVec3::new(0.1, 1.0, 0.3),
    DVec3::new(0.2, 0.3, 1.0),
];
const BAND2_DIRS: [DVec3; 5] = [
    DVec3::new(1.0, 0.3, 0.2),
    DVec3::new(0.2, 1.0, 0.4),
    DVec3::new(0.3, 0.1, 1.0),
    DVec3::new(1.0, 1.0, 0.1),
    DVec3::new(-0.2, 1.0, 1.0),
];

/// Integrals over c = cos θ ∈ [c_lo, c_hi] of the θ factors of the basis (dω = dc dφ).
struct CosIntegrals {
    /// ∫ 1
    one: f64,
    /// ∫ c
    c: f64,
    /// ∫ c²
    c2: f64,
    /// ∫ s (s = sin θ = √(1 − c²))
    s: f64,
    /// ∫ s c
    sc: f64,
    /// ∫ s²
    s2: f64,
}

impl CosIntegrals {
    fn new(c_lo: f64, c_hi: f64) -> Self {
        let root = |c: f64| (1.0 - c * c).max(0.0).sqrt();
        let f_s = |c: f64| (c * root(c) + c.clamp(-1.0, 1.0).asin()) / 2.0;
        let f_sc = |c: f64| -root(c).powi(3) / 3.0;
        let one = c_hi - c_lo;
        let c2 = (c_hi.powi(3) - c_lo.powi(3)) / 3.0;
        Self {
            one,
            c: (c_hi * c_hi - c_lo * c_lo) / 2.0,
            c2,
            s: f_s(c_hi) - f_s(c_lo),
            sc: f_sc(c_hi) - f_sc(c_lo),
            s2: one - c2,
        }
    }
}

/// Integrals over φ ∈ [φ0, φ1] of the φ factors.
struct PhiIntegrals {
    one: f64,
    cos: f64,
    sin: f64,
    sin2: f64,
    cos2: f64,
    sincos: f64,
}

impl PhiIntegrals {
    fn new(p0: f64, p1: f64) -> Self {
        let (s0, c0) = p0.sin_cos();
        let (s1, c1) = p1.sin_cos();
        let d = p1 - p0;
        let s2diff = (2.0 * p1).sin() - (2.0 * p0).sin();
        Self {
            one: d,
            cos: s1 - s0,
            sin: c0 - c1,
            sin2: d / 2.0 - s2diff / 4.0,
            cos2: d / 2.0 + s2diff / 4.0,
            sincos: (s1 * s1 - s0 * s0) / 2.0,
        }
    }
}

/// ∫ Y_lm dω over the lat-long cell, in world (x, y, z) = (s cos φ, c, s sin φ).
fn texel_integrals(z: &CosIntegrals, p: &PhiIntegrals) -> [f64; SH_COUNT] {
    [
        K0 * z.one * p.one,
        K1 * z.c * p.one,
        K1 * z.s * p.sin,
        K1 * z.s * p.cos,
        K2 * z.sc * p.cos,
        K2 * z.sc * p.sin,
        K3 * (3.0 * z.s2 * p.sin2 - z.one * p.one),
        K2 * z.s2 * p.sincos,
        K4 * (z.s2 * p.cos2 - z.c2 * p.one),
    ]
}

/// The φ integrals of each of `width` columns.
fn column_integrals(width: usize) -> Vec<PhiIntegrals> {
    let dphi = 2.0 * PI / width as f64;
    (0..width)
        .map(|c| PhiIntegrals::new(dphi * c as f64, dphi * (c + 1) as f64))
        .collect()
}

/// ∫ Y_lm dω of each texel of lat-long row `row` (of `height`).
fn row_weights(
    row: usize,
    height: usize,
    columns: &[PhiIntegrals],
) -> impl Iterator<Item = [f64; SH_COUNT]> + '_ {
    let (t0, t1) = latlong::row_theta_bounds(row, height);
    let zi = CosIntegrals::new(t1.cos(), t0.cos());
    columns.iter().map(move |p| texel_integrals(&zi, p))
}

/// The minimum over the sphere of a delta light's windowed response B (unit power), found on
/// a fine grid of t = r·l: the ringing a window leaves (negative = a negative lobe).
#[must_use]
pub fn delta_response_minimum(window: Window) -> f64 {
    let sh = Sh9::delta(DVec3::Z, [1.0; 3]).windowed(window);
    (0..=20_000)
        .map(|i| {
            let t = -1.0 + 2.0 * f64::from(i) / 20_000.0;
            let r = DVec3::new((1.0 - t * t).max(0.0).sqrt(), 0.0, t);
            sh.irradiance(r)[0]
        })
        .fold(f64::INFINITY, f64::min)
}
