//! The shared frame on whatever adapter exists (lavapipe in CI), against CPU references:
//! the alpha matte against a CPU rasteriser's sample coverage, occlusion against a CPU depth
//! test under both depth conventions, the backdrop only behind objects, and pipelines built
//! once for a whole sequence.

mod common;

use glam::{Mat4, Vec2, Vec3};
use gpu_context::PipelineStats;
use gpu_context::testing::gpu_or_skip;
use render::{
    Background, Camera, DepthConvention, DrawMesh, FrameFormat, Renderer, output, tone::Display,
};

/// Standard sample positions (Vulkan/D3D) inside a pixel, origin top-left, y down.
fn sample_positions(samples: u32) -> Vec<Vec2> {
    match samples {
        1 => vec![Vec2::splat(0.5)],
        4 => vec![
            Vec2::new(0.375, 0.125),
            Vec2::new(0.875, 0.375),
            Vec2::new(0.125, 0.625),
            Vec2::new(0.625, 0.875),
        ],
        n => panic!("no CPU reference for {n} samples"),
    }
}

/// Screen position (pixels, origin top-left, y down) of a world point.
fn to_screen(clip_from_world: Mat4, p: Vec3, w: u32, h: u32) -> Vec2 {
    let ndc = clip_from_world.project_point3(p);
    Vec2::new(
        (ndc.x + 1.0) * 0.5 * w as f32,
        (1.0 - ndc.y) * 0.5 * h as f32,
    )
}

fn inside(tri: [Vec2; 3], q: Vec2) -> bool {
    let edge = |a: Vec2, b: Vec2| (b - a).perp_dot(q - a);
    let e = [
        edge(tri[0], tri[1]),
        edge(tri[1], tri[2]),
        edge(tri[2], tri[0]),
    ];
    e.iter().all(|v| *v >= 0.0) || e.iter().all(|v| *v <= 0.0)
}

/// Fraction of each pixel's samples that some triangle covers.
fn cpu_coverage(
    camera: &Camera,
    positions: &[Vec3],
    triangles: &[[u32; 3]],
    samples: u32,
) -> Vec<f32> {
    let m = camera.clip_from_world().unwrap();
    let (w, h) = (camera.width, camera.height);
    let tris: Vec<[Vec2; 3]> = triangles
        .iter()
        .map(|t| t.map(|i| to_screen(m, positions[i as usize], w, h)))
        .collect();
    let offsets = sample_positions(samples);
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let hit = offsets
                .iter()
                .filter(|o| {
                    let q = Vec2::new(x as f32, y as f32) + **o;
                    tris.iter().any(|t| inside(*t, q))
                })
                .count();
            out.push(hit as f32 / offsets.len() as f32);
        }
    }
    out
}

fn flat(positions: &[Vec3], c: Vec3) -> Vec<Vec3> {
    vec![c; positions.len()]
}

#[test]
fn alpha_matte_equals_the_cpu_sample_coverage() {
    let Some(gpu) = gpu_or_skip() else { return };
    let format = FrameFormat::for_context(&gpu);
    let mut renderer = Renderer::new(&gpu.device, format);
    // A tilted quad and a separate thin triangle: long slanted edges at many sub-pixel phases.
    let positions = [
        Vec3::new(-0.9, -0.5, 0.0),
        Vec3::new(0.2, -0.8, 0.1),
        Vec3::new(0.5, 0.6, -0.2),
        Vec3::new(-0.6, 0.7, 0.0),
        Vec3::new(0.45, -0.7, 0.3),
        Vec3::new(0.93, -0.1, 0.2),
        Vec3::new(0.62, 0.81, 0.25),
    ];
    let triangles = [[0u32, 1, 2], [0, 2, 3], [4, 5, 6]];
    let colour = flat(&positions, Vec3::new(0.3, 0.6, 0.9));
    common::one_mesh(
        &mut renderer,
        &gpu,
        &positions,
        &triangles,
        &colour,
        &colour,
    )
    .unwrap();
    let camera = Camera::look_at(Vec3::new(0.1, 0.2, 3.0), Vec3::ZERO, Vec3::Y, 40.0, 97, 61);
    let image = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Transparent,
            &[],
        )
        .unwrap();
    let expected = cpu_coverage(&camera, &positions, &triangles, format.samples);
    let step = 1.0 / format.samples as f32;
    let mut differing = 0;
    let mut edge_pixels = 0;
    for (i, (p, e)) in image.pixels().iter().zip(&expected).enumerate() {
        let a = p[3];
        if *e > 0.0 && *e < 1.0 {
            edge_pixels += 1;
        }
        assert!(
            (a - e).abs() <= step + 1e-6,
            "pixel {i}: alpha {a} vs coverage {e} (more than one sample apart)"
        );
        if (a - e).abs() > 1e-6 {
            differing += 1;
        }
        // Premultiplied colour: rgb = coverage · colour (resolve in f32, centroid shading).
        assert!((p[0] - 0.3 * a).abs() < 1e-3, "pixel {i}: {p:?}");
    }
    // Samples exactly on an edge are the only place a CPU test and the rasteriser's fill rule
    // may differ; generic geometry puts almost none there.
    assert!(
        differing <= 2,
        "{differing} pixels differ from the CPU coverage ({edge_pixels} edge pixels, {} samples)",
        format.samples
    );
    if format.samples > 1 {
        assert!(
            edge_pixels > 100,
            "MSAA must give fractional edges: {edge_pixels}"
        );
    }
    eprintln!(
        "{} samples: {edge_pixels} edge pixels, {differing} differ from the CPU coverage",
        format.samples
    );
}

/// Two quads crossing at an angle: each is in front over part of the image.
fn crossing_quads() -> (Vec<Vec3>, Vec<Vec3>, Vec<[u32; 3]>) {
    let a = vec![
        Vec3::new(-1.0, -1.0, -0.6),
        Vec3::new(1.0, -1.0, 0.6),
        Vec3::new(1.0, 1.0, 0.6),
        Vec3::new(-1.0, 1.0, -0.6),
    ];
    let b = vec![
        Vec3::new(-1.0, -0.9, 0.5),
        Vec3::new(1.0, -0.9, -0.5),
        Vec3::new(1.0, 0.9, -0.5),
        Vec3::new(-1.0, 0.9, 0.5),
    ];
    (a, b, vec![[0u32, 1, 2], [0, 2, 3]])
}

/// Ray from `eye` through pixel centre (x, y): distance to the quad's plane if inside it.
fn hit_quad(camera: &Camera, quad: &[Vec3], x: u32, y: u32) -> Option<f32> {
    let m = camera.clip_from_world().unwrap();
    let inv = m.inverse();
    let ndc = Vec2::new(
        (x as f32 + 0.5) / camera.width as f32 * 2.0 - 1.0,
        1.0 - (y as f32 + 0.5) / camera.height as f32 * 2.0,
    );
    let p = inv.project_point3(ndc.extend(0.5));
    let dir = (p - camera.eye).normalize();
    let n = (quad[1] - quad[0]).cross(quad[3] - quad[0]).normalize();
    let t = (quad[0] - camera.eye).dot(n) / dir.dot(n);
    let q = camera.eye + dir * t;
    let (u, v) = (
        (q - quad[0]).dot(quad[1] - quad[0]),
        (q - quad[0]).dot(quad[3] - quad[0]),
    );
    let inside = u >= 0.0
        && v >= 0.0
        && u <= (quad[1] - quad[0]).length_squared()
        && v <= (quad[3] - quad[0]).length_squared();
    inside.then_some(t)
}

#[test]
fn occlusion_matches_a_cpu_depth_test_under_both_depth_conventions() {
    let Some(gpu) = gpu_or_skip() else { return };
    let (a, b, tris) = crossing_quads();
    let red = flat(&a, Vec3::X);
    let green = flat(&b, Vec3::Y);
    let camera = Camera::look_at(Vec3::new(0.3, 0.4, 4.0), Vec3::ZERO, Vec3::Y, 45.0, 80, 64);
    for depth in [DepthConvention::Standard, DepthConvention::ReversedInfinite] {
        let format = FrameFormat::single_sample(&gpu.device).with_depth(depth);
        let mut renderer = Renderer::new(&gpu.device, format);
        renderer
            .gouraud
            .set_meshes(
                &gpu.device,
                &gpu.queue,
                &[
                    DrawMesh {
                        positions: &a,
                        triangles: &tris,
                        front: &red,
                        back: &red,
                    },
                    DrawMesh {
                        positions: &b,
                        triangles: &tris,
                        front: &green,
                        back: &green,
                    },
                ],
            )
            .unwrap();
        let image = renderer
            .render(
                &gpu.device,
                &gpu.queue,
                &camera,
                Background::Transparent,
                &[],
            )
            .unwrap();
        let (mut checked, mut wrong, mut red_wins, mut green_wins) = (0, 0, 0, 0);
        for y in 0..camera.height {
            for x in 0..camera.width {
                let (ta, tb) = (hit_quad(&camera, &a, x, y), hit_quad(&camera, &b, x, y));
                let (Some(ta), Some(tb)) = (ta, tb) else {
                    continue;
                };
                // Skip the crossing line itself, where depths tie to rounding.
                if (ta - tb).abs() < 1e-2 {
                    continue;
                }
                let p = image.pixels()[(y * camera.width + x) as usize];
                let gpu_red = p[0] > p[1];
                checked += 1;
                if gpu_red != (ta < tb) {
                    wrong += 1;
                }
                if ta < tb {
                    red_wins += 1;
                } else {
                    green_wins += 1;
                }
            }
        }
        assert!(
            red_wins > 200 && green_wins > 200,
            "{red_wins} / {green_wins}"
        );
        assert!(
            wrong <= checked / 200,
            "{depth:?}: {wrong} of {checked} pixels disagree with the CPU depth test"
        );
    }
}

#[test]
fn backdrop_fills_only_the_background_and_black_means_black() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let positions = [
        Vec3::new(-0.3, -0.3, 0.0),
        Vec3::new(0.3, -0.3, 0.0),
        Vec3::new(0.0, 0.3, 0.0),
    ];
    let c = flat(&positions, Vec3::splat(0.25));
    common::one_mesh(&mut renderer, &gpu, &positions, &[[0, 1, 2]], &c, &c).unwrap();
    // A constant sky of radiance 7.
    let texels = vec![[7.0f32; 3]; 8 * 4];
    renderer.backdrop.set_environment(
        &gpu.device,
        Some(render::Backdrop {
            width: 8,
            height: 4,
            texels: &texels,
            world_from_env: glam::Quat::IDENTITY,
        }),
    );
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 2.0), Vec3::ZERO, Vec3::Y, 45.0, 32, 32);
    let centre = (16 * 32 + 16) as usize;
    let env = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Environment,
            &[],
        )
        .unwrap();
    assert_eq!(
        env.pixels()[0],
        [7.0, 7.0, 7.0, 0.0],
        "corner shows the sky, alpha 0"
    );
    assert_eq!(env.pixels()[centre], [0.25, 0.25, 0.25, 1.0]);
    let black = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Color([0.0; 3]),
            &[],
        )
        .unwrap();
    assert_eq!(
        black.pixels()[0],
        [0.0; 4],
        "black is black even with a map uploaded"
    );
    let blue = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Color([0.0, 0.0, 2.0]),
            &[],
        )
        .unwrap();
    assert_eq!(blue.pixels()[0], [0.0, 0.0, 2.0, 0.0]);
    // Auto exposure reads the triangle, not the sky 28× brighter.
    let ev = output::auto_exposure(&env);
    assert!((ev - (0.8f32 / 0.25).log2()).abs() < 1e-4, "{ev}");
    let rgba = output::to_rgba8(&env, &Display::default(), Background::Environment);
    assert!(rgba.chunks(4).all(|p| p[3] == 255));
}

#[test]
fn a_sequence_builds_its_pipelines_once_and_rewrites_buffers_in_place() {
    let Some(gpu) = gpu_or_skip() else { return };
    let before = PipelineStats::on_this_thread();
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let built = PipelineStats::on_this_thread();
    assert_eq!(
        built.render_pipelines - before.render_pipelines,
        3,
        "gouraud + backdrop + tone map"
    );
    let triangles = [[0u32, 1, 2]];
    for frame in 0..6 {
        let s = 0.2 + 0.1 * frame as f32;
        let positions = [
            Vec3::new(-s, -s, 0.0),
            Vec3::new(s, -s, 0.0),
            Vec3::new(0.0, s, 0.0),
        ];
        let c = flat(&positions, Vec3::splat(frame as f32));
        common::one_mesh(&mut renderer, &gpu, &positions, &triangles, &c, &c).unwrap();
        let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 45.0, 24, 24);
        let image = renderer
            .render(
                &gpu.device,
                &gpu.queue,
                &camera,
                Background::Transparent,
                &[],
            )
            .unwrap();
        // The new radiance arrived: the buffer was rewritten, not stale.
        assert_eq!(image.pixels()[12 * 24 + 12][0], frame as f32);
    }
    assert_eq!(
        PipelineStats::on_this_thread(),
        built,
        "no pipeline or shader built per frame"
    );
    assert_eq!(
        renderer.gouraud.allocations(),
        1,
        "one allocation, then in-place writes"
    );
    assert_eq!(renderer.frames_rendered(), 6);
}

#[test]
fn bad_meshes_and_cameras_are_errors_not_panics() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::single_sample(&gpu.device));
    let p = [Vec3::ZERO; 3];
    let c = [Vec3::ONE; 2];
    let err = common::one_mesh(&mut renderer, &gpu, &p, &[[0, 1, 2]], &c, &c).unwrap_err();
    assert!(err.to_string().contains("mesh 0"), "{err}");
    let c = [Vec3::ONE; 3];
    let err = common::one_mesh(&mut renderer, &gpu, &p, &[[0, 1, 3]], &c, &c).unwrap_err();
    assert!(err.to_string().contains("triangle 0"), "{err}");
    let camera = Camera::look_at(Vec3::Z, Vec3::Z, Vec3::Y, 45.0, 8, 8);
    let err = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Transparent,
            &[],
        )
        .unwrap_err();
    assert!(err.to_string().contains("target"), "{err}");
    let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, Vec3::Y, 45.0, 100_000, 8);
    let err = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            &camera,
            Background::Transparent,
            &[],
        )
        .unwrap_err();
    assert!(err.to_string().contains("frame width"), "{err}");
}
