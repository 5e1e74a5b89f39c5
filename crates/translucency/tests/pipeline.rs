//! The GPU pipeline against the f64 model: the SH reduction against the f64 projection (on
//! real maps from ../shared/data/env too), the cube map of a sphere, the light distance map of
//! a slab (d = w), and whole frames against eq. 12 evaluated on the CPU pixel by pixel.

#![cfg(feature = "gpu")]

mod common;

use common::*;
use glam::DVec3;
use render::{FrameFormat, Renderer};
use translucency::gpu::{PipelineParams, TranslucentMesh};
use translucency::model::Light;
use translucency::{CubeMap, Material, Sh9};

fn relative_error(a: &Sh9, b: &Sh9) -> f64 {
    let mut num = 0.0;
    let mut den = 0.0;
    for k in 0..9 {
        for c in 0..3 {
            num += (a.coeffs[k][c] - b.coeffs[k][c]).powi(2);
            den += b.coeffs[k][c].powi(2);
        }
    }
    (num / den).sqrt()
}

#[test]
fn gpu_projection_equals_the_f64_sum_on_real_maps() {
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    let renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let p = pass(&gpu, &renderer, PipelineParams::default());
    let Some(dir) = test_data::shared_file("env") else {
        return;
    };
    let mut checked = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !matches!(ext, "hdr" | "exr") {
            continue;
        }
        let env = lightsphere::Environment::load(&path).unwrap();
        let cube = CubeMap::from_fn(64, |d| env.radiance_f64(d).to_array()).unwrap();
        let cpu = Sh9::project_cube(&cube);
        let gpu_sh = p.project_on_gpu(&gpu.device, &gpu.queue, &cube).unwrap();
        let err = relative_error(&gpu_sh, &cpu);
        eprintln!("{}: GPU vs f64 relative error {err:.2e}", path.display());
        assert!(err < 1e-4, "{}: {err:e}", path.display());
        // And the cube projection agrees with the exact lat-long one to the cube's resolution.
        let ll = Sh9::project_latlong(&env);
        // Point-sampled 64² faces alias small bright sources: reported, not a target.
        eprintln!(
            "  cube 64² (point-sampled) vs exact lat-long: {:.2e}",
            relative_error(&cpu, &ll)
        );
        checked += 1;
    }
    assert!(checked > 0, "no .hdr/.exr in {}", dir.display());
}

#[test]
fn the_cube_map_of_a_sphere_holds_its_irradiance_by_direction() {
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    let renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let mut p = pass(&gpu, &renderer, PipelineParams::default());
    let s = sphere(0.7, 48, 96).offset(DVec3::new(3.0, -1.0, 2.0));
    // E_t = 1 + 0.5·n.x + 0.25·n.y: linear, so its SH is exact to band 1.
    let irradiance: Vec<[f32; 3]> = s
        .normals
        .iter()
        .map(|n| [1.0 + 0.5 * n.x, 1.0 + 0.25 * n.y, 1.0])
        .collect();
    let mesh = TranslucentMesh {
        positions: &s.positions,
        normals: &s.normals,
        triangles: &s.triangles,
        irradiance: &irradiance,
    };
    p.prepare(
        &gpu.device,
        &gpu.queue,
        &mesh,
        Light::Directional(DVec3::Y),
        &Material::default(),
        DVec3::new(0.0, 0.0, 9.0),
        false,
    )
    .unwrap();
    let cube = p.read_cube_map(&gpu.device, &gpu.queue).unwrap();
    let mut worst = 0.0f32;
    for (i, t) in cube.texels().iter().enumerate() {
        let d = translucency::cube::texel_direction(64, i).as_vec3();
        let want = [1.0 + 0.5 * d.x, 1.0 + 0.25 * d.y, 1.0];
        for c in 0..3 {
            worst = worst.max((t[c] - want[c]).abs());
        }
    }
    // Facets of a 48 × 96 sphere: interpolated normals differ from the direction by < 2 %.
    assert!(worst < 0.02, "worst texel error {worst}");
    let gpu_sh = p.read_coefficients(&gpu.device, &gpu.queue).unwrap();
    assert!(relative_error(&gpu_sh, &Sh9::project_cube(&cube)) < 1e-4);
}

#[test]
fn a_slab_lit_from_one_side_is_w_thick() {
    let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
        return;
    };
    let renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let params = PipelineParams {
        light_map_size: 128,
        ..Default::default()
    };
    let mut p = pass(&gpu, &renderer, params);
    let w = 0.3;
    let s = cuboid(
        DVec3::new(-1.0, -1.0, -w / 2.0),
        DVec3::new(1.0, 1.0, w / 2.0),
    );
    let irr = vec![[1.0f32; 3]; s.positions.len()];
    let mesh = TranslucentMesh {
        positions: &s.positions,
        normals: &s.normals,
        triangles: &s.triangles,
        irradiance: &irr,
    };
    // The pass's bounding radius (1.01 × the box's half diagonal) decides a point light's map:
    // six 90° faces within 1.5 radii, one face fitted to the sphere (half-angle θ, sin θ = R/D)
    // beyond, the directional map beyond 10⁴ radii.
    let radius = 1.01 * DVec3::new(1.0, 1.0, w / 2.0).length();
    for light in [
        Light::Directional(DVec3::Z),
        Light::Point(DVec3::new(0.0, 0.0, 2.0)),
        Light::Point(DVec3::new(0.0, 0.0, 3.0)),
        Light::Point(DVec3::new(0.0, 0.0, 300.0)),
        Light::Point(DVec3::new(0.0, 0.0, 1e5)),
    ] {
        p.prepare(
            &gpu.device,
            &gpu.queue,
            &mesh,
            light,
            &Material::default(),
            DVec3::new(0.0, 0.0, -5.0),
            false,
        )
        .unwrap();
        let (first, second) = p.read_light_layers(&gpu.device, &gpu.queue).unwrap();
        let n = 128usize;
        // The face looking at the slab (slot 0, or −Z: slot 5, of the six faces), and
        // 1 / tan of its half-angle (∞: parallel rays).
        let (slot, scale) = match light {
            Light::Point(p) if p.length() <= 1.5 * radius => (5, 1.0),
            Light::Point(p) if p.length() <= 1e4 * radius => {
                (0, (p.length_squared() - radius * radius).sqrt() / radius)
            }
            _ => (0, f64::INFINITY),
        };
        let mut checked = 0;
        for row in 0..n {
            for col in 0..n {
                let i = (slot * n + row) * n + col;
                if first[i] >= 1e29 || second[i] >= 1e29 {
                    continue;
                }
                // Away from the slab's rim (blur, oblique rays of the point light).
                let (u, v) = (
                    2.0 * (col as f64 + 0.5) / n as f64 - 1.0,
                    1.0 - 2.0 * (row as f64 + 0.5) / n as f64,
                );
                if u.abs() > 0.25 || v.abs() > 0.25 {
                    continue;
                }
                let d = f64::from(second[i] - first[i]);
                // Along the texel's oblique ray from the point light the chord is w / cos.
                let exact = w * (1.0 + (u * u + v * v) / (scale * scale)).sqrt();
                assert!(
                    (d - exact).abs() < 3e-3,
                    "{light:?} texel ({row}, {col}): d = {d}, exact {exact}"
                );
                checked += 1;
            }
        }
        assert!(checked > 50, "{light:?}: only {checked} texels");
    }
}

#[test]
fn the_frame_equals_eq_12_in_f64_pixel_by_pixel() {
    if gpu_context::testing::gpu_or_skip().is_none() {
        return;
    }
    let (worst, count) = slab_frame_against_cpu(DVec3::ZERO, 1.0, None);
    eprintln!("{count} pixels, worst relative error {worst:.2e}");
    assert!(count > 300, "{count} pixels");
    assert!(worst < 2e-3, "worst relative error {worst}");
}

#[test]
fn a_point_light_frame_equals_eq_12_in_f64() {
    if gpu_context::testing::gpu_or_skip().is_none() {
        return;
    }
    // The slab's bounding radius is 0.0716: a light 0.09 away (1.3 radii) draws the faces of
    // the six-face map the slab reaches (one here); 0.5 and 50 (7 and 700 radii) one face fitted
    // to the bounding sphere; 1e4 (1.4 × 10⁵ radii) the directional light's map. On six faces
    // the slab spanned ~2 texels of 512 at 50 away, and the frame was wrong everywhere.
    for distance in [0.09, 0.5, 50.0, 1e4] {
        let (worst, count) = slab_frame_against_cpu(DVec3::ZERO, 1.0, Some(distance));
        eprintln!("light {distance}: {count} pixels, worst relative error {worst:.2e}");
        assert!(count > 300, "light {distance}: {count} pixels");
        // A point light's distance field curves (as 1/r) across the map, so the Gaussian
        // (σ = 2 texels) and the bilinear look-up bias d by ~0.2 %, which A(d) ∝ d⁻³ triples.
        assert!(
            worst < 2e-2,
            "light {distance}: worst relative error {worst}"
        );
    }
}
