//! The project's lat-long (equirectangular) convention, shared with the `synth` crate.
//!
//! World is +Y up. An equirectangular image of width W and height H: row r (0 = top) covers
//! the polar angle θ ∈ [π r/H, π (r+1)/H] measured from +Y; column c covers the azimuth
//! φ ∈ [2π c/W, 2π (c+1)/W]; the texel centre is θ = π (r+½)/H, φ = 2π (c+½)/W. The direction
//! of (θ, φ) is d = (sin θ cos φ, cos θ, sin θ sin φ). A texel's solid angle is
//! (2π/W)·(cos θ_top − cos θ_bottom), exact, in f64. Texels are linear RGB `[f32; 3]`,
//! row-major, row 0 first.
//!
//! The seed (paper 000 §5) calls this parameterisation "latitude-longitude" with
//! θ ∈ [0, π], φ ∈ [0, 2π].

use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Unit direction of polar angle `theta` (from +Y) and azimuth `phi`, in radians.
///
/// # Examples
/// ```
/// let d = lightsphere::latlong::direction(0.0, 1.0);
/// assert!((d - glam::DVec3::Y).length() < 1e-15);
/// ```
#[must_use]
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    DVec3::new(sin_t * cos_p, cos_t, sin_t * sin_p)
}

/// Polar angle θ ∈ [0, π] and azimuth φ ∈ [0, 2π) of a direction (need not be unit length).
///
/// Returns `None` for a zero or non-finite vector. At the poles φ is 0.
#[must_use]
pub fn theta_phi(dir: DVec3) -> Option<(f64, f64)> {
    if !dir.is_finite() || dir == DVec3::ZERO {
        return None;
    }
    // atan2 of (horizontal length, y) is accurate near the poles, unlike acos(y/|d|).
    let theta = dir.x.hypot(dir.z).atan2(dir.y);
    let mut phi = dir.z.atan2(dir.x);
    if phi < 0.0 {
        phi += TAU;
    }
    if phi >= TAU {
        // -tiny + 2π rounds to 2π.
        phi = 0.0;
    }
    Some((theta, phi))
}

/// Polar angles `(θ_top, θ_bottom)` bounding row `row` of a map with `height` rows.
#[must_use]
pub fn row_theta_bounds(row: usize, height: usize) -> (f64, f64) {
    let h = height as f64;
    (PI * row as f64 / h, PI * (row as f64 + 1.0) / h)
}

/// Polar angle of the centre of row `row` of a map with `height` rows.
#[must_use]
pub fn row_theta(row: usize, height: usize) -> f64 {
    PI * (row as f64 + 0.5) / height as f64
}

/// Azimuth of the centre of column `col` of a map with `width` columns.
#[must_use]
pub fn col_phi(col: usize, width: usize) -> f64 {
    TAU * (col as f64 + 0.5) / width as f64
}

/// Unit direction of the centre of texel (`row`, `col`).
#[must_use]
pub fn texel_direction(row: usize, col: usize, width: usize, height: usize) -> DVec3 {
    direction(row_theta(row, height), col_phi(col, width))
}

/// Solid angle of the band between polar angles `theta_top < theta_bottom` over an azimuth
/// range `delta_phi`: `delta_phi·(cos θ_top − cos θ_bottom)`, evaluated as
/// `2·sin(mean)·sin(half difference)` so that thin bands near the poles keep their digits.
#[must_use]
pub fn band_solid_angle(theta_top: f64, theta_bottom: f64, delta_phi: f64) -> f64 {
    let mean = 0.5 * (theta_top + theta_bottom);
    let half = 0.5 * (theta_bottom - theta_top);
    delta_phi * 2.0 * mean.sin() * half.sin()
}

/// Exact solid angle of one texel of row `row` in a `width` × `height` map.
///
/// The solid angles of all texels sum to 4π.
///
/// # Examples
/// ```
/// use lightsphere::latlong::texel_solid_angle;
/// let total: f64 = (0..8).map(|r| 16.0 * texel_solid_angle(r, 16, 8)).sum();
/// assert!((total - 4.0 * std::f64::consts::PI).abs() < 1e-12);
/// ```
#[must_use]
pub fn texel_solid_angle(row: usize, width: usize, height: usize) -> f64 {
    let (top, bottom) = row_theta_bounds(row, height);
    band_solid_angle(top, bottom, TAU / width as f64)
}

/// Continuous texel coordinates `(x, y)` of a direction: `x = φ/(2π)·W − ½`,
/// `y = θ/π·H − ½`, so that texel centres sit at integers. `None` for zero or non-finite input.
#[must_use]
pub fn texel_coordinates(dir: DVec3, width: usize, height: usize) -> Option<(f64, f64)> {
    let (theta, phi) = theta_phi(dir)?;
    Some((
        phi / TAU * width as f64 - 0.5,
        theta / PI * height as f64 - 0.5,
    ))
}

/// The texel (row, col) whose area contains `dir` (closed on the top/left edges).
/// `None` for zero or non-finite input.
#[must_use]
pub fn texel_containing(dir: DVec3, width: usize, height: usize) -> Option<(usize, usize)> {
    let (theta, phi) = theta_phi(dir)?;
    let row = ((theta / PI * height as f64).floor() as usize).min(height.saturating_sub(1));
    let col = ((phi / TAU * width as f64).floor() as usize).min(width.saturating_sub(1));
    Some((row, col))
}
