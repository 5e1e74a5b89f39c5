//! The BTF material pass in the shared frame (crate `render`): a BTF object and a Gouraud
//! object cross each other, and each pixel shows whichever a CPU depth test (ray against the
//! two planes) finds nearer — one depth buffer for both kinds of object.
#![cfg(feature = "gpu")]

use btf::render::{BtfMesh, GpuBtfRenderer, Light, RenderParams, tangent_frames};
use btf::{BtfPca, BtfPcaParams, Sampling, ViewSlot};
use glam::{Vec2, Vec3};
use gpu_context::testing::gpu_or_skip;
use render::{Background, Camera, DrawMesh, FrameFormat, FramePass, Renderer};

/// A 2 × 2 grey BTF: 0.5 · max(l·n, 0) at every texel and view.
fn grey_btf() -> BtfPca {
    let s = Sampling::H1;
    let load = |j| {
        let data = (0..81)
            .flat_map(|i| [0.5 * s.vector(i).z.max(0.0); 12])
            .collect();
        ViewSlot::new(j, 2, 2, data)
    };
    BtfPca::compress_with(s, 2, 2, &BtfPcaParams::default(), load, None)
        .unwrap()
        .0
}

/// Distance along the ray through pixel (x, y)'s centre to the quad, if the ray hits it.
fn hit_quad(camera: &Camera, quad: &[Vec3; 4], x: u32, y: u32) -> Option<f32> {
    let inv = camera.clip_from_world().unwrap().inverse();
    let ndc = Vec2::new(
        (x as f32 + 0.5) / camera.width as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / camera.height as f32 * 2.0,
    );
    let dir = (inv.project_point3(ndc.extend(0.5)) - camera.eye).normalize();
    let (e1, e2) = (quad[1] - quad[0], quad[3] - quad[0]);
    let n = e1.cross(e2).normalize();
    let t = (quad[0] - camera.eye).dot(n) / dir.dot(n);
    let q = camera.eye + dir * t - quad[0];
    let (u, v) = (
        q.dot(e1) / e1.length_squared(),
        q.dot(e2) / e2.length_squared(),
    );
    ((0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v)).then_some(t)
}

#[test]
fn btf_and_gouraud_objects_occlude_each_other_as_a_cpu_depth_test_says() {
    let Some(gpu) = gpu_or_skip() else { return };
    let btf_quad = [
        Vec3::new(-1.0, -1.0, -0.6),
        Vec3::new(1.0, -1.0, 0.6),
        Vec3::new(1.0, 1.0, 0.6),
        Vec3::new(-1.0, 1.0, -0.6),
    ];
    let plain_quad = [
        Vec3::new(-1.0, -0.9, 0.5),
        Vec3::new(1.0, -0.9, -0.5),
        Vec3::new(1.0, 0.9, -0.5),
        Vec3::new(-1.0, 0.9, 0.5),
    ];
    let triangles = [[0u32, 1, 2], [0, 2, 3]];
    let normal = (btf_quad[1] - btf_quad[0])
        .cross(btf_quad[3] - btf_quad[0])
        .normalize();
    let normals = [normal; 4];
    let uvs = [
        Vec2::new(0.0, 1.0),
        Vec2::new(1.0, 1.0),
        Vec2::new(1.0, 0.0),
        Vec2::new(0.0, 0.0),
    ];
    let tangents = tangent_frames(&btf_quad, &normals, &uvs, &triangles).unwrap();
    let mesh = BtfMesh {
        positions: &btf_quad,
        normals: &normals,
        tangents: &tangents,
        uvs: &uvs,
        triangles: &triangles,
    };
    let camera = Camera::look_at(Vec3::new(0.3, 0.4, 4.0), Vec3::ZERO, Vec3::Y, 45.0, 80, 64);
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let red = [Vec3::X; 4];
    renderer
        .gouraud
        .set_meshes(
            &gpu.device,
            &gpu.queue,
            &[DrawMesh {
                positions: &plain_quad,
                triangles: &triangles,
                front: &red,
                back: &red,
            }],
        )
        .unwrap();
    let btf = GpuBtfRenderer::for_frame(
        &gpu.device,
        &gpu.queue,
        &grey_btf(),
        &renderer.pass_context(),
    )
    .unwrap();
    let light = Light::Directional {
        dir_to_light_world: normal,
        radiance: Vec3::ONE,
    };
    let draw = btf
        .prepare(&mesh, &light, &camera, &RenderParams::default())
        .unwrap();
    let passes: [&dyn FramePass; 1] = [&draw];
    let image = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Transparent,
            &passes,
        )
        .unwrap();
    let (mut checked, mut wrong, mut btf_wins, mut plain_wins) = (0, 0, 0, 0);
    for y in 0..camera.height {
        for x in 0..camera.width {
            let p = image.pixels()[(y * camera.width + x) as usize];
            let (tb, tp) = (
                hit_quad(&camera, &btf_quad, x, y),
                hit_quad(&camera, &plain_quad, x, y),
            );
            let (Some(tb), Some(tp)) = (tb, tp) else {
                continue;
            };
            if (tb - tp).abs() < 1e-2 {
                continue; // the crossing line: depths tie to rounding
            }
            // BTF pixels are grey (g ≈ 0.5), Gouraud pixels pure red (g = 0).
            let gpu_btf = p[1] > 0.1;
            checked += 1;
            wrong += usize::from(gpu_btf != (tb < tp));
            if tb < tp {
                btf_wins += 1;
            } else {
                plain_wins += 1;
            }
        }
    }
    assert!(
        btf_wins > 200 && plain_wins > 200,
        "{btf_wins} / {plain_wins}"
    );
    assert!(
        wrong <= checked / 200,
        "{wrong} of {checked} pixels disagree with the CPU depth test"
    );
}
