//! BTFs under environment light (thesis §5.5.2, eqs. 5.10–5.11) against closed forms: a
//! Lambertian BTF (`synth::LambertianBtf`, every image ρ cos θ) under a uniform environment
//! reflects ρ L for every vertex frame and view, and half of it when a wall hides half the
//! sky; hard cases: every direction occluded, a light exactly at a measured direction, a sun
//! 10⁴ times the sky.

use btf::env::EnvLightWeights;
use btf::{DIRECTIONS, Sampling};
use glam::Vec3;

#[path = "common/env.rs"]
mod env_common;
use env_common::{RES, lambertian, random_frame, rng, sphere_directions};

fn assert_rel(got: [f32; 3], want: Vec3, tol: f32, what: &str) {
    for (g, w) in got.iter().zip(want.to_array()) {
        assert!(
            (g - w).abs() <= tol * w.abs().max(1e-3),
            "{what}: {got:?} vs {want}"
        );
    }
}

#[test]
fn a_lambertian_btf_under_a_uniform_sky_reflects_rho_l_for_every_frame_and_view() {
    let sky = Vec3::new(1.0, 0.8, 0.6);
    let (dirs, omega) = sphere_directions(20_000);
    let radiance_omega = vec![sky * omega; dirs.len()];
    let mut next = rng(3);
    for sampling in Sampling::ALL {
        let (pca, lam) = lambertian(sampling);
        let mut worst = 0.0f32;
        for _ in 0..40 {
            let frame = random_frame(&mut next);
            let mut w = EnvLightWeights::default();
            w.add_samples(sampling, frame, &dirs, &radiance_omega, |_| true);
            for _ in 0..4 {
                // A view up to 80° from the normal, any azimuth.
                let theta = 80f32.to_radians() * next();
                let phi = std::f32::consts::TAU * next();
                let view = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                );
                let (x, y) = (
                    (next() * RES as f32) as usize % RES,
                    (next() * RES as f32) as usize % RES,
                );
                let u = (x as f32 + 0.5) / RES as f32;
                let v = (y as f32 + 0.5) / RES as f32;
                let got = pca.eval_env(view, &w, u, v);
                let want = lam.albedo(x, y) * sky;
                for (g, w) in got.iter().zip(want.to_array()) {
                    worst = worst.max((g / w - 1.0).abs());
                }
                assert_rel(got, want, 0.01, "ρL");
            }
        }
        eprintln!("{sampling}: largest relative error {worst:.2e}");
    }
}

#[test]
fn a_wall_hiding_half_the_sky_halves_it() {
    // Visible: directions with d·x ≥ 0, a wall along the normal's plane through x = 0.
    let sky = Vec3::splat(2.0);
    let (dirs, omega) = sphere_directions(40_000);
    let radiance_omega = vec![sky * omega; dirs.len()];
    let (pca, lam) = lambertian(Sampling::H1);
    let frame = [Vec3::X, Vec3::Y, Vec3::Z];
    let mut w = EnvLightWeights::default();
    w.add_samples(Sampling::H1, frame, &dirs, &radiance_omega, |d| {
        dirs[d].x >= 0.0
    });
    let got = pca.eval_env(Vec3::Z, &w, 0.01, 0.01);
    assert_rel(got, lam.albedo(0, 0) * sky * 0.5, 0.01, "half sky");
}

#[test]
fn every_direction_occluded_gives_black() {
    let (dirs, omega) = sphere_directions(1000);
    let radiance_omega = vec![Vec3::splat(omega); dirs.len()];
    let (pca, _) = lambertian(Sampling::H2);
    let mut w = EnvLightWeights::default();
    w.add_samples(
        Sampling::H2,
        [Vec3::X, Vec3::Y, Vec3::Z],
        &dirs,
        &radiance_omega,
        |_| false,
    );
    assert_eq!(w.total(), Vec3::ZERO);
    assert_eq!(pca.eval_env(Vec3::Z, &w, 0.3, 0.6), [0.0; 3]);
}

#[test]
fn a_light_exactly_at_a_measured_direction_is_that_image() {
    let s = Sampling::H1;
    let (pca, _) = lambertian(s);
    let m = 30;
    let mut w = EnvLightWeights::default();
    let lw = Vec3::new(3.0, 2.0, 1.0);
    w.add_samples(
        s,
        [Vec3::X, Vec3::Y, Vec3::Z],
        &[s.vector(m)],
        &[lw],
        |_| true,
    );
    let nonzero: Vec<usize> = (0..DIRECTIONS)
        .filter(|&i| w.weights[i] != Vec3::ZERO)
        .collect();
    assert_eq!(nonzero, vec![m]);
    let mut gamma = vec![Vec3::ZERO; pca.gamma_len(0)];
    pca.env_gamma(0, &w, &mut gamma);
    let image = pca.image(0, m);
    for (x, y) in [(0, 0), (5, 3)] {
        let got = pca.texel_rgb(0, &gamma, x, y);
        let want = Vec3::from(image[y * RES + x]) * lw / std::f32::consts::PI;
        assert_rel(got, want, 1e-5, "measured direction");
    }
}

#[test]
fn a_sun_ten_thousand_times_the_sky_adds_linearly() {
    let s = Sampling::H2;
    let (pca, _) = lambertian(s);
    let (dirs, omega) = sphere_directions(5000);
    let sky = vec![Vec3::splat(omega); dirs.len()];
    let sun_dir = Vec3::new(0.3, -0.2, 0.9).normalize();
    let sun = [Vec3::splat(1e4 * 6.8e-5)];
    let frame = [Vec3::X, Vec3::Y, Vec3::Z];
    let eval = |with_sky: bool, with_sun: bool| {
        let mut w = EnvLightWeights::default();
        if with_sky {
            w.add_samples(s, frame, &dirs, &sky, |_| true);
        }
        if with_sun {
            w.add_samples(s, frame, &[sun_dir], &sun, |_| true);
        }
        pca.eval_env(Vec3::new(0.2, 0.1, 0.97).normalize(), &w, 0.7, 0.2)
    };
    let (both, sky_only, sun_only) = (eval(true, true), eval(true, false), eval(false, true));
    for c in 0..3 {
        assert!(both[c].is_finite());
        assert!(
            (both[c] - sky_only[c] - sun_only[c]).abs() <= 1e-5 * both[c],
            "{both:?}"
        );
    }
    assert!(sun_only[0] > 0.1 * sky_only[0]);
}

#[test]
fn the_sparse_transfer_gives_the_direct_sum_for_any_environment() {
    let s = Sampling::H1;
    let (dirs, omega) = sphere_directions(2000);
    let omegas = vec![omega; dirs.len()];
    let mut next = rng(11);
    let frames: Vec<[Vec3; 3]> = (0..25).map(|_| random_frame(&mut next)).collect();
    // Visibility: a vertex-dependent half space, like a wall beside each vertex.
    let visible = |i: usize, d: usize| dirs[d].dot(frames[i][0]) + 0.1 * (i % 3) as f32 > -0.2;
    let transfer = btf::env::EnvTransfer::build(s, &frames, &dirs, &omegas, visible);
    assert_eq!(transfer.vertices(), 25);
    for env in 0..3 {
        let radiance: Vec<Vec3> = dirs
            .iter()
            .map(|d| Vec3::new(1.0 + d.x, 0.5 + env as f32 * d.y.abs(), 2.0 * d.z.max(0.0)))
            .collect();
        let mut fast = Vec::new();
        transfer.update(&radiance, &mut fast);
        for (i, w) in fast.iter().enumerate() {
            let lw: Vec<Vec3> = radiance.iter().map(|l| *l * omega).collect();
            let mut direct = EnvLightWeights::default();
            direct.add_samples(s, frames[i], &dirs, &lw, |d| visible(i, d));
            for m in 0..DIRECTIONS {
                let (a, b) = (w.weights[m], direct.weights[m]);
                assert!(
                    (a - b).abs().max_element() <= 1e-5 * (1.0 + b.abs().max_element()),
                    "{i} {m}"
                );
            }
        }
    }
}
