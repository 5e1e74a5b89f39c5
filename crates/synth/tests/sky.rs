//! Properties of the procedural sky, computed with the lat-long convention's formulas
//! written out here (not the crate's helpers), so a convention bug shows up.

use glam::{DVec3, Vec3};
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;
use synth::{LatLongImage, SkyParams, sky, sun_direction, sun_radiance};

/// Relative tolerance of the sun's power in the image (the splat conserves it up to f32
/// rounding of the texels; the brief asks for 1%).
const POWER_TOL: f64 = 0.01;
/// Relative tolerance of the measured sun-to-sky ratio: the crate normalises by the sky
/// mean integrated on its own fine grid, the test measures it on the image's texels.
const RATIO_TOL: f64 = 0.01;

fn luminance(rgb: [f64; 3]) -> f64 {
    0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]
}

fn texel_f64(image: &LatLongImage, row: usize, col: usize) -> [f64; 3] {
    image.texels[row * image.width + col].map(f64::from)
}

/// (2π/W)(cos θ_top − cos θ_bottom) with θ_top = π r/H.
fn solid_angle(width: usize, height: usize, row: usize) -> f64 {
    let top = PI * row as f64 / height as f64;
    let bottom = PI * (row + 1) as f64 / height as f64;
    TAU / width as f64 * (top.cos() - bottom.cos())
}

/// d(θ, φ) = (sin θ cos φ, cos θ, sin θ sin φ) at the texel centre.
fn centre_direction(width: usize, height: usize, row: usize, col: usize) -> DVec3 {
    let theta = PI * (row as f64 + 0.5) / height as f64;
    let phi = TAU * (col as f64 + 0.5) / width as f64;
    DVec3::new(
        theta.sin() * phi.cos(),
        theta.cos(),
        theta.sin() * phi.sin(),
    )
}

fn sun_solid_angle(params: &SkyParams) -> f64 {
    let alpha = f64::from(params.sun_angular_radius_deg).to_radians();
    TAU * (1.0 - alpha.cos())
}

fn is_sky_row(height: usize, row: usize) -> bool {
    (PI * (row as f64 + 0.5) / height as f64).cos() > 0.0
}

fn default_sky() -> &'static LatLongImage {
    static SKY: OnceLock<LatLongImage> = OnceLock::new();
    SKY.get_or_init(|| sky(&SkyParams::default()).expect("default parameters are valid"))
}

#[test]
fn texels_are_finite_and_non_negative() {
    let image = default_sky();
    assert_eq!(
        (image.width, image.height, image.texels.len()),
        (1024, 512, 1024 * 512)
    );
    for (k, t) in image.texels.iter().enumerate() {
        assert!(
            t.iter().all(|c| c.is_finite() && *c >= 0.0),
            "texel {k}: {t:?}"
        );
    }
}

/// Per channel, Σ (with sun − without sun) · Ω over the sky rows.
#[track_caller]
fn sun_power(params: &SkyParams) -> [f64; 3] {
    let with = sky(params).expect("valid");
    let without = sky(&SkyParams {
        sun_to_sky_ratio: 0.0,
        ..*params
    })
    .expect("valid");
    let mut power = [0.0; 3];
    for row in (0..params.height).filter(|&r| is_sky_row(params.height, r)) {
        let omega = solid_angle(params.width, params.height, row);
        for col in 0..params.width {
            let (a, b) = (texel_f64(&with, row, col), texel_f64(&without, row, col));
            for k in 0..3 {
                power[k] += (a[k] - b[k]) * omega;
            }
        }
    }
    power
}

#[test]
fn sun_power_is_conserved_at_low_and_high_resolution() {
    for (width, height) in [(256, 128), (1024, 512), (64, 32)] {
        let params = SkyParams {
            width,
            height,
            ..Default::default()
        };
        let expected = sun_radiance(&params).expect("valid").as_dvec3() * sun_solid_angle(&params);
        let power = sun_power(&params);
        for k in 0..3 {
            let error = (power[k] - expected[k]).abs() / expected[k];
            eprintln!(
                "{width}×{height} channel {k}: sun power {:.6e}, expected {:.6e}, error {error:.2e}",
                power[k], expected[k]
            );
            assert!(
                error < POWER_TOL,
                "{width}×{height} channel {k}: error {error}"
            );
        }
    }
}

#[test]
fn sun_is_the_requested_multiple_of_the_mean_sky() {
    let params = SkyParams::default();
    let image = default_sky();
    let without = sky(&SkyParams {
        sun_to_sky_ratio: 0.0,
        ..params
    })
    .expect("valid");
    // Mean sky luminance over the sky rows, solid-angle weighted, excluding sun texels.
    let (mut weighted, mut area, mut weighted_all, mut area_all) = (0.0, 0.0, 0.0, 0.0);
    for row in 0..params.height {
        let omega = solid_angle(params.width, params.height, row);
        for col in 0..params.width {
            let texel = texel_f64(image, row, col);
            // Sky texels touched by the sun disc are left out. (The ground differs between
            // the two images everywhere: the sun lights it.)
            if is_sky_row(params.height, row) && texel != texel_f64(&without, row, col) {
                continue;
            }
            weighted_all += luminance(texel) * omega;
            area_all += omega;
            if is_sky_row(params.height, row) {
                weighted += luminance(texel) * omega;
                area += omega;
            }
        }
    }
    let mean_sky = weighted / area;
    let mean_all = weighted_all / area_all;
    let power = sun_power(&params);
    let sun_mean = luminance(power) / sun_solid_angle(&params);
    let ratio = sun_mean / mean_sky;
    eprintln!(
        "sun {sun_mean:.4e}, sky mean {mean_sky:.4}, ratio {ratio:.1}, ratio to the whole map {:.1}",
        sun_mean / mean_all
    );
    let wanted = f64::from(params.sun_to_sky_ratio);
    assert!(
        (ratio - wanted).abs() < RATIO_TOL * wanted,
        "ratio {ratio} vs {wanted}"
    );
    assert!(
        sun_mean > 1e4 * mean_all,
        "sun only {} × the map mean",
        sun_mean / mean_all
    );
}

#[test]
fn brightest_texel_is_in_the_sun_direction() {
    let cases = [
        (35.0, 60.0),
        (10.0, 200.0),
        (80.0, 359.9),
        (45.0, 0.05),
        (3.0, 271.0),
    ];
    for (width, height) in [(256, 128), (1024, 512)] {
        for (elevation, azimuth) in cases {
            let params = SkyParams {
                width,
                height,
                sun_elevation_deg: elevation,
                sun_azimuth_deg: azimuth,
                ..Default::default()
            };
            let image = sky(&params).expect("valid");
            let (index, _) = image
                .texels
                .iter()
                .enumerate()
                .map(|(k, t)| (k, luminance(t.map(f64::from))))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .expect("texels");
            let (row, col) = (index / width, index % width);
            let found = centre_direction(width, height, row, col);
            let (e, a) = (
                f64::from(elevation).to_radians(),
                f64::from(azimuth).to_radians(),
            );
            let sun = DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin());
            assert!((sun_direction(&params).as_dvec3() - sun).length() < 1e-6);
            // Within the sun's radius plus a texel's diagonal (in φ, shrunk by sin θ).
            let theta = PI * (row as f64 + 0.5) / height as f64;
            let diagonal = (PI / height as f64).hypot(TAU / width as f64 * theta.sin());
            let limit = f64::from(params.sun_angular_radius_deg).to_radians() + diagonal;
            let angle = found.angle_between(sun);
            assert!(
                angle <= limit,
                "{width}×{height} sun ({elevation}°, {azimuth}°): brightest texel ({row}, {col}) is {:.3}° off",
                angle.to_degrees()
            );
        }
    }
}

#[test]
fn sun_disc_lands_where_the_sun_is_with_its_size() {
    // At 2048×1024 a texel is 0.088°: the 0.27° disc covers ~30 texels.
    let params = SkyParams {
        width: 2048,
        height: 1024,
        sun_elevation_deg: 52.0,
        sun_azimuth_deg: 300.0,
        ..Default::default()
    };
    let with = sky(&params).expect("valid");
    let without = sky(&SkyParams {
        sun_to_sky_ratio: 0.0,
        ..params
    })
    .expect("valid");
    let sun = sun_direction(&params).as_dvec3();
    let alpha = f64::from(params.sun_angular_radius_deg).to_radians();
    let texel = PI / params.height as f64;
    let (mut centroid, mut touched) = (DVec3::ZERO, 0);
    for row in (0..params.height).filter(|&r| is_sky_row(params.height, r)) {
        let omega = solid_angle(params.width, params.height, row);
        for col in 0..params.width {
            let added =
                luminance(texel_f64(&with, row, col)) - luminance(texel_f64(&without, row, col));
            if added != 0.0 {
                let d = centre_direction(params.width, params.height, row, col);
                assert!(
                    d.angle_between(sun) < alpha + 1.5 * texel,
                    "sun light at ({row}, {col})"
                );
                centroid += d * added * omega;
                touched += 1;
            }
        }
    }
    let disc_texels =
        sun_solid_angle(&params) / solid_angle(params.width, params.height, params.height / 4);
    eprintln!("disc touches {touched} texels (its area is {disc_texels:.1} texels)");
    assert!(
        touched as f64 > disc_texels,
        "disc squeezed into {touched} texels"
    );
    let offset = centroid.normalize().angle_between(sun);
    assert!(
        offset < 0.1 * texel,
        "power centroid {:.4}° from the sun",
        offset.to_degrees()
    );
}

#[test]
fn sun_direction_follows_the_convention() {
    let at = |e: f32, a: f32| {
        sun_direction(&SkyParams {
            sun_elevation_deg: e,
            sun_azimuth_deg: a,
            ..Default::default()
        })
    };
    assert!((at(0.0, 0.0) - Vec3::X).length() < 1e-6);
    assert!((at(0.0, 90.0) - Vec3::Z).length() < 1e-6);
    assert!((at(90.0, 123.0) - Vec3::Y).length() < 1e-6);
}

#[test]
fn ground_is_lambertian_under_this_sky_and_darker_than_the_horizon() {
    let params = SkyParams::default();
    let image = default_sky();
    let (w, h) = (params.width, params.height);
    // Irradiance on the ground from the image's own sky rows (sun included).
    let mut irradiance = [0.0; 3];
    for row in (0..h).filter(|&r| is_sky_row(h, r)) {
        let omega = solid_angle(w, h, row);
        for col in 0..w {
            let cos_theta = centre_direction(w, h, row, col).y;
            let t = texel_f64(image, row, col);
            for k in 0..3 {
                irradiance[k] += t[k] * cos_theta * omega;
            }
        }
    }
    let albedo = params.ground_albedo.as_dvec3().to_array();
    let ground = texel_f64(image, h - 1, 0);
    for row in (0..h).filter(|&r| !is_sky_row(h, r)) {
        for col in 0..w {
            assert_eq!(
                texel_f64(image, row, col),
                ground,
                "ground texel ({row}, {col}) differs"
            );
        }
    }
    for k in 0..3 {
        let expected = albedo[k] / PI * irradiance[k];
        let error = (ground[k] - expected).abs() / expected;
        assert!(
            error < 0.01,
            "channel {k}: ground {} vs ρ/π·E = {expected}",
            ground[k]
        );
    }
    let horizon_row = h / 2 - 1;
    let horizon: f64 = (0..w)
        .map(|c| luminance(texel_f64(image, horizon_row, c)))
        .sum::<f64>()
        / w as f64;
    assert!(
        luminance(ground) < horizon,
        "ground {} not darker than horizon {horizon}",
        luminance(ground)
    );
    // Ground-coloured: redder than the (bluish) light falling on it, by the albedo's tint.
    let tint = (ground[0] / ground[2]) / (irradiance[0] / irradiance[2]);
    assert!(
        (tint - albedo[0] / albedo[2]).abs() < 0.01 * tint,
        "tint {tint}"
    );
}

#[test]
fn sky_is_deterministic_across_thread_counts() {
    let params = SkyParams {
        width: 128,
        height: 64,
        ..Default::default()
    };
    let a = sky(&params).expect("valid");
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .expect("pool");
    let b = pool.install(|| sky(&params)).expect("valid");
    let single = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool");
    let c = single.install(|| sky(&params)).expect("valid");
    assert!(a == b && a == c);
}
