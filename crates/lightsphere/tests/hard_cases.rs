//! Named adversarial cases: a sun 10⁴× the mean, 1×1 and 2×1 maps, invalid texels, truncated
//! and oversized files (a header claiming more texels than its bytes hold; FIFOs and devices
//! named like maps), look-ups exactly at the poles and seams, rotation by 360°, degenerate
//! queries and parameters.

mod common;

use common::{Rng, assert_close, assert_rel3, test_map, texel_power};
use glam::{DVec3, Quat, Vec3};
use lightsphere::{
    CellMeanParams, CellNormalization, Environment, Lightsphere, LightsphereError, RadianceMethod,
    latlong,
};
use std::io::Write;
use std::path::Path;

/// A 256×128 sky whose sun (one texel at θ = 60°) is 10⁴× the map's mean radiance.
fn sun_map() -> (Environment, usize) {
    let (w, h) = (256, 128);
    let mut texels: Vec<[f32; 3]> = test_map(w, h, 77).texels().to_vec();
    let mean = texels.iter().map(|t| f64::from(t[1])).sum::<f64>() / texels.len() as f64;
    let sun = 42 * w + 100;
    texels[sun] = [
        (3e4 * mean) as f32,
        (1e4 * mean) as f32,
        (5e3 * mean) as f32,
    ];
    (Environment::from_latlong(w, h, texels).unwrap(), sun)
}

#[test]
fn sun_ten_thousand_times_the_mean_keeps_power_and_finite_values() {
    let (env, sun) = sun_map();
    let exact = texel_power(&env);
    let sun_dir = latlong::texel_direction(sun / 256, sun % 256, 256, 128);
    for level in 0..=5 {
        let s = Lightsphere::new(level).unwrap();
        let i = env
            .radiance_per_direction(&s, RadianceMethod::CellMean)
            .unwrap();
        assert!(i.iter().all(|v| v.is_finite() && v.min_element() >= 0.0));
        assert_rel3(
            s.power(&i).unwrap(),
            exact,
            1e-5,
            &format!("CellMean level {level}"),
        );
        // The sun's energy lands in the cell that contains it.
        let j = s.nearest_f64(sun_dir);
        let brightest = (0..s.len())
            .max_by(|&a, &b| i[a].y.total_cmp(&i[b].y))
            .unwrap();
        assert_eq!(brightest, j, "level {level}");
        let sigma = lightsphere::matched_sigma_deg(s.len());
        let lookup = env
            .radiance_per_direction(&s, RadianceMethod::PrefilteredLookup { sigma_deg: sigma })
            .unwrap();
        assert!(
            lookup
                .iter()
                .all(|v| v.is_finite() && v.min_element() >= 0.0)
        );
    }
    let filtered = env.prefiltered(3.0).unwrap();
    assert_rel3(
        filtered.total_power(),
        exact,
        0.01,
        "prefiltered power with a sun",
    );
}

#[test]
fn one_by_one_map_is_constant_everywhere() {
    let env = Environment::from_latlong(1, 1, vec![[2.0, 3.0, 4.0]]).unwrap();
    let mut rng = Rng::new(3);
    for _ in 0..50 {
        assert_eq!(env.radiance_f64(rng.unit()), Vec3::new(2.0, 3.0, 4.0));
    }
    assert_eq!(env.radiance(Vec3::Y), Vec3::new(2.0, 3.0, 4.0));
    for level in [0, 3, 5] {
        let s = Lightsphere::new(level).unwrap();
        let params = CellMeanParams {
            normalization: CellNormalization::SampledSolidAngle,
            ..CellMeanParams::default()
        };
        let cm = env.cell_mean(&s, &params).unwrap();
        assert_eq!(cm.empty_cells, 0, "level {level}");
        assert!(
            cm.radiance
                .iter()
                .all(|v| (*v - Vec3::new(2.0, 3.0, 4.0)).abs().max_element() < 1e-5)
        );
        let i = env
            .radiance_per_direction(&s, RadianceMethod::CellMean)
            .unwrap();
        assert_rel3(s.power(&i).unwrap(), env.total_power(), 1e-6, "1×1 power");
    }
    let f = env.prefiltered(30.0).unwrap();
    assert_eq!((f.width(), f.height()), (1, 1));
    assert_close(f64::from(f.texels()[0][1]), 3.0, 1e-5, "prefiltered 1×1");
}

#[test]
fn two_by_one_map_splits_east_and_west() {
    let env = Environment::from_latlong(2, 1, vec![[1.0; 3], [3.0; 3]]).unwrap();
    // Column 0 covers φ ∈ [0, π) (z > 0), column 1 φ ∈ [π, 2π).
    assert_eq!(
        env.radiance_f64(latlong::direction(
            std::f64::consts::FRAC_PI_2,
            0.5 * std::f64::consts::PI
        )),
        Vec3::ONE
    );
    assert_eq!(
        env.radiance_f64(latlong::direction(
            std::f64::consts::FRAC_PI_2,
            1.5 * std::f64::consts::PI
        )),
        Vec3::splat(3.0)
    );
    assert_eq!(env.radiance(Vec3::Y), Vec3::splat(2.0));
    assert_close(
        env.total_power()[0],
        8.0 * std::f64::consts::PI,
        1e-12,
        "2×1 power",
    );
    let s = Lightsphere::new(4).unwrap();
    let i = env
        .radiance_per_direction(&s, RadianceMethod::CellMean)
        .unwrap();
    assert_rel3(
        s.power(&i).unwrap(),
        env.total_power(),
        1e-6,
        "2×1 power via I_j",
    );
    let f = env.prefiltered(20.0).unwrap();
    assert_rel3(
        f.total_power(),
        env.total_power(),
        0.01,
        "2×1 prefiltered power",
    );
}

#[test]
fn nan_infinite_and_negative_texels_are_rejected() {
    for bad in [f32::NAN, f32::NEG_INFINITY, -1.0, -f32::MIN_POSITIVE] {
        let mut t = vec![[0.5f32; 3]; 6];
        t[4] = [0.0, bad, 0.0];
        let err = Environment::from_latlong(3, 2, t).unwrap_err();
        assert!(
            matches!(
                err,
                LightsphereError::InvalidTexel {
                    row: 1,
                    col: 1,
                    channel: 1,
                    ..
                }
            ),
            "{bad}: {err}"
        );
    }
}

/// Issue #12: an `.hdr` whose RGBE exponent is 255 (radiance ~6.6·10³⁵, finite) lit the
/// cloth into f32 overflow and rendered black with exit 0. Above `MAX_RADIANCE` is refused
/// when the map loads, naming the file, texel and value; `MAX_RADIANCE` itself loads.
#[test]
fn huge_but_finite_radiance_is_refused_when_the_map_loads() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("blinding.hdr");
    write_flat_hdr(&path, 2, 1, &[[128, 128, 128, 129], [255, 255, 255, 255]]);
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LightsphereError::InvalidTexel {
                row: 0,
                col: 1,
                channel: 0,
                ..
            }
        ),
        "{err}"
    );
    let message = err.to_string();
    assert!(
        message.contains("blinding.hdr") && message.contains("MAX_RADIANCE"),
        "{message}"
    );
    let edge = Environment::from_latlong(2, 1, vec![[lightsphere::MAX_RADIANCE; 3], [0.0; 3]]);
    assert!(edge.is_ok());
    let above = Environment::from_latlong(2, 1, vec![[lightsphere::MAX_RADIANCE * 1.01; 3]; 2]);
    assert!(above.is_err());
}

fn write_flat_hdr(path: &Path, width: usize, height: usize, pixels: &[[u8; 4]]) {
    let mut f = std::fs::File::create(path).unwrap();
    write!(
        f,
        "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n"
    )
    .unwrap();
    for p in pixels {
        f.write_all(p).unwrap();
    }
}

#[test]
fn crafted_hdr_decodes_rgbe_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tiny.hdr");
    // RGBE (128, 64, 32, e=129): value = m · 2^(e−136) → (1.0, 0.5, 0.25).
    write_flat_hdr(&path, 2, 1, &[[128, 64, 32, 129], [0, 0, 0, 0]]);
    let env = Environment::load(&path).unwrap();
    assert_eq!(env.texels(), &[[1.0, 0.5, 0.25], [0.0, 0.0, 0.0]]);
}

#[test]
fn hdr_signatures_of_other_programs_decode_the_same() {
    // Mitsuba writes `#?RGBE`; stb_image reads it. Any "#?" + program name is a Radiance file.
    let dir = tempfile::tempdir().unwrap();
    let radiance = dir.path().join("radiance.hdr");
    write_flat_hdr(&radiance, 2, 1, &[[128, 64, 32, 129], [0, 0, 0, 0]]);
    let reference = Environment::load(&radiance).unwrap();
    let bytes = std::fs::read(&radiance).unwrap();
    for signature in ["#?RGBE", "#?MITSUBA", "#?RADIANCE\r"] {
        let path = dir.path().join("other.hdr");
        let mut renamed = signature.as_bytes().to_vec();
        renamed.extend_from_slice(&bytes["#?RADIANCE".len()..]);
        std::fs::write(&path, renamed).unwrap();
        let env = Environment::load(&path).unwrap_or_else(|e| panic!("{signature}: {e}"));
        assert_eq!(env.texels(), reference.texels(), "{signature}");
    }
    // Not a signature at all: still an error naming the file.
    let path = dir.path().join("not.hdr");
    std::fs::write(&path, [b"P6 1 1 255\n".as_slice(), &bytes[11..]].concat()).unwrap();
    let err = Environment::load(&path).unwrap_err();
    assert!(err.to_string().contains("not.hdr"), "{err}");
}

#[test]
fn truncated_hdr_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.hdr");
    write_flat_hdr(&path, 4, 4, &[[128, 64, 32, 129]; 5]);
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LightsphereError::Decode { .. } | LightsphereError::Io { .. }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cut.hdr"), "{err}");
    // Cut inside the header.
    std::fs::write(&path, b"#?RADIANCE\nFORMAT=32-bit_rle").unwrap();
    assert!(Environment::load(&path).is_err());
    // Empty file.
    std::fs::write(&path, b"").unwrap();
    assert!(Environment::load(&path).is_err());
    // A real map cut in half.
    if let Some(real) = test_data::shared_file("env/kiara_1_dawn_1k.hdr") {
        let bytes = std::fs::read(real).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
        assert!(Environment::load(&path).is_err());
    }
}

#[test]
fn oversized_hdr_header_is_rejected_before_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.hdr");
    write_flat_hdr(&path, 1_000_000, 1_000_000, &[[1, 2, 3, 4]]);
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LightsphereError::EnvironmentSize {
                width: 1_000_000,
                height: 1_000_000,
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().contains("huge.hdr") && err.to_string().contains("1000000"),
        "{err}"
    );
}

#[test]
fn a_tiny_hdr_whose_header_claims_gigabytes_is_refused_before_allocation() {
    // Issue #12: a 52-byte .hdr saying `-Y 8192 +X 16384` (within the size limits) allocated
    // 1.6 GB before failing. Beyond 2^22 texels the header must be backed by the file's bytes.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("liar.hdr");
    write_flat_hdr(&path, 16_384, 8_192, &[]);
    assert!(std::fs::metadata(&path).unwrap().len() < 64);
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(
            err,
            LightsphereError::HdrHeaderTooLarge {
                width: 16_384,
                height: 8_192,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("liar.hdr"), "{err}");
    // Up to the floor the header is taken at its word, and the short data is the error.
    write_flat_hdr(&path, 2048, 2048, &[]);
    assert!(matches!(
        Environment::load(&path).unwrap_err(),
        LightsphereError::Decode { .. } | LightsphereError::Io { .. }
    ));
}

#[cfg(unix)]
#[test]
fn fifos_and_devices_named_like_maps_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for name in ["sky.hdr", "sky.exr"] {
        let fifo = dir.path().join(name);
        test_data::make_fifo(&fifo);
        let message = Environment::load(&fifo).unwrap_err().to_string();
        assert!(
            message.contains(name) && message.contains("FIFO"),
            "{message}"
        );
    }
}

fn write_exr_rgba_f16(path: &Path, width: usize, height: usize) {
    use exr::prelude::f16;
    exr::prelude::write_rgba_file(path, width, height, |x, y| {
        let v = f16::from_f32((x + 10 * y) as f32 * 0.25);
        (v, v, f16::from_f32(1.5), f16::from_f32(0.5))
    })
    .unwrap();
}

#[test]
fn exr_with_half_rgba_layer_loads() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("half.exr");
    write_exr_rgba_f16(&path, 5, 3);
    let env = Environment::load(&path).unwrap();
    assert_eq!((env.width(), env.height()), (5, 3));
    assert_eq!(env.texel(2, 4), [6.0, 6.0, 1.5]);
}

#[test]
fn truncated_exr_is_an_error_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("full.exr");
    test_map(64, 32, 4).write_exr(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    for cut in [8, 40, bytes.len() / 3, bytes.len() / 2, bytes.len() - 7] {
        let p = dir.path().join(format!("cut{cut}.exr"));
        std::fs::write(&p, &bytes[..cut]).unwrap();
        let err = Environment::load(&p).unwrap_err();
        assert!(
            matches!(err, LightsphereError::Decode { .. }),
            "cut at {cut}: {err}"
        );
        assert!(err.to_string().contains(&format!("cut{cut}.exr")), "{err}");
    }
}

#[test]
fn exr_without_rgb_channels_is_named() {
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("luma.exr");
    let size = Vec2(4, 2);
    let channel = AnyChannel::new("Y", FlatSamples::F32(vec![0.5; size.area()]));
    let layer = Layer::new(
        size,
        LayerAttributes::named("main"),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(vec![channel].into()),
    );
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(&err, LightsphereError::ExrMissingRgb { channels, .. } if channels == "Y"),
        "{err}"
    );
}

#[test]
fn exr_with_nan_texel_names_the_file_and_texel() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("nan.exr");
    exr::prelude::write_rgb_file(&path, 3, 2, |x, y| {
        if (x, y) == (2, 1) {
            (0.0f32, f32::NAN, 0.0f32)
        } else {
            (1.0, 1.0, 1.0)
        }
    })
    .unwrap();
    let err = Environment::load(&path).unwrap_err();
    assert!(
        matches!(
            &err,
            LightsphereError::InvalidTexel {
                row: 1,
                col: 2,
                channel: 1,
                path: Some(_),
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("nan.exr"));
}

#[test]
fn lookups_exactly_at_poles_and_seams() {
    let env = test_map(16, 8, 19);
    let row_mean = |r: usize| {
        (0..16)
            .map(|c| Vec3::from_array(env.texel(r, c)))
            .sum::<Vec3>()
            / 16.0
    };
    for (dir, expected) in [
        (Vec3::Y, row_mean(0)),
        (Vec3::NEG_Y, row_mean(7)),
        (Vec3::new(-0.0, 1.0, 0.0), row_mean(0)),
    ] {
        assert!((env.radiance(dir) - expected).abs().max_element() < 1e-5);
    }
    // The φ = 0 seam approached from both sides.
    let theta = latlong::row_theta(3, 8);
    let a = env.radiance_f64(latlong::direction(theta, 1e-12));
    let b = env.radiance_f64(latlong::direction(theta, -1e-12));
    assert!((a - b).abs().max_element() < 1e-5, "{a} vs {b}");
    let seam = env.radiance(Vec3::new(1.0, 0.0, -0.0));
    assert!(seam.is_finite());
    // Nearest direction exactly at the poles and seams.
    let s = Lightsphere::new(5).unwrap();
    for q in [
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::new(1.0, 0.0, -0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(-1.0, 1.0, 1.0),
    ] {
        assert_eq!(s.nearest_f64(q), s.nearest_linear_f64(q), "{q}");
    }
}

#[test]
fn rotation_by_360_degrees_is_the_identity() {
    let full = Quat::from_rotation_y(std::f32::consts::TAU);
    let s = Lightsphere::new(4).unwrap();
    let r = s.rotated(full);
    assert_eq!(r.solid_angles(), s.solid_angles());
    for (a, b) in r.directions_f64().iter().zip(s.directions_f64()) {
        assert!((*a - *b).length() < 1e-6);
    }
    let mut rng = Rng::new(5);
    for _ in 0..200 {
        let q = rng.unit();
        // Away from cell borders the answer cannot change.
        let j = s.nearest_f64(q);
        let second = s
            .directions_f64()
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != j)
            .map(|(_, l)| l.dot(q))
            .fold(f64::MIN, f64::max);
        if s.directions_f64()[j].dot(q) - second > 1e-5 {
            assert_eq!(r.nearest_f64(q), j);
        }
    }
    let env = test_map(32, 16, 6);
    let turned = env.clone().with_rotation(full);
    for _ in 0..100 {
        let d = rng.unit();
        assert!(
            (turned.radiance_f64(d) - env.radiance_f64(d))
                .abs()
                .max_element()
                < 1e-4
        );
    }
}

#[test]
fn degenerate_queries_and_parameters() {
    let s = Lightsphere::new(3).unwrap();
    assert_eq!(s.nearest(Vec3::ZERO), 0);
    assert_eq!(s.nearest(Vec3::splat(f32::NAN)), 0);
    assert_eq!(s.nearest(Vec3::new(0.0, 0.0, 1e-45)), 4); // +Z, subnormal length
    assert_eq!(s.nearest(Vec3::new(0.0, f32::MAX, 0.0)), 2);
    assert!(matches!(
        Lightsphere::new(u32::MAX),
        Err(LightsphereError::LevelTooHigh { .. })
    ));
    assert!(
        s.try_rotated(Quat::from_xyzw(f32::INFINITY, 0.0, 0.0, 1.0))
            .is_err()
    );
    let env = test_map(8, 4, 1);
    let zero = CellMeanParams {
        samples_per_cell: 0,
        ..CellMeanParams::default()
    };
    assert!(env.cell_mean(&s, &zero).is_err());
    assert!(
        env.radiance_per_direction(
            &s,
            RadianceMethod::PrefilteredLookup {
                sigma_deg: f64::NAN
            }
        )
        .is_err()
    );
}

#[test]
fn tiny_sigma_returns_the_input_and_huge_sigma_the_mean() {
    let env = test_map(32, 16, 8);
    let same = env.prefiltered(0.01).unwrap();
    assert_eq!((same.width(), same.height()), (32, 16));
    for (a, b) in same.texels().iter().zip(env.texels()) {
        for c in 0..3 {
            assert_close(
                f64::from(a[c]),
                f64::from(b[c]),
                1e-6 * f64::from(b[c]),
                "σ = 0.01°",
            );
        }
    }
    // σ = 90°: nearly uniform, and still power preserving.
    let wide = env.prefiltered(90.0).unwrap();
    assert_rel3(wide.total_power(), env.total_power(), 0.01, "σ = 90° power");
}

#[test]
fn oversized_exr_header_is_rejected_before_allocation() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.exr");
    test_map(4, 2, 1).write_exr(&path).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    // dataWindow is a box2i attribute: name, type, size 16, then xMin yMin xMax yMax (i32 LE).
    for key in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = bytes
            .windows(key.len())
            .position(|w| w == key)
            .expect("window attribute")
            + key.len()
            + 4;
        bytes[at + 8..at + 12].copy_from_slice(&(1i32 << 20).to_le_bytes()); // xMax
        bytes[at + 12..at + 16].copy_from_slice(&(1i32 << 19).to_le_bytes()); // yMax
    }
    std::fs::write(&path, &bytes).unwrap();
    let err = Environment::load(&path).unwrap_err();
    assert!(err.to_string().contains("huge.exr"), "{err}");
    assert!(
        matches!(
            err,
            LightsphereError::EnvironmentSize {
                width: 1_048_577,
                height: 524_289,
                ..
            }
        ),
        "{err}"
    );
}
