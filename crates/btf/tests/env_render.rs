//! Rendering a BTF under environment light (thesis §5.5.2): a Lambertian BTF on a sphere
//! under a uniform sky with nothing in the way is ρ L at every pixel (the closed form), on
//! the CPU reference and on the GPU, and the GPU matches the CPU.

use btf::Sampling;
use btf::env::EnvTransfer;
use btf::render::{BtfMesh, Camera, RenderParams, render_cpu_env, tangent_frames};
use glam::{Vec2, Vec3};

#[path = "common/env.rs"]
mod env_common;
use env_common::{A, B, lambertian, sphere_directions};

const SKY: Vec3 = Vec3::new(1.0, 0.8, 0.6);

struct Sphere {
    positions: Vec<Vec3>,
    uvs: Vec<Vec2>,
    triangles: Vec<[u32; 3]>,
}

fn sphere(rings: u32, segments: u32) -> Sphere {
    let (mut positions, mut uvs, mut triangles) = (Vec::new(), Vec::new(), Vec::new());
    for r in 0..=rings {
        let v = r as f32 / rings as f32;
        let theta = v * std::f32::consts::PI;
        for s in 0..=segments {
            let u = s as f32 / segments as f32;
            let phi = u * std::f32::consts::TAU;
            positions.push(Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ));
            uvs.push(Vec2::new(u, v));
        }
    }
    let row = segments + 1;
    for r in 0..rings {
        for s in 0..segments {
            let (a, b) = (r * row + s, r * row + s + 1);
            let (c, d) = (a + row, b + row);
            if r > 0 {
                triangles.push([a, c, b]);
            }
            if r + 1 < rings {
                triangles.push([b, c, d]);
            }
        }
    }
    Sphere {
        positions,
        uvs,
        triangles,
    }
}

#[test]
fn a_lambertian_sphere_under_a_uniform_sky_is_rho_l_at_every_pixel() {
    let (pca, _) = lambertian(Sampling::H1);
    let sph = sphere(24, 48);
    let normals = sph.positions.clone();
    let tangents = tangent_frames(&sph.positions, &normals, &sph.uvs, &sph.triangles).unwrap();
    let mesh = BtfMesh {
        positions: &sph.positions,
        normals: &normals,
        tangents: &tangents,
        uvs: &sph.uvs,
        triangles: &sph.triangles,
    };
    let frames: Vec<[Vec3; 3]> = tangents
        .iter()
        .zip(&normals)
        .map(|(t, n)| {
            let t3 = t.truncate();
            [t3, t.w * n.cross(t3), *n]
        })
        .collect();
    let (dirs, omega) = sphere_directions(6000);
    let omegas = vec![omega; dirs.len()];
    // Nothing occludes a convex sphere: every direction above the horizon is visible.
    let transfer = EnvTransfer::build(Sampling::H1, &frames, &dirs, &omegas, |_, _| true);
    let mut w = Vec::new();
    transfer.update(&vec![SKY; dirs.len()], &mut w);
    let camera = Camera::look_at(Vec3::new(0.5, 0.8, 3.5), Vec3::ZERO, Vec3::Y, 40.0, 96, 96);
    let params = RenderParams::default();
    let cpu = render_cpu_env(&pca, &mesh, &w, &camera, &params).unwrap();
    let targets = [A * SKY, B * SKY];
    let (mut covered, mut worst) = (0, 0.0f32);
    for y in 0..96 {
        for x in 0..96 {
            if !cpu.covered(x, y) {
                continue;
            }
            covered += 1;
            let p = Vec3::from(cpu.pixel(x, y));
            // One of the two albedos of the checkerboard, or between them on a texel
            // boundary of the nearest lookup: the distance to the segment between them.
            let (a, b) = (targets[0], targets[1]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            worst = worst.max((p - (a + t * (b - a))).abs().max_element());
        }
    }
    assert!(covered > 3000, "{covered}");
    eprintln!("CPU: {covered} pixels, largest distance from ρL {worst:.2e}");
    assert!(worst < 0.012, "largest distance from ρL: {worst}");

    #[cfg(feature = "gpu")]
    {
        let Some(gpu) = gpu_context::testing::gpu_or_skip() else {
            return;
        };
        let renderer = btf::render::GpuBtfRenderer::new(&gpu.device, &gpu.queue, &pca).unwrap();
        let draw = renderer.prepare_env(&mesh, &w, &camera, &params).unwrap();
        let mut frame =
            render::Renderer::new(&gpu.device, render::FrameFormat::single_sample(&gpu.device));
        let image = frame
            .render(
                &gpu.device,
                &gpu.queue,
                &camera,
                render::Background::Color([0.0; 3]),
                &[&draw],
            )
            .unwrap();
        let mut diff = 0.0f64;
        for y in 0..96u32 {
            for x in 0..96u32 {
                let g = image.pixels()[(y * 96 + x) as usize];
                let c = cpu.pixel(x, y);
                for k in 0..3 {
                    diff += f64::from((g[k] - c[k]).abs());
                }
            }
        }
        let mean = diff / (96.0 * 96.0 * 3.0);
        eprintln!("GPU vs CPU: mean |Δ| {mean:.2e}");
        assert!(mean < 2e-3, "GPU and CPU differ by {mean} on average");
    }
}
