//! Procedural HDR sky: Preetham clear sky above the horizon, a Lambertian ground below it,
//! and a limb-darkened sun disc whose radiance is a chosen multiple of the mean sky
//! radiance — the "HDR maps with a sun 10⁴× the mean" hard case of the design, in the
//! shared [lat-long convention](crate::latlong).
//!
//! Radiometry:
//! * Sky (texel centre above the horizon): Preetham et al. 1999 (`preetham.rs`), linear
//!   Rec.709 RGB on Preetham's luminance scale (kcd/m²).
//! * Sun: mean radiance over the disc `L_sun = ratio · L̄_sky · c_sun`, where `L̄_sky` is
//!   the solid-angle mean luminance of the sky dome (upper hemisphere, without the sun) and
//!   `c_sun` the colour of sunlight after Rayleigh and aerosol extinction, of unit
//!   luminance. The disc is splatted with power conservation (see `sun.rs`).
//! * Ground (texel centre at or below the horizon): `L = ρ/π · (E_sky + E_sun)`, the
//!   radiance of a Lambertian ground of albedo ρ lit by this sky and sun (no shadowing).
//!
//! `L̄_sky` and `E_sky` are integrated from the analytic model on a fixed fine grid, so the
//! sky's radiance does not depend on the image resolution.

mod preetham;
mod sun;

use crate::error::{Result, SynthError, check_range};
use crate::latlong::{LatLongImage, row_theta, texel_direction};
use glam::{DVec3, Vec3};
use preetham::{PreethamSky, luminance};
use rayon::prelude::*;
use std::f64::consts::{PI, TAU};

/// Largest accepted `width × height` (128 Mi texels, 1.5 GiB).
pub const MAX_TEXELS: u128 = 1 << 27;
/// Quadrature of the sky dome for `L̄_sky` and `E_sky`: samples in cos θ and in φ
/// (equal-area midpoint rule; doubling both changes the mean and the irradiance by
/// < 5·10⁻⁴ relative, most for a sun near the zenith, whose circumsolar peak is sharp).
const DOME_SAMPLES_COS: usize = 256;
const DOME_SAMPLES_PHI: usize = 512;

/// Tuning knobs of [`sky`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkyParams {
    /// Columns of the lat-long image (≥ 1; default 1024).
    pub width: usize,
    /// Rows of the lat-long image (≥ 1; default 512).
    pub height: usize,
    /// Sun elevation above the horizon in degrees, 0 ..= 90 (default 35).
    pub sun_elevation_deg: f32,
    /// Sun azimuth φ in degrees, measured like the convention's φ: 0 = +X, 90 = +Z
    /// (default 60).
    pub sun_azimuth_deg: f32,
    /// Mean luminance of the sun disc divided by the mean luminance of the sky dome (upper
    /// hemisphere, sun excluded); ≥ 0, 0 = no sun (default 5·10⁴).
    pub sun_to_sky_ratio: f32,
    /// Atmospheric turbidity T of the Preetham model, 1.7 ..= 10 (default 3: clear).
    pub turbidity: f32,
    /// Linear RGB albedo of the ground, each in 0 ..= 1 (default (0.3, 0.25, 0.2)).
    pub ground_albedo: Vec3,
    /// Angular radius of the sun disc in degrees, (0, 5] (default 0.27).
    pub sun_angular_radius_deg: f32,
    /// Limb-darkening coefficient u of `I(μ) = 1 − u(1 − μ)`, 0 ..= 1 (default 0.6, the
    /// Sun in visible light).
    pub limb_darkening: f32,
}

impl Default for SkyParams {
    fn default() -> Self {
        Self {
            width: 1024,
            height: 512,
            sun_elevation_deg: 35.0,
            sun_azimuth_deg: 60.0,
            sun_to_sky_ratio: 5.0e4,
            turbidity: 3.0,
            ground_albedo: Vec3::new(0.3, 0.25, 0.2),
            sun_angular_radius_deg: 0.27,
            limb_darkening: 0.6,
        }
    }
}

impl SkyParams {
    /// Checks every field.
    ///
    /// # Errors
    /// [`SynthError::InvalidParameter`] naming the first offending field, or
    /// [`SynthError::TooLarge`] when `width × height` exceeds [`MAX_TEXELS`].
    pub fn validate(&self) -> Result<()> {
        for (field, value) in [
            ("SkyParams::width", self.width),
            ("SkyParams::height", self.height),
        ] {
            if value == 0 {
                return Err(SynthError::InvalidParameter {
                    field,
                    value: 0.0,
                    expected: "at least 1 texel",
                });
            }
        }
        let texels = self.width as u128 * self.height as u128;
        if texels > MAX_TEXELS {
            return Err(SynthError::TooLarge {
                field: "SkyParams::width × height",
                requested: texels,
                maximum: MAX_TEXELS,
                unit: "texels",
            });
        }
        check_range(
            "SkyParams::sun_elevation_deg",
            self.sun_elevation_deg,
            0.0,
            90.0,
            "0 ..= 90 degrees (the sky model needs the sun above the horizon)",
        )?;
        check_range(
            "SkyParams::sun_azimuth_deg",
            self.sun_azimuth_deg,
            f32::MIN,
            f32::MAX,
            "a finite angle in degrees",
        )?;
        check_range(
            "SkyParams::sun_to_sky_ratio",
            self.sun_to_sky_ratio,
            0.0,
            f32::MAX,
            "a finite ratio ≥ 0",
        )?;
        check_range(
            "SkyParams::turbidity",
            self.turbidity,
            1.7,
            10.0,
            "1.7 ..= 10 (the range the Preetham model was fitted on)",
        )?;
        for (k, albedo) in self.ground_albedo.to_array().into_iter().enumerate() {
            let field = [
                "SkyParams::ground_albedo.x",
                "SkyParams::ground_albedo.y",
                "SkyParams::ground_albedo.z",
            ][k];
            check_range(field, albedo, 0.0, 1.0, "0 ..= 1")?;
        }
        check_range(
            "SkyParams::sun_angular_radius_deg",
            self.sun_angular_radius_deg,
            f32::MIN_POSITIVE,
            5.0,
            "0 < radius ≤ 5 degrees",
        )?;
        check_range(
            "SkyParams::limb_darkening",
            self.limb_darkening,
            0.0,
            1.0,
            "0 ..= 1",
        )?;
        Ok(())
    }
}

/// Unit direction towards the sun centre: `(cos e cos a, sin e, cos e sin a)` for elevation
/// e and azimuth a, i.e. the convention's d(θ = 90° − e, φ = a).
pub fn sun_direction(params: &SkyParams) -> Vec3 {
    sun_direction_f64(params).as_vec3()
}

fn sun_direction_f64(params: &SkyParams) -> DVec3 {
    let e = f64::from(params.sun_elevation_deg).to_radians();
    let a = f64::from(params.sun_azimuth_deg).to_radians();
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

/// Mean linear RGB radiance of the sun disc (its power divided by its solid angle), the
/// value [`sky`] splats; the disc's luminance is `sun_to_sky_ratio` × the sky dome's mean.
/// (Where the disc dips below the horizon, [`sky`] hides that part behind the ground.)
///
/// # Errors
/// As [`sky`].
pub fn sun_radiance(params: &SkyParams) -> Result<Vec3> {
    params.validate()?;
    let model = PreethamSky::new(sun_direction_f64(params), f64::from(params.turbidity));
    let dome = integrate_dome(&model, DOME_SAMPLES_COS, DOME_SAMPLES_PHI);
    Ok(DVec3::from_array(sun_mean_radiance(params, dome.mean_luminance)).as_vec3())
}

fn sun_mean_radiance(params: &SkyParams, mean_sky_luminance: f64) -> [f64; 3] {
    let elevation = f64::from(params.sun_elevation_deg).to_radians();
    let colour = sun::sun_colour(elevation, f64::from(params.turbidity));
    colour.map(|c| c * f64::from(params.sun_to_sky_ratio) * mean_sky_luminance)
}

/// Renders the sky, ground and sun into a lat-long image (see [`crate::latlong`]).
///
/// * Sky (texel centre above the horizon): the Preetham–Shirley–Smits clear-sky model
///   (1999) evaluated at the texel centre, converted xyY → linear Rec.709 RGB, on
///   Preetham's luminance scale (kcd/m²; scale the image as needed).
/// * Sun: a limb-darkened disc of angular radius `sun_angular_radius_deg` whose mean
///   luminance is `sun_to_sky_ratio` × the mean luminance of the sky dome (upper hemisphere,
///   sun excluded, solid-angle weighted), coloured by Rayleigh and aerosol extinction. It is
///   integrated over the disc (an equal-area spiral of ≥ 4096 directions) and added to the
///   texels it covers divided by their exact solid angles, so `Σ ΔL·Ω` equals the disc's
///   power at every resolution, even when the disc is far smaller than a texel.
/// * Ground (texel centre at or below the horizon): a Lambertian ground of albedo ρ lit by
///   this sky and sun, `L = ρ/π · (E_sky + E_sun)`.
///
/// The sky dome's mean and irradiance are integrated from the analytic model on a fixed
/// fine grid, so the radiances do not depend on the resolution. Rows are rendered in
/// parallel (rayon); the result is identical for any thread count.
///
/// # Errors
/// [`SynthError`] when a parameter is out of range (see [`SkyParams::validate`]).
///
/// # Examples
/// ```
/// let params = synth::SkyParams { width: 64, height: 32, ..Default::default() };
/// let image = synth::sky(&params)?;
/// assert_eq!(image.texels.len(), 64 * 32);
/// # Ok::<(), synth::SynthError>(())
/// ```
pub fn sky(params: &SkyParams) -> Result<LatLongImage> {
    params.validate()?;
    let (width, height) = (params.width, params.height);
    let sun_dir = sun_direction_f64(params);
    let model = PreethamSky::new(sun_dir, f64::from(params.turbidity));
    let dome = integrate_dome(&model, DOME_SAMPLES_COS, DOME_SAMPLES_PHI);
    let sun_radiance = sun_mean_radiance(params, dome.mean_luminance);

    let mut texels = vec![[0.0f32; 3]; width * height];
    texels
        .par_chunks_mut(width)
        .enumerate()
        .for_each(|(row, out)| {
            if row_theta(row, height).cos() > 0.0 {
                for (col, texel) in out.iter_mut().enumerate() {
                    *texel = model
                        .radiance(texel_direction(row, col, width, height))
                        .map(|c| c as f32);
                }
            }
        });
    let alpha = f64::from(params.sun_angular_radius_deg).to_radians();
    let sun_irradiance = if params.sun_to_sky_ratio > 0.0 {
        let limb = f64::from(params.limb_darkening);
        sun::splat_disc(
            &mut texels,
            (width, height),
            sun_dir,
            alpha,
            limb,
            sun_radiance,
        )
    } else {
        [0.0; 3]
    };
    let albedo = params.ground_albedo.as_dvec3().to_array();
    let ground =
        [0, 1, 2].map(|k| (albedo[k] / PI * (dome.irradiance[k] + sun_irradiance[k])) as f32);
    for row in (0..height).filter(|&r| row_theta(r, height).cos() <= 0.0) {
        texels[row * width..(row + 1) * width].fill(ground);
    }
    Ok(LatLongImage {
        width,
        height,
        texels,
    })
}

/// Integrals of the analytic sky over the upper hemisphere.
struct Dome {
    /// Solid-angle mean luminance.
    mean_luminance: f64,
    /// Irradiance on a horizontal surface, ∫ L cos θ dΩ, per RGB channel.
    irradiance: [f64; 3],
}

/// Equal-area midpoint quadrature in (cos θ, φ); rows run in parallel, their partial sums
/// are added in order, so the result does not depend on the thread count.
fn integrate_dome(model: &PreethamSky, samples_cos: usize, samples_phi: usize) -> Dome {
    let rows: Vec<(f64, [f64; 3])> = (0..samples_cos)
        .into_par_iter()
        .map(|i| {
            let cos_theta = (i as f64 + 0.5) / samples_cos as f64;
            let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
            let mut lum = 0.0;
            let mut irr = [0.0; 3];
            for j in 0..samples_phi {
                let phi = TAU * (j as f64 + 0.5) / samples_phi as f64;
                let dir = DVec3::new(sin_theta * phi.cos(), cos_theta, sin_theta * phi.sin());
                let rgb = model.radiance(dir);
                lum += luminance(rgb);
                for k in 0..3 {
                    irr[k] += rgb[k] * cos_theta;
                }
            }
            (lum, irr)
        })
        .collect();
    let n = (samples_cos * samples_phi) as f64;
    let mut lum = 0.0;
    let mut irr = [0.0; 3];
    for (l, e) in rows {
        lum += l;
        for k in 0..3 {
            irr[k] += e[k];
        }
    }
    // Each sample stands for 2π/n steradians.
    Dome {
        mean_luminance: lum / n,
        irradiance: irr.map(|e| e * TAU / n),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dome_quadrature_has_converged() {
        for elevation in [5.0f64, 35.0, 89.0] {
            let e = elevation.to_radians();
            let model = PreethamSky::new(DVec3::new(e.cos(), e.sin(), 0.0), 3.0);
            let coarse = integrate_dome(&model, DOME_SAMPLES_COS, DOME_SAMPLES_PHI);
            let fine = integrate_dome(&model, 2 * DOME_SAMPLES_COS, 2 * DOME_SAMPLES_PHI);
            let error = (coarse.mean_luminance - fine.mean_luminance).abs() / fine.mean_luminance;
            assert!(error < 5e-4, "elevation {elevation}: mean off by {error}");
            for k in 0..3 {
                let error = (coarse.irradiance[k] - fine.irradiance[k]).abs() / fine.irradiance[k];
                assert!(
                    error < 5e-4,
                    "elevation {elevation}: irradiance {k} off by {error}"
                );
            }
        }
    }
}
