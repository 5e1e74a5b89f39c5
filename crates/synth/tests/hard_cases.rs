//! Named adversarial cases: degenerate sizes, bad starts, extreme knobs, huge offsets,
//! invalid parameters. Results must be finite, deterministic and within stated error.

use glam::Vec3;
use std::f64::consts::{PI, TAU};
use synth::{
    ClothAnimation, ClothParams, Obstacle, SkyParams, SynthError, simulate_cloth, sky, sun_radiance,
};

/// Small, quick variant of the default drape.
fn quick(grid: usize, frames: usize) -> ClothParams {
    ClothParams {
        grid,
        frames,
        ..Default::default()
    }
}

#[track_caller]
fn assert_finite(anim: &ClothAnimation) {
    for (f, frame) in anim.frames.iter().enumerate() {
        assert!(
            frame.iter().all(|p| p.is_finite()),
            "frame {f} has a non-finite vertex"
        );
    }
}

/// No vertex deeper inside the sphere or below the ground than `tolerance` (metres), where
/// the solver keeps `collision_margin` outside both.
#[track_caller]
fn assert_outside(anim: &ClothAnimation, params: &ClothParams, tolerance: f32) {
    let Obstacle::Sphere { centre, radius } = params.obstacle;
    for (f, frame) in anim.frames.iter().enumerate() {
        for (v, p) in frame.iter().enumerate() {
            let depth = radius + params.collision_margin - p.distance(centre);
            assert!(
                depth < tolerance,
                "frame {f} vertex {v} is {depth} m inside the sphere"
            );
            if let Some(ground) = params.ground_height {
                let below = ground + params.collision_margin - p.y;
                assert!(
                    below < tolerance,
                    "frame {f} vertex {v} is {below} m below the ground"
                );
            }
        }
    }
}

#[test]
fn tiny_grid_2x2() {
    let params = quick(2, 40);
    let anim = simulate_cloth(&params).expect("valid");
    assert_eq!(
        (
            anim.vertex_count(),
            anim.triangles.len(),
            anim.frame_count()
        ),
        (4, 2, 40)
    );
    assert_finite(&anim);
    assert_outside(&anim, &params, 1e-5);
    // Four vertices 2 m apart stay a rigid-ish square (stretch holds with 5 edges).
    let last = &anim.frames[39];
    assert!((last[0].distance(last[1]) / params.size - 1.0).abs() < 0.05);
}

#[test]
fn cloth_starting_inside_the_sphere_is_pushed_out() {
    let params = ClothParams {
        drop_height: -0.2,
        ..quick(33, 60)
    };
    let anim = simulate_cloth(&params).expect("valid");
    assert_finite(&anim);
    // Frame 0 already: the intersecting part was projected to the surface.
    assert_outside(&anim, &params, 1e-5);
    let Obstacle::Sphere { centre, radius } = params.obstacle;
    let touching = anim.frames[0]
        .iter()
        .filter(|p| p.distance(centre) < radius + 2.0 * params.collision_margin)
        .count();
    assert!(touching > 0, "the start did not intersect the sphere");
}

#[test]
fn single_frame_is_the_initial_cloth() {
    let params = quick(16, 1);
    let anim = simulate_cloth(&params).expect("valid");
    assert_eq!(anim.frame_count(), 1);
    // Flat within the tilt (≤ 3°) and jitter, drop_height above the top of the sphere.
    let top = params.obstacle.anchor().y + params.obstacle.top_above_anchor();
    let half_diagonal = params.size * std::f32::consts::SQRT_2 / 2.0;
    for p in &anim.frames[0] {
        let above = p.y - (top + params.drop_height);
        assert!(
            above.abs() < half_diagonal * 3f32.to_radians().sin() + 0.01,
            "{p}"
        );
    }
}

#[test]
fn zero_compliance_is_stiff_and_finite() {
    let params = ClothParams {
        stretch_compliance: 0.0,
        bend_compliance: 0.0,
        ..quick(24, 45)
    };
    let anim = simulate_cloth(&params).expect("valid");
    assert_finite(&anim);
    assert_outside(&anim, &params, 1e-5);
}

#[test]
fn huge_compliance_degrades_to_free_particles_without_blowing_up() {
    let params = ClothParams {
        stretch_compliance: 1e30,
        bend_compliance: f32::MAX,
        ..quick(24, 45)
    };
    let anim = simulate_cloth(&params).expect("valid");
    assert_finite(&anim);
    assert_outside(&anim, &params, 1e-5);
}

#[test]
fn very_heavy_friction_makes_the_cloth_stick_where_it_lands() {
    let params = ClothParams {
        friction: 1e6,
        ..quick(33, 60)
    };
    let anim = simulate_cloth(&params).expect("valid");
    assert_finite(&anim);
    assert_outside(&anim, &params, 1e-5);
    // The centre lands on the top of the sphere around frame 8 and no longer slides.
    let g = anim.grid;
    let centre = (g / 2) * g + g / 2;
    let slide = anim.frames[20][centre].distance(anim.frames[59][centre]);
    assert!(slide < 0.01, "centre slid {slide} m under μ = 10⁶");
}

#[test]
fn huge_coordinate_offset_gives_the_same_drape() {
    let base = quick(24, 30);
    let offset = Vec3::new(1.0e4, 1.0e4, -1.0e4);
    let Obstacle::Sphere { centre, radius } = base.obstacle;
    let far = ClothParams {
        obstacle: Obstacle::Sphere {
            centre: centre + offset,
            radius,
        },
        ground_height: base.ground_height.map(|g| g + offset.y),
        ..base
    };
    let near = simulate_cloth(&base).expect("valid");
    let away = simulate_cloth(&far).expect("valid");
    assert_finite(&away);
    // The solver works relative to the sphere, so only the final f32 sum differs: half an
    // ulp at 10⁴ (4.9e-4 m) per coordinate.
    let tolerance = 1.0e4f32 * f32::EPSILON;
    for (f, (a, b)) in near.frames.iter().zip(&away.frames).enumerate() {
        for (v, (p, q)) in a.iter().zip(b).enumerate() {
            let error = (*q - offset - *p).abs().max_element();
            assert!(error <= tolerance, "frame {f} vertex {v}: {error} m");
        }
    }
}

#[test]
fn no_ground_and_one_substep() {
    let no_ground = ClothParams {
        ground_height: None,
        ..quick(24, 60)
    };
    let anim = simulate_cloth(&no_ground).expect("valid");
    assert_finite(&anim);
    assert_outside(&anim, &no_ground, 1e-5);
    let coarse = ClothParams {
        substeps: 1,
        ..quick(24, 60)
    };
    let anim = simulate_cloth(&coarse).expect("valid");
    assert_finite(&anim);
    assert_outside(&anim, &coarse, 1e-5);
}

#[test]
fn zero_gravity_cloth_stays_where_it_is() {
    let params = ClothParams {
        gravity: Vec3::ZERO,
        ..quick(33, 60)
    };
    let anim = simulate_cloth(&params).expect("valid");
    let drift = anim.frames[0]
        .iter()
        .zip(&anim.frames[59])
        .map(|(a, b)| a.distance(*b))
        .fold(0.0f32, f32::max);
    // Only the jitter (5% of a spacing = 3 mm) relaxes; nothing is amplified.
    assert!(drift < 0.01, "vertices drifted {drift} m without gravity");
}

#[test]
fn invalid_cloth_parameters_are_rejected_with_the_field_name() {
    let cases: Vec<(ClothParams, &str)> = vec![
        (
            ClothParams {
                grid: 1,
                ..Default::default()
            },
            "ClothParams::grid",
        ),
        (
            ClothParams {
                frames: 0,
                ..Default::default()
            },
            "ClothParams::frames",
        ),
        (
            ClothParams {
                substeps: 0,
                ..Default::default()
            },
            "ClothParams::substeps",
        ),
        (
            ClothParams {
                size: f32::NAN,
                ..Default::default()
            },
            "ClothParams::size",
        ),
        (
            ClothParams {
                friction: -1.0,
                ..Default::default()
            },
            "ClothParams::friction",
        ),
        (
            ClothParams {
                bend_compliance: f32::INFINITY,
                ..Default::default()
            },
            "ClothParams::bend_compliance",
        ),
        (
            ClothParams {
                gravity: Vec3::new(0.0, f32::NEG_INFINITY, 0.0),
                ..Default::default()
            },
            "ClothParams::gravity",
        ),
        (
            ClothParams {
                obstacle: Obstacle::Sphere {
                    centre: Vec3::ZERO,
                    radius: 0.0,
                },
                ..Default::default()
            },
            "ClothParams::obstacle (sphere radius)",
        ),
        (
            ClothParams {
                ground_height: Some(f32::NAN),
                ..Default::default()
            },
            "ClothParams::ground_height",
        ),
        (
            ClothParams {
                self_collision_distance: 3.0,
                ..Default::default()
            },
            "ClothParams::self_collision_distance",
        ),
    ];
    for (params, field) in cases {
        match simulate_cloth(&params) {
            Err(SynthError::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{field}: expected InvalidParameter, got {other:?}"),
        }
    }
    let error = simulate_cloth(&ClothParams {
        grid: 1 << 20,
        ..Default::default()
    })
    .expect_err("too large");
    assert!(matches!(error, SynthError::TooLarge { .. }), "{error}");
    let error = simulate_cloth(&ClothParams {
        grid: 1024,
        frames: 1000,
        ..Default::default()
    })
    .expect_err("too large");
    assert!(error.to_string().contains("frames × grid²"), "{error}");
}

/// Σ (with sun − without sun) · Ω per channel over the whole image.
fn sun_power(params: &SkyParams) -> [f64; 3] {
    let with = sky(params).expect("valid");
    let without = sky(&SkyParams {
        sun_to_sky_ratio: 0.0,
        ..*params
    })
    .expect("valid");
    let (w, h) = (params.width, params.height);
    let mut power = [0.0; 3];
    for row in 0..h {
        let omega = TAU / w as f64
            * ((PI * row as f64 / h as f64).cos() - (PI * (row + 1) as f64 / h as f64).cos());
        for col in 0..w {
            let is_ground = (PI * (row as f64 + 0.5) / h as f64).cos() <= 0.0;
            if is_ground {
                continue; // lit by the sun, but not the disc
            }
            let (a, b) = (with.texels[row * w + col], without.texels[row * w + col]);
            for k in 0..3 {
                power[k] += f64::from(a[k] - b[k]) * omega;
            }
        }
    }
    power
}

#[track_caller]
fn assert_power_fraction(params: &SkyParams, fraction: f64, tolerance: f64) {
    let alpha = f64::from(params.sun_angular_radius_deg).to_radians();
    let expected =
        sun_radiance(params).expect("valid").as_dvec3() * (TAU * (1.0 - alpha.cos())) * fraction;
    let power = sun_power(params);
    for k in 0..3 {
        let error = (power[k] - expected[k]).abs() / expected[k];
        assert!(
            error < tolerance,
            "{}×{}: channel {k} power {} vs {}",
            params.width,
            params.height,
            power[k],
            expected[k]
        );
    }
}

#[test]
fn one_texel_sky_conserves_the_sun() {
    let params = SkyParams {
        width: 1,
        height: 1,
        ..Default::default()
    };
    let image = sky(&params).expect("valid");
    assert!(image.texels[0].iter().all(|c| c.is_finite() && *c > 0.0));
    assert_power_fraction(&params, 1.0, 1e-4);
}

#[test]
fn odd_sizes_and_sun_at_the_zenith() {
    for (width, height) in [(3, 5), (7, 1), (256, 128)] {
        let params = SkyParams {
            width,
            height,
            sun_elevation_deg: 90.0,
            ..Default::default()
        };
        assert_power_fraction(&params, 1.0, 1e-4);
    }
}

#[test]
fn sun_on_the_horizon_is_half_hidden() {
    let params = SkyParams {
        width: 1024,
        height: 512,
        sun_elevation_deg: 0.0,
        ..Default::default()
    };
    // Half of a limb-darkened disc by solid angle is exactly half of its power.
    assert_power_fraction(&params, 0.5, 0.02);
}

#[test]
fn extreme_ratio_and_turbidity_stay_finite() {
    for params in [
        SkyParams {
            width: 64,
            height: 32,
            sun_to_sky_ratio: 1e8,
            ..Default::default()
        },
        SkyParams {
            width: 64,
            height: 32,
            turbidity: 1.7,
            ..Default::default()
        },
        SkyParams {
            width: 64,
            height: 32,
            turbidity: 10.0,
            sun_elevation_deg: 1.0,
            ..Default::default()
        },
        SkyParams {
            width: 64,
            height: 32,
            ground_albedo: Vec3::ZERO,
            limb_darkening: 1.0,
            sun_angular_radius_deg: 5.0,
            ..Default::default()
        },
    ] {
        let image = sky(&params).expect("valid");
        assert!(
            image
                .texels
                .iter()
                .flatten()
                .all(|c| c.is_finite() && *c >= 0.0),
            "{params:?}"
        );
        assert_power_fraction(&params, 1.0, 1e-3);
    }
}

#[test]
fn invalid_sky_parameters_are_rejected_with_the_field_name() {
    let cases: Vec<(SkyParams, &str)> = vec![
        (
            SkyParams {
                width: 0,
                ..Default::default()
            },
            "SkyParams::width",
        ),
        (
            SkyParams {
                height: 0,
                ..Default::default()
            },
            "SkyParams::height",
        ),
        (
            SkyParams {
                sun_elevation_deg: -1.0,
                ..Default::default()
            },
            "SkyParams::sun_elevation_deg",
        ),
        (
            SkyParams {
                sun_elevation_deg: 90.5,
                ..Default::default()
            },
            "SkyParams::sun_elevation_deg",
        ),
        (
            SkyParams {
                sun_azimuth_deg: f32::NAN,
                ..Default::default()
            },
            "SkyParams::sun_azimuth_deg",
        ),
        (
            SkyParams {
                sun_to_sky_ratio: -1.0,
                ..Default::default()
            },
            "SkyParams::sun_to_sky_ratio",
        ),
        (
            SkyParams {
                turbidity: 1.0,
                ..Default::default()
            },
            "SkyParams::turbidity",
        ),
        (
            SkyParams {
                ground_albedo: Vec3::new(0.2, 1.5, 0.2),
                ..Default::default()
            },
            "SkyParams::ground_albedo.y",
        ),
        (
            SkyParams {
                sun_angular_radius_deg: 0.0,
                ..Default::default()
            },
            "SkyParams::sun_angular_radius_deg",
        ),
        (
            SkyParams {
                limb_darkening: 2.0,
                ..Default::default()
            },
            "SkyParams::limb_darkening",
        ),
    ];
    for (params, field) in cases {
        match sky(&params) {
            Err(SynthError::InvalidParameter { field: f, .. }) => assert_eq!(f, field),
            other => panic!("{field}: expected InvalidParameter, got {other:?}"),
        }
    }
    let error = sky(&SkyParams {
        width: 1 << 20,
        height: 1 << 19,
        ..Default::default()
    })
    .expect_err("too large");
    assert!(
        matches!(error, SynthError::TooLarge { .. }) && error.to_string().contains("texels"),
        "{error}"
    );
}
