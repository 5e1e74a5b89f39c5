//! Spherical Gaussian prefilter of a lat-long map (paper 000 §5: "we pre-filter the
//! environment … and apply gaussian blur as a filter").
//!
//! The seed blurs the lat-long image in HDRShop, a 2-D blur that is wrong near the poles
//! (it neither widens in φ towards them nor blurs across them). This module filters on the
//! sphere instead:
//!
//! L'(d) = Σ_t w(γ(d, d_t)) L_t Ω_t / Σ_t w(γ(d, d_t)) Ω_t,  w(γ) = exp(−γ²/(2σ²)),
//!
//! over the source texel centres d_t with exact texel solid angles Ω_t, where γ is the angle
//! between directions (haversine form, accurate at small angles), truncated at
//! γ ≤ `truncation_sigmas`·σ. A constant map stays exactly constant, the poles included.
//!
//! Cost: the output resolution is matched to σ (about `output_texels_per_sigma` texels per σ)
//! with a width that divides the source width, so for a fixed pair (output row, source row)
//! the weights depend only on the column offset: each pair is one 1-D circular convolution
//! along φ over the window |Δφ| ≤ Δφ_max(θ, θ'), which widens towards the poles and covers all
//! φ near them. Output rows run in parallel (rayon); sums over a pair are f32, over rows f64.
//! Each kernel tap is a multiply-add over a whole output row (see `PhaseRows`).

use super::Environment;
use crate::{LightsphereError, latlong};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// Largest accepted σ in degrees; wider kernels are close to the constant mean anyway.
pub const MAX_PREFILTER_SIGMA_DEG: f64 = 90.0;

/// Output texels per σ by default: bilinear look-up of a Gaussian-blurred signal sampled at
/// σ/3 errs by at most (1/3)²/8 ≈ 1.4 % of its curvature scale, below the seed's own accuracy.
const DEFAULT_OUTPUT_TEXELS_PER_SIGMA: f64 = 3.0;

/// Kernel truncation by default: the Gaussian beyond 4σ holds e^−8 ≈ 3.4e-4 of the weight.
const DEFAULT_TRUNCATION_SIGMAS: f64 = 4.0;

/// Tuning knobs of [`Environment::prefiltered_with`].
///
/// Construct with struct-update syntax: `Params { field: value, ..Default::default() }`.
#[derive(Clone, Debug, PartialEq)]
pub struct PrefilterParams {
    /// Target output texels per σ along θ; the output is downsampled by the largest divisor m
    /// of the width with m ≤ σ_in_texels / this (m = 1 keeps the input resolution).
    pub output_texels_per_sigma: f64,
    /// Kernel support radius in units of σ.
    pub truncation_sigmas: f64,
}

impl Default for PrefilterParams {
    fn default() -> Self {
        Self {
            output_texels_per_sigma: DEFAULT_OUTPUT_TEXELS_PER_SIGMA,
            truncation_sigmas: DEFAULT_TRUNCATION_SIGMAS,
        }
    }
}

/// A σ whose Gaussian covers the mean solid angle of one of `direction_count` directions:
/// 2πσ² = 4π/k, i.e. σ = √(2/k) radians, returned in degrees (33.1° for k = 6, 1.27° for
/// k = 4098). The seed gives no rule for σ; this one is used for
/// [`super::RadianceMethod::PrefilteredLookup`] reports.
#[must_use]
pub fn matched_sigma_deg(direction_count: usize) -> f64 {
    (2.0 / direction_count.max(1) as f64).sqrt().to_degrees()
}

impl Environment {
    /// The spherical-Gaussian prefiltered map (angular σ in degrees) with default
    /// [`PrefilterParams`]; see [`Environment::prefiltered_with`].
    ///
    /// # Errors
    /// [`LightsphereError::InvalidSigma`] unless 0 < σ ≤ [`MAX_PREFILTER_SIGMA_DEG`].
    pub fn prefiltered(&self, sigma_deg: f64) -> Result<Self, LightsphereError> {
        self.prefiltered_with(sigma_deg, &PrefilterParams::default())
    }

    /// The spherical-Gaussian prefiltered map, at a resolution matched to σ (the width
    /// divides this map's width). It keeps this map's `world_from_env`.
    ///
    /// # Errors
    /// [`LightsphereError::InvalidSigma`] unless 0 < σ ≤ [`MAX_PREFILTER_SIGMA_DEG`];
    /// [`LightsphereError::InvalidParameter`] for non-positive or non-finite parameters.
    pub fn prefiltered_with(
        &self,
        sigma_deg: f64,
        params: &PrefilterParams,
    ) -> Result<Self, LightsphereError> {
        if !(sigma_deg > 0.0 && sigma_deg <= MAX_PREFILTER_SIGMA_DEG) {
            return Err(LightsphereError::InvalidSigma {
                sigma_deg,
                maximum: MAX_PREFILTER_SIGMA_DEG,
            });
        }
        let positive = |name, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(LightsphereError::InvalidParameter {
                    name,
                    value,
                    requirement: "finite and > 0",
                })
            }
        };
        positive("output_texels_per_sigma", params.output_texels_per_sigma)?;
        positive("truncation_sigmas", params.truncation_sigmas)?;

        let (w, h) = (self.width, self.height);
        let sigma = sigma_deg.to_radians();
        let sigma_in_texels = sigma / (PI / h as f64);
        let target = (sigma_in_texels / params.output_texels_per_sigma)
            .floor()
            .max(1.0);
        let m = (1..=w)
            .rev()
            .find(|&m| w % m == 0 && m as f64 <= target)
            .unwrap_or(1);
        let (out_w, out_h) = (w / m, ((h as f64 / m as f64).round() as usize).max(1));

        let source = PhaseRows::new(self, m);
        let truncation = (params.truncation_sigmas * sigma).min(PI);
        let rows: Vec<Vec<[f32; 3]>> = (0..out_h)
            .into_par_iter()
            .map(|i| {
                let theta0 = latlong::row_theta(i, out_h);
                filter_row(&source, theta0, out_w, sigma, truncation)
            })
            .collect();
        let texels = rows.into_iter().flatten().collect();
        let mut out = Self::from_texels(None, out_w, out_h, texels)?;
        out.world_from_env = self.world_from_env;
        Ok(out)
    }
}

/// Source rows as planar channels in polyphase form: for downsampling factor m and phase
/// p ∈ [0, m), `phase(row, c, p)[t] = L[row][(m·t + p) mod W][c]` for t < 3W/m. Output column
/// c′ and column offset j then read `phase(row, c, (j + W) mod m)[c′ + (j + W) div m]`, which
/// is contiguous in c′, so each kernel tap is one vectorised multiply-add over the output row.
struct PhaseRows {
    width: usize,
    height: usize,
    m: usize,
    /// Length of one phase array: 3W/m.
    len: usize,
    data: Vec<f32>,
}

impl PhaseRows {
    fn new(env: &Environment, m: usize) -> Self {
        let (w, h) = (env.width, env.height);
        let len = 3 * w / m;
        let mut data = vec![0.0f32; h * 3 * m * len];
        // Blocks of `len` floats in (row, channel, phase) order.
        for (block, out) in data.chunks_exact_mut(len).enumerate() {
            let (row, c, p) = (block / (3 * m), block / m % 3, block % m);
            let line = &env.texels[row * w..(row + 1) * w];
            for (t, slot) in out.iter_mut().enumerate() {
                *slot = line[(m * t + p) % w][c];
            }
        }
        Self {
            width: w,
            height: h,
            m,
            len,
            data,
        }
    }

    fn phase(&self, row: usize, c: usize, p: usize) -> &[f32] {
        let base = ((row * 3 + c) * self.m + p) * self.len;
        &self.data[base..base + self.len]
    }
}

/// One output row at polar angle `theta0`: `out_w` texels.
fn filter_row(
    src: &PhaseRows,
    theta0: f64,
    out_w: usize,
    sigma: f64,
    truncation: f64,
) -> Vec<[f32; 3]> {
    let (w, h, m) = (src.width, src.height, src.m);
    let sin2_t = (0.5 * truncation).sin().powi(2);
    let inv_two_sigma2 = 1.0 / (2.0 * sigma * sigma);
    // Column offset of the output centre relative to source centres: Δφ = 2π(j + off)/W.
    let off = (1.0 - m as f64) / 2.0;
    let first = ((theta0 - truncation) / PI * h as f64 - 0.5)
        .ceil()
        .max(0.0) as usize;
    let last = (((theta0 + truncation) / PI * h as f64 - 0.5)
        .floor()
        .max(0.0) as usize)
        .min(h - 1);

    let mut total = vec![[0.0f64; 3]; out_w];
    let mut pair = [
        vec![0.0f32; out_w],
        vec![0.0f32; out_w],
        vec![0.0f32; out_w],
    ];
    let mut normaliser = 0.0f64;
    for row in first..=last {
        let theta = latlong::row_theta(row, h);
        let sin2_dtheta = (0.5 * (theta - theta0)).sin().powi(2);
        if sin2_dtheta > sin2_t {
            continue;
        }
        let omega = latlong::texel_solid_angle(row, w, h);
        let cross = theta0.sin() * theta.sin();
        // Window half-width in columns; the whole row once it reaches around.
        let reach = if cross > 0.0 {
            ((sin2_t - sin2_dtheta) / cross).min(1.0)
        } else {
            1.0
        };
        let half_width = 2.0 * reach.sqrt().asin() / TAU * w as f64;
        let (j_lo, j_hi) = if reach >= 1.0 || 2.0 * half_width + 3.0 >= w as f64 {
            let lo = -((w / 2) as i64);
            (lo, lo + w as i64 - 1)
        } else {
            (
                (-half_width - off).ceil() as i64 - 1,
                (half_width - off).floor() as i64 + 1,
            )
        };
        let mut row_weight = 0.0f64;
        for j in j_lo..=j_hi {
            let dphi = TAU * (j as f64 + off) / w as f64;
            let hav = sin2_dtheta + cross * (0.5 * dphi).sin().powi(2);
            if hav > sin2_t {
                continue;
            }
            let gamma = 2.0 * hav.sqrt().min(1.0).asin();
            let weight = (-gamma * gamma * inv_two_sigma2).exp() * omega;
            row_weight += weight;
            let q = usize::try_from(j + w as i64).expect("offset within one period");
            let (p, t0) = (q % m, q / m);
            for (c, acc) in pair.iter_mut().enumerate() {
                axpy(acc, weight as f32, &src.phase(row, c, p)[t0..t0 + out_w]);
            }
        }
        if row_weight == 0.0 {
            continue;
        }
        normaliser += row_weight;
        for (c, acc) in pair.iter_mut().enumerate() {
            for (t, a) in total.iter_mut().zip(acc.iter_mut()) {
                t[c] += f64::from(*a);
                *a = 0.0;
            }
        }
    }
    assert!(normaliser > 0.0, "prefilter window holds no source texel");
    total
        .iter()
        .map(|t| t.map(|v| (v / normaliser) as f32))
        .collect()
}

/// `acc += k·x` (vectorises: no reduction).
fn axpy(acc: &mut [f32], k: f32, x: &[f32]) {
    for (a, &v) in acc.iter_mut().zip(x) {
        *a += k * v;
    }
}
