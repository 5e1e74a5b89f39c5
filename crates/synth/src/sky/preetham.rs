//! The Preetham–Shirley–Smits clear-sky model ("A Practical Analytic Model for Daylight",
//! SIGGRAPH 1999, appendix A.2): luminance Y and chromaticity x, y of the sky in the
//! direction at zenith angle θ and angle γ from the sun are
//!
//! `Y = Y_z · F(θ, γ) / F(0, θ_s)` with the Perez function
//! `F(θ, γ) = (1 + A e^{B / cos θ}) (1 + C e^{D γ} + E cos² γ)`,
//!
//! with coefficients linear in the turbidity T and zenith values Y_z, x_z, y_z fitted as
//! functions of T and the sun's zenith angle θ_s. The result (Y in kcd/m²) is converted
//! xyY → XYZ → linear Rec.709 RGB. All in f64.

use glam::DVec3;

/// cos θ is clamped to at least this when evaluating e^{B/cos θ} at the horizon, where the
/// fit is singular (B < 0 makes the term vanish smoothly as cos θ → 0⁺).
const MIN_COS_THETA: f64 = 1e-3;

/// Perez coefficients A..E for one of Y, x, y.
#[derive(Debug, Clone, Copy)]
struct Perez([f64; 5]);

impl Perez {
    fn eval(&self, cos_theta: f64, gamma: f64, cos_gamma: f64) -> f64 {
        let [a, b, c, d, e] = self.0;
        (1.0 + a * (b / cos_theta.max(MIN_COS_THETA)).exp())
            * (1.0 + c * (d * gamma).exp() + e * cos_gamma * cos_gamma)
    }
}

/// The sky for one sun position and turbidity.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PreethamSky {
    sun: DVec3,
    perez: [Perez; 3],
    /// Zenith value divided by F(0, θ_s), for Y, x, y.
    scale: [f64; 3],
}

impl PreethamSky {
    /// `sun`: unit direction towards the sun (y ≥ 0); `turbidity` in [1.7, 10].
    pub(crate) fn new(sun: DVec3, turbidity: f64) -> Self {
        let t = turbidity;
        let perez = [
            Perez([
                0.1787 * t - 1.4630,
                -0.3554 * t + 0.4275,
                -0.0227 * t + 5.3251,
                0.1206 * t - 2.5771,
                -0.0670 * t + 0.3703,
            ]),
            Perez([
                -0.0193 * t - 0.2592,
                -0.0665 * t + 0.0008,
                -0.0004 * t + 0.2125,
                -0.0641 * t - 0.8989,
                -0.0033 * t + 0.0452,
            ]),
            Perez([
                -0.0167 * t - 0.2608,
                -0.0950 * t + 0.0092,
                -0.0079 * t + 0.2102,
                -0.0441 * t - 1.6537,
                -0.0109 * t + 0.0529,
            ]),
        ];
        let theta_s = sun.y.clamp(-1.0, 1.0).acos();
        let zenith = zenith_values(t, theta_s);
        let cos_s = theta_s.cos();
        let scale = [0, 1, 2].map(|k| zenith[k] / perez[k].eval(1.0, theta_s, cos_s));
        Self { sun, perez, scale }
    }

    /// Linear Rec.709 RGB radiance (kcd/m² luminance scale) towards unit `dir` (y > 0).
    pub(crate) fn radiance(&self, dir: DVec3) -> [f64; 3] {
        let cos_gamma = dir.dot(self.sun).clamp(-1.0, 1.0);
        let gamma = cos_gamma.acos();
        let [lum, x, y] =
            [0, 1, 2].map(|k| self.scale[k] * self.perez[k].eval(dir.y, gamma, cos_gamma));
        xyy_to_rgb(x, y, lum)
    }
}

/// Zenith luminance (kcd/m²) and chromaticity, Preetham et al. appendix A.2.
fn zenith_values(t: f64, theta_s: f64) -> [f64; 3] {
    let chi = (4.0 / 9.0 - t / 120.0) * (std::f64::consts::PI - 2.0 * theta_s);
    let lum = (4.0453 * t - 4.9710) * chi.tan() - 0.2155 * t + 2.4192;
    let (s1, s2, s3) = (theta_s, theta_s * theta_s, theta_s * theta_s * theta_s);
    let poly = |m: [[f64; 4]; 3]| {
        let row = |r: [f64; 4]| r[0] * s3 + r[1] * s2 + r[2] * s1 + r[3];
        t * t * row(m[0]) + t * row(m[1]) + row(m[2])
    };
    let x = poly([
        [0.00166, -0.00375, 0.00209, 0.0],
        [-0.02903, 0.06377, -0.03202, 0.00394],
        [0.11693, -0.21196, 0.06052, 0.25886],
    ]);
    let y = poly([
        [0.00275, -0.00610, 0.00317, 0.0],
        [-0.04214, 0.08970, -0.04153, 0.00516],
        [0.15346, -0.26756, 0.06670, 0.26688],
    ]);
    [lum, x, y]
}

/// CIE xyY → XYZ → linear Rec.709 RGB (D65), negative components clamped to 0.
pub(crate) fn xyy_to_rgb(x: f64, y: f64, lum: f64) -> [f64; 3] {
    if y <= 0.0 || lum <= 0.0 {
        return [0.0; 3];
    }
    let big_x = x * lum / y;
    let big_z = (1.0 - x - y) * lum / y;
    [
        3.240_454_2 * big_x - 1.537_138_5 * lum - 0.498_531_4 * big_z,
        -0.969_266_0 * big_x + 1.876_010_8 * lum + 0.041_556_0 * big_z,
        0.055_643_4 * big_x - 0.204_025_9 * lum + 1.057_225_2 * big_z,
    ]
    .map(|c| c.max(0.0))
}

/// Relative luminance of linear Rec.709 RGB.
pub(crate) fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zenith_equals_fitted_zenith_values() {
        // At the zenith F(0, γ = θ_s) / F(0, θ_s) = 1, so Y, x, y equal the zenith fits.
        let sun = DVec3::new(0.6, 0.8, 0.0);
        let sky = PreethamSky::new(sun, 3.0);
        let [lum, x, y] = zenith_values(3.0, 0.8f64.acos());
        let expect = xyy_to_rgb(x, y, lum);
        let got = sky.radiance(DVec3::Y);
        for k in 0..3 {
            assert!((got[k] - expect[k]).abs() < 1e-12 * expect[k].abs().max(1.0));
        }
        assert!(
            (luminance(got) - lum).abs() < 1e-3 * lum,
            "{} vs {lum}",
            luminance(got)
        );
        // Plausible clear-sky zenith: a few kcd/m², bluish white (x, y ≈ 0.25–0.3).
        assert!(lum > 1.0 && lum < 20.0 && (0.2..0.35).contains(&x) && (0.2..0.35).contains(&y));
    }

    #[test]
    fn brighter_towards_sun_and_horizon_blue_at_zenith() {
        let sun = DVec3::new(0.0, 0.5, 0.75f64.sqrt());
        let sky = PreethamSky::new(sun, 3.0);
        let near_sun = sky.radiance(DVec3::new(0.05, 0.5, 0.75f64.sqrt()).normalize());
        let away = sky.radiance(DVec3::new(0.0, 0.5, -(0.75f64.sqrt())));
        assert!(luminance(near_sun) > 3.0 * luminance(away));
        let zenith = sky.radiance(DVec3::Y);
        assert!(zenith[2] > zenith[0], "zenith not blue: {zenith:?}");
    }

    #[test]
    fn white_point_maps_to_grey() {
        let [r, g, b] = xyy_to_rgb(0.3127, 0.3290, 1.0);
        for c in [r, g, b] {
            assert!((c - 1.0).abs() < 1e-3, "{r} {g} {b}");
        }
    }
}
