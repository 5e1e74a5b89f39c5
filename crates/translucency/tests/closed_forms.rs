//! The oracles of SEED-NOTES §5.6 and the printed constants of seed 004 (eqs. 9–12), checked
//! against closed forms in f64.

use glam::{DQuat, DVec3};
use lightsphere::{Environment, latlong};
use std::f64::consts::PI;
use translucency::cube::{self, CubeMap};
use translucency::model::{
    AccumulationFrame, attenuation, attenuation_clamped, refract, refraction_vector,
    schlick_transmittance,
};
use translucency::sh::{self, C, SH_COUNT, Sh9, basis};
use translucency::{Material, PRESETS};

fn directions(n: usize) -> Vec<DVec3> {
    // A Fibonacci sphere: deterministic and spread.
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let r = (1.0 - y * y).sqrt();
            let phi = golden * i as f64;
            DVec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

#[test]
fn basis_and_matrix_constants_match_the_printed_six_digits() {
    let d = DVec3::new(0.36, 0.48, 0.8);
    let y = basis(d);
    let printed = [
        0.282095,
        0.488603 * d.y,
        0.488603 * d.z,
        0.488603 * d.x,
        1.092548 * d.x * d.y,
        1.092548 * d.y * d.z,
        0.315392 * (3.0 * d.z * d.z - 1.0),
        1.092548 * d.x * d.z,
        0.546274 * (d.x * d.x - d.y * d.y),
    ];
    for k in 0..SH_COUNT {
        assert!(
            (y[k] - printed[k]).abs() < 1e-6,
            "Y_{k}: {} vs {}",
            y[k],
            printed[k]
        );
    }
    let eq11 = [0.429043, 0.511664, 0.743125, 0.886227, 0.247708];
    // R&H print c3 = 0.743125 for the exact 3π/4·√(5/16π) = 0.7431239 (off by 1.1e-6).
    for i in 0..5 {
        assert!(
            (C[i] - eq11[i]).abs() < 1.2e-6,
            "c{}: {} vs {}",
            i + 1,
            C[i],
            eq11[i]
        );
    }
}

#[test]
#[allow(clippy::needless_range_loop)]
fn the_basis_is_orthonormal_over_the_sphere() {
    // Exact lat-long cell integrals of products are not available, so integrate products on
    // a fine cube map with exact solid angles (second-order accurate).
    let n = 256;
    let w = cube::projection_weights(n);
    for a in 0..SH_COUNT {
        for b in 0..SH_COUNT {
            let s: f64 = (0..6 * n * n)
                .map(|i| w[i][a] * basis(cube::texel_direction(n, i))[b])
                .sum();
            let want = if a == b { 1.0 } else { 0.0 };
            assert!((s - want).abs() < 1e-4, "<Y{a}, Y{b}> = {s}");
        }
    }
}

#[test]
fn uniform_environment_gives_b_equal_pi_for_every_r() {
    for (w, h) in [(4, 2), (64, 32), (37, 19)] {
        let env = Environment::from_latlong(w, h, vec![[1.0; 3]; w * h]).unwrap();
        let sh = Sh9::project_latlong(&env);
        assert!(
            (sh.coeffs[0][0] - 4.0 * PI * sh::K0).abs() < 1e-12,
            "{w}×{h}: E00 {}",
            sh.coeffs[0][0]
        );
        for k in 1..SH_COUNT {
            assert!(
                sh.coeffs[k][0].abs() < 1e-12,
                "{w}×{h}: E_{k} = {}",
                sh.coeffs[k][0]
            );
        }
        for r in directions(50) {
            let b = sh.irradiance(r)[1];
            assert!((b - PI).abs() < 1e-12, "{w}×{h}: B({r}) = {b}");
        }
    }
    // The printed constants give 3.141595 (SEED-NOTES §5.6): ours are exact.
    assert!((0.886227f64 * 3.544910 - 3.141595).abs() < 1e-6);
    let cube = CubeMap::from_fn(8, |_| [1.0; 3]).unwrap();
    let sh = Sh9::project_cube(&cube);
    for r in directions(20) {
        assert!(
            (sh.irradiance(r)[2] - PI).abs() < 2e-3,
            "cube 8²: B = {}",
            sh.irradiance(r)[2]
        );
    }
}

#[test]
fn cube_texel_solid_angles_are_exact() {
    for n in [1, 2, 3, 64] {
        let total: f64 = (0..n * n)
            .map(|i| cube::texel_solid_angle(n, i / n, i % n))
            .sum();
        assert!(
            (6.0 * total - 4.0 * PI).abs() < 1e-12,
            "{n}²: Σ Δω = {}",
            6.0 * total
        );
    }
    // One face of a 1² cube sees 4π/6; a corner texel of a 2² cube sees a quarter of it.
    assert!((cube::texel_solid_angle(2, 0, 0) - PI / 6.0).abs() < 1e-14);
    // Every texel direction lands in its face and the face table is right-handed enough to
    // cover the sphere once: directions are unique and unit.
    for i in 0..6 * 4 * 4 {
        assert!((cube::texel_direction(4, i).length() - 1.0).abs() < 1e-14);
    }
}

#[test]
fn delta_light_along_z_gives_the_printed_b_of_t() {
    let sh = Sh9::delta(DVec3::Z, [1.0; 3]);
    for (t, want) in [
        (1.0, 1.0625),
        (0.5, 0.460938),
        (0.0, 0.09375),
        (-0.5, -0.039063),
        (-1.0, 0.0625),
    ] {
        let r = DVec3::new((1.0f64 - t * t).sqrt(), 0.0, t);
        let b = sh.irradiance(r)[0];
        assert!((b - want).abs() < 1e-6, "B({t}) = {b}, want {want}");
        let formula = 0.25 + 0.5 * t + 0.15625 * (3.0 * t * t - 1.0);
        assert!((b - formula).abs() < 1e-12);
        assert_eq!(sh.irradiance_clamped(r)[0], b.max(0.0));
    }
}

#[test]
fn the_irradiance_matrix_is_symmetric_and_fixes_the_printed_row_4() {
    let env = Environment::from_latlong(
        8,
        4,
        (0..32).map(|i| [i as f32, 1.0, (i % 5) as f32]).collect(),
    )
    .unwrap();
    let sh = Sh9::project_latlong(&env);
    for c in 0..3 {
        let m = sh.irradiance_matrix(c);
        assert!((m - m.transpose()).abs_diff_eq(glam::DMat4::ZERO, 0.0));
        // Row 4 is (c2 E11, c2 E1−1, c2 E10, c4 E00 − c5 E20), not the printed (c1 E11, c2 E2−1, …).
        let row4 = m.row(3);
        assert!((row4.x - C[1] * sh.coeffs[3][c]).abs() < 1e-15);
        assert!((row4.y - C[1] * sh.coeffs[1][c]).abs() < 1e-15);
    }
    // B equals the direct SH convolution Σ Â_l E_lm Y_lm(r) (Â = π, 2π/3, π/4).
    let a_hat = [PI, 2.0 * PI / 3.0, PI / 4.0];
    for r in directions(30) {
        let y = basis(r);
        let direct: f64 = (0..SH_COUNT)
            .map(|k| a_hat[sh::BAND[k]] * sh.coeffs[k][0] * y[k])
            .sum();
        assert!((sh.irradiance(r)[0] - direct).abs() < 1e-12 * direct.abs().max(1.0));
    }
}

#[test]
fn linear_environments_project_to_second_order() {
    // E(ω) = a + b·ω: E00 = 4π K0 a, E1m = (4π/3) K1 b_m, band 2 = 0.
    let (a, b) = (2.0, DVec3::new(0.3, -0.7, 0.5));
    let mut want = [0.0; SH_COUNT];
    want[0] = 4.0 * PI * sh::K0 * a;
    want[1] = 4.0 * PI / 3.0 * sh::K1 * b.y;
    want[2] = 4.0 * PI / 3.0 * sh::K1 * b.z;
    want[3] = 4.0 * PI / 3.0 * sh::K1 * b.x;
    let norm = want.iter().map(|v| v * v).sum::<f64>().sqrt();
    let err = |sh: &Sh9| {
        (0..SH_COUNT)
            .map(|k| (sh.coeffs[k][0] - want[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            / norm
    };
    let e = |d: DVec3| [(a + b.dot(d)) as f32; 3];
    let (w, h) = (2048, 1024);
    let texels = (0..w * h)
        .map(|i| e(latlong::texel_direction(i / w, i % w, w, h)))
        .collect();
    let ll = err(&Sh9::project_latlong(
        &Environment::from_latlong(w, h, texels).unwrap(),
    ));
    let cube = err(&Sh9::project_cube(&CubeMap::from_fn(512, e).unwrap()));
    // f32 texels limit both to ~1e-7; the quadrature error is O(h²).
    assert!(ll < 1e-6, "lat-long 2048×1024: relative error {ll:e}");
    assert!(cube < 1e-6, "cube 512²: relative error {cube:e}");
    let coarse = err(&Sh9::project_cube(&CubeMap::from_fn(64, e).unwrap()));
    assert!(coarse < 1e-4, "cube 64²: relative error {coarse:e}");
}

#[test]
fn rotation_is_exact_for_l_up_to_2() {
    let q = DQuat::from_euler(glam::EulerRot::YXZ, 0.7, -1.1, 0.4);
    for d in directions(10) {
        let rotated = Sh9::delta(d, [1.0, 2.0, 3.0]).rotated(q);
        let direct = Sh9::delta(q * d, [1.0, 2.0, 3.0]);
        for k in 0..SH_COUNT {
            for c in 0..3 {
                assert!((rotated.coeffs[k][c] - direct.coeffs[k][c]).abs() < 1e-12);
            }
        }
    }
    // A rotated environment's projection equals the projection rotated.
    let env = Environment::from_latlong(
        16,
        8,
        (0..128)
            .map(|i| [(i % 7) as f32, (i / 16) as f32, 1.0])
            .collect(),
    )
    .unwrap();
    let plain = Sh9::project_latlong(&env);
    let turned = Sh9::project_latlong(&env.clone().with_rotation(q.as_quat()));
    let by_rotation = plain.rotated(q);
    for k in 0..SH_COUNT {
        assert!(
            (turned.coeffs[k][0] - by_rotation.coeffs[k][0]).abs() < 1e-5,
            "k {k}"
        );
    }
}

#[test]
fn windows_trade_sharpness_for_ringing() {
    use translucency::Window;
    let none = sh::delta_response_minimum(Window::None);
    assert!((none + 0.0396).abs() < 5e-4, "unwindowed minimum {none}");
    let lanczos = sh::delta_response_minimum(Window::Lanczos { width: 3.0 });
    assert!(lanczos < 0.0 && lanczos > none, "Lanczos 3: {lanczos}");
    let gauss = sh::delta_response_minimum(Window::Gaussian {
        width: sh::GAUSSIAN_NON_NEGATIVE_WIDTH,
    });
    assert!(gauss >= 0.0, "Gaussian 5: {gauss}");
    let too_sharp = sh::delta_response_minimum(Window::Gaussian { width: 6.0 });
    assert!(too_sharp < 0.0, "Gaussian 6: {too_sharp}");
    assert!(Window::Gaussian { width: 0.0 }.validate().is_err());
}

#[test]
fn schlick_and_attenuation_match_the_oracles() {
    for (eta, f1, fh) in [(1.3, 0.982987, 0.952268), (1.5, 0.96, 0.93)] {
        assert!((schlick_transmittance(eta, 1.0) - f1).abs() < 1e-6);
        assert!((schlick_transmittance(eta, 0.5) - fh).abs() < 1e-6);
    }
    assert_eq!(schlick_transmittance(1.5, 0.0), 0.0);
    for (d, want) in [
        (0.1, 995.32),
        (0.5, 7.278),
        (1.0, 0.735759),
        (2.0, 0.050751),
    ] {
        let a = attenuation(1.0, 1.0, d);
        assert!(
            (a - want).abs() < 1e-5 * want.max(1.0) * 10.0,
            "A({d}) = {a}"
        );
    }
    // The clamp: at and below d_min, the value at d_min; one distance for all channels,
    // the longest mean free path.
    let skin = Material::preset("skin1").unwrap();
    assert!((skin.clamp_distance() - 1.0 / 0.772).abs() < 1e-12);
    assert_eq!(
        attenuation_clamped(1.0, 2.0, 0.0, 0.5),
        attenuation(1.0, 2.0, 0.5)
    );
    assert_eq!(
        attenuation_clamped(1.0, 2.0, 3.0, 0.5),
        attenuation(1.0, 2.0, 3.0)
    );
}

#[test]
fn refraction_follows_snell_and_eta_1_refracts_nothing() {
    let n = DVec3::Y;
    for w in directions(40).into_iter().filter(|w| w.y > 0.05) {
        let r1 = refraction_vector(n, w, 1.0);
        assert!((r1 + w).length() < 1e-12, "η = 1: {r1} vs {}", -w);
        let r = refraction_vector(n, w, 1.3);
        let sin_i = (1.0 - w.y * w.y).sqrt();
        let sin_t = (1.0 - r.y * r.y).sqrt();
        assert!((sin_i - 1.3 * sin_t).abs() < 1e-12, "Snell");
        assert!(r.y < 0.0 && (r.length() - 1.0).abs() < 1e-12);
    }
    assert!(refract(DVec3::new(0.99, -0.141, 0.0).normalize(), n, 1.5).is_none());
}

#[test]
fn the_shift_fix_hits_the_box() {
    let frame =
        AccumulationFrame::of_points([DVec3::new(-2.0, -1.0, -0.5), DVec3::new(2.0, 1.0, 0.5)])
            .unwrap();
    // From the centre the shifted direction is the cube-space direction of r.
    let s = frame.shifted_direction(frame.centre, DVec3::X);
    assert!((s - DVec3::X).length() < 1e-15);
    // From (1, 0, 0) along +y (cube space (0.5, 0, 0) along +y) the exit is (0.5, 1, 0).
    let s = frame.shifted_direction(DVec3::new(1.0, 0.0, 0.0), DVec3::Y);
    assert!((s - DVec3::new(0.5, 1.0, 0.0).normalize()).length() < 1e-15);
}

#[test]
fn presets_are_jensens_table_with_the_dipole_coefficients() {
    assert_eq!(PRESETS.len(), 12);
    let skin = Material::preset("Skin1").unwrap();
    assert_eq!(skin.sigma_s_prime, [0.74, 0.88, 1.01]);
    let tp = skin.sigma_t_prime();
    let tr = skin.sigma_tr();
    assert!((tp[0] - 0.772).abs() < 1e-12);
    assert!((tr[0] - (3.0f64 * 0.032 * 0.772).sqrt()).abs() < 1e-12);
    let err = Material::preset("jade").unwrap_err().to_string();
    assert!(err.contains("jade") && err.contains("marble"), "{err}");
    assert!(
        Material::new([-1.0, 0.0, 0.0], [1.0; 3], 1.3)
            .unwrap_err()
            .to_string()
            .contains("sigma_a")
    );
    assert!(Material::new([0.0; 3], [0.0, 1.0, 1.0], 1.3).is_err());
    assert!(Material::new([0.1; 3], [1.0; 3], f64::NAN).is_err());
}

#[test]
fn dipole_diffuse_reflectance_matches_jensens_table() {
    // Spectralon does not absorb: R_d = 1.
    let r = Material::preset("spectralon")
        .unwrap()
        .diffuse_reflectance();
    assert!(r.iter().all(|v| (v - 1.0).abs() < 1e-12), "{r:?}");
    // Marble (η = 1.5): Jensen et al. 2001's table prints R_d = 0.83, 0.79, 0.75.
    let r = Material::preset("marble").unwrap().diffuse_reflectance();
    for (got, want) in r.iter().zip([0.83, 0.79, 0.75]) {
        assert!((got - want).abs() < 0.006, "marble R_d {r:?}");
    }
    // Strong absorption makes it dark.
    let ink = Material::new([10.0; 3], [0.1; 3], 1.3)
        .unwrap()
        .diffuse_reflectance();
    assert!(ink[0] < 0.01);
}

#[test]
fn a_window_reports_its_closed_form_band_factors() {
    // Lanczos: h_l = sinc(l / 3), sin(π/3)/(π/3) = 0.8270, sin(2π/3)/(2π/3) = 0.4135;
    // Gaussian: h_l = exp(−l(l + 1) / 10), e^−0.2 = 0.8187, e^−0.6 = 0.5488.
    assert_eq!(sh::Window::None.to_string(), "no window");
    assert_eq!(
        sh::Window::Lanczos { width: 3.0 }.to_string(),
        "Lanczos σ window, w = 3: h_1 = 0.8270, h_2 = 0.4135"
    );
    assert_eq!(
        sh::Window::Gaussian { width: 5.0 }.to_string(),
        "Gaussian window, w = 5: h_1 = 0.8187, h_2 = 0.5488"
    );
}
