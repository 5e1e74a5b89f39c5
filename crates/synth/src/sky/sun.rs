//! The sun disc: its colour and its power-conserving splat into a lat-long image.
//!
//! The disc (angular radius α) is far smaller than a texel at common resolutions
//! (0.27° vs 1.4° at 256×128), so it is integrated, not point-sampled: N directions on a
//! Vogel (sunflower) spiral cover the disc in equal solid-angle parts, each carries its
//! share of the disc's power weighted by limb darkening `I(μ) = 1 − u(1 − μ)`, and each is
//! added to the texel that contains it, divided by that texel's exact solid angle. The
//! weights are normalised so that they sum to `L_sun · Ω_disc` exactly; power is conserved
//! at every resolution, and the shape of the disc is resolved once texels are smaller than
//! it.

use crate::latlong::{texel_containing, texel_solid_angle};
use glam::DVec3;
use std::f64::consts::{PI, TAU};

/// Fewest samples on the disc; enough to spread it over the 1–9 texels it touches at
/// 256×128 … 4096×2048 with under 1% error in each texel's share.
const MIN_SUN_SAMPLES: usize = 4096;
/// Samples per texel the disc covers, at high resolutions.
const SAMPLES_PER_COVERED_TEXEL: f64 = 64.0;
/// Most samples on the disc (bounds the work at absurd resolutions).
const MAX_SUN_SAMPLES: usize = 1 << 20;
/// Rayleigh optical depth of the atmosphere at 680, 550, 440 nm (Bucholtz 1995,
/// τ(λ) ≈ 0.0088 λ^−4.05 with λ in µm), the representative wavelengths of R, G, B.
const RAYLEIGH_DEPTH: [f64; 3] = [0.041, 0.097, 0.243];
/// Ångström exponent of the aerosol optical depth τ_a(λ) = β λ^−1.3 (Preetham et al. A.1).
const ANGSTROM_ALPHA: f64 = 1.3;
/// Wavelengths (µm) at which R, G, B are evaluated.
const WAVELENGTHS_UM: [f64; 3] = [0.68, 0.55, 0.44];

/// Solid angle of a disc (spherical cap) of angular radius `alpha` (radians).
pub(crate) fn disc_solid_angle(alpha: f64) -> f64 {
    // 2π(1 − cos α) written without cancellation.
    4.0 * PI * (alpha / 2.0).sin().powi(2)
}

/// Colour of the sunlight after the atmosphere (Rayleigh + aerosol extinction along the
/// Kasten–Young air mass), scaled to unit luminance.
pub(crate) fn sun_colour(elevation_rad: f64, turbidity: f64) -> [f64; 3] {
    let zenith_deg = 90.0 - elevation_rad.to_degrees();
    let air_mass =
        1.0 / (zenith_deg.to_radians().cos() + 0.50572 * (96.07995 - zenith_deg).powf(-1.6364));
    // Preetham et al. A.1: Ångström β = 0.04608 T − 0.04586.
    let beta = 0.04608 * turbidity - 0.04586;
    let transmittance = [0, 1, 2].map(|k| {
        let aerosol = beta * WAVELENGTHS_UM[k].powf(-ANGSTROM_ALPHA);
        (-(RAYLEIGH_DEPTH[k] + aerosol) * air_mass).exp()
    });
    let lum = super::preetham::luminance(transmittance).max(f64::MIN_POSITIVE);
    transmittance.map(|c| c / lum)
}

/// How many samples to put on a disc of solid angle `omega` in a `width × height` image.
fn sample_count(width: usize, height: usize, omega: f64) -> usize {
    // Smallest texel solid angle is at the poles; the equator's, 2π²/(W H), is typical.
    let texel = 2.0 * PI * PI / (width as f64 * height as f64);
    let wanted = SAMPLES_PER_COVERED_TEXEL * omega / texel;
    (wanted.ceil() as usize).clamp(MIN_SUN_SAMPLES, MAX_SUN_SAMPLES)
}

/// One weighted direction on the disc.
#[derive(Debug, Clone, Copy)]
pub(crate) struct DiscSample {
    pub(crate) dir: DVec3,
    /// Fraction of the disc's power carried by this sample (all sum to 1).
    pub(crate) weight: f64,
}

/// Equal-solid-angle Vogel spiral over the disc around unit `centre` with angular radius
/// `alpha`, weighted by limb darkening with coefficient `limb` (0 = uniform disc).
pub(crate) fn disc_samples(centre: DVec3, alpha: f64, limb: f64, count: usize) -> Vec<DiscSample> {
    let (t1, t2) = centre.any_orthonormal_pair();
    let one_minus_cos_alpha = 2.0 * (alpha / 2.0).sin().powi(2);
    let golden_angle = PI * (3.0 - 5.0f64.sqrt());
    let mut samples: Vec<DiscSample> = (0..count)
        .map(|k| {
            // t ∈ (0, 1) is the fraction of the disc's solid angle inside radius ρ.
            let t = (k as f64 + 0.5) / count as f64;
            let one_minus_cos_rho = t * one_minus_cos_alpha;
            let cos_rho = 1.0 - one_minus_cos_rho;
            let sin_rho = (one_minus_cos_rho * (2.0 - one_minus_cos_rho)).sqrt();
            let psi = (k as f64 * golden_angle) % TAU;
            let dir = centre * cos_rho + (t1 * psi.cos() + t2 * psi.sin()) * sin_rho;
            // μ = cos of the emission angle on the solar sphere = √(1 − (ρ/α)²) ≈ √(1 − t).
            let mu = (1.0 - t).sqrt();
            DiscSample {
                dir,
                weight: 1.0 - limb * (1.0 - mu),
            }
        })
        .collect();
    let total: f64 = samples.iter().map(|s| s.weight).sum();
    for s in &mut samples {
        s.weight /= total;
    }
    samples
}

/// Adds the disc of mean radiance `radiance` (RGB) to `texels`; samples below the horizon
/// are hidden by the ground and dropped. Returns the irradiance the visible disc casts on
/// the horizontal ground, Σ power_k · max(d_k.y, 0).
pub(crate) fn splat_disc(
    texels: &mut [[f32; 3]],
    (width, height): (usize, usize),
    centre: DVec3,
    alpha: f64,
    limb: f64,
    radiance: [f64; 3],
) -> [f64; 3] {
    let omega = disc_solid_angle(alpha);
    let samples = disc_samples(centre, alpha, limb, sample_count(width, height, omega));
    // Accumulate per texel in f64 first (a disc covers few texels; sort to merge).
    let mut hits: Vec<(usize, f64)> = samples
        .iter()
        .filter(|s| s.dir.y > 0.0)
        .filter_map(|s| {
            let (row, col) = texel_containing(s.dir, width, height)?;
            Some((row * width + col, s.weight))
        })
        .collect();
    hits.sort_by_key(|h| h.0);
    for run in hits.chunk_by(|a, b| a.0 == b.0) {
        let index = run[0].0;
        let share: f64 = run.iter().map(|h| h.1).sum();
        let texel_omega = texel_solid_angle(index / width, width, height);
        for k in 0..3 {
            let added = radiance[k] * omega * share / texel_omega;
            texels[index][k] = (f64::from(texels[index][k]) + added) as f32;
        }
    }
    let cos_weighted: f64 = samples.iter().map(|s| s.weight * s.dir.y.max(0.0)).sum();
    radiance.map(|c| c * omega * cos_weighted)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_stay_inside_the_disc_and_limb_darkening_integrates_analytically() {
        let centre = DVec3::new(0.3, 0.8, -0.52).normalize();
        let alpha = 0.27f64.to_radians();
        let samples = disc_samples(centre, alpha, 0.6, 4096);
        for s in &samples {
            assert!((s.dir.length() - 1.0).abs() < 1e-12);
            assert!(s.dir.angle_between(centre) <= alpha * (1.0 + 1e-9));
        }
        // ∫₀¹ (1 − u(1 − √(1 − t))) dt = 1 − u/3: the centre is brighter than the mean by
        // 1/(1 − u/3); the outermost sample (t → 1) by (1 − u)/(1 − u/3).
        let n = samples.len() as f64;
        let first = samples[0].weight * n;
        assert!((first - 1.0 / (1.0 - 0.2)).abs() < 1e-3, "{first}");
        let last = samples[samples.len() - 1].weight * n;
        assert!((last - 0.4 / 0.8).abs() < 2e-2, "{last}");
        // Mean direction is the centre (the spiral is balanced).
        let mean: DVec3 = samples.iter().map(|s| s.dir * s.weight).sum();
        assert!(mean.normalize().angle_between(centre) < 1e-3 * alpha);
    }

    #[test]
    fn sun_turns_red_near_the_horizon() {
        let high = sun_colour(60f64.to_radians(), 3.0);
        let low = sun_colour(3f64.to_radians(), 3.0);
        assert!((super::super::preetham::luminance(high) - 1.0).abs() < 1e-12);
        assert!(
            low[0] / low[2] > 2.0 * high[0] / high[2],
            "{low:?} vs {high:?}"
        );
    }
}
