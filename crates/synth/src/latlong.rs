//! The project's shared equirectangular (lat-long) convention, identical in `lightsphere`
//! (kept dependency-free here; the workspace test `tests/latlong.rs` checks that both agree
//! texel for texel, and render's backdrop shader states the same convention):
//!
//! World is +Y up. In an image of `width` W × `height` H, row r (0 = top) covers polar
//! angle θ ∈ [π r/H, π (r+1)/H] measured from +Y; column c covers azimuth
//! φ ∈ [2π c/W, 2π (c+1)/W]; the texel centre is θ = π (r+½)/H, φ = 2π (c+½)/W. The
//! direction of (θ, φ) is d = (sin θ cos φ, cos θ, sin θ sin φ). A texel's solid angle is
//! exactly (2π/W)·(cos θ_top − cos θ_bottom). Texels are linear RGB `[f32; 3]`, row-major,
//! row 0 first.

use glam::{DVec3, Vec3};
use std::f64::consts::{PI, TAU};

/// A linear-RGB equirectangular image in the shared lat-long convention (see the module
/// docs of [`latlong`](crate::latlong)).
#[derive(Debug, Clone, PartialEq)]
pub struct LatLongImage {
    /// Columns (azimuth samples).
    pub width: usize,
    /// Rows (polar-angle samples).
    pub height: usize,
    /// `width × height` linear RGB texels, row-major, row 0 (around +Y) first.
    pub texels: Vec<[f32; 3]>,
}

impl LatLongImage {
    /// The texel at `row`, `col`.
    ///
    /// # Panics
    /// If `row ≥ height` or `col ≥ width`.
    pub fn texel(&self, row: usize, col: usize) -> [f32; 3] {
        assert!(
            row < self.height && col < self.width,
            "texel ({row}, {col}) outside {}×{}",
            self.width,
            self.height
        );
        self.texels[row * self.width + col]
    }

    /// Unit direction of the centre of texel (`row`, `col`).
    pub fn direction(&self, row: usize, col: usize) -> Vec3 {
        texel_direction(row, col, self.width, self.height).as_vec3()
    }

    /// Solid angle in steradians of any texel in `row`.
    pub fn solid_angle(&self, row: usize) -> f64 {
        texel_solid_angle(row, self.width, self.height)
    }
}

/// Polar angle θ of the centre of `row` in an image of `height` rows.
pub fn row_theta(row: usize, height: usize) -> f64 {
    PI * (row as f64 + 0.5) / height as f64
}

/// Azimuth φ of the centre of `col` in an image of `width` columns.
pub fn col_phi(col: usize, width: usize) -> f64 {
    TAU * (col as f64 + 0.5) / width as f64
}

/// Unit direction d(θ, φ) = (sin θ cos φ, cos θ, sin θ sin φ).
pub fn direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

/// Unit direction of the centre of texel (`row`, `col`) in a `width × height` image.
pub fn texel_direction(row: usize, col: usize, width: usize, height: usize) -> DVec3 {
    direction(row_theta(row, height), col_phi(col, width))
}

/// Exact solid angle of a texel in `row`: (2π/W)·(cos θ_top − cos θ_bottom).
pub fn texel_solid_angle(row: usize, width: usize, height: usize) -> f64 {
    let top = PI * row as f64 / height as f64;
    let bottom = PI * (row + 1) as f64 / height as f64;
    // cos θ_top − cos θ_bottom as 2·sin(mean)·sin(half difference), as lightsphere: thin rows
    // near the poles keep their digits.
    let (mean, half) = (0.5 * (top + bottom), 0.5 * (bottom - top));
    TAU / width as f64 * 2.0 * mean.sin() * half.sin()
}

/// The texel (`row`, `col`) whose area contains direction `dir` (need not be normalised),
/// or `None` for a zero or non-finite `dir`. Boundaries belong to the texel below / to the
/// right, the poles to the first and last row, φ = 2π wraps to column 0.
pub fn texel_containing(dir: DVec3, width: usize, height: usize) -> Option<(usize, usize)> {
    if !dir.is_finite() || dir == DVec3::ZERO {
        return None;
    }
    // The same arithmetic as lightsphere, so both agree on boundaries: atan2 of (horizontal
    // length, y) is accurate near the poles, unlike acos; −tiny + 2π rounding to 2π is φ = 0.
    let theta = dir.x.hypot(dir.z).atan2(dir.y);
    let mut phi = dir.z.atan2(dir.x);
    if phi < 0.0 {
        phi += TAU;
    }
    if phi >= TAU {
        phi = 0.0;
    }
    let row = ((theta / PI * height as f64).floor() as usize).min(height.saturating_sub(1));
    let col = ((phi / TAU * width as f64).floor() as usize).min(width.saturating_sub(1));
    Some((row, col))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solid_angles_partition_the_sphere() {
        for (w, h) in [(1, 1), (4, 3), (256, 128), (1024, 512)] {
            let total: f64 = (0..h).map(|r| w as f64 * texel_solid_angle(r, w, h)).sum();
            assert!(
                (total - 4.0 * PI).abs() < 1e-12 * 4.0 * PI,
                "{w}×{h}: {total}"
            );
        }
    }

    #[test]
    fn centres_round_trip_and_axes_match_the_convention() {
        let (w, h) = (64, 32);
        for r in 0..h {
            for c in 0..w {
                let d = texel_direction(r, c, w, h);
                assert_eq!(texel_containing(d, w, h), Some((r, c)));
            }
        }
        assert_eq!(texel_containing(DVec3::Y, w, h), Some((0, 0)));
        assert_eq!(texel_containing(-DVec3::Y, w, h).map(|t| t.0), Some(h - 1));
        // φ = 0 is +X, φ = π/2 is +Z (the first quarter of the columns), horizon at θ = π/2.
        let x = DVec3::new(1.0, 1e-9, 1e-9);
        assert_eq!(texel_containing(x, w, h), Some((h / 2 - 1, 0)));
        let z = DVec3::new(-1e-9, 1e-9, 1.0);
        assert_eq!(texel_containing(z, w, h).map(|t| t.1), Some(w / 4));
        assert_eq!(texel_containing(DVec3::ZERO, w, h), None);
        assert_eq!(texel_containing(DVec3::NAN, w, h), None);
    }
}
