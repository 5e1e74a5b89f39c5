//! Environment maps: validation, power, bilinear look-up (seams, poles), rotation, file I/O.

mod common;

use common::{Rng, assert_close, test_map, texel_power};
use glam::{DVec3, Quat, Vec3};
use lightsphere::{Environment, LightsphereError, MAX_ENV_DIMENSION, latlong};
use std::f64::consts::PI;

#[track_caller]
fn assert_vec_close(a: Vec3, b: Vec3, tol: f32, what: &str) {
    assert!(
        (a - b).abs().max_element() <= tol * b.abs().max_element().max(1.0),
        "{what}: {a} vs {b}"
    );
}

#[test]
fn from_latlong_validates_size_count_and_values() {
    assert!(matches!(
        Environment::from_latlong(4, 2, vec![[0.0; 3]; 7]),
        Err(LightsphereError::TexelCount {
            expected: 8,
            actual: 7,
            ..
        })
    ));
    assert!(matches!(
        Environment::from_latlong(0, 2, vec![]),
        Err(LightsphereError::EnvironmentSize { width: 0, .. })
    ));
    // Checked before the texel count, so no w·h allocation is ever implied.
    assert!(matches!(
        Environment::from_latlong(MAX_ENV_DIMENSION + 1, 1 << 20, vec![]),
        Err(LightsphereError::EnvironmentSize { .. })
    ));
    for (bad, name) in [
        (f32::NAN, "NaN"),
        (-1e-3, "negative"),
        (f32::INFINITY, "infinite"),
    ] {
        let mut texels = vec![[1.0f32; 3]; 8];
        texels[6][2] = bad;
        let err = Environment::from_latlong(4, 2, texels).unwrap_err();
        match &err {
            LightsphereError::InvalidTexel {
                row,
                col,
                channel,
                path,
                ..
            } => {
                assert_eq!((*row, *col, *channel), (1, 2, 2), "{name}");
                assert!(path.is_none());
            }
            other => panic!("{name}: unexpected {other}"),
        }
        let msg = err.to_string();
        assert!(msg.contains("row 1") && msg.contains("col 2"), "{msg}");
    }
    // −0.0 is a valid radiance.
    assert!(Environment::from_latlong(1, 1, vec![[-0.0, 0.0, 1.0]]).is_ok());
}

#[test]
fn total_power_matches_analytic_integrals() {
    // Constant L: 4πL.
    let env = Environment::from_latlong(7, 5, vec![[1.0, 2.0, 0.5]; 35]).unwrap();
    let p = env.total_power();
    for (c, l) in [1.0, 2.0, 0.5].into_iter().enumerate() {
        assert_close(p[c], 4.0 * PI * l, 1e-12, "constant map");
    }
    // L = cos²θ stored as exact row averages: ∫ = 4π/3.
    let (w, h) = (8, 64);
    let texels = (0..h)
        .flat_map(|r| {
            let (t0, t1) = latlong::row_theta_bounds(r, h);
            // ∫ cos²θ sinθ dθ = (cos³t0 − cos³t1)/3, divided by (cos t0 − cos t1).
            let mean = (t0.cos().powi(3) - t1.cos().powi(3)) / 3.0 / (t0.cos() - t1.cos());
            std::iter::repeat_n([mean as f32; 3], w)
        })
        .collect();
    let env = Environment::from_latlong(w, h, texels).unwrap();
    assert_close(env.total_power()[0], 4.0 * PI / 3.0, 1e-6, "cos² map");
    let env = test_map(33, 17, 3);
    let (a, b) = (env.total_power(), texel_power(&env));
    for c in 0..3 {
        assert_close(a[c], b[c], 1e-12 * b[c], "independent texel sum");
    }
}

#[test]
fn bilinear_lookup_hits_texel_centres_and_interpolates() {
    let env = test_map(16, 8, 5);
    for r in 0..8 {
        for c in 0..16 {
            let d = latlong::texel_direction(r, c, 16, 8);
            assert_vec_close(
                env.radiance_f64(d),
                Vec3::from_array(env.texel(r, c)),
                1e-5,
                "texel centre",
            );
        }
    }
    // Halfway between two columns of row 3.
    let theta = latlong::row_theta(3, 8);
    let phi = 2.0 * PI * 5.0 / 16.0; // boundary between columns 4 and 5
    let mid = env.radiance_f64(latlong::direction(theta, phi));
    let expected = (Vec3::from_array(env.texel(3, 4)) + Vec3::from_array(env.texel(3, 5))) * 0.5;
    assert_vec_close(mid, expected, 1e-5, "column midpoint");
}

#[test]
fn lookup_wraps_across_the_phi_seam() {
    let env = test_map(16, 8, 9);
    let theta = latlong::row_theta(2, 8);
    let expected = (Vec3::from_array(env.texel(2, 0)) + Vec3::from_array(env.texel(2, 15))) * 0.5;
    for phi in [0.0, 1e-300, -1e-15, 2.0 * PI] {
        assert_vec_close(
            env.radiance_f64(latlong::direction(theta, phi)),
            expected,
            1e-5,
            "seam",
        );
    }
}

#[test]
fn lookup_is_continuous_at_the_poles() {
    let env = test_map(16, 8, 13);
    let mean = |row: usize| {
        (0..16)
            .map(|c| Vec3::from_array(env.texel(row, c)))
            .sum::<Vec3>()
            / 16.0
    };
    assert_vec_close(env.radiance(Vec3::Y), mean(0), 1e-5, "north pole");
    assert_vec_close(env.radiance(Vec3::NEG_Y), mean(7), 1e-5, "south pole");
    // Approaching the pole along any meridian converges to the same value.
    for k in 0..12 {
        let phi = 2.0 * PI * k as f64 / 12.0;
        for (theta, pole) in [(1e-7, Vec3::Y), (PI - 1e-7, Vec3::NEG_Y)] {
            let v = env.radiance_f64(latlong::direction(theta, phi));
            assert_vec_close(v, env.radiance(pole), 1e-4, "near pole");
        }
    }
    // Zero and non-finite directions give black instead of garbage.
    assert_eq!(env.radiance(Vec3::ZERO), Vec3::ZERO);
    assert_eq!(env.radiance(Vec3::NAN), Vec3::ZERO);
}

#[test]
fn rotation_moves_lookups_with_the_map() {
    let env = test_map(32, 16, 17);
    let q = Quat::from_euler(glam::EulerRot::YXZ, 1.1, 0.3, -0.7);
    let rotated = env.clone().with_rotation(q);
    assert!((rotated.world_from_env().dot(q.normalize())).abs() > 1.0 - 1e-6);
    let mut rng = Rng::new(1);
    for _ in 0..200 {
        let d = rng.unit();
        let moved = q.as_dquat().normalize() * d;
        assert_vec_close(
            rotated.radiance_f64(moved),
            env.radiance_f64(d),
            1e-4,
            "rotated look-up",
        );
    }
    assert!(
        env.try_with_rotation(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0))
            .is_err()
    );
}

#[test]
fn exr_round_trip_is_exact_and_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("map.exr");
    let mut env = test_map(24, 12, 21);
    env = Environment::from_latlong(24, 12, {
        let mut t = env.texels().to_vec();
        t[5] = [1e4, 0.0, 3.5e-6]; // sun-like and tiny values survive f32 storage
        t
    })
    .unwrap();
    env.write_exr(&path).unwrap();
    // Overwriting an existing file works too.
    env.write_exr(&path).unwrap();
    let back = Environment::load(&path).unwrap();
    assert_eq!((back.width(), back.height()), (24, 12));
    assert_eq!(back.texels(), env.texels());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn writing_below_a_file_fails_without_output_and_missing_folders_are_created() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("taken"), b"a file").unwrap();
    let path = dir.path().join("taken").join("map.exr");
    let err = test_map(4, 2, 1).write_exr(&path).unwrap_err();
    assert!(matches!(err, LightsphereError::Io { .. }), "{err}");
    assert!(err.to_string().contains("taken"), "{err}");
    assert!(!path.exists());
    let nested = dir.path().join("new").join("map.exr");
    test_map(4, 2, 1).write_exr(&nested).unwrap();
    assert!(nested.is_file());
}

#[test]
fn unsupported_extension_is_named() {
    let err = Environment::load(std::path::Path::new("sky.png")).unwrap_err();
    assert!(
        matches!(&err, LightsphereError::UnsupportedFormat { extension, .. } if extension == "png")
    );
    assert!(err.to_string().contains("sky.png"));
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let err = Environment::load(std::path::Path::new("/nonexistent/dir/sky.hdr")).unwrap_err();
    assert!(matches!(err, LightsphereError::Io { .. }));
    assert!(err.to_string().contains("/nonexistent/dir/sky.hdr"));
}

#[test]
fn real_hdr_maps_load_with_their_header_size() {
    for name in ["venice_sunset_1k.hdr", "kiara_1_dawn_1k.hdr"] {
        let Some(path) = test_data::shared_file(&format!("env/{name}")) else {
            return;
        };
        let env = Environment::load(&path).unwrap();
        assert_eq!((env.width(), env.height()), (1024, 512), "{name}");
        let p = env.total_power();
        assert!(p.iter().all(|v| v.is_finite() && *v > 0.0), "{name}: {p:?}");
        // The sky is brighter than the ground in both maps.
        let up = env.radiance(Vec3::Y).length();
        let down = env.radiance(Vec3::NEG_Y).length();
        assert!(up > down, "{name}: up {up}, down {down}");
        let _ = DVec3::ZERO;
    }
}
