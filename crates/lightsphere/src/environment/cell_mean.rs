//! Integral of the (piecewise-constant) lat-long map over every Voronoi cell of a lightsphere.
//!
//! The map is cut into thin bands (texel rows split into s sub-rows, each sub-row with its
//! exact band solid angle). Along each band the integral is exact in φ: the band is sampled at
//! s sub-column centres per texel, every sample is assigned to its nearest direction
//! ([`crate::Lightsphere::nearest`]), and where two consecutive samples belong to different
//! directions a and b the cell boundary is located on the band by bisection on
//! (l_a − l_b)·d(θ, φ) = 0. Each sample interval is then split exactly at that boundary (and
//! at the texel-value change in its middle), so only the band's θ-midpoint rule remains: the
//! error in a cell's area is second order in the sub-row height instead of first order.
//!
//! Every interval is split, never dropped, so the per-cell integrals sum exactly (up to
//! rounding) to the texel-exact ∫L dω. A cell thinner than the sample spacing along a band
//! loses that band's share to its neighbours.

use super::Environment;
use crate::{Lightsphere, latlong};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::TAU;

/// Illinois (modified regula falsi) steps locating a cell boundary within one sample
/// interval. f is a sinusoid sampled over a tiny arc, almost linear, so the first secant is
/// already within ~Δφ² of the root and six steps reach f32 precision of the stored fraction.
const FALSE_POSITION_STEPS: usize = 6;

/// Sub-rows processed per parallel block (bounds the scratch memory to 64 × samples per row).
const BLOCK_ROWS: usize = 64;

/// Per-direction ∫L dω (RGB) and sampled solid angle.
pub(super) struct CellIntegrals {
    pub sums: Vec<[f64; 3]>,
    pub areas: Vec<f64>,
}

/// Integrate `env` over the Voronoi cells of `sphere` with `s` × `s` samples per texel.
pub(super) fn integrate_cells(env: &Environment, sphere: &Lightsphere, s: usize) -> CellIntegrals {
    let (w, h) = (env.width, env.height);
    let (sw, sh) = (w * s, h * s);
    let dphi = TAU / sw as f64;
    let (cos_phi, sin_phi): (Vec<f64>, Vec<f64>) = (0..sw)
        .map(|c| (dphi * (c as f64 + 0.5)).sin_cos())
        .map(|(sin, cos)| (cos, sin))
        .unzip();
    let world_from_env = env.world_from_env;
    let env_from_world = world_from_env.inverse();
    let directions_in_env: Vec<DVec3> = sphere
        .directions_f64()
        .iter()
        .map(|&l| env_from_world * l)
        .collect();

    let mut sums = vec![[0.0f64; 3]; sphere.len()];
    let mut areas = vec![0.0f64; sphere.len()];
    let mut owners = vec![0u32; BLOCK_ROWS.min(sh) * sw];
    let mut crossings = vec![0.0f32; BLOCK_ROWS.min(sh) * sw];
    for block_start in (0..sh).step_by(BLOCK_ROWS) {
        let rows = BLOCK_ROWS.min(sh - block_start);
        owners[..rows * sw]
            .par_chunks_mut(sw)
            .zip(crossings[..rows * sw].par_chunks_mut(sw))
            .enumerate()
            .for_each(|(k, (owner, crossing))| {
                let theta = latlong::row_theta(block_start + k, sh);
                let (sin_t, cos_t) = theta.sin_cos();
                for (c, slot) in owner.iter_mut().enumerate() {
                    let d = DVec3::new(sin_t * cos_phi[c], cos_t, sin_t * sin_phi[c]);
                    *slot = sphere.nearest_f64(world_from_env * d) as u32;
                }
                for c in 0..sw {
                    let (a, b) = (owner[c] as usize, owner[(c + 1) % sw] as usize);
                    if a != b {
                        let g = directions_in_env[a] - directions_in_env[b];
                        let phi0 = dphi * (c as f64 + 0.5);
                        crossing[c] = boundary_fraction(g, theta, phi0, dphi) as f32;
                    }
                }
            });
        for k in 0..rows {
            let (top, bottom) = latlong::row_theta_bounds(block_start + k, sh);
            // Solid angle of one sample interval of this band.
            let step = latlong::band_solid_angle(top, bottom, dphi);
            let texel_row = &env.texels[((block_start + k) / s) * w..][..w];
            let owner = &owners[k * sw..(k + 1) * sw];
            let crossing = &crossings[k * sw..(k + 1) * sw];
            let mut add = |j: usize, value: [f32; 3], fraction: f64| {
                let omega = fraction * step;
                for ch in 0..3 {
                    sums[j][ch] += f64::from(value[ch]) * omega;
                }
                areas[j] += omega;
            };
            for c in 0..sw {
                let next = (c + 1) % sw;
                let (a, b) = (owner[c] as usize, owner[next] as usize);
                // The interval between sample centres c and c+1: its first half has sub-column
                // c's value, its second half sub-column c+1's.
                let (left, right) = (texel_row[c / s], texel_row[next / s]);
                if a == b {
                    add(a, left, 0.5);
                    add(a, right, 0.5);
                } else {
                    let t = f64::from(crossing[c]);
                    add(a, left, t.min(0.5));
                    add(a, right, (t - 0.5).max(0.0));
                    add(b, left, (0.5 - t).max(0.0));
                    add(b, right, (1.0 - t).min(0.5));
                }
            }
        }
    }
    CellIntegrals { sums, areas }
}

/// Fraction t ∈ [0, 1] of the interval [φ0, φ0 + Δφ] on the parallel θ where
/// f(φ) = g·d(θ, φ) changes sign (g = l_a − l_b in the map frame, f ≥ 0 at the start where
/// a is nearest, f ≤ 0 at the end). ½ when rounding breaks that sign pattern.
fn boundary_fraction(g: DVec3, theta: f64, phi0: f64, dphi: f64) -> f64 {
    let (sin_t, cos_t) = theta.sin_cos();
    let f = |t: f64| {
        let (sin_p, cos_p) = (phi0 + t * dphi).sin_cos();
        g.x * sin_t * cos_p + g.y * cos_t + g.z * sin_t * sin_p
    };
    let (mut a, mut fa, mut b, mut fb) = (0.0, f(0.0), 1.0, f(1.0));
    if !(fa >= 0.0 && fb <= 0.0) {
        return 0.5;
    }
    if fa == fb {
        return 0.5;
    }
    // Illinois method: keep the bracket [a, b], halve a stale end's value.
    let mut c = 0.5;
    let mut side = 0i8;
    for _ in 0..FALSE_POSITION_STEPS {
        c = (a * fb - b * fa) / (fb - fa);
        let fc = f(c);
        if fc == 0.0 {
            break;
        }
        if fc > 0.0 {
            (a, fa) = (c, fc);
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            (b, fb) = (c, fc);
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    c.clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn boundary_fraction_finds_the_bisector_crossing() {
        // Directions a and b on the equator at φ = 0.3 ± 0.05: the bisector is φ = 0.3.
        let (a, b) = (latlong::direction(1.2, 0.25), latlong::direction(1.2, 0.35));
        let t = boundary_fraction(a - b, 1.0, 0.29, 0.02);
        let crossing = 0.29 + t * 0.02;
        assert!((crossing - 0.3).abs() < 1e-12, "{crossing}");
        // Wrong sign pattern: fall back to the middle.
        assert_eq!(boundary_fraction(b - a, 1.0, 0.29, 0.02), 0.5);
    }
}
