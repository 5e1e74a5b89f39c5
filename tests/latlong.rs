//! One lat-long convention: `synth` (which makes skies) and `lightsphere` (which reads
//! environments) implement the same equirectangular mapping independently, so that `synth`
//! stays free of image dependencies. This test holds them to each other texel for texel:
//! centre directions, solid angles, and the texel containing a direction — at random, on the
//! poles, on the φ = 0 / 2π seam and exactly on row and column boundaries.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SIZES: [(usize, usize); 4] = [(1, 1), (4, 3), (256, 128), (1000, 333)];

#[test]
fn texel_centres_and_solid_angles_agree() {
    for (w, h) in SIZES {
        for row in 0..h {
            let a = lightsphere::latlong::texel_solid_angle(row, w, h);
            let b = synth::latlong::texel_solid_angle(row, w, h);
            assert!(
                (a - b).abs() <= 1e-15 * a.abs().max(1e-300),
                "{w}x{h} row {row}"
            );
            for col in (0..w).step_by((w / 7).max(1)) {
                let a = lightsphere::latlong::texel_direction(row, col, w, h);
                let b = synth::latlong::texel_direction(row, col, w, h);
                assert!(
                    (a - b).length() < 1e-15,
                    "{w}x{h} ({row}, {col}): {a} vs {b}"
                );
            }
        }
    }
}

fn same_texel(d: DVec3, w: usize, h: usize) {
    let a = lightsphere::latlong::texel_containing(d, w, h);
    let b = synth::latlong::texel_containing(d, w, h);
    assert_eq!(a, b, "{w}x{h}: direction {d:?}");
}

#[test]
fn random_directions_fall_into_the_same_texel() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for (w, h) in SIZES {
        for _ in 0..20_000 {
            let mut u = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            let d = DVec3::new(u(), u(), u());
            same_texel(d, w, h);
        }
    }
}

#[test]
fn poles_seam_boundaries_and_degenerate_directions_agree() {
    let tiny = 1e-300;
    for (w, h) in SIZES {
        for d in [
            DVec3::Y,
            -DVec3::Y,
            DVec3::new(tiny, 1.0, 0.0),
            DVec3::new(0.0, -1.0, tiny),
            DVec3::X,
            DVec3::new(1.0, 0.0, -tiny),
            DVec3::new(1.0, 0.0, -1e-17),
            DVec3::new(1.0, 0.3, tiny),
            -DVec3::X,
            DVec3::Z,
            -DVec3::Z,
        ] {
            same_texel(d, w, h);
        }
        // Texel corners: exactly on a row boundary θ = π r/H and a column boundary φ = 2π c/W.
        for row in 0..=h {
            for col in (0..w).step_by((w / 5).max(1)) {
                let theta = std::f64::consts::PI * row as f64 / h as f64;
                let phi = std::f64::consts::TAU * col as f64 / w as f64;
                same_texel(lightsphere::latlong::direction(theta, phi), w, h);
            }
        }
        for d in [DVec3::ZERO, DVec3::NAN, DVec3::new(f64::INFINITY, 0.0, 0.0)] {
            assert_eq!(lightsphere::latlong::texel_containing(d, w, h), None);
            assert_eq!(synth::latlong::texel_containing(d, w, h), None);
        }
    }
}
