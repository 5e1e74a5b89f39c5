//! Named adversarial cases: degenerate sizes, bad starts, extreme knobs, huge offsets,
//! grazing directions, invalid parameters. Results must be finite, deterministic and within stated error.

use glam::Vec3;
use std::f64::consts::{PI, TAU};
use synth::{
    ClothAnimation, ClothParams, Obstacle, SkyParams, SynthError, WovenBtf, WovenBtfParams,
    simulate_cloth, sky, sun_radiance,
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

// ------------------------------------------------------------------ woven-cloth BTF

/// d(θ, φ) = (sin θ cos φ, sin θ sin φ, cos θ), angles in degrees.
fn woven_dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    glam::DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()).as_vec3()
}

fn woven(params: WovenBtfParams) -> WovenBtf {
    WovenBtf::new(&params).expect("valid parameters")
}

/// Every channel finite and in `[0, bound]`.
#[track_caller]
fn assert_radiance_in(image: &[[f32; 3]], bound: f32) {
    for (i, texel) in image.iter().enumerate() {
        for c in texel {
            assert!(c.is_finite() && (0.0..=bound).contains(c), "texel {i}: {c}");
        }
    }
}

/// The largest radiance the model can produce (see `synth::btf`).
fn radiance_bound(params: &WovenBtfParams) -> f32 {
    let albedo = params
        .warp_albedo
        .max_element()
        .max(params.weft_albedo.max_element())
        * (1.0 + params.albedo_variation);
    params.diffuse_weight * albedo.max(params.gap_albedo.max_element())
        + params.glossy_weight * (params.glossy_exponent + 8.0) / 8.0
        + 1e-6
}

#[test]
fn woven_one_texel_one_sample() {
    let params = WovenBtfParams {
        res: 1,
        supersample: 1,
        ..Default::default()
    };
    let btf = woven(params);
    for view in [woven_dir(0.0, 0.0), woven_dir(85.0, 15.0)] {
        let hits = btf.view(view).expect("view");
        assert_eq!(hits.hits().len(), 1);
        for light in [woven_dir(0.0, 0.0), woven_dir(85.0, 200.0)] {
            let image = hits.shade(light);
            assert_eq!(image.len(), 1);
            assert_radiance_in(&image, radiance_bound(&params));
            assert_eq!(image, btf.view(view).expect("view").shade(light));
        }
    }
}

#[test]
fn woven_many_thin_yarns_on_a_coarse_image() {
    // 256 yarns each way on 8² × 2² sub-samples: far less than a sub-sample per yarn (the
    // shadow lattice would be too coarse to tell the yarns apart, so every hit is traced).
    let params = WovenBtfParams {
        res: 8,
        warp_count: 256,
        weft_count: 256,
        ..Default::default()
    };
    let btf = woven(params);
    let light = woven_dir(80.0, 30.0);
    for view in [woven_dir(0.0, 0.0), woven_dir(68.0, 144.0)] {
        let hits = btf.view(view).expect("view");
        assert_radiance_in(&hits.shade(light), radiance_bound(&params));
    }
    // Seen from above, the grazing light still leaves a share of the surface in shadow.
    let hits = btf.view(woven_dir(0.0, 0.0)).expect("view");
    let shadowed = hits.cast_shadows(light).iter().filter(|&&s| s).count();
    assert!(
        shadowed * 10 > hits.hits().len(),
        "only {shadowed} in cast shadow"
    );
}

#[test]
fn woven_no_gaps_and_no_crimp() {
    // Yarns as wide as their pitch leave no gap; without crimp warp and weft tie at every
    // crossing (the warp wins ties).
    let params = WovenBtfParams {
        res: 16,
        yarn_width: 1.0,
        crimp: 0.0,
        ..Default::default()
    };
    let btf = woven(params);
    for view in [
        woven_dir(0.0, 0.0),
        woven_dir(51.0, 20.0),
        woven_dir(85.0, 290.0),
    ] {
        let hits = btf.view(view).expect("view");
        assert!(
            hits.hits().iter().all(|h| h.yarn != synth::Yarn::Gap),
            "{view}"
        );
        for light in [woven_dir(0.0, 0.0), woven_dir(75.0, 45.0)] {
            assert_radiance_in(&hits.shade(light), radiance_bound(&params));
        }
    }
    let crossing = btf.surface(0.125, 0.125);
    assert_eq!(crossing.yarn, synth::Yarn::Warp(0));
}

#[test]
fn woven_view_at_the_minimum_elevation() {
    let params = WovenBtfParams {
        res: 16,
        ..Default::default()
    };
    let btf = woven(params);
    let (floor, top) = btf.height_range();
    // 1.2° above the surface: each ray travels up to 11 tiles before it meets the floor.
    let hits = btf.view(woven_dir(88.8, 37.0)).expect("view");
    for hit in hits.hits() {
        assert!(hit.position.is_finite() && hit.normal.is_finite());
        assert!(hit.position.z >= floor && hit.position.z <= top + 1e-6);
        // So grazing a view only sees the tops of the yarns.
        assert!(hit.position.z > 0.0, "{hit:?}");
    }
    assert_radiance_in(&hits.shade(woven_dir(30.0, 0.0)), radiance_bound(&params));
}

#[test]
fn woven_light_grazing_the_horizon_stays_finite_and_dark() {
    let params = WovenBtfParams {
        res: 16,
        ..Default::default()
    };
    let btf = woven(params);
    for view in [woven_dir(0.0, 0.0), woven_dir(60.0, 100.0)] {
        let hits = btf.view(view).expect("view");
        for theta in [89.0, 89.9, 89.999] {
            let image = hits.shade(woven_dir(theta, 10.0));
            assert_radiance_in(&image, radiance_bound(&params));
            let mean = image.iter().flatten().sum::<f32>() / (3 * image.len()) as f32;
            assert!(mean < 0.02, "θ {theta}: mean {mean}");
        }
        // Exactly on the horizon: black, by definition.
        let horizon = hits.shade(Vec3::new(0.6, 0.8, 0.0));
        assert!(horizon.iter().all(|t| *t == [0.0; 3]));
    }
}

#[test]
fn woven_extreme_gloss_stays_in_range() {
    for (glossy_weight, glossy_exponent) in [(1.0, 1.0e4), (1.0, 31.5), (0.5, 1.0), (1.0, 2.5)] {
        let params = WovenBtfParams {
            res: 12,
            glossy_weight,
            glossy_exponent,
            ..Default::default()
        };
        let btf = woven(params);
        for view in [woven_dir(0.0, 0.0), woven_dir(45.0, 0.0)] {
            let hits = btf.view(view).expect("view");
            for light in [
                woven_dir(0.0, 0.0),
                woven_dir(45.0, 180.0),
                woven_dir(80.0, 90.0),
            ] {
                assert_radiance_in(&hits.shade(light), radiance_bound(&params));
            }
        }
    }
}

#[test]
fn woven_directions_need_not_be_unit() {
    let btf = woven(WovenBtfParams {
        res: 12,
        ..Default::default()
    });
    let (view, light) = (woven_dir(40.0, 75.0), woven_dir(70.0, 300.0));
    // Scaling by a power of two normalises back to the same bits.
    let hits = btf.view(view).expect("view");
    let scaled = btf.view(4.0 * view).expect("view");
    assert_eq!(hits.hits(), scaled.hits());
    assert_eq!(hits.shade(light), scaled.shade(0.25 * light));
    // Other lengths give the same image up to rounding of the direction.
    let rescaled = hits.shade(3.0 * light);
    let worst = hits
        .shade(light)
        .iter()
        .zip(&rescaled)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
        .fold(0.0f32, f32::max);
    assert!(worst < 0.05, "{worst}");
}

#[test]
fn woven_more_lights_than_the_table_cache_holds_is_still_deterministic() {
    let params = WovenBtfParams {
        res: 4,
        ..Default::default()
    };
    let btf = woven(params);
    let hits = btf.view(woven_dir(51.0, 60.0)).expect("view");
    let probe = woven_dir(68.0, 18.0);
    let first = hits.shade(probe);
    // 300 distinct lights: the shadow-table cache (128) overflows.
    for k in 0..300 {
        let light = woven_dir(1.0 + 0.29 * f64::from(k), 1.7 * f64::from(k));
        assert_radiance_in(&hits.shade(light), radiance_bound(&params));
    }
    assert_eq!(hits.shade(probe), first);
    assert_eq!(
        woven(params)
            .view(woven_dir(51.0, 60.0))
            .expect("view")
            .shade(probe),
        first
    );
}

#[test]
fn woven_surface_at_huge_tile_offsets() {
    let btf = woven(WovenBtfParams {
        res: 8,
        ..Default::default()
    });
    let (mut same_yarn, mut worst_smooth) = (0, 0.0f32);
    let n = 2000;
    for k in 0..n {
        let (x, y) = ((k as f32 * 0.618_034) % 1.0, (k as f32 * 0.754_877_7) % 1.0);
        let near = btf.surface(x, y);
        // 1000 tiles away f32 keeps 6·10⁻⁵ of a tile: the point moves by up to that much.
        let far = btf.surface(x + 1000.0, y - 1000.0);
        assert!(far.position.is_finite() && far.normal.is_finite());
        assert!(far.position.x < 1.0 && far.position.y < 1.0);
        if far.yarn == near.yarn {
            same_yarn += 1;
            if near.normal.z > 0.5 {
                worst_smooth = worst_smooth.max((far.position.z - near.position.z).abs());
            }
        }
    }
    assert!(
        same_yarn * 100 >= 99 * n,
        "{same_yarn} of {n} on the same yarn"
    );
    assert!(
        worst_smooth < 2e-4,
        "height off by {worst_smooth} 1000 tiles away"
    );
}
