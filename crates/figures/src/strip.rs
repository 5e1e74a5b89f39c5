//! A strip of frames: K evenly spaced frames of an animation drawn side by side into one image,
//! all through one camera that frames the whole animation, so that motion reads as a change of
//! pose and place from panel to panel (the way the thesis shows generated sequences, Figs.
//! 3.7–3.10).
//!
//! One [`render::Renderer`] draws every panel (its pipelines are built once per strip, not per
//! panel; the mesh buffers are rewritten in place); the shading is a fixed key light
//! plus ambient on a grey Lambertian surface, two-sided, with normals computed from the
//! triangles of each frame (the clips carry none). The panels are tone-mapped with gamma 2.2
//! and copied into one RGBA8 image.

use std::path::Path;

use glam::Vec3;
use render::tone::{Display, ToneCurve};
use render::{Background, Camera, DrawMesh, FrameFormat, Renderer, bounding_sphere};

use crate::FigureError as Error;

/// Panels in a strip when not given (`--strip-frames`).
pub const DEFAULT_STRIP_FRAMES: usize = 8;
/// Most panels in one strip: 64 panels of 256 pixels are already 16,384 pixels wide.
pub const MAX_STRIP_FRAMES: usize = 64;
/// Panel size (width, height) in pixels when not given (`--strip-size`).
pub const DEFAULT_PANEL_SIZE: [u32; 2] = [256, 256];
/// Largest panel side (wgpu's guaranteed 2D texture limit).
pub const MAX_PANEL_SIDE: u32 = 8192;

/// Direction towards the key light, world space (normalised on use): above and in front,
/// from the side of the camera ([`render::camera::DEFAULT_VIEW_DIRECTION`]),
/// so that surfaces facing the viewer are lit and folds show. Chosen by eye on the synthetic
/// cloth and the horse gallop.
const KEY_LIGHT_DIRECTION: Vec3 = Vec3::new(-0.2, 0.8, 0.6);
/// Share of the albedo seen without the key light, so that surfaces turned away stay visible.
const AMBIENT: f32 = 0.25;
/// Linear grey albedo of the surface.
const ALBEDO: f32 = 0.75;

/// The indices of `count` evenly spaced frames of an animation of `total` frames: the first
/// and the last frame and equal steps between them (rounded), or frame 0 alone for one panel.
///
/// # Panics
/// If `count` is 0 or greater than `total` (callers validate both first).
pub fn strip_frame_indices(total: usize, count: usize) -> Vec<usize> {
    assert!(
        (1..=total).contains(&count),
        "strip of {count} panels from {total} frames"
    );
    if count == 1 {
        return vec![0];
    }
    (0..count)
        .map(|k| ((k * (total - 1)) as f64 / (count - 1) as f64).round() as usize)
        .collect()
}

/// Shaded linear radiance of a vertex with unit normal `n` (zero normal: ambient only) and
/// linear albedo `albedo`.
fn shade(n: Vec3, albedo: Vec3) -> Vec3 {
    let light = KEY_LIGHT_DIRECTION.normalize();
    albedo * (AMBIENT + (1.0 - AMBIENT) * n.dot(light).max(0.0))
}

/// `count` clearly distinct linear-RGB albedos, one per label (cluster pictures, thesis Figs.
/// 3.12/3.13): hues spread by the golden angle, alternating two lightness levels so that
/// neighbouring labels differ in brightness too.
pub fn label_colours(count: usize) -> Vec<Vec3> {
    (0..count)
        .map(|i| {
            let hue = (i as f32 * 0.618_034).fract() * 6.0;
            let value = if i % 2 == 0 { 0.85 } else { 0.55 };
            let x = 1.0 - ((hue % 2.0) - 1.0).abs();
            let (r, g, b) = match hue as u32 {
                0 => (1.0, x, 0.0),
                1 => (x, 1.0, 0.0),
                2 => (0.0, 1.0, x),
                3 => (0.0, x, 1.0),
                4 => (x, 0.0, 1.0),
                _ => (1.0, 0.0, x),
            };
            // sRGB-ish primaries at 85% saturation, to linear.
            let c = |v: f32| ((0.15 + 0.85 * v) * value).powf(2.2);
            Vec3::new(c(r), c(g), c(b))
        })
        .collect()
}

/// Per-vertex linear albedo from per-vertex labels in `0..count` ([`label_colours`]); a label
/// out of range is drawn mid grey.
pub fn label_albedo(labels: &[u32], count: usize) -> Vec<Vec3> {
    let colours = label_colours(count);
    labels
        .iter()
        .map(|&j| colours.get(j as usize).copied().unwrap_or(Vec3::splat(0.2)))
        .collect()
}

/// A strip of [`DEFAULT_STRIP_FRAMES`] panels (fewer for a shorter clip) of
/// [`DEFAULT_PANEL_SIZE`], each vertex coloured by its label in `0..count` ([`label_albedo`]):
/// the clusters of a compressed clip on its decoded frames (thesis Figs. 3.12/3.13).
///
/// # Errors
/// As [`render_strip`].
pub fn render_label_strip(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    frames: &[Vec<Vec3>],
    triangles: &[[u32; 3]],
    labels: &[u32],
    count: usize,
    what: &Path,
) -> Result<image::RgbaImage, Error> {
    let albedo = label_albedo(labels, count);
    render_strip(
        device,
        queue,
        frames,
        triangles,
        &StripOptions {
            count: DEFAULT_STRIP_FRAMES.min(frames.len()).max(1),
            panel_size: DEFAULT_PANEL_SIZE,
            albedo: Some(&albedo),
        },
        what,
    )
}

/// What a strip shows: how many panels, their size, and the vertex colours.
#[derive(Clone, Copy, Debug)]
pub struct StripOptions<'a> {
    /// Panels (evenly spaced frames).
    pub count: usize,
    /// Size (width, height) of one panel in pixels.
    pub panel_size: [u32; 2],
    /// Linear albedo per vertex (e.g. [`label_colours`] by cluster); `None` draws grey.
    pub albedo: Option<&'a [Vec3]>,
}

/// Renders `options.count` evenly spaced frames of `frames` ([`strip_frame_indices`]) side by side,
/// each `panel_size` pixels, into one RGBA8 image `count · width` × `height`, through one
/// camera framing the bounding sphere of every frame's vertices that `triangles` use.
/// `options.albedo` gives each vertex its own linear colour; `None` draws the default grey.
///
/// # Errors
/// [`Error::Request`] (naming `what`) when there are no frames or triangles, `count` is not in
/// 1..=min([`MAX_STRIP_FRAMES`], frames) or a panel side is not in 1..=[`MAX_PANEL_SIDE`];
/// [`Error::Render`] when rendering fails.
pub fn render_strip(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    frames: &[Vec<Vec3>],
    triangles: &[[u32; 3]],
    options: &StripOptions<'_>,
    what: &Path,
) -> Result<image::RgbaImage, Error> {
    let StripOptions {
        count,
        panel_size,
        albedo,
    } = *options;
    check_strip(frames.len(), count, panel_size, what)?;
    if let Some(a) = albedo.filter(|a| a.len() != frames[0].len()) {
        return Err(Error::Request {
            path: what.to_owned(),
            message: format!(
                "{} vertex colours for {} vertices",
                a.len(),
                frames[0].len()
            ),
        });
    }
    if triangles.is_empty() {
        return Err(Error::Request {
            path: what.to_owned(),
            message: "a strip needs triangles to draw, and the animation has none (an .npy \
                      without topology)"
                .to_owned(),
        });
    }
    let used = used_vertices(frames[0].len(), triangles);
    let (centre, radius) =
        bounding_sphere(frames.iter().flat_map(|f| used.iter().map(move |&i| &f[i])))
            .unwrap_or((Vec3::ZERO, 1.0));
    let [width, height] = panel_size;
    let camera = Camera::framing(
        centre,
        radius,
        centre,
        render::camera::DEFAULT_VIEW_DIRECTION,
        Vec3::Y,
        render::camera::DEFAULT_FOV_Y_DEG,
        width,
        height,
    );
    // The seed's display mapping: the strip's shading is bounded by 1, no filmic curve needed.
    let display = Display {
        exposure_ev: 0.0,
        curve: ToneCurve::Clamp { gamma: 2.2 },
    };
    let mut renderer = Renderer::new(device, FrameFormat::single_sample(device));
    let mut strip = image::RgbaImage::new(width * count as u32, height);
    for (panel, &index) in strip_frame_indices(frames.len(), count).iter().enumerate() {
        let positions = &frames[index];
        let normals = meshio::compute_normals(positions, triangles, meshio::NormalWeighting::Angle);
        let colour = |m: usize| albedo.map_or(Vec3::splat(ALBEDO), |a| a[m]);
        let front: Vec<Vec3> = normals
            .iter()
            .enumerate()
            .map(|(m, n)| shade(*n, colour(m)))
            .collect();
        let back: Vec<Vec3> = normals
            .iter()
            .enumerate()
            .map(|(m, n)| shade(-*n, colour(m)))
            .collect();
        let mesh = DrawMesh {
            positions,
            triangles,
            front: &front,
            back: &back,
        };
        renderer.gouraud.set_meshes(device, queue, &[mesh])?;
        let background = Background::Color([0.0; 3]);
        let image = renderer.render(device, queue, &camera, background, &[])?;
        let rgba = render::output::to_rgba8(&image, &display, background);
        let x0 = panel as u32 * width;
        for (i, px) in rgba.chunks_exact(4).enumerate() {
            let (x, y) = (i as u32 % width, i as u32 / width);
            strip.put_pixel(x0 + x, y, image::Rgba([px[0], px[1], px[2], 255]));
        }
    }
    Ok(strip)
}

/// Checks a strip request before any work: `count` panels of `panel_size` from `frames`
/// frames, naming `what` in the error.
///
/// # Errors
/// [`Error::Request`] as [`render_strip`] describes.
pub fn check_strip(
    frames: usize,
    count: usize,
    panel_size: [u32; 2],
    what: &Path,
) -> Result<(), Error> {
    let invalid = |message: String| Error::Request {
        path: what.to_owned(),
        message,
    };
    if frames == 0 {
        return Err(invalid("a strip needs at least one frame".to_owned()));
    }
    if !(1..=MAX_STRIP_FRAMES.min(frames)).contains(&count) {
        return Err(invalid(format!(
            "--strip-frames {count}: a strip shows 1..={} frames (at most {MAX_STRIP_FRAMES}, \
             and no more than the {frames} frames generated)",
            MAX_STRIP_FRAMES.min(frames)
        )));
    }
    let [w, h] = panel_size;
    if !(1..=MAX_PANEL_SIDE).contains(&w) || !(1..=MAX_PANEL_SIDE).contains(&h) {
        return Err(invalid(format!(
            "--strip-size {w}x{h}: each panel side must be 1..={MAX_PANEL_SIDE}"
        )));
    }
    Ok(())
}

/// Writes `image` as a PNG that appears complete or not at all.
///
/// # Errors
/// [`Error::Gpu`] (gpu-context's image output) naming the file when writing fails.
pub fn write_png(path: &Path, image: &image::RgbaImage) -> Result<(), Error> {
    gpu_context::write_rgba8_png(path, image.as_raw(), image.width(), image.height())?;
    Ok(())
}

/// Indices of the vertices some triangle uses, ascending.
fn used_vertices(n: usize, triangles: &[[u32; 3]]) -> Vec<usize> {
    let mut used = vec![false; n];
    for &i in triangles.iter().flatten() {
        if let Some(u) = used.get_mut(i as usize) {
            *u = true;
        }
    }
    (0..n).filter(|&i| used[i]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_run_from_the_first_to_the_last_frame_in_even_steps() {
        assert_eq!(strip_frame_indices(10, 1), vec![0]);
        assert_eq!(strip_frame_indices(10, 2), vec![0, 9]);
        assert_eq!(strip_frame_indices(9, 5), vec![0, 2, 4, 6, 8]);
        assert_eq!(strip_frame_indices(300, 8).last(), Some(&299));
        let all = strip_frame_indices(7, 7);
        assert_eq!(all, (0..7).collect::<Vec<_>>());
    }

    #[test]
    fn the_lit_side_is_brighter_and_nothing_is_black() {
        let l = KEY_LIGHT_DIRECTION.normalize();
        assert!((shade(l, Vec3::splat(ALBEDO)).x - ALBEDO).abs() < 1e-6);
        assert!((shade(-l, Vec3::splat(ALBEDO)).x - ALBEDO * AMBIENT).abs() < 1e-6);
        assert_eq!(shade(Vec3::ZERO, Vec3::splat(ALBEDO)).x, ALBEDO * AMBIENT);
    }

    #[test]
    fn bad_strips_are_refused_naming_the_flag() {
        let p = Path::new("s.png");
        let e = check_strip(10, 0, DEFAULT_PANEL_SIZE, p).unwrap_err();
        assert!(e.to_string().contains("--strip-frames 0"), "{e}");
        let e = check_strip(10, 11, DEFAULT_PANEL_SIZE, p).unwrap_err();
        assert!(e.to_string().contains("10 frames"), "{e}");
        let e = check_strip(10, 4, [0, 64], p).unwrap_err();
        assert!(e.to_string().contains("--strip-size 0x64"), "{e}");
        assert!(check_strip(10, 10, [64, 64], p).is_ok());
    }
}
