//! The spherical Gaussian prefilter: constants stay constant (poles included), power is
//! preserved, a polar cap blurs like an equatorial one, and the fast filter agrees with an
//! O(N²) f64 brute force.

mod common;

use common::{assert_close, brute_force_prefilter, test_map};
use glam::{DQuat, DVec3, Vec3};
use lightsphere::{Environment, LightsphereError, PrefilterParams, latlong};
use std::f64::consts::PI;

#[test]
fn a_constant_map_stays_constant_everywhere() {
    let env = Environment::from_latlong(64, 32, vec![[1.0, 2.0, 3.0]; 64 * 32]).unwrap();
    for sigma in [3.0, 10.0, 40.0] {
        let f = env.prefiltered(sigma).unwrap();
        for (i, t) in f.texels().iter().enumerate() {
            for (c, expected) in [1.0, 2.0, 3.0].into_iter().enumerate() {
                assert_close(
                    f64::from(t[c]),
                    expected,
                    2e-5 * expected,
                    &format!("σ={sigma} texel {i}"),
                );
            }
        }
    }
}

#[test]
fn power_is_preserved() {
    let env = test_map(128, 64, 2);
    let p = env.total_power();
    for sigma in [2.0, 6.0, 20.0] {
        let q = env.prefiltered(sigma).unwrap().total_power();
        for c in 0..3 {
            assert_close(q[c], p[c], 0.01 * p[c], &format!("power at σ = {sigma}"));
        }
    }
}

#[test]
fn output_resolution_is_matched_to_sigma() {
    let env = test_map(96, 48, 4);
    // σ = 5° is 1.33 source texels: keep the resolution.
    let f = env.prefiltered(5.0).unwrap();
    assert_eq!((f.width(), f.height()), (96, 48));
    // σ = 30° is 8 texels: downsample by the largest divisor of 96 that is ≤ 8/3.
    let f = env.prefiltered(30.0).unwrap();
    assert_eq!((f.width(), f.height()), (48, 24));
}

/// A cap at the pole must blur into the same radial profile as the same cap at the equator;
/// a 2-D blur of the lat-long image does not (it neither blurs across the pole nor widens).
#[test]
fn a_polar_cap_blurs_like_an_equatorial_cap() {
    let (w, h) = (256, 128);
    let cap = 6f64.to_radians();
    let make = |centre: DVec3| {
        let texels = (0..w * h)
            .map(|i| {
                let d = latlong::texel_direction(i / w, i % w, w, h);
                if d.dot(centre) >= cap.cos() {
                    [1.0f32; 3]
                } else {
                    [0.0; 3]
                }
            })
            .collect();
        Environment::from_latlong(w, h, texels).unwrap()
    };
    let sigma = 8.0;
    let polar = make(DVec3::Y).prefiltered(sigma).unwrap();
    let equatorial = make(DVec3::X).prefiltered(sigma).unwrap();
    // Rotational symmetry about the pole: every output row is constant in φ.
    for r in 0..polar.height() {
        let row = &polar.texels()[r * polar.width()..(r + 1) * polar.width()];
        let max = row.iter().map(|t| t[0]).fold(0.0f32, f32::max);
        let min = row.iter().map(|t| t[0]).fold(f32::INFINITY, f32::min);
        assert!(max - min <= 1e-5 * max.max(1e-3), "row {r}: {min}..{max}");
    }
    // Same radial profile: compare at angle γ from each cap centre.
    let peak = f64::from(polar.radiance(Vec3::Y).x);
    for k in 0..=30 {
        let gamma = (k as f64).to_radians();
        let from_pole = DQuat::from_rotation_z(gamma) * DVec3::Y;
        // Rotating about the cap centre (X) changes the azimuth around it, not γ.
        let from_equator =
            DQuat::from_rotation_x(0.4 * k as f64) * (DQuat::from_rotation_z(gamma) * DVec3::X);
        let a = f64::from(polar.radiance_f64(from_pole).x);
        let b = f64::from(equatorial.radiance_f64(from_equator).x);
        assert_close(a, b, 0.03 * peak, &format!("profile at γ = {k}°"));
    }
}

#[test]
fn agrees_with_brute_force_at_full_resolution() {
    let mut env = test_map(48, 24, 8);
    let mut t = env.texels().to_vec();
    t[3] = [50.0, 10.0, 1.0]; // a bright texel next to the pole
    t[24 * 12 + 7] = [0.0, 80.0, 0.0];
    env = Environment::from_latlong(48, 24, t).unwrap();
    // Truncations are chosen so that no texel lies exactly on the cut-off circle (3σ = 75° =
    // 10 rows would, and rounding would then decide whether it counts).
    for (sigma, truncation) in [(12.0, 4.0), (12.0, 10.0), (25.0, 3.1)] {
        let params = PrefilterParams {
            truncation_sigmas: truncation,
            ..PrefilterParams::default()
        };
        let fast = env.prefiltered_with(sigma, &params).unwrap();
        let reference = brute_force_prefilter(&env, sigma, truncation, fast.width(), fast.height());
        let scale = reference.iter().flatten().fold(0.0f64, |m, v| m.max(*v));
        for (i, (a, b)) in fast.texels().iter().zip(&reference).enumerate() {
            for c in 0..3 {
                assert_close(
                    f64::from(a[c]),
                    b[c],
                    2e-6 * scale,
                    &format!("σ={sigma} texel {i} channel {c}"),
                );
            }
        }
    }
}

#[test]
fn agrees_with_brute_force_when_downsampled() {
    let env = test_map(96, 48, 12);
    let params = PrefilterParams {
        output_texels_per_sigma: 1.5,
        ..PrefilterParams::default()
    };
    // σ = 20° is 5.33 texels, so m = 3: output 32 × 16, centres between source columns.
    let fast = env.prefiltered_with(20.0, &params).unwrap();
    assert_eq!((fast.width(), fast.height()), (32, 16));
    let reference = brute_force_prefilter(&env, 20.0, 4.0, 32, 16);
    for (i, (a, b)) in fast.texels().iter().zip(&reference).enumerate() {
        for c in 0..3 {
            assert_close(
                f64::from(a[c]),
                b[c],
                2e-6 * b[c],
                &format!("texel {i} channel {c}"),
            );
        }
    }
}

#[test]
fn keeps_the_rotation() {
    let q = glam::Quat::from_rotation_x(0.5);
    let env = test_map(32, 16, 1).with_rotation(q);
    let f = env.prefiltered(10.0).unwrap();
    assert_eq!(f.world_from_env(), env.world_from_env());
}

#[test]
fn invalid_sigma_and_parameters_are_errors() {
    let env = test_map(8, 4, 1);
    for sigma in [0.0, -1.0, f64::NAN, f64::INFINITY, 90.5] {
        assert!(
            matches!(
                env.prefiltered(sigma),
                Err(LightsphereError::InvalidSigma { .. })
            ),
            "σ = {sigma}"
        );
    }
    let params = PrefilterParams {
        truncation_sigmas: 0.0,
        ..PrefilterParams::default()
    };
    assert!(matches!(
        env.prefiltered_with(5.0, &params),
        Err(LightsphereError::InvalidParameter {
            name: "truncation_sigmas",
            ..
        })
    ));
    let _ = PI;
}
