//! Cross-crate: the synthetic sky (synth) as a lightsphere Environment, lit through the facade's
//! Lambertian quadrature, against the exact irradiance summed over every texel in f64.
//!
//! E(n) = Σ_texels L_t max(0, n·d_t) Ω_t is the exact integral of the piecewise-constant map;
//! the lightsphere quadrature Σ_j I_j ω_j max(0, n·l_j) must approach it as the level grows,
//! even with a sun 5·10⁴× the mean sky concentrated in one or two texels.

use glam::{DVec3, Vec3};
use rand::{Rng, SeedableRng};

/// Uniform in [-1, 1) from 24 random bits.
fn symmetric(rng: &mut impl Rng) -> f32 {
    (rng.next_u64() >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
}

fn exact_irradiance(sky: &synth::LatLongImage, n: DVec3) -> DVec3 {
    let mut e = DVec3::ZERO;
    for r in 0..sky.height {
        let omega = sky.solid_angle(r);
        for c in 0..sky.width {
            let d = sky.direction(r, c).as_dvec3();
            let cos = n.dot(d);
            if cos > 0.0 {
                let t = sky.texel(r, c);
                e += DVec3::new(t[0].into(), t[1].into(), t[2].into()) * cos * omega;
            }
        }
    }
    e
}

#[test]
fn lightsphere_irradiance_converges_to_the_exact_texel_sum() {
    let params = synth::SkyParams {
        width: 256,
        height: 128,
        ..synth::SkyParams::default()
    };
    let sky = synth::sky(&params).unwrap();
    let env =
        lightsphere::Environment::from_latlong(sky.width, sky.height, sky.texels.clone()).unwrap();
    let sun = synth::sun_direction(&params);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut normals = vec![sun, Vec3::Y, -Vec3::Y];
    for _ in 0..40 {
        let v = Vec3::new(
            symmetric(&mut rng),
            symmetric(&mut rng),
            symmetric(&mut rng),
        );
        if let Some(n) = v.try_normalize() {
            normals.push(n);
        }
    }
    let exact: Vec<DVec3> = normals
        .iter()
        .map(|n| exact_irradiance(&sky, n.as_dvec3()))
        .collect();
    let scale = exact.iter().map(|e| e.length()).fold(0.0, f64::max);
    let mut errors = Vec::new();
    for level in [3u32, 5] {
        let sphere = lightsphere::Lightsphere::new(level).unwrap();
        let radiance = env
            .radiance_per_direction(&sphere, lightsphere::RadianceMethod::CellMean)
            .unwrap();
        // albedo π turns the returned ρ/π·E into E.
        let albedo = Vec3::splat(std::f32::consts::PI);
        let lit = cloth_vis::lighting::lambertian_radiance(
            &normals,
            sphere.directions(),
            sphere.solid_angles(),
            &radiance,
            albedo,
        );
        let worst = lit
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a.as_dvec3() - *b).length() / scale)
            .fold(0.0, f64::max);
        errors.push(worst);
    }
    eprintln!(
        "worst irradiance error relative to the sunlit maximum: level 3 {:.4}, level 5 {:.4}",
        errors[0], errors[1]
    );
    // Cell means move each texel's power to its cell's direction: the cosine is then taken up to
    // one cell radius away (≈ 7° at level 3, ≈ 2° at level 5).
    assert!(errors[0] < 0.08, "level 3: {}", errors[0]);
    assert!(errors[1] < 0.02, "level 5: {}", errors[1]);
    assert!(errors[1] < errors[0]);
}
