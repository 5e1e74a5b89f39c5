//! A strip drawn on the GPU: each panel shows its own frame, where a CPU projection through
//! the same camera says it is.

use figures::strip::{StripOptions, render_strip};
use glam::Vec3;
use gpu_context::testing::gpu_or_skip;

/// A unit square in the z = 0 plane at horizontal offset `x`.
fn square(x: f32) -> Vec<Vec3> {
    vec![
        Vec3::new(x - 0.5, -0.5, 0.0),
        Vec3::new(x + 0.5, -0.5, 0.0),
        Vec3::new(x + 0.5, 0.5, 0.0),
        Vec3::new(x - 0.5, 0.5, 0.0),
    ]
}

/// Mean horizontal pixel position of the lit pixels of panel `panel`, in panel pixels.
fn lit_centre(image: &image::RgbaImage, panel: u32, width: u32) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for y in 0..image.height() {
        for x in 0..width {
            if image.get_pixel(panel * width + x, y)[0] > 20 {
                sum += f64::from(x);
                n += 1;
            }
        }
    }
    assert!(n > 50, "panel {panel} shows the square ({n} lit pixels)");
    sum / n as f64
}

#[test]
fn each_panel_shows_its_frame_through_one_camera() {
    let Some(gpu) = gpu_or_skip() else { return };
    // Three frames of a square sliding from x = -1 to x = +1.
    let frames: Vec<Vec<Vec3>> = [-1.0, 0.0, 1.0].into_iter().map(square).collect();
    let triangles = [[0, 1, 2], [0, 2, 3]];
    let (w, h) = (96, 64);
    let image = render_strip(
        &gpu.device,
        &gpu.queue,
        &frames,
        &triangles,
        &StripOptions {
            count: 3,
            panel_size: [w, h],
            albedo: None,
        },
        std::path::Path::new("strip.png"),
    )
    .unwrap();
    assert_eq!(image.dimensions(), (3 * w, h));
    let centres: Vec<f64> = (0..3).map(|p| lit_centre(&image, p, w)).collect();
    // One camera frames all frames, so the square moves across the panels; the middle frame
    // sits at the centre of the bounding sphere, hence of the panel (within two pixels).
    assert!(
        (centres[1] - f64::from(w - 1) / 2.0).abs() < 2.0,
        "{centres:?}"
    );
    // The camera looks from +z, a little right and above, so world +x is screen right.
    assert!(
        centres[0] < centres[1] && centres[1] < centres[2],
        "{centres:?}"
    );
    assert!((centres[2] - centres[0]).abs() > 10.0, "{centres:?}");
}
