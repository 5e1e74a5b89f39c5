//! The GPU tone map (the frame's last pass) against the CPU one on the read-back HDR image:
//! every curve, exposures from −6 to +6 EV, radiance from 10⁻⁴ to a 10⁴× sun, an opaque and a
//! transparent background (un-premultiplied edges), all within one 8-bit code per channel.

mod common;

use glam::Vec3;
use gpu_context::testing::gpu_or_skip;
use render::tone::{Display, ToneCurve};
use render::{Background, Camera, FrameFormat, Renderer, output};

#[test]
fn gpu_tone_map_matches_the_cpu_within_one_code() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    // A fan of triangles whose vertex radiance spans 10⁻⁴ … 10⁴ across the image, so the
    // Gouraud interpolation sweeps every part of every curve; MSAA edges give fractional alpha.
    let mut positions = Vec::new();
    let mut colours = Vec::new();
    let mut triangles = Vec::new();
    let n = 24u32;
    for i in 0..=n {
        let t = i as f32 / n as f32;
        let x = -1.2 + 2.4 * t;
        let level = 10f32.powf(-4.0 + 8.0 * t);
        positions.push(Vec3::new(x, -0.9, 0.0));
        positions.push(Vec3::new(x, 0.9, 0.0));
        colours.push(Vec3::new(level, 0.5 * level, 0.1 * level));
        colours.push(Vec3::new(0.02 * level, level, 0.3));
    }
    for i in 0..n {
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        triangles.push([a, c, b]);
        triangles.push([b, c, d]);
    }
    // A thin diagonal sliver: partial coverage all along its edges.
    let base = positions.len() as u32;
    positions.extend([
        Vec3::new(-1.0, -1.05, 0.1),
        Vec3::new(1.0, 1.0, 0.1),
        Vec3::new(1.0, 1.03, 0.1),
    ]);
    colours.extend([Vec3::splat(0.3); 3]);
    triangles.push([base, base + 1, base + 2]);
    common::one_mesh(
        &mut renderer,
        &gpu,
        &positions,
        &triangles,
        &colours,
        &colours,
    )
    .unwrap();
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 83, 57);
    let mut worst = 0u8;
    let mut compared = 0usize;
    for background in [Background::Color([0.05, 0.1, 0.2]), Background::Transparent] {
        let hdr = renderer
            .render(&gpu.device, &gpu.queue, &camera, background, &[])
            .unwrap();
        for curve in [
            ToneCurve::AcesFitted,
            ToneCurve::Clamp { gamma: 2.2 },
            ToneCurve::ClampSrgb,
        ] {
            for exposure_ev in [-6.0, 0.0, 2.5, 6.0] {
                let display = Display { exposure_ev, curve };
                let cpu = output::to_rgba8(&hdr, &display, background);
                let gpu_bytes = renderer
                    .render_display(&gpu.device, &gpu.queue, &camera, background, &[], &display)
                    .unwrap();
                assert_eq!(gpu_bytes.len(), cpu.len());
                for (k, (g, c)) in gpu_bytes.iter().zip(&cpu).enumerate() {
                    let d = g.abs_diff(*c);
                    assert!(
                        d <= 1,
                        "{curve:?} {exposure_ev} EV {background:?}: byte {k} (pixel {}, channel {}) \
                         GPU {g} vs CPU {c}",
                        k / 4,
                        k % 4
                    );
                    worst = worst.max(d);
                    compared += 1;
                }
            }
        }
    }
    assert!(compared > 100_000, "{compared}");
    eprintln!("GPU vs CPU tone map: worst difference {worst} code(s) over {compared} bytes");
}

#[test]
fn the_renderer_builds_the_tone_map_once_and_reuses_it() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let before = gpu_context::PipelineStats::on_this_thread();
    let camera = Camera::look_at(Vec3::new(0.0, 0.0, 3.0), Vec3::ZERO, Vec3::Y, 50.0, 16, 16);
    let display = Display::default();
    for size in [16, 16, 24] {
        let camera = Camera {
            width: size,
            height: size,
            ..camera
        };
        let bytes = renderer
            .render_display(
                &gpu.device,
                &gpu.queue,
                &camera,
                Background::Color([1.0, 0.0, 0.0]),
                &[],
                &display,
            )
            .unwrap();
        assert_eq!(bytes.len(), (4 * size * size) as usize);
        // ACES(1) = 0.804 → sRGB 0.9085 → 232; no object, so opaque background everywhere.
        assert!(
            bytes.chunks(4).all(|p| p == [232, 0, 0, 255]),
            "{:?}",
            &bytes[..4]
        );
    }
    assert_eq!(
        gpu_context::PipelineStats::on_this_thread().render_pipelines,
        before.render_pipelines,
        "no pipeline built per frame or per size"
    );
    assert!(renderer.hdr_view().is_some());
}
