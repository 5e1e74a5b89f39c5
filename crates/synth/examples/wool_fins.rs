//! Renders the 81 images of a procedural wool fin BTF in the lighting of thesis Tab. 5.3
//! (fixed grazing view θ_V = 90°, φ_V = 0°; lights at θ_L ∈ {0, 15, 30, 45, 60, 75}° with
//! 1, 6, 12, 18, 20 and 24 azimuths φ_L = k·360°/count) and prints the time and summary
//! statistics (this crate has no image dependency, so nothing is written):
//!
//! ```text
//! cargo run --release -p synth --example wool_fins -- [WIDTH] [HEIGHT] [SUPERSAMPLE]
//! ```
//!
//! * the time to build the fin (strands, fixed-view hits, shadow grid) and to shade the
//!   81 images;
//! * the mean alpha of four bands of rows, top (tips) to bottom (base);
//! * per light ring: the mean and the range of the pixels' luminance, and the mean
//!   luminance with the light in front of (φ_L = 0°) and behind (φ_L = 180°) the fibres.
//!
//! Measured on the shared 2-core development machine (other jobs running), default
//! parameters (128² × 2²): 2.0–2.2 s for the 81 images on both cores, 3.8 s on one thread
//! (details in the `synth::fins` module documentation). The strand count stays at its
//! default, so a wider image is less densely covered.

use glam::Vec3;
use std::error::Error;
use std::time::Instant;
use synth::{FinImage, WoolFinParams, WoolFins};

/// (θ_L in degrees, number of azimuths) of thesis Tab. 5.3.
const RINGS: [(f32, u32); 6] = [
    (0.0, 1),
    (15.0, 6),
    (30.0, 12),
    (45.0, 18),
    (60.0, 20),
    (75.0, 24),
];

fn direction(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (theta, phi) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    )
}

/// Rec. 709 luminance of a linear RGB pixel.
fn luminance(p: &[f32; 4]) -> f32 {
    0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
}

fn mean_luminance(image: &FinImage) -> f64 {
    image
        .rgba
        .iter()
        .map(|p| f64::from(luminance(p)))
        .sum::<f64>()
        / image.rgba.len() as f64
}

fn main() -> Result<(), Box<dyn Error>> {
    let mut args = std::env::args().skip(1);
    let mut number = |default: usize| -> Result<usize, Box<dyn Error>> {
        match args.next() {
            Some(arg) => Ok(arg.parse()?),
            None => Ok(default),
        }
    };
    let params = WoolFinParams {
        width: number(128)?,
        height: number(128)?,
        supersample: number(2)?,
        ..Default::default()
    };

    let start = Instant::now();
    let fins = WoolFins::new(&params)?;
    let build = start.elapsed().as_secs_f64();
    let mut images = Vec::new();
    for (theta, count) in RINGS {
        for k in 0..count {
            let phi = 360.0 * k as f32 / count as f32;
            images.push((theta, phi, fins.image(direction(theta, phi))));
        }
    }
    let total = start.elapsed().as_secs_f64();
    assert_eq!(images.len(), 81);
    println!(
        "{w}×{h} pixels × {n}² sub-samples, {s} strands: build {build:.2} s, 81 images {:.2} s, total {total:.2} s",
        total - build,
        w = params.width,
        h = params.height,
        n = params.supersample,
        s = params.strands,
    );

    let (width, height) = (params.width, params.height);
    let bands: Vec<String> = (0..4)
        .map(|band| {
            let rows = band * height / 4..((band + 1) * height / 4).max(band * height / 4 + 1);
            let rows = rows.start.min(height - 1)..rows.end.min(height);
            let values = &fins.alpha()[rows.start * width..rows.end * width];
            format!("{:.3}", values.iter().sum::<f32>() / values.len() as f32)
        })
        .collect();
    println!(
        "mean alpha per row band, top to bottom: {}",
        bands.join(", ")
    );

    for (theta, _) in RINGS {
        let ring: Vec<&(f32, f32, FinImage)> =
            images.iter().filter(|(t, _, _)| *t == theta).collect();
        let (mut low, mut high) = (f32::INFINITY, f32::NEG_INFINITY);
        for (_, _, image) in &ring {
            for p in &image.rgba {
                low = low.min(luminance(p));
                high = high.max(luminance(p));
            }
        }
        let mean = ring
            .iter()
            .map(|(_, _, image)| mean_luminance(image))
            .sum::<f64>()
            / ring.len() as f64;
        let at = |phi: f32| {
            ring.iter()
                .find(|(_, p, _)| *p == phi)
                .map_or("-".to_string(), |(_, _, image)| {
                    format!("{:.4}", mean_luminance(image))
                })
        };
        println!(
            "θ_L {theta:>2}°: mean luminance {mean:.4}, range [{low:.4}, {high:.4}], φ_L = 0°: {}, φ_L = 180°: {}",
            at(0.0),
            at(180.0),
        );
    }
    Ok(())
}
