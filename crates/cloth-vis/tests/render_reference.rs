//! The renderer against CPU references: the environment backdrop equals lightsphere's bilinear
//! look-up along each pixel's view ray (same lat-long convention on both sides), and a
//! triangle covers the pixels a CPU edge test says it covers, with the right face colour.

mod common;

use cloth_vis::camera::resolve;
use cloth_vis::scene::CameraDesc;
use glam::{Quat, Vec3, Vec4Swizzles};
use gpu_context::testing::gpu_or_skip as gpu;
use gpu_context::{GpuContext, HdrImage};
use render::{Backdrop, Background, Camera, DrawMesh, FrameFormat, Renderer};

/// One single-sample frame of the shared renderer (pixel-exact against CPU references).
fn render(
    gpu: &GpuContext,
    camera: &Camera,
    meshes: &[DrawMesh<'_>],
    backdrop: Option<Backdrop<'_>>,
) -> HdrImage {
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, meshes)
        .unwrap();
    let background = if backdrop.is_some() {
        Background::Environment
    } else {
        Background::Color([0.0; 3])
    };
    renderer.backdrop.set_environment(&gpu.device, backdrop);
    renderer
        .render(&gpu.device, &gpu.queue, camera, background, &[])
        .unwrap()
}

/// A smooth synthetic environment with structure in both angles.
fn environment(width: usize, height: usize) -> lightsphere::Environment {
    let texels = (0..width * height)
        .map(|i| {
            let (r, c) = (i / width, i % width);
            let u = c as f32 / width as f32;
            let v = r as f32 / height as f32;
            [1.0 + u * 3.0, 0.5 + (v * 6.0).sin().abs(), 2.0 - v]
        })
        .collect();
    lightsphere::Environment::from_latlong(width, height, texels).unwrap()
}

#[test]
fn backdrop_matches_cpu_lookup_along_view_rays() {
    let Some(gpu) = gpu() else { return };
    let rotation = Quat::from_rotation_y(0.7);
    let env = environment(64, 32).with_rotation(rotation);
    let desc = CameraDesc {
        eye: Some([0.3, 0.2, 0.1]),
        target: Some([1.0, 0.5, -0.4]),
        fov_deg: 80.0,
        width: 48,
        height: 40,
        ..CameraDesc::default()
    };
    let camera = resolve(&desc, Vec3::ZERO, 1.0);
    let backdrop = Backdrop {
        width: env.width(),
        height: env.height(),
        texels: env.texels(),
        world_from_env: rotation,
    };
    let image = render(&gpu, &camera, &[], Some(backdrop));
    let world_from_clip = camera.clip_from_world().unwrap().inverse();
    let mut worst = 0.0f32;
    for y in 0..desc.height {
        for x in 0..desc.width {
            let ndc_x = (x as f32 + 0.5) / desc.width as f32 * 2.0 - 1.0;
            let ndc_y = 1.0 - (y as f32 + 0.5) / desc.height as f32 * 2.0;
            let far = world_from_clip * glam::Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let dir = far.xyz() / far.w - camera.eye;
            let expected = env.radiance(dir.normalize());
            let got = image.pixels()[(y * desc.width + x) as usize];
            let rel =
                ((Vec3::new(got[0], got[1], got[2]) - expected).abs() / expected).max_element();
            worst = worst.max(rel);
        }
    }
    // f32 trigonometry on both sides; texel seams may differ by rounding of the column index.
    assert!(worst < 2e-3, "worst relative difference {worst}");
}

#[test]
fn a_triangle_covers_the_pixels_a_cpu_edge_test_predicts_with_two_sided_colours() {
    let Some(gpu) = gpu() else { return };
    let desc = CameraDesc {
        eye: Some([0.0, 0.0, 3.0]),
        target: Some([0.0, 0.0, 0.0]),
        width: 64,
        height: 64,
        ..CameraDesc::default()
    };
    let camera = resolve(&desc, Vec3::ZERO, 1.0);
    let positions = [
        Vec3::new(-0.8, -0.6, 0.0),
        Vec3::new(0.7, -0.5, 0.0),
        Vec3::new(0.1, 0.8, 0.0),
    ];
    let front = [Vec3::new(1.0, 0.0, 0.0); 3];
    let back = [Vec3::new(0.0, 0.0, 1.0); 3];
    for (tri, expected) in [
        ([0u32, 1, 2], [1.0, 0.0, 0.0]),
        ([0, 2, 1], [0.0, 0.0, 1.0]),
    ] {
        let triangles = [tri];
        let mesh = DrawMesh {
            positions: &positions,
            triangles: &triangles,
            front: &front,
            back: &back,
        };
        let image = render(&gpu, &camera, &[mesh], None);
        let screen: Vec<glam::Vec2> = positions
            .iter()
            .map(|p| {
                let ndc = camera.clip_from_world().unwrap().project_point3(*p);
                glam::Vec2::new((ndc.x + 1.0) * 32.0, (1.0 - ndc.y) * 32.0)
            })
            .collect();
        let edge = |a: glam::Vec2, b: glam::Vec2, p: glam::Vec2| (b - a).perp_dot(p - a);
        let mut mismatches = 0;
        for y in 0..64 {
            for x in 0..64 {
                let p = glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let e = [
                    edge(screen[0], screen[1], p),
                    edge(screen[1], screen[2], p),
                    edge(screen[2], screen[0], p),
                ];
                let inside = e.iter().all(|v| *v < -1e-3) || e.iter().all(|v| *v > 1e-3);
                let on_edge = e.iter().any(|v| v.abs() <= 1e-3 * 64.0);
                let got = image.pixels()[y * 64 + x];
                let covered = got[..3] == expected;
                if inside != covered && !on_edge {
                    mismatches += 1;
                }
                if !covered {
                    assert_eq!(
                        got[..3],
                        [0.0, 0.0, 0.0],
                        "pixel ({x}, {y}) has a foreign colour"
                    );
                }
            }
        }
        assert_eq!(mismatches, 0, "winding {tri:?}");
    }
}
