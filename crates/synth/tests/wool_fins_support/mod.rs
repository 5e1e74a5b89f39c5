//! Helpers shared by the wool fin tests (`wool_fins.rs`, `wool_fins_shading.rs`).
#![allow(dead_code)] // Each test file uses a different subset.

use glam::{DVec3, Vec3};
use synth::{FinImage, WoolFinParams, WoolFins, WoolStrand};

/// d(θ, φ) = (sin θ cos φ, sin θ sin φ, cos θ), angles in degrees.
pub fn dir(theta_deg: f64, phi_deg: f64) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos()).as_vec3()
}

/// The fin of `params`, which must be valid.
pub fn fins(params: &WoolFinParams) -> WoolFins {
    WoolFins::new(params).expect("valid parameters")
}

/// The fin of hand-built `strands`, which must be valid.
pub fn custom(params: &WoolFinParams, strands: Vec<WoolStrand>) -> WoolFins {
    WoolFins::from_strands(params, strands).expect("valid strands")
}

/// Rec. 709 luminance of a pixel's colour.
pub fn luminance(p: &[f32; 4]) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// Mean of `value` over the pixels of rows `rows.0 .. rows.1`.
pub fn band_mean(image: &FinImage, rows: (usize, usize), value: impl Fn(&[f32; 4]) -> f64) -> f64 {
    let pixels = &image.rgba[rows.0 * image.width..rows.1 * image.width];
    pixels.iter().map(value).sum::<f64>() / pixels.len() as f64
}

/// The rows of the top quarter (the tips).
pub fn top_quarter(image: &FinImage) -> (usize, usize) {
    (0, image.height / 4)
}

/// The rows of the bottom quarter (the base).
pub fn bottom_quarter(image: &FinImage) -> (usize, usize) {
    (image.height - image.height / 4, image.height)
}

/// A straight strand of `segments` equal segments from `root` to `tip`.
pub fn straight(root: Vec3, tip: Vec3, segments: usize, radius: f32, colour: Vec3) -> WoolStrand {
    WoolStrand {
        points: (0..=segments)
            .map(|k| root.lerp(tip, k as f32 / segments as f32))
            .collect(),
        root_radius: radius,
        colour,
    }
}

/// The 81 light directions of thesis Tab. 5.3 (θ°, φ°).
pub fn table_5_3() -> Vec<(f64, f64)> {
    [
        (0.0, 1),
        (15.0, 6),
        (30.0, 12),
        (45.0, 18),
        (60.0, 20),
        (75.0, 24),
    ]
    .into_iter()
    .flat_map(|(theta, count)| (0..count).map(move |k| (theta, 360.0 * k as f64 / count as f64)))
    .collect()
}
