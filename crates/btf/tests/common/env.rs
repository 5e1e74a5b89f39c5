//! The Lambertian oracle BTF and an equal-area direction set for the environment-light tests.
#![allow(dead_code)]

use btf::{BtfPca, BtfPcaParams, DIRECTIONS, Sampling, Storage, ViewSlot};
use glam::Vec3;

/// Texels per side of the oracle BTF.
pub const RES: usize = 8;
/// Its two albedos (a checkerboard).
pub const A: Vec3 = Vec3::new(0.8, 0.5, 0.3);
pub const B: Vec3 = Vec3::new(0.2, 0.6, 0.9);

/// `synth::LambertianBtf` (every image ρ cos θ_l) compressed with f32 storage.
pub fn lambertian(sampling: Sampling) -> (BtfPca, synth::LambertianBtf) {
    let lam = synth::LambertianBtf::new(RES, A, B).unwrap();
    let load = |j| {
        let data = (0..DIRECTIONS)
            .flat_map(|i| lam.image(sampling.vector(i)))
            .flatten()
            .collect();
        ViewSlot::new(j, RES, RES, data)
    };
    let params = BtfPcaParams {
        storage: Storage::F32,
        mean_storage: Storage::F32,
        ..Default::default()
    };
    let (pca, _) = BtfPca::compress_with(sampling, RES, RES, &params, load, None).unwrap();
    (pca, lam)
}

/// `n` directions of a Fibonacci sphere, each with solid angle 4π/n.
pub fn sphere_directions(n: usize) -> (Vec<Vec3>, f32) {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let dirs = (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
            let r = (1.0 - z * z).sqrt();
            let phi = golden * i as f64;
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
        })
        .collect();
    (dirs, (4.0 * std::f64::consts::PI / n as f64) as f32)
}

/// A random orthonormal (tangent, bitangent, normal).
pub fn random_frame(next: &mut impl FnMut() -> f32) -> [Vec3; 3] {
    let n = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize();
    let t0 = n.any_orthonormal_vector();
    let angle = std::f32::consts::TAU * next();
    let t = t0 * angle.cos() + n.cross(t0) * angle.sin();
    [t, n.cross(t), n]
}

/// A seeded LCG giving floats in [0, 1).
pub fn rng(seed: u64) -> impl FnMut() -> f32 {
    let mut s = seed;
    move || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 40) as f32 / (1u64 << 24) as f32
    }
}
