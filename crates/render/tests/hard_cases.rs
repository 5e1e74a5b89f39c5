//! The hard cases the frame defends: a sun 10⁴× the sky, non-finite radiance, degenerate and
//! empty meshes, huge coordinate offsets, a scene of zero size, scenes 10⁻⁸ to 10¹² across.

mod common;

use glam::Vec3;
use gpu_context::HdrImage;
use gpu_context::testing::gpu_or_skip;
use render::tone::{Display, ToneCurve, aces_fitted};
use render::{Background, Camera, DrawMesh, FrameFormat, Renderer, output};

#[test]
fn a_sun_ten_thousand_times_the_sky_stays_finite_and_white_and_leaves_the_sky_graded() {
    let d = Display::default();
    assert_eq!(d.map_u8(1e4), 255);
    assert_eq!(d.map_u8(f32::MAX), 255);
    // The sky at 1 and at 0.5 stay apart under the curve (not both clipped).
    assert!(d.map_u8(1.0) > d.map_u8(0.5) + 10);
    assert!(aces_fitted(1e4).is_finite());
    // The seed's clamp burns both to white.
    let seed = Display {
        curve: ToneCurve::Clamp { gamma: 2.2 },
        exposure_ev: 2.0,
    };
    assert_eq!(seed.map_u8(1.0), seed.map_u8(0.5));
}

#[test]
fn non_finite_radiance_becomes_black_or_white_never_garbage() {
    let image = HdrImage::new(
        4,
        1,
        vec![
            [f32::NAN, 0.5, 0.5, 1.0],
            [f32::INFINITY, 0.5, 0.5, 1.0],
            [f32::NEG_INFINITY, 0.5, 0.5, 1.0],
            [0.5, 0.5, 0.5, f32::NAN],
        ],
    )
    .unwrap();
    let rgba = output::to_rgba8(&image, &Display::default(), Background::Transparent);
    assert_eq!(rgba[0], 0, "NaN → 0");
    assert_eq!(rgba[4], 255, "+∞ → white");
    assert_eq!(rgba[8], 0, "−∞ → 0");
    assert_eq!(rgba[15], 0, "NaN coverage → transparent");
    // Auto exposure ignores them and stays finite.
    assert!(output::auto_exposure(&image).is_finite());
}

#[test]
fn a_scene_of_zero_size_frames_a_valid_camera() {
    let cam = Camera::framing(Vec3::ONE, 0.0, Vec3::ONE, Vec3::Z, Vec3::Y, 35.0, 64, 64);
    cam.validate().unwrap();
    assert!(cam.clip_from_world().unwrap().is_finite());
    // Up parallel to the view direction is refused, not a NaN matrix.
    let bad = Camera::framing(Vec3::ZERO, 1.0, Vec3::ZERO, Vec3::Y, Vec3::Y, 35.0, 64, 64);
    assert_eq!(bad.clip_from_world().unwrap_err().name, "up");
}

fn covered(renderer: &mut Renderer, gpu: &gpu_context::GpuContext, camera: &Camera) -> usize {
    let image = renderer
        .render(
            &gpu.device,
            &gpu.queue,
            camera,
            Background::Transparent,
            &[],
        )
        .unwrap();
    image.pixels().iter().filter(|p| p[3] > 0.5).count()
}

#[test]
fn degenerate_and_empty_meshes_draw_nothing_and_do_not_fail() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
    let c = [Vec3::ONE; 3];
    renderer
        .gouraud
        .set_meshes(
            &gpu.device,
            &gpu.queue,
            &[
                DrawMesh {
                    positions: &line,
                    triangles: &[[0, 1, 2], [1, 1, 1]],
                    front: &c,
                    back: &c,
                },
                DrawMesh {
                    positions: &[],
                    triangles: &[],
                    front: &[],
                    back: &[],
                },
            ],
        )
        .unwrap();
    let camera = Camera::look_at(Vec3::new(1.0, 0.5, 3.0), Vec3::X, Vec3::Y, 45.0, 32, 32);
    assert_eq!(covered(&mut renderer, &gpu, &camera), 0);
    renderer
        .gouraud
        .set_meshes(&gpu.device, &gpu.queue, &[])
        .unwrap();
    assert_eq!(covered(&mut renderer, &gpu, &camera), 0);
}

#[test]
fn huge_coordinate_offsets_render_the_same_coverage() {
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let mut counts = Vec::new();
    for offset in [Vec3::ZERO, Vec3::new(1e5, -3e4, 2e5)] {
        let p = [
            offset + Vec3::new(-1.0, -1.0, 0.0),
            offset + Vec3::new(1.0, -1.0, 0.0),
            offset + Vec3::new(0.0, 1.0, 0.0),
        ];
        let c = [Vec3::ONE; 3];
        common::one_mesh(&mut renderer, &gpu, &p, &[[0, 1, 2]], &c, &c).unwrap();
        let (centre, radius) = render::bounding_sphere(&p).unwrap();
        let camera = Camera::framing(centre, radius, centre, Vec3::Z, Vec3::Y, 35.0, 64, 64);
        counts.push(covered(&mut renderer, &gpu, &camera));
    }
    // f32 positions at 2e5 carry ~0.02 of absolute error on a triangle of size 2: the
    // silhouette moves by under a pixel.
    let (a, b) = (counts[0] as f32, counts[1] as f32);
    assert!(a > 500.0 && (a - b).abs() / a < 0.05, "{counts:?}");
}

#[test]
fn a_scene_at_any_scale_renders_the_same_coverage() {
    // A triangle 2·2^e across, framed by `Camera::framing`: the camera's sizes are all
    // relative, so the same pixels are covered at every scale (powers of two scale f32
    // exactly). A near plane floored at 10⁻⁴ units once clipped every scene under 10⁻⁴
    // across (the Stanford bunny scaled by 10⁻⁴ rendered empty).
    let Some(gpu) = gpu_or_skip() else { return };
    let mut renderer = Renderer::new(&gpu.device, FrameFormat::for_context(&gpu));
    let mut counts = Vec::new();
    for e in [0, -27, -14, 20, 40] {
        let s = 2f32.powi(e);
        let p = [
            Vec3::new(-1.0, -1.0, 0.3) * s,
            Vec3::new(1.0, -1.0, -0.2) * s,
            Vec3::new(0.0, 1.0, 0.0) * s,
        ];
        let c = [Vec3::ONE; 3];
        common::one_mesh(&mut renderer, &gpu, &p, &[[0, 1, 2]], &c, &c).unwrap();
        let (centre, radius) = render::bounding_sphere(&p).unwrap();
        let camera = Camera::framing(centre, radius, centre, Vec3::Z, Vec3::Y, 35.0, 64, 64);
        camera.validate().unwrap();
        counts.push((e, covered(&mut renderer, &gpu, &camera)));
    }
    let reference = counts[0].1;
    assert!(reference > 500, "{counts:?}");
    for &(e, count) in &counts {
        assert_eq!(count, reference, "scale 2^{e}: {counts:?}");
    }
}
