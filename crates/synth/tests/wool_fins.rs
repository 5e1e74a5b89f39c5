//! Properties of the procedural wool fin BTF, checked through the public API: determinism,
//! periodicity in y, the black background, the alpha profile and parameter validation.
//! The shading (exact oracles, forward scattering, self-shadowing) is in
//! `wool_fins_shading.rs`.

mod wool_fins_support;

use glam::Vec3;
use rayon::prelude::*;
use synth::{FIN_VIEW_DIR, FinImage, SynthError, WoolFinParams, WoolFins, WoolStrand};
use wool_fins_support::*;

#[test]
fn images_are_deterministic_and_depend_on_the_seed() {
    fn send_sync<T: Send + Sync>() {}
    send_sync::<WoolFins>();

    let params = WoolFinParams {
        width: 64,
        height: 48,
        strands: 200,
        ..Default::default()
    };
    let lights = [dir(0.0, 0.0), dir(45.0, 100.0), dir(75.0, 180.0)];
    let a = fins(&params);
    let sequential: Vec<FinImage> = lights.iter().map(|&l| a.image(l)).collect();
    // Rebuilt on one thread, shaded in parallel and in reverse order: bit-identical.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let b = pool.install(|| fins(&params));
    let mut parallel: Vec<(usize, FinImage)> = lights
        .par_iter()
        .enumerate()
        .rev()
        .map(|(k, &l)| (k, b.image(l)))
        .collect();
    parallel.sort_by_key(|(k, _)| *k);
    for ((_, p), s) in parallel.iter().zip(&sequential) {
        assert_eq!(p, s);
    }
    assert_eq!(a.strands(), b.strands());
    // Supplying the generated strands gives the generated fin.
    let again = custom(&params, a.strands().to_vec());
    assert_eq!(again.image(lights[1]), sequential[1]);

    let other = fins(&WoolFinParams { seed: 12, ..params });
    assert_ne!(other.alpha(), a.alpha());
    assert_ne!(other.image(lights[1]).rgba, sequential[1].rgba);
    assert_eq!((sequential[0].width, sequential[0].height), (64, 48));
    assert_eq!(FIN_VIEW_DIR, Vec3::X);
}

#[test]
fn a_strand_crossing_the_edge_appears_on_both_sides() {
    let params = WoolFinParams {
        width: 64,
        height: 64,
        shadow_sigma: 0.0,
        ..Default::default()
    };
    let colour = Vec3::new(0.5, 0.6, 0.7);
    // Dyadic coordinates, so that shifting by ½ changes no rounding.
    let strand = |dy: f32| {
        straight(
            Vec3::new(-0.125, 0.96875 + dy, 0.0),
            Vec3::new(-0.125, 1.09375 + dy, 0.5),
            8,
            0.015625,
            colour,
        )
    };
    let crossing = custom(&params, vec![strand(0.0)]);
    let image = crossing.image(dir(30.0, 45.0));
    let alpha = |column: usize, row: usize| image.pixel(column, row).unwrap()[3];
    // Row 48 is z ∈ [15, 16)/64: the axis is at y ≈ 1.03, i.e. column 1 or 2 after
    // wrapping; near the root (rows 56 and 60) it is at columns 63 and 62.
    assert!(
        (0..4).any(|c| alpha(c, 48) > 0.0),
        "the wrapped part is missing"
    );
    assert!(alpha(63, 60) > 0.0 || alpha(62, 60) > 0.0);
    assert!(alpha(0, 56) > 0.0 || alpha(63, 56) > 0.0);
    assert_eq!(alpha(32, 48), 0.0);
    assert!((0..64).any(|row| alpha(0, row) > 0.0) && (0..64).any(|row| alpha(63, row) > 0.0));

    // The same strand shifted by half a period gives the image rolled by half its width.
    let shifted = custom(&params, vec![strand(-0.5)]).image(dir(30.0, 45.0));
    for row in 0..64 {
        for column in 0..64 {
            let a = image.pixel(column, row).unwrap();
            let b = shifted.pixel((column + 32) % 64, row).unwrap();
            assert_eq!(a[3], b[3], "alpha at ({column}, {row})");
            for c in 0..3 {
                assert!((a[c] - b[c]).abs() <= 1e-6, "colour at ({column}, {row})");
            }
        }
    }
}

#[test]
fn generated_fur_tiles_seamlessly() {
    let params = WoolFinParams {
        width: 64,
        height: 64,
        strands: 200,
        ..Default::default()
    };
    let fin = fins(&params);
    let light = dir(60.0, 90.0);
    let reference = fin.image(light);
    for period in [-1.0f32, 1.0] {
        let moved: Vec<WoolStrand> = fin
            .strands()
            .iter()
            .map(|s| WoolStrand {
                points: s
                    .points
                    .iter()
                    .map(|p| *p + Vec3::new(0.0, period, 0.0))
                    .collect(),
                ..s.clone()
            })
            .collect();
        let image = custom(&params, moved).image(light);
        let (mut alpha, mut colour) = (0.0, 0.0);
        for (a, b) in image.rgba.iter().zip(&reference.rgba) {
            alpha += f64::from((a[3] - b[3]).abs());
            colour += (luminance(a) - luminance(b)).abs();
        }
        let n = image.rgba.len() as f64;
        assert!(
            alpha / n < 2e-3,
            "alpha changed by {} on average",
            alpha / n
        );
        assert!(
            colour / n < 2e-3,
            "luminance changed by {} on average",
            colour / n
        );
    }
}

#[test]
fn the_background_is_black_and_values_stay_in_range() {
    let params = WoolFinParams::default();
    let fin = fins(&params);
    let max_albedo = fin
        .strands()
        .iter()
        .map(|s| s.colour.max_element())
        .fold(0.0f32, f32::max);
    let bound = max_albedo * (params.diffuse_weight + params.forward_weight);
    assert!(bound < 0.9);
    let quantum = 1.0 / (params.supersample * params.supersample) as f32;
    let mut covered = 0;
    for (k, (theta, phi)) in table_5_3().into_iter().enumerate() {
        if k % 7 != 0 && theta != 75.0 {
            continue;
        }
        let image = fin.image(dir(theta, phi));
        for (p, &alpha) in image.rgba.iter().zip(fin.alpha()) {
            assert_eq!(p[3], alpha);
            assert!((0.0..=1.0).contains(&alpha));
            assert_eq!(
                (alpha / quantum).fract(),
                0.0,
                "alpha {alpha} is not a sub-sample count"
            );
            if alpha == 0.0 {
                assert_eq!(
                    p[..3],
                    [0.0; 3],
                    "background not black under ({theta}, {phi})"
                );
            } else {
                covered += 1;
                for &c in &p[..3] {
                    assert!(
                        c.is_finite() && c >= 0.0 && c <= alpha * bound + 1e-6,
                        "{p:?}"
                    );
                }
            }
        }
    }
    assert!(covered > 0);
    // A light at or below the horizon, or no direction at all: black with the coverage.
    for light in [-Vec3::Z, Vec3::X, Vec3::ZERO, Vec3::splat(f32::NAN)] {
        let image = fin.image(light);
        assert!(
            image
                .rgba
                .iter()
                .zip(fin.alpha())
                .all(|(p, &a)| *p == [0.0, 0.0, 0.0, a])
        );
    }
    // Lengths do not matter.
    assert_eq!(fin.image(dir(30.0, 60.0) * 3.0), fin.image(dir(30.0, 60.0)));
    assert_eq!(fin.image(Vec3::Z).pixel(params.width, 0), None);
}

#[test]
fn alpha_falls_off_at_the_tips() {
    let fin = fins(&WoolFinParams::default());
    let image = fin.image(dir(45.0, 0.0));
    let bottom = band_mean(&image, bottom_quarter(&image), |p| f64::from(p[3]));
    let top = band_mean(&image, top_quarter(&image), |p| f64::from(p[3]));
    assert!(bottom > 0.8, "bottom quarter mean alpha {bottom}");
    assert!(top < 0.5 * bottom, "top quarter mean alpha {top}");
    // And it falls all the way up: every quarter is less covered than the one below.
    let quarters: Vec<f64> = (0..4)
        .map(|q| band_mean(&image, (q * 32, q * 32 + 32), |p| f64::from(p[3])))
        .collect();
    assert!(quarters.windows(2).all(|w| w[0] < w[1]), "{quarters:?}");
    // The very top rows are nearly empty.
    assert!(band_mean(&image, (0, 4), |p| f64::from(p[3])) < 0.05);
}

#[test]
fn invalid_parameters_name_the_field() {
    let ok = WoolFinParams::default();
    assert_eq!(ok.validate(), Ok(()));
    let field_of = |params: WoolFinParams| match WoolFins::new(&params) {
        Err(SynthError::InvalidParameter { field, .. } | SynthError::TooLarge { field, .. }) => {
            field
        }
        Ok(_) => panic!("accepted {params:?}"),
    };
    let cases: Vec<(WoolFinParams, &str)> = vec![
        (WoolFinParams { width: 0, ..ok }, "WoolFinParams::width"),
        (WoolFinParams { height: 0, ..ok }, "WoolFinParams::height"),
        (WoolFinParams { width: 5000, ..ok }, "WoolFinParams::width"),
        (
            WoolFinParams {
                supersample: 0,
                ..ok
            },
            "WoolFinParams::supersample",
        ),
        (
            WoolFinParams {
                supersample: 9,
                ..ok
            },
            "WoolFinParams::supersample",
        ),
        (
            WoolFinParams {
                width: 4096,
                height: 4096,
                ..ok
            },
            "WoolFinParams::width · height · supersample²",
        ),
        (WoolFinParams { strands: 0, ..ok }, "WoolFinParams::strands"),
        (
            WoolFinParams { segments: 0, ..ok },
            "WoolFinParams::segments",
        ),
        (
            WoolFinParams {
                strands: 1 << 20,
                ..ok
            },
            "WoolFinParams::strands · segments",
        ),
        (
            WoolFinParams {
                depth: f32::INFINITY,
                ..ok
            },
            "WoolFinParams::depth",
        ),
        (
            WoolFinParams {
                depth: f32::NAN,
                ..ok
            },
            "WoolFinParams::depth",
        ),
        (
            WoolFinParams {
                length_max: 0.5,
                ..ok
            },
            "WoolFinParams::length_max",
        ),
        (
            WoolFinParams {
                max_tilt_deg: 90.0,
                ..ok
            },
            "WoolFinParams::max_tilt_deg",
        ),
        (
            WoolFinParams {
                root_radius_px: 0.0,
                ..ok
            },
            "WoolFinParams::root_radius_px",
        ),
        (
            WoolFinParams {
                colour: Vec3::new(0.5, f32::NAN, 0.5),
                ..ok
            },
            "WoolFinParams::colour.y",
        ),
        (
            WoolFinParams {
                colour: Vec3::new(1.5, 0.5, 0.5),
                ..ok
            },
            "WoolFinParams::colour.x",
        ),
        (
            WoolFinParams {
                forward_exponent: 0.0,
                ..ok
            },
            "WoolFinParams::forward_exponent",
        ),
        (
            WoolFinParams {
                shadow_sigma: -1.0,
                ..ok
            },
            "WoolFinParams::shadow_sigma",
        ),
        (
            WoolFinParams {
                diffuse_weight: 2.0,
                ..ok
            },
            "WoolFinParams::diffuse_weight",
        ),
    ];
    for (params, field) in cases {
        assert_eq!(field_of(params), field);
    }
    let message = WoolFins::new(&WoolFinParams {
        supersample: 0,
        ..ok
    })
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("supersample") && message.contains('0'),
        "{message}"
    );

    let good = straight(Vec3::ZERO, Vec3::Z * 0.5, 4, 0.01, Vec3::ONE);
    let strand_field =
        |strand: WoolStrand| match WoolFins::from_strands(&ok, vec![good.clone(), strand]) {
            Err(SynthError::InvalidParameter { field, .. }) => field,
            other => panic!("{other:?}"),
        };
    assert_eq!(
        strand_field(WoolStrand {
            points: vec![Vec3::ZERO],
            ..good.clone()
        }),
        "WoolStrand::points.len()"
    );
    assert_eq!(
        strand_field(WoolStrand {
            points: vec![Vec3::ZERO, Vec3::new(0.0, f32::NAN, 1.0)],
            ..good.clone()
        }),
        "WoolStrand::points"
    );
    assert_eq!(
        strand_field(WoolStrand {
            points: vec![Vec3::ZERO, Vec3::new(0.0, 2e4, 1.0)],
            ..good.clone()
        }),
        "WoolStrand::points"
    );
    assert_eq!(
        strand_field(WoolStrand {
            root_radius: -0.1,
            ..good.clone()
        }),
        "WoolStrand::root_radius"
    );
    assert_eq!(
        strand_field(WoolStrand {
            colour: Vec3::new(0.5, 0.5, 2.0),
            ..good.clone()
        }),
        "WoolStrand::colour.z"
    );
    assert!(matches!(
        WoolFins::from_strands(&WoolFinParams { width: 0, ..ok }, vec![good.clone()]),
        Err(SynthError::InvalidParameter {
            field: "WoolFinParams::width",
            ..
        })
    ));
    // No strands at all is a valid, empty fin.
    let empty = WoolFins::from_strands(&ok, Vec::new()).unwrap();
    assert!(empty.image(Vec3::Z).rgba.iter().all(|p| *p == [0.0; 4]));
}
